// Scenario files for the end-to-end CLI tests: the robotaxi example, and
// copies of them with a line changed, written beside the calibration and
// profile they name relative to themselves.
#ifndef ADSE_TESTS_HARNESS_CLI_EXAMPLE_FILES_H_
#define ADSE_TESTS_HARNESS_CLI_EXAMPLE_FILES_H_

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "tests/testing/temp_files.h"

namespace adse::testing {

inline std::string Example() {
  return std::string(ADSE_SOURCE_DIR) + "/scenarios/robotaxi_parking_lot.yaml";
}

// Writes scenario text to the test's scratch folder as adse_cli_<name>.yaml,
// with the bundled calibration and profiles beside it (the examples name
// them relative to themselves).
inline std::string WriteScenario(const std::string& name,
                                 const std::string& text) {
  namespace fs = std::filesystem;
  const fs::path path = TestScratch() / ("adse_cli_" + name + ".yaml");
  std::ofstream(path) << text;
  for (const char* file : {"calibration/reference.json",
                           "profiles/autoware-2022.12-i9-12900kf.yaml",
                           "profiles/autoware-2022.12-i9-12900kf-valet.yaml"}) {
    const fs::path to = TestScratch() / file;
    fs::create_directories(to.parent_path());
    fs::copy_file(std::string(ADSE_SOURCE_DIR) + "/scenarios/" + file, to,
                  fs::copy_options::overwrite_existing);
  }
  return path.string();
}

// The text of the file at `path`.
inline std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  return std::string((std::istreambuf_iterator<char>(in)),
                     std::istreambuf_iterator<char>());
}

// `text` with its first `from` replaced by `to`; a failure when it has none.
inline std::string Replaced(std::string text, const std::string& from,
                            const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// A copy of the robotaxi example with one line replaced.
inline std::string Variant(const std::string& name, const std::string& from,
                           const std::string& to) {
  return WriteScenario(name, Replaced(ReadText(Example()), from, to));
}

}  // namespace adse::testing

#endif  // ADSE_TESTS_HARNESS_CLI_EXAMPLE_FILES_H_
