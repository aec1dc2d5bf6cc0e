// Tests that make scratch folders and pass or fail, for temp_files_test:
// each prints the folders it made ("made <path>").
#include <filesystem>
#include <fstream>
#include <iostream>

#include <gtest/gtest.h>

#include "tests/testing/temp_files.h"

namespace {

namespace fs = std::filesystem;

class ScratchProbe : public ::testing::Test {
 protected:
  // Made outside any test: the program's, kept until its end.
  static void SetUpTestSuite() {
    suite_dir_ = adse::testing::FreshTempDir("adse-probe-suite", "shared");
    std::cout << "made " << suite_dir_ << std::endl;
  }

  // The folders a test makes, each holding a file, announced.
  void MakeFolders() {
    const fs::path scratch = adse::testing::TestScratch();
    std::ofstream(scratch / "file") << "kept while the test runs";
    // The same folder for the rest of the test, its files kept.
    EXPECT_EQ(adse::testing::TestScratch(), scratch);
    EXPECT_TRUE(fs::exists(scratch / "file"));
    const std::string named = adse::testing::TestTempDir("adse-probe");
    EXPECT_TRUE(fs::is_directory(named));
    EXPECT_TRUE(fs::is_directory(suite_dir_));
    std::cout << "made " << scratch.string() << "\nmade " << named << std::endl;
  }

  static std::string suite_dir_;
};

std::string ScratchProbe::suite_dir_;

TEST_F(ScratchProbe, Passes) { MakeFolders(); }

TEST_F(ScratchProbe, Fails) {
  MakeFolders();
  ADD_FAILURE() << "fails on purpose";
}

}  // namespace
