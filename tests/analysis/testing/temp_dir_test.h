// A fixture that gives each test a fresh temporary folder, removed after it.
#ifndef ADSE_TESTS_ANALYSIS_TESTING_TEMP_DIR_TEST_H_
#define ADSE_TESTS_ANALYSIS_TESTING_TEMP_DIR_TEST_H_

#include <stdlib.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include <gtest/gtest.h>

namespace adse::testing {

class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = ::testing::TempDir() + "adse_test_XXXXXX";
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  std::string Path(const std::string& name) const {
    return (std::filesystem::path(dir_) / name).string();
  }
  // The folder's entries, sorted: names, or with `recursive` every entry
  // below it as a path relative to it.
  std::vector<std::string> Listing(bool recursive = false) const {
    namespace fs = std::filesystem;
    std::vector<std::string> names;
    if (recursive) {
      for (const auto& e : fs::recursive_directory_iterator(dir_)) {
        names.push_back(fs::relative(e.path(), dir_).string());
      }
    } else {
      for (const auto& e : fs::directory_iterator(dir_)) {
        names.push_back(e.path().filename().string());
      }
    }
    std::sort(names.begin(), names.end());
    return names;
  }

  std::string dir_;
};

}  // namespace adse::testing

#endif  // ADSE_TESTS_ANALYSIS_TESTING_TEMP_DIR_TEST_H_
