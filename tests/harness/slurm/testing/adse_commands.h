// Running the adse binary as a user does, on scenario copies written for a
// test, for the Slurm tests.
#ifndef ADSE_TESTS_HARNESS_SLURM_TESTING_ADSE_COMMANDS_H_
#define ADSE_TESTS_HARNESS_SLURM_TESTING_ADSE_COMMANDS_H_

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "stack/base/files.h"
#include "stack/base/subprocess.h"
#include "tests/testing/temp_files.h"

namespace adse::slurm::testing {

inline std::string AdseBinary() {
  return std::string(ADSE_BINARY_DIR) + "/bin/adse";
}

struct AdseRun {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

// `adse <args>`; `env` are NAME=VALUE settings (NAME= alone unsets it)
// applied through env(1).
inline AdseRun Adse(const std::vector<std::string>& args,
                    const std::vector<std::string>& env = {}) {
  std::vector<std::string> argv;
  if (!env.empty()) {
    argv.push_back("env");
    for (const std::string& e : env) {
      if (e.back() == '=') {
        argv.push_back("-u");
        argv.push_back(e.substr(0, e.size() - 1));
      } else {
        argv.push_back(e);
      }
    }
  }
  argv.push_back(AdseBinary());
  argv.insert(argv.end(), args.begin(), args.end());
  Result<ProcessResult> r = RunProcess(argv, 1 << 20);
  EXPECT_TRUE(r.ok()) << r.status().message();
  if (!r.ok()) return {};
  return {r->exit_code, r->output};
}

// A fresh folder for one test (removed first if a failed run left it),
// removed again once the test passed; a failed one's is the evidence.
class TestFolder {
 public:
  explicit TestFolder(const std::string& name)
      : path_(adse::testing::FreshTempDir("adse-slurm-test", name)) {}
  TestFolder(const TestFolder&) = delete;
  TestFolder& operator=(const TestFolder&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// scenarios/robotaxi_small.yaml copied into `dir` (with the calibration it
// names), its exploration line replaced and `harness` added.
inline std::string SmallScenarioIn(const std::string& dir,
                                   const std::string& exploration,
                                   const std::string& harness) {
  namespace fs = std::filesystem;
  const std::string source = ADSE_SOURCE_DIR;
  std::string text =
      ReadFile(source + "/scenarios/robotaxi_small.yaml").value();
  const std::string from = "exploration: {strategy: exhaustive, budget: 12}";
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "robotaxi_small.yaml changed";
  if (at != std::string::npos) {
    text.replace(at, from.size(),
                 "exploration: " + exploration + "\nharness: " + harness);
  }
  // The files the scenario names relative to itself.
  for (const char* file : {"calibration/reference.json",
                           "profiles/autoware-2022.12-i9-12900kf.yaml"}) {
    fs::create_directories(fs::path(dir + "/" + file).parent_path());
    fs::copy_file(source + "/scenarios/" + file, dir + "/" + file,
                  fs::copy_options::overwrite_existing);
  }
  const std::string path = dir + "/scenario.yaml";
  std::ofstream(path) << text;
  return path;
}

}  // namespace adse::slurm::testing

#endif  // ADSE_TESTS_HARNESS_SLURM_TESTING_ADSE_COMMANDS_H_
