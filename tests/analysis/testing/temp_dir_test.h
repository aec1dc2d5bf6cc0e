// A fixture that gives each test a fresh temporary folder (its scratch
// folder, removed once it passes).
#ifndef ADSE_TESTS_ANALYSIS_TESTING_TEMP_DIR_TEST_H_
#define ADSE_TESTS_ANALYSIS_TESTING_TEMP_DIR_TEST_H_

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/testing/temp_files.h"

namespace adse::testing {

class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = TestScratch().string(); }
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
