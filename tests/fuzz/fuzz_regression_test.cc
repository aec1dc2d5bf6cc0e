// Replays the committed fuzz corpus and every input a fuzzer once crashed on
// through the fuzz entry points, in the ordinary (unsanitised) build, so CI
// checks them without clang. Inputs live in tests/fuzz/{corpus,regressions}/
// <target>/; regressions/README.md says what each one found.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "tests/fuzz/fuzz_entries.h"

namespace adse::fuzz {
namespace {

namespace fs = std::filesystem;

// ADSE_FUZZ_INPUT=<file> replays that one file instead, to find which input
// of a set a report comes from.
std::vector<fs::path> InputsOf(const std::string& target) {
  std::vector<fs::path> files;
  if (const char* one = std::getenv("ADSE_FUZZ_INPUT")) {
    if (fs::path(one).parent_path().filename() == target) files.push_back(one);
    return files;
  }
  for (const char* set : {"corpus", "regressions"}) {
    const fs::path dir =
        fs::path(ADSE_SOURCE_DIR) / "tests/fuzz" / set / target;
    if (!fs::is_directory(dir)) continue;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
      if (entry.is_regular_file() && entry.path().filename() != "README.md") {
        files.push_back(entry.path());
      }
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<uint8_t> ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

template <typename Entry>
void ReplayAll(const std::string& target, size_t min_inputs, Entry entry) {
  const std::vector<fs::path> inputs = InputsOf(target);
  if (std::getenv("ADSE_FUZZ_INPUT") == nullptr) {
    ASSERT_GE(inputs.size(), min_inputs)
        << "corpus of " << target << " missing";
  }
  for (const fs::path& input : inputs) {
    SCOPED_TRACE(input.string());
    const std::vector<uint8_t> bytes = ReadBytes(input);
    const Status status = entry(bytes.data(), bytes.size());
    EXPECT_TRUE(status.ok()) << status.ToString();
  }
}

TEST(FuzzRegression, EverySpecInputParsesOrIsRejectedAndRoundTrips) {
  ReplayAll("spec", 10, FuzzSpecParser);
}

TEST(FuzzRegression, EveryRunFileInputIsReadOrRejectedWithoutCrashing) {
  ReplayAll("run_file", 3, FuzzRunFile);
}

}  // namespace
}  // namespace adse::fuzz
