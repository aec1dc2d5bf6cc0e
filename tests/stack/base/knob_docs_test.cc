// Every stack knob is documented in scenarios/README.md, with its default.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <fstream>
#include <sstream>

#include "stack/config/stack_config.h"

namespace adse {
namespace {

TEST(KnobDocsTest, EveryKnobIsInTheScenarioReference) {
  std::ifstream in(std::string(ADSE_SOURCE_DIR) + "/scenarios/README.md");
  ASSERT_TRUE(in) << "scenarios/README.md is missing";
  std::stringstream text;
  text << in.rdbuf();
  const std::string doc = text.str();
  for (const KnobInfo& knob : StackKnobs()) {
    const std::string row_start = "| `" + knob.path + "` |";
    const size_t at = doc.find(row_start);
    ASSERT_NE(at, std::string::npos) << knob.path << " is not documented";
    const std::string row = doc.substr(at, doc.find('\n', at) - at);
    EXPECT_NE(row.find(fmt::format("| {:g} |", knob.default_value)),
              std::string::npos)
        << knob.path << ": the documented default differs from "
        << knob.default_value << "\n"
        << row;
  }
}

}  // namespace
}  // namespace adse
