// The agents' answers are untrusted: each parser accepts exactly its
// schema, and everything else gets a message the model can act on.
#include "harness/llm/agents.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "harness/llm/prompts.h"
#include "tests/harness/llm/testing/scripted_backend.h"
#include "tests/harness/testing/small_scenario.h"

namespace adse::llm {
namespace {

using adse::testing::SmallPoint;
using adse::testing::SmallScenario;
using ::testing::HasSubstr;

TEST(DseAnswerTest, AcceptsAPointOfAllowedValuesAndSnapsThem) {
  const spec::Spec spec = SmallScenario();
  Result<DseAnswer> a = ParseDseAnswer(
      R"js({"point": {"cores": 4, "freq_ghz": 2.1000000000001, "lidar_hz": 14},
          "rationale": "more  cores\nfor NDT", "converged": false})js",
      spec.design_space, {});
  ASSERT_TRUE(a.ok()) << a.status().ToString();
  EXPECT_EQ(a->point, SmallPoint(4, 2.1, 14));
  EXPECT_EQ(a->rationale, "more cores for NDT");
  EXPECT_FALSE(a->converged);
}

TEST(DseAnswerTest, DropsAReasoningBlockBeforeTheJson) {
  const spec::Spec spec = SmallScenario();
  Result<DseAnswer> a = ParseDseAnswer(
      "<think>let me see {not json}</think>\n{\"point\": {\"cores\": 1, "
      "\"freq_ghz\": 1.0, "
      "\"lidar_hz\": 7}, \"rationale\": \"cheapest\"}",
      spec.design_space, {});
  ASSERT_TRUE(a.ok()) << a.status().ToString();
  EXPECT_EQ(a->point, SmallPoint(1, 1.0, 7));
}

TEST(DseAnswerTest, RefusesEverythingElseWithAnActionableMessage) {
  const spec::Spec spec = SmallScenario();
  const std::set<spec::DesignPoint> seen = {SmallPoint(4, 2.1, 14)};
  struct Case {
    const char* answer;
    const char* message;
  } cases[] = {
      {"cores=4", "not valid JSON"},
      {"```json\n{\"point\": {}}\n```", "not valid JSON"},
      {"[1, 2]", "one JSON object"},
      {R"js({"point": {"cores": 4, "freq_ghz": 1.0, "lidar_hz": 14}})js",
       "lacks \"rationale\""},
      {R"js({"point": {"cores": 3, "freq_ghz": 1.0, "lidar_hz": 14}, "rationale": "x"})js",
       "cores=3 is outside the design space; cores takes one of 1, 4, 16"},
      {R"js({"point": {"cores": 4, "freq_ghz": 1.0}, "rationale": "x"})js",
       "lacks lidar_hz"},
      {R"js({"point": {"cores": 4, "freq_ghz": 1.0, "lidar_hz": 14, "gpu": 1}, "rationale": "x"})js",
       "not a design parameter"},
      {R"js({"point": {"cores": "4", "freq_ghz": 1.0, "lidar_hz": 14}, "rationale": "x"})js",
       "must be a number"},
      {R"js({"point": {"cores": 4, "freq_ghz": 2.1, "lidar_hz": 14}, "rationale": "x"})js",
       "was evaluated already"},
      {R"js({"point": {"cores": 4, "freq_ghz": 2.1, "lidar_hz": 7}, "rationale": "x",
           "command": "rm -rf /"})js",
       "unknown key 'command'"},
  };
  for (const Case& c : cases) {
    Result<DseAnswer> a = ParseDseAnswer(c.answer, spec.design_space, seen);
    ASSERT_FALSE(a.ok()) << c.answer;
    EXPECT_EQ(a.status().code(), Status::Code::kInvalidArgument);
    EXPECT_THAT(a.status().message(), HasSubstr(c.message)) << c.answer;
  }
}

TEST(DseAnswerTest, ConvergenceNeedsSomethingEvaluated) {
  const spec::Spec spec = SmallScenario();
  const char* answer = R"js({"converged": true, "rationale": "front found"})js";
  EXPECT_FALSE(ParseDseAnswer(answer, spec.design_space, {}).ok());
  Result<DseAnswer> a =
      ParseDseAnswer(answer, spec.design_space, {SmallPoint(1, 1.0, 7)});
  ASSERT_TRUE(a.ok());
  EXPECT_TRUE(a->converged);
  EXPECT_TRUE(a->point.empty());
}

