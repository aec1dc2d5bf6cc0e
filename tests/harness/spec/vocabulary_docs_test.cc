// Every vocabulary of the scenario format appears in scenarios/README.md
// exactly as the parser knows it (same values, same order), and every map
// generator parameter with its range and default. The lists are the single
// source; this test keeps the docs from drifting away from them.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "harness/pool/worker_pool.h"
#include "harness/spec/spec_parser.h"
#include "harness/spec/types.h"
#include "stack/base/platform_limits.h"
#include "stack/runtime/executor.h"
#include "stack/world/world_options.h"

namespace adse::spec {
namespace {

std::string Reference() {
  std::ifstream in(std::string(ADSE_SOURCE_DIR) + "/scenarios/README.md");
  EXPECT_TRUE(in) << "scenarios/README.md is missing";
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// "`a` \| `b` \| `c`", as the reference's type column writes a choice.
std::string Choice(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& name : names) {
    if (!out.empty()) out += " \\| ";
    out += "`" + name + "`";
  }
  return out;
}

// The table row documenting `field` ("| `field` | ..."), or "".
std::string RowOf(const std::string& doc, const std::string& field,
                  const std::string& containing) {
  const std::string start = "| `" + field + "` |";
  for (size_t at = doc.find(start); at != std::string::npos;
       at = doc.find(start, at + 1)) {
    const std::string row = doc.substr(at, doc.find('\n', at) - at);
    if (row.find(containing) != std::string::npos) return row;
  }
  return "";
}

TEST(VocabularyDocsTest, EveryChoiceIsDocumentedAsTheParserKnowsIt) {
  const std::string doc = Reference();
  const struct {
    const char* field;
    std::vector<std::string> names;
  } kChoices[] = {
      {"map.generate", world::MapGeneratorNames()},
      {"weather", world::WeatherNames()},
      {"kind", world::TaskKindNames()},
      {"kind", PlatformKindNames()},
      {"cost_model", CostModelNames()},
      {"clock_by", ClockByNames()},
      {"dispatch", DispatchNames()},
      {"strategy", StrategyNames()},
      {"backend", LlmBackendNames()},
      {"isolation", pool::IsolationNames()},
      {"executor", ExecutorNames()},
      {"role", KnobRoleNames()},
  };
  for (const auto& choice : kChoices) {
    ASSERT_GE(choice.names.size(), 2u) << choice.field;
    EXPECT_NE(RowOf(doc, choice.field, Choice(choice.names)), "")
        << "scenarios/README.md has no row `" << choice.field
        << "` listing exactly " << Choice(choice.names);
  }
}

TEST(VocabularyDocsTest, TheStrategyListIncludesTheLanguageModelStrategy) {
  EXPECT_TRUE(IsStrategyName(kLlmStrategy));
  EXPECT_TRUE(IsStrategyName("exhaustive"));
  EXPECT_FALSE(IsStrategyName("LLM"));
}

// The generator table: "| `grid` | `number` | integer | 2 … 12 | 3 |", the
// generator cell left empty after its first parameter.
TEST(VocabularyDocsTest,
     EveryGeneratorParameterIsDocumentedWithRangeAndDefault) {
  const std::string doc = Reference();
  for (const std::string& generator : world::MapGeneratorNames()) {
    const auto* params = world::MapGeneratorParams(generator);
    ASSERT_NE(params, nullptr) << generator;
    for (const world::MapGeneratorParam& param : *params) {
      const std::string cell = "| `" + std::string(param.name) + "` |";
      const size_t at = doc.find(cell);
      ASSERT_NE(at, std::string::npos)
          << generator << "." << param.name << " is not documented";
      const size_t begin = doc.rfind('\n', at) + 1;
      std::vector<std::string> cells;
      std::stringstream row(doc.substr(begin, doc.find('\n', at) - begin));
      for (std::string c; std::getline(row, c, '|');) cells.push_back(c);
      // "", generator, name, type, range, default
      ASSERT_GE(cells.size(), 6u) << generator << "." << param.name;
      const std::string& range = cells[4];
      const size_t dots = range.find("…");
      ASSERT_NE(dots, std::string::npos) << range;
      EXPECT_DOUBLE_EQ(std::strtod(range.c_str(), nullptr), param.min_value)
          << generator << "." << param.name << " minimum";
      EXPECT_DOUBLE_EQ(
          std::strtod(range.c_str() + dots + std::string("…").size(), nullptr),
          param.max_value)
          << generator << "." << param.name << " maximum";
      EXPECT_DOUBLE_EQ(std::strtod(cells[5].c_str(), nullptr),
                       param.default_value)
          << generator << "." << param.name << " default";
      EXPECT_EQ(cells[3].find("integer") != std::string::npos, param.integer)
          << generator << "." << param.name << " type";
    }
  }
}

// The parser and the executor read the same limit: the largest machine a
// scenario may name is one the executor accepts, and one more core is
// refused by both.
TEST(PlatformLimitsTest, TheParserAndTheExecutorAgreeOnTheLargestMachine) {
  const auto scenario = [](int cores) {
    return "adse: 1\nworld:\n  map: {generate: grid}\ntask:\n"
           "  start: {x: 0, y: 0}\n  goal: {x: 100, y: 0}\n"
           "platform: {cores: " +
           std::to_string(cores) +
           "}\ndesign_space:\n"
           "  freq: {bind: platform.freq_ghz, values: [1.0, 2.0]}\n";
  };
  ParseOptions options;
  options.check_files = false;
  stack::VirtualPlatformOptions platform;
  platform.freq_ghz = 2.0;
  platform.reference_ghz = 2.0;

  Result<Spec> largest =
      ParseSpec(scenario(kMaxPlatformCores), "limits.yaml", "", options);
  ASSERT_TRUE(largest.ok()) << largest.status().message();
  platform.cores = largest->platform.cores;
  EXPECT_TRUE(stack::ValidateVirtualPlatformOptions(platform).ok());

  EXPECT_FALSE(
      ParseSpec(scenario(kMaxPlatformCores + 1), "limits.yaml", "", options)
          .ok());
  platform.cores = kMaxPlatformCores + 1;
  EXPECT_FALSE(stack::ValidateVirtualPlatformOptions(platform).ok());
}

}  // namespace
}  // namespace adse::spec
