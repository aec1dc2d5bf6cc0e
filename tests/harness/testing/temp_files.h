// Scratch folders and raw file access for tests.
#ifndef ADSE_TESTS_HARNESS_TESTING_TEMP_FILES_H_
#define ADSE_TESTS_HARNESS_TESTING_TEMP_FILES_H_

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace adse::testing {

// An empty folder <tmp>/<prefix>-<name>-<pid>, emptied if it existed.
inline std::string FreshTempDir(const std::string& prefix,
                                const std::string& name) {
  namespace fs = std::filesystem;
  const std::string dir = fs::temp_directory_path().string() + "/" + prefix +
                          "-" + name + "-" + std::to_string(::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// FreshTempDir named after the running test.
inline std::string TestTempDir(const std::string& prefix) {
  return FreshTempDir(
      prefix, ::testing::UnitTest::GetInstance()->current_test_info()->name());
}

// Writes `text` exactly (no atomic rename: tests use it to plant damage).
inline void WriteRaw(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

// The whole file; empty when it cannot be read.
inline std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in),
                     std::istreambuf_iterator<char>());
}

}  // namespace adse::testing

#endif  // ADSE_TESTS_HARNESS_TESTING_TEMP_FILES_H_