TEST(CommandAnswerTest, AcceptsTheSchemaAndComparesWithTheDerivedCommands) {
  const spec::Spec spec = SmallScenario();
  const Commands derived = DeriveCommands(spec, SmallPoint(4, 1.0, 14), 3);
  EXPECT_THAT(derived.map, ::testing::StartsWith("generate parking_lot ("));
  EXPECT_THAT(derived.map, HasSubstr("rows=2"));
  EXPECT_EQ(derived.platform.at("platform.cores"), 4);
  EXPECT_EQ(derived.platform.at("stack.lidar.rate_hz"), 14);
  std::string agreeing =
      R"js({"world": {"map": "MAP", "traffic_seed": 3,
                    "weather": "clear"},
          "platform": {"platform.cores": 4, "platform.freq_ghz": 1.0, "stack.lidar.rate_hz": 14},
          "tracing": {"record": ["callbacks", "topics", "trajectory", "controls", "vehicles"]}})js";
  agreeing.replace(agreeing.find("MAP"), 3, derived.map);
  Result<Commands> c = ParseCommandAnswer(agreeing, spec);
  ASSERT_TRUE(c.ok()) << c.status().ToString();
  EXPECT_TRUE(CompareCommands(*c, derived).empty());

  std::string wrong = agreeing;
  wrong.replace(wrong.find("\"platform.cores\": 4"), 19,
                "\"platform.cores\": 16");
  c = ParseCommandAnswer(wrong, spec);
  ASSERT_TRUE(c.ok());
  EXPECT_THAT(CompareCommands(*c, derived),
              ::testing::ElementsAre("platform.cores=16 instead of 4"));
}

TEST(CommandAnswerTest, RefusesShellTextPathsAndUnknownKeys) {
  const spec::Spec spec = SmallScenario();
  const char* cases[] = {
      // A path instead of the scenario's map.
      R"js({"world": {"map": "../../etc/passwd", "traffic_seed": 3, "weather": "clear"},
          "platform": {}, "tracing": {"record": []}})js",
      // Shell text in a free slot.
      R"js({"world": {"map": "generate parking_lot (rows=2, slots_per_row=8)", "traffic_seed": 3,
                    "weather": "clear; rm -rf ~"}, "platform": {}, "tracing": {"record": []}})js",
      // An output path where none is asked for.
      R"js({"world": {"map": "generate parking_lot (rows=2, slots_per_row=8)", "traffic_seed": 3,
                    "weather": "clear"}, "platform": {},
          "tracing": {"record": ["callbacks"], "output": "/tmp/adse-evil.h5"}})js",
      R"js({"world": {"map": "generate parking_lot (rows=2, slots_per_row=8)", "traffic_seed": 3,
                    "weather": "clear"}, "platform": {"platform.cores": "$(reboot)"},
          "tracing": {"record": []}})js",
      R"js({"world": {"map": "generate parking_lot (rows=2, slots_per_row=8)", "traffic_seed": 3,
                    "weather": "clear"}, "platform": {},
          "tracing": {"record": ["`curl evil`"]}})js",
      R"js({"exec": "sh -c id"})js",
  };
  for (const char* answer : cases) {
    Result<Commands> c = ParseCommandAnswer(answer, spec);
    EXPECT_FALSE(c.ok()) << answer;
    EXPECT_EQ(c.status().code(), Status::Code::kInvalidArgument);
  }
}

TEST(DecipherTest, TextReadingIsComparedByNodeAndKind) {
  Result<TextReading> r = ParseTextReading(
      R"js({"bottlenecks": [{"node": "ndt_scan_matcher", "kind": "cpu_bound",
                           "remedy": "higher frequency"},
                          {"node": "planner", "kind": "frequency_bound", "remedy": "x"}],
          "summary": "NDT falls behind"})js");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  const std::vector<explore::BottleneckHint> found = {
      {analysis::FindingKind::kCpuBound, "ndt_scan_matcher", "higher frequency",
       0.6},
      {analysis::FindingKind::kCpuBound, "euclidean_cluster", "more cores",
       0.3}};
  EXPECT_THAT(CompareTextReading(*r, found),
              ::testing::UnorderedElementsAre(
                  "missed cpu_bound euclidean_cluster",
                  "named frequency_bound planner (not found)"));
  const Result<TextReading> slow = ParseTextReading(
      R"js({"bottlenecks": [{"node": "a", "kind": "slow"}]})js");
  ASSERT_FALSE(slow.ok());
  EXPECT_NE(slow.status().message().find(
                "one of cpu_bound, frequency_bound, starved_input, found"),
            std::string::npos)
      << slow.status().message();
  EXPECT_FALSE(ParseTextReading(R"js({"summary": "fine"})js").ok());
}

TEST(DecipherTest, ATextReadingCanNameAStarvedInputAsTheDiagnosisDoes) {
  // Every kind the diagnosis finds is one the text agent may name: a run
  // whose planner starves its own subscription is not a disagreement
  // when the agent says so.
  Result<TextReading> r = ParseTextReading(
      R"js({"bottlenecks": [{"node": "freespace_planner",
                             "kind": "starved_input",
                             "remedy": "own callback group"}],
            "summary": "the planner's timer starves its pose input"})js");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  const std::vector<explore::BottleneckHint> found = {
      {analysis::FindingKind::kStarvedInput, "freespace_planner",
       "give it a callback group", 0.5}};
  EXPECT_TRUE(CompareTextReading(*r, found).empty());
}

