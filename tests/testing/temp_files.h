// Scratch folders and raw file access for tests.
#ifndef ADSE_TESTS_TESTING_TEMP_FILES_H_
#define ADSE_TESTS_TESTING_TEMP_FILES_H_

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

namespace adse::testing {
namespace internal {

// Removes the scratch folders a test made once it has passed, and keeps
// those of a test that failed, naming them, to be looked into. Folders made
// outside a test (a suite's set-up) go when the whole program has passed.
// Only the process that made a folder removes it: a forked child that
// returns through gtest must not take its parent's folders.
class ScratchCleaner : public ::testing::EmptyTestEventListener {
 public:
  // The one cleaner of this process, appended to gtest's listeners (which
  // own it) on first use.
  static ScratchCleaner& Get() {
    static ScratchCleaner* const cleaner = [] {
      auto* c = new ScratchCleaner;
      ::testing::UnitTest::GetInstance()->listeners().Append(c);
      return c;
    }();
    return *cleaner;
  }

  void Add(const std::string& dir) {
    const bool in_test =
        ::testing::UnitTest::GetInstance()->current_test_info() != nullptr;
    (in_test ? test_dirs_ : program_dirs_).push_back(dir);
  }

  // The running test's scratch folder once made (see TestScratch), else
  // empty; made outside a test, the program's.
  std::string& scratch() {
    return ::testing::UnitTest::GetInstance()->current_test_info() != nullptr
               ? test_scratch_
               : program_scratch_;
  }

  void OnTestEnd(const ::testing::TestInfo& info) override {
    Settle(info.result()->Failed(), "test", &test_dirs_);
    test_scratch_.clear();
  }
  void OnTestProgramEnd(const ::testing::UnitTest& unit) override {
    Settle(unit.Failed(), "test program", &program_dirs_);
  }

 private:
  void Settle(bool failed, const char* what,
              std::vector<std::string>* dirs) const {
    if (::getpid() != owner_) return;
    for (const std::string& dir : *dirs) {
      if (failed) {
        std::fprintf(stderr, "scratch folder kept for the failed %s: %s\n",
                     what, dir.c_str());
      } else {
        std::error_code ec;
        std::filesystem::remove_all(dir, ec);
      }
    }
    dirs->clear();
  }

  const pid_t owner_ = ::getpid();
  std::vector<std::string> test_dirs_;
  std::vector<std::string> program_dirs_;
  std::string test_scratch_;
  std::string program_scratch_;
};

}  // namespace internal

// An empty folder <tmp>/<prefix>-<name>-<pid>, emptied if it existed, and
// removed after the test that made it passes.
inline std::string FreshTempDir(const std::string& prefix,
                                const std::string& name) {
  namespace fs = std::filesystem;
  std::string leaf = name;  // a parameterised test's name holds a '/'
  std::replace(leaf.begin(), leaf.end(), '/', '_');
  const std::string dir = fs::temp_directory_path().string() + "/" + prefix +
                          "-" + leaf + "-" + std::to_string(::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  internal::ScratchCleaner::Get().Add(dir);
  return dir;
}

// FreshTempDir named after the running test.
inline std::string TestTempDir(const std::string& prefix) {
  return FreshTempDir(
      prefix, ::testing::UnitTest::GetInstance()->current_test_info()->name());
}

// The running test's own scratch folder, <tmp>/adse-<test>-<pid>: made
// empty on first use in the test, the same folder for the rest of it, and
// removed after it passes. Tests put their fixed-name files here rather
// than in <tmp> itself, so that they neither pile up nor meet another
// test's (or another checkout's) files of the same name. Outside a test,
// the program's: <tmp>/adse-test-<pid>.
inline std::filesystem::path TestScratch() {
  std::string& scratch = internal::ScratchCleaner::Get().scratch();
  if (scratch.empty()) {
    const ::testing::TestInfo* test =
        ::testing::UnitTest::GetInstance()->current_test_info();
    scratch = FreshTempDir("adse", test != nullptr ? test->name() : "test");
  }
  return scratch;
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

#endif  // ADSE_TESTS_TESTING_TEMP_FILES_H_
