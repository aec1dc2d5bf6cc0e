#include "tests/testing/temp_files.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "stack/base/subprocess.h"

namespace adse::testing {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

struct Probe {
  int exit_code = -1;
  std::string output;
  std::vector<std::string> folders;  // every "made <path>" it printed
};

// The probe's tests matching `filter`, with its temporary folder in this
// test's scratch folder.
Probe RunProbe(const std::string& filter) {
  const std::string tmp = (TestScratch() / "tmp").string();
  fs::create_directories(tmp);
  Result<ProcessResult> r = RunProcess(
      {"env", "TMPDIR=" + tmp, ADSE_SCRATCH_PROBE, "--gtest_filter=" + filter});
  EXPECT_TRUE(r.ok()) << r.status().message();
  if (!r.ok()) return {};
  Probe probe{r->exit_code, r->output, {}};
  std::istringstream lines(r->output);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("made ", 0) == 0) probe.folders.push_back(line.substr(5));
  }
  return probe;
}

TEST(TempFilesTest, APassedTestsFoldersAreRemovedOnceItEnds) {
  const Probe probe = RunProbe("ScratchProbe.Passes");
  EXPECT_EQ(probe.exit_code, 0) << probe.output;
  ASSERT_EQ(probe.folders.size(), 3u) << probe.output;
  for (const std::string& folder : probe.folders) {
    EXPECT_FALSE(fs::exists(folder)) << folder;
  }
  EXPECT_THAT(probe.output, ::testing::Not(HasSubstr("kept")));
}

TEST(TempFilesTest, AFailedTestsFoldersAreKeptAndNamed) {
  const Probe probe = RunProbe("ScratchProbe.*");
  EXPECT_NE(probe.exit_code, 0) << probe.output;
  // The suite's folder, then two for each of the two tests.
  ASSERT_EQ(probe.folders.size(), 5u) << probe.output;
  const std::string suite = probe.folders[0];
  const std::vector<std::string> passed = {probe.folders[1], probe.folders[2]};
  const std::vector<std::string> failed = {probe.folders[3], probe.folders[4]};
  for (const std::string& folder : passed) {
    EXPECT_FALSE(fs::exists(folder)) << folder;
  }
  for (const std::string& folder : failed) {
    EXPECT_TRUE(fs::exists(folder)) << folder;
    EXPECT_THAT(
        probe.output,
        HasSubstr("scratch folder kept for the failed test: " + folder));
  }
  EXPECT_TRUE(fs::exists(fs::path(failed[0]) / "file"));
  // The program failed, so what it made outside its tests stays too.
  EXPECT_TRUE(fs::exists(suite)) << suite;
  EXPECT_THAT(
      probe.output,
      HasSubstr("scratch folder kept for the failed test program: " + suite));
}

}  // namespace
}  // namespace adse::testing