TEST(DecipherTest, VisionReadingIsComparedWithTheMetrics) {
  const VisionReading truth = VisionFromMetrics(
      {{"completed", 1}, {"zigzag_index", 0.5}, {"max_deviation_m", 0.4}});
  EXPECT_TRUE(truth.reached_goal);
  EXPECT_FALSE(truth.smooth);
  EXPECT_FALSE(truth.left_lane);
  Result<VisionReading> r = ParseVisionReading(
      R"js({"reached_goal": true, "smooth": true, "left_lane": false, "notes": "fine"})js");
  ASSERT_TRUE(r.ok());
  EXPECT_THAT(CompareVisionReading(*r, truth),
              ::testing::ElementsAre("smooth: yes (metrics: no)"));
  EXPECT_FALSE(ParseVisionReading(R"js({"reached_goal": "yes", "smooth": true,
                                      "left_lane": false})js")
                   .ok());
}

TEST(DecipherTest, TraceSummaryReadsTheReportsTrace) {
  Result<std::string> s = TraceSummaryFromReport(R"js({
    "metrics": {"ctrl_rate_hz": 9.5, "e2e_latency_p50_s": 0.12, "e2e_latency_p99_s": 0.3},
    "trace": {"topics": [{"name": "/points", "publisher": "external", "publish_rate_hz": 14,
                          "slowest_take_rate_hz": 3.5, "drops": 120,
                          "longest_take_gap_s": 61.04}],
              "callbacks": [{"name": "ndt/on_points", "latency_p50_s": 0.25,
                             "latency_p99_s": 0.4, "utilization": 0.98}]}})js");
  ASSERT_TRUE(s.ok());
  EXPECT_THAT(*s,
              HasSubstr("/points (external): 14 Hz, 3.5 Hz, 120 drops, 61 s"));
  EXPECT_THAT(*s, HasSubstr("ndt/on_points: 250 / 400 ms, 0.98"));
  EXPECT_THAT(*s, HasSubstr("control rate 9.5 Hz"));
  EXPECT_EQ(TraceSummaryFromReport("{}").status().code(),
            Status::Code::kNotFound);
}

TEST(AskWithCorrectionTest, SendsOneCorrectiveFollowUpThenGivesUp) {
  Result<PromptSet> prompts = PromptSet::Load("");
  ASSERT_TRUE(prompts.ok()) << prompts.status().ToString();
  int calls = 0;
  testing::ScriptedBackend backend(
      [&](const ChatRequest&) -> Result<ChatReply> {
        ++calls;
        return testing::ScriptedBackend::Reply(calls == 1 ? "not json"
                                                          : "{\"ok\": true}");
      });
  auto accept = [](const std::string& text) {
    return text.find("ok") != std::string::npos
               ? Status::Ok()
               : Status::InvalidArgument("no ok in it");
  };
  TurnResult t = AskWithCorrection(backend, *prompts,
                                   {"dse", "m", {{"user", "hi", {}}}, true},
                                   accept, "Say ok.");
  EXPECT_TRUE(t.ok);
  EXPECT_EQ(t.rejected, std::vector<std::string>{"no ok in it"});
  ASSERT_EQ(backend.requests().size(), 2u);
  const ChatRequest& second = backend.requests()[1];
  ASSERT_EQ(second.messages.size(), 3u);
  EXPECT_EQ(second.messages[1].role, "assistant");
  EXPECT_EQ(second.messages[1].text, "not json");
  EXPECT_THAT(second.messages[2].text, HasSubstr("no ok in it"));
  EXPECT_THAT(second.messages[2].text, HasSubstr("Say ok."));

  calls = 0;
  testing::ScriptedBackend stubborn(
      [&](const ChatRequest&) -> Result<ChatReply> {
        return testing::ScriptedBackend::Reply("no");
      });
  t = AskWithCorrection(stubborn, *prompts,
                        {"dse", "m", {{"user", "hi", {}}}, true}, accept, "");
  EXPECT_FALSE(t.ok);
  EXPECT_TRUE(t.error.ok());
  EXPECT_EQ(t.rejected.size(), 2u);
  EXPECT_EQ(stubborn.requests().size(), 2u);

  testing::ScriptedBackend down([](const ChatRequest&) -> Result<ChatReply> {
    return Status::Unavailable("cannot reach http://127.0.0.1:1");
  });
  t = AskWithCorrection(down, *prompts,
                        {"dse", "m", {{"user", "hi", {}}}, true}, accept, "");
  EXPECT_FALSE(t.ok);
  EXPECT_EQ(t.error.code(), Status::Code::kUnavailable);
  EXPECT_EQ(down.requests().size(), 1u);
}

TEST(SanitizeTextTest, DropsControlCharactersAndBoundsLength) {
  EXPECT_EQ(SanitizeText("a\x1b[31m\tb\n\nc"), "a[31m b c");
  EXPECT_EQ(SanitizeText(std::string(600, 'x'), 10), "xxxxxxxxxx...");
  // A multi-byte character is never cut in half.
  EXPECT_EQ(SanitizeText("ééééé", 3), "é...");
}

}  // namespace
}  // namespace adse::llm
