#include "harness/llm/llm_strategy.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "tests/testing/temp_files.h"

namespace adse::llm {
namespace {
using ::testing::HasSubstr;

TEST(LlmStrategyTest, EveryEventKindRoundTripsAndAnUnknownOneIsNot) {
  const std::vector<std::string> names = LlmEventKindNames();
  ASSERT_EQ(names,
            (std::vector<std::string>{"rejected", "fallback", "disagreement",
                                      "converged", "error"}));
  for (size_t i = 0; i < names.size(); ++i) {
    const LlmEventKind kind = static_cast<LlmEventKind>(i);
    EXPECT_EQ(LlmEventKindToString(kind), names[i]);
    LlmEventKind back = LlmEventKind::kError;
    ASSERT_TRUE(StringToLlmEventKind(names[i], &back)) << names[i];
    EXPECT_EQ(back, kind);
  }
  LlmEventKind unchanged = LlmEventKind::kConverged;
  EXPECT_FALSE(StringToLlmEventKind("fell_back", &unchanged));
  EXPECT_EQ(unchanged, LlmEventKind::kConverged);
}

TEST(LlmStrategyTest, EventsAreReadBackTypedAndAnUnknownKindNamesItsLine) {
  const std::string dir = adse::testing::TestTempDir("adse-llm-events");
  std::filesystem::create_directories(dir + "/llm");
  const std::string path = EventsPath(dir);
  adse::testing::WriteRaw(
      path,
      R"({"iteration":2,"agent":"dse","kind":"fallback","detail":"d"})"
      "\n"
      R"({"iteration":3,"agent":"text","kind":"disagreement","detail":"e"})"
      "\n");
  Result<std::vector<LlmEvent>> events = LoadEvents(path);
  ASSERT_TRUE(events.ok()) << events.status().ToString();
  ASSERT_EQ(events->size(), 2u);
  EXPECT_EQ((*events)[0].kind, LlmEventKind::kFallback);
  EXPECT_EQ((*events)[0].iteration, 2);
  EXPECT_EQ((*events)[1].kind, LlmEventKind::kDisagreement);
  EXPECT_EQ((*events)[1].agent, "text");

  adse::testing::WriteRaw(
      path, R"({"iteration":2,"agent":"dse","kind":"fallback","detail":"d"})"
            "\n"
            R"({"iteration":3,"agent":"dse","kind":"fell_back","detail":"d"})"
            "\n");
  events = LoadEvents(path);
  ASSERT_FALSE(events.ok());
  EXPECT_EQ(events.status().code(), Status::Code::kCorruption);
  EXPECT_THAT(events.status().message(),
              HasSubstr(path + ":2: not an llm event (unknown event kind "
                               "'fell_back'; valid kinds: rejected, fallback"));
}

}  // namespace
}  // namespace adse::llm
