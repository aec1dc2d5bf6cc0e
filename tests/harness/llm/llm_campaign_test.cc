// End to end: campaigns with `strategy: llm` on real `adse worker`
// processes, the agents answered by a local HTTP server that speaks the
// Ollama and OpenAI APIs from a script. Whatever the models say — valid
// points, malformed JSON, points outside the space, repeats, shell text,
// paths, slow or failing or huge answers — the campaign finishes, the
// report says what happened, and a recorded campaign replays exactly.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "analysis/runfile/campaign_file.h"
#include "harness/campaign/campaign.h"
#include "harness/campaign/replay.h"
#include "harness/llm/agents.h"
#include "harness/llm/exchange_log.h"
#include "harness/llm/llm_strategy.h"
#include "harness/spec/spec_parser.h"
#include "stack/base/files.h"
#include "tests/harness/llm/testing/fake_llm_server.h"
#include "tests/harness/testing/small_scenario.h"
#include "tests/testing/temp_files.h"

namespace adse::llm {
namespace {
namespace fs = std::filesystem;
using adse::testing::SmallPoint;
using testing::FakeAnswer;
using testing::FakeLlmServer;
using ::testing::HasSubstr;
using testing::ReceivedRequest;

const std::string kAdse = std::string(ADSE_BINARY_DIR) + "/bin/adse";

std::string TempDir(const std::string& name) {
  return adse::testing::FreshTempDir("adse-llm", name);
}

std::string PointJson(const spec::DesignPoint& p,
                      const std::string& rationale = "because") {
  return nlohmann::json({{"point", p}, {"rationale", rationale}}).dump();
}

// The four agents' parts of the script: DSE answers in order (the last one
// repeats), well-formed answers for the others unless overridden.
struct Team {
  std::vector<FakeAnswer> dse;
  std::function<FakeAnswer(const ReceivedRequest&)> command;
  std::function<FakeAnswer(const ReceivedRequest&)> vision;
  size_t next_dse = 0;
};

FakeLlmServer::Script Script(const spec::Spec& spec, Team* team) {
  return [&spec, team](const ReceivedRequest& r) -> FakeAnswer {
    if (r.model == "dse-model") {
      const size_t i = std::min(team->next_dse++, team->dse.size() - 1);
      return team->dse[i];
    }
    if (r.model == "command-model") {
      if (team->command) return team->command(r);
      // Agree with the point named in the prompt.
      const std::string text = r.TextOf("user");
      const size_t at = text.find("Design point: ") + 14;
      Result<spec::DesignPoint> point = spec::ParsePoint(
          spec.design_space, text.substr(at, text.find('\n', at) - at));
      const Commands c =
          DeriveCommands(spec, point.ok() ? *point : spec::DesignPoint{},
                         spec.world.traffic.seed);
      nlohmann::json j = {{"world",
                           {{"map", c.map},
                            {"traffic_seed", c.traffic_seed},
                            {"weather", c.weather}}},
                          {"platform", c.platform},
                          {"tracing", {{"record", c.record}}}};
      return {200, j.dump()};
    }
    if (r.model == "text-model") {
      return {200,
              R"js({"bottlenecks": [], "summary": "the stack keeps up"})js"};
    }
    if (r.model == "vision-model") {
      if (team->vision) return team->vision(r);
      return {200,
              R"js({"reached_goal": true, "smooth": true, "left_lane": false,
                         "notes": "a clean drive"})js"};
    }
    return {404, "unknown model " + r.model};
  };
}

// The small scenario with `strategy: llm` and an llm section naming one
// model per agent, written as a file (the campaign stores its text).
spec::Spec LlmScenario(const std::string& dir, const std::string& url,
                       const std::string& api = "ollama",
                       const std::string& extra = "timeout_s: 20, retries: 0") {
  std::string text = ReadFile(adse::testing::SmallScenarioPath()).value();
  const std::string profile = "profiles/autoware-2022.12-i9-12900kf.yaml";
  text.replace(text.find(profile), profile.size(),
               std::string(ADSE_SOURCE_DIR) + "/scenarios/" + profile);
  const size_t exploration = text.find("exploration:");
  text.erase(exploration, text.find('\n', exploration) - exploration);
  text += "exploration: {strategy: llm, budget: 2}\n";
  text +=
      "llm: {backend: " + api + ", endpoint: \"" + url +
      "\", models: {dse: dse-model, command: command-model, text: text-model, "
      "vision: vision-model, interpretation: interpretation-model}, " +
      extra + "}\n";
  const std::string path = dir + "/scenario.yaml";
  EXPECT_TRUE(WriteFileAtomic(path, text).ok());
  Result<spec::Spec> spec = spec::LoadSpec(path);
  EXPECT_TRUE(spec.ok()) << spec.status().ToString();
  return std::move(spec).value();
}

// The first event of an agent and kind.
std::string Detail(const std::vector<LlmEvent>& events,
                   const std::string& agent, LlmEventKind kind) {
  for (const LlmEvent& e : events) {
    if (e.agent == agent && e.kind == kind) return e.detail;
  }
  return "(no " + agent + " " + LlmEventKindToString(kind) + " event)";
}

campaign::CampaignOptions Options(const std::string& out, int budget) {
  campaign::CampaignOptions o;
  o.output_dir = out;
  o.budget = budget;
  o.workers = 1;
  o.worker_command = {kAdse, "worker"};
  return o;  // the shared test cache keeps repeated points cheap
}

std::vector<spec::DesignPoint> Points(const campaign::CampaignSummary& s) {
  std::vector<spec::DesignPoint> points;
  for (const auto& row : s.exploration.evaluations) points.push_back(row.point);
  return points;
}

std::vector<LlmEvent> Events(const std::string& out) {
  Result<std::vector<LlmEvent>> events = LoadEvents(EventsPath(out));
  EXPECT_TRUE(events.ok()) << events.status().ToString();
  return events.ok() ? *events : std::vector<LlmEvent>{};
}

int Count(const std::vector<LlmEvent>& events, const std::string& agent,
          LlmEventKind kind) {
  int n = 0;
  for (const LlmEvent& e : events) n += e.agent == agent && e.kind == kind;
  return n;
}

std::vector<ExchangeRecord> Exchanges(const std::string& out) {
  Result<std::vector<ExchangeRecord>> x = LoadExchanges(ExchangesPath(out));
  EXPECT_TRUE(x.ok()) << x.status().ToString();
  return x.ok() ? *x : std::vector<ExchangeRecord>{};
}

const spec::DesignPoint kP1 = SmallPoint(16, 2.1, 14);
const spec::DesignPoint kP2 = SmallPoint(16, 2.1, 7);
const spec::DesignPoint kP3 = SmallPoint(4, 2.1, 14);

TEST(LlmCampaignTest,
     AShortCampaignAsksEveryAgentRecordsEveryExchangeAndReplaysExactly) {
  const spec::Spec base = adse::testing::SmallScenario();
  Team team;
  team.dse = {{200, PointJson(kP1)}, {200, PointJson(kP2)}};
  Result<std::unique_ptr<FakeLlmServer>> server =
      FakeLlmServer::Start(Script(base, &team));
  ASSERT_TRUE(server.ok()) << server.status().ToString();
  const std::string dir = TempDir("short");
  const spec::Spec spec = LlmScenario(dir, (*server)->url());
  const std::string out = dir + "/campaign";

  Result<campaign::CampaignSummary> first =
      campaign::RunCampaign(spec, Options(out, 2));
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  EXPECT_EQ(Points(*first), (std::vector<spec::DesignPoint>{kP1, kP2}));
  EXPECT_EQ(first->failed, 0);

  // DSE and command per iteration, text and vision per evaluation.
  const std::vector<ExchangeRecord> exchanges = Exchanges(out);
  ASSERT_EQ(exchanges.size(), 8u);
  std::map<std::string, int> by_agent;
  for (const ExchangeRecord& e : exchanges) {
    by_agent[e.agent] += 1;
    EXPECT_TRUE(e.ok) << e.error;
    EXPECT_EQ(e.backend, "ollama");
    EXPECT_GT(e.completion_tokens, 0);
  }
  EXPECT_EQ(by_agent,
            (std::map<std::string, int>{
                {"command", 2}, {"dse", 2}, {"text", 2}, {"vision", 2}}));
  // Ollama was asked not to stream; the vision part got the trajectory PNG.
  int images = 0;
  for (const ReceivedRequest& r : (*server)->requests()) {
    EXPECT_EQ(r.path, "/api/chat");
    EXPECT_THAT(r.body, HasSubstr("\"stream\":false"));
    for (const auto& m : r.messages) {
      for (const std::string& png : m.images_png) {
        EXPECT_EQ(png.substr(1, 3), "PNG");
        ++images;
      }
    }
  }
  EXPECT_EQ(images, 2);
  // The DSE agent's second instruction carries the first result and memory.
  const std::string second_step = exchanges[4].prompt;
  EXPECT_EQ(exchanges[4].agent, "dse");
  EXPECT_THAT(
      second_step,
      HasSubstr("Last point evaluated: cores=16,freq_ghz=2.1,lidar_hz=14"));
  EXPECT_THAT(second_step, HasSubstr("cheapest feasible"));
  // The deciphering agents' readings are compared with the analysis.
  // (At 16 cores, 2.1 GHz and 14 Hz the single-threaded ground filter
  // cannot keep up with the scans.)
  EXPECT_THAT(second_step, HasSubstr("diagnosis: cpu_bound ground_filter"));
  EXPECT_THAT(second_step, HasSubstr("text agent (disagrees, not used): "));
  EXPECT_THAT(second_step, HasSubstr("missed cpu_bound ground_filter"));
  EXPECT_THAT(second_step, HasSubstr("vision agent (agrees): a clean drive"));

  Result<runfile::CampaignIndex> index =
      runfile::ReadCampaignIndex(out + "/campaign.h5");
  ASSERT_TRUE(index.ok()) << index.status().ToString();
  EXPECT_EQ(index->llm_exchanges.size(), 8u);
  EXPECT_EQ(index->llm_exchanges[0].agent, "dse");
  EXPECT_EQ(index->iterations.size(), 2u);
  EXPECT_EQ(index->iterations[0].rationale, "because");
  const std::string report = ReadFile(out + "/report.md").value();
  EXPECT_THAT(report, HasSubstr("## LLM agents"));
  EXPECT_THAT(report, HasSubstr("8 exchanges (8 answered"));
  EXPECT_THAT(report, HasSubstr("0 iterations proposed by the built-in agent"));

  // No server from here on.
  server->reset();

  // Resumed in place: every answer comes from the folder's own record.
  Result<campaign::CampaignSummary> resumed =
      campaign::RunCampaign(spec, Options(out, 2));
  ASSERT_TRUE(resumed.ok()) << resumed.status().ToString();
  EXPECT_EQ(Points(*resumed), Points(*first));
  EXPECT_EQ(resumed->simulated, 0);
  EXPECT_EQ(Exchanges(out).size(), 8u);  // nothing appended twice

  // Replayed into a fresh folder with `backend: replay`.
  const std::string replay_dir = TempDir("short-replay");
  const spec::Spec replay =
      LlmScenario(replay_dir, "http://127.0.0.1:9", "replay",
                  "replay_from: \"" + out + "\"");
  const std::string again = replay_dir + "/campaign";
  Result<campaign::CampaignSummary> replayed =
      campaign::RunCampaign(replay, Options(again, 2));
  ASSERT_TRUE(replayed.ok()) << replayed.status().ToString();
  EXPECT_EQ(Points(*replayed), Points(*first));
  const std::vector<ExchangeRecord> copied = Exchanges(again);
  ASSERT_EQ(copied.size(), exchanges.size());
  for (size_t i = 0; i < copied.size(); ++i) {
    EXPECT_EQ(copied[i].request_sha256, exchanges[i].request_sha256);
    EXPECT_EQ(copied[i].answer, exchanges[i].answer);
  }

  // And through the recorded campaign, as `adse explore --replay` does.
  Result<campaign::Recording> recording = campaign::LoadRecording(out);
  ASSERT_TRUE(recording.ok()) << recording.status().ToString();
  Result<campaign::ReplayRun> run =
      campaign::Replay(*recording, "llm", spec.exploration.seed, 2);
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  ASSERT_EQ(run->proposals.size(), 2u);

  // Another budget changes the prompts: the replay stops with a clear
  // error instead of quietly becoming a different campaign.
  const std::string beyond = replay_dir + "/beyond";
  Result<campaign::CampaignSummary> more =
      campaign::RunCampaign(replay, Options(beyond, 3));
  ASSERT_FALSE(more.ok());
  EXPECT_EQ(more.status().code(), Status::Code::kNotFound);
  EXPECT_THAT(more.status().message(),
              HasSubstr("no recorded answer for this dse request"));
  EXPECT_THAT(more.status().message(), HasSubstr(out + "/llm/exchanges.jsonl"));
  EXPECT_TRUE(fs::exists(beyond + "/report.md"));
}

TEST(LlmCampaignTest,
     MalformedJsonGetsOneCorrectionAndTheCorrectedPointIsUsed) {
  const spec::Spec base = adse::testing::SmallScenario();
  Team team;
  team.dse = {{200, "{\"point\": {\"cores\": 16, "}, {200, PointJson(kP1)}};
  Result<std::unique_ptr<FakeLlmServer>> server =
      FakeLlmServer::Start(Script(base, &team));
  ASSERT_TRUE(server.ok());
  const std::string dir = TempDir("malformed"), out = dir + "/campaign";
  Result<campaign::CampaignSummary> s = campaign::RunCampaign(
      LlmScenario(dir, (*server)->url()), Options(out, 1));
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(Points(*s), std::vector<spec::DesignPoint>{kP1});
  const std::vector<LlmEvent> events = Events(out);
  EXPECT_EQ(Count(events, "dse", LlmEventKind::kRejected), 1);
  EXPECT_EQ(Count(events, "dse", LlmEventKind::kFallback), 0);
  EXPECT_THAT(Detail(events, "dse", LlmEventKind::kRejected),
              HasSubstr("not valid JSON"));
  // The follow-up showed the model its answer and what was wrong.
  const std::vector<ExchangeRecord> x = Exchanges(out);
  ASSERT_GE(x.size(), 2u);
  EXPECT_THAT(
      x[1].prompt,
      HasSubstr("Your answer cannot be used: the answer is not valid JSON"));
  EXPECT_THAT(ReadFile(out + "/report.md").value(),
              HasSubstr("1 answers rejected"));
}

TEST(LlmCampaignTest,
     APointOutsideTheSpaceTwiceFallsBackToTheBuiltInAgentForThatIteration) {
  const spec::Spec base = adse::testing::SmallScenario();
  const std::string outside =
      PointJson({{"cores", 3}, {"freq_ghz", 2.1}, {"lidar_hz", 14}});
  Team team;
  team.dse = {{200, outside}, {200, outside}, {200, PointJson(kP3)}};
  Result<std::unique_ptr<FakeLlmServer>> server =
      FakeLlmServer::Start(Script(base, &team));
  ASSERT_TRUE(server.ok());
  const std::string dir = TempDir("outside"), out = dir + "/campaign";
  Result<campaign::CampaignSummary> s = campaign::RunCampaign(
      LlmScenario(dir, (*server)->url()), Options(out, 2));
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  ASSERT_EQ(s->exploration.evaluations.size(), 2u);
  EXPECT_NE(s->exploration.evaluations[0].point.at("cores"), 3);
  EXPECT_EQ(s->exploration.evaluations[1].point, kP3);
  const std::vector<LlmEvent> events = Events(out);
  EXPECT_EQ(Count(events, "dse", LlmEventKind::kRejected), 2);
  EXPECT_EQ(Count(events, "dse", LlmEventKind::kFallback), 1);
  ASSERT_EQ(s->exploration.iterations.size(), 2u);
  EXPECT_THAT(s->exploration.iterations[0].rationale,
              HasSubstr("fallback to the built-in agent: the DSE agent gave "
                        "answers that could not be used ("));
  EXPECT_THAT(s->exploration.iterations[0].rationale,
              HasSubstr("cores=3 is outside"));
  EXPECT_THAT(ReadFile(out + "/report.md").value(),
              HasSubstr("1 iterations proposed by the built-in agent instead"));
}

TEST(LlmCampaignTest, ARepeatedPointIsRefusedAndCorrected) {
  const spec::Spec base = adse::testing::SmallScenario();
  Team team;
  team.dse = {
      {200, PointJson(kP1)}, {200, PointJson(kP1)}, {200, PointJson(kP2)}};
  Result<std::unique_ptr<FakeLlmServer>> server =
      FakeLlmServer::Start(Script(base, &team));
  ASSERT_TRUE(server.ok());
  const std::string dir = TempDir("repeat"), out = dir + "/campaign";
  Result<campaign::CampaignSummary> s = campaign::RunCampaign(
      LlmScenario(dir, (*server)->url()), Options(out, 2));
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(Points(*s), (std::vector<spec::DesignPoint>{kP1, kP2}));
  const std::vector<LlmEvent> events = Events(out);
  ASSERT_EQ(Count(events, "dse", LlmEventKind::kRejected), 1);
  EXPECT_THAT(Detail(events, "dse", LlmEventKind::kRejected),
              HasSubstr("was evaluated already"));
}

TEST(LlmCampaignTest, ShellTextAndPathsOutsideTheOutputFolderChangeNothing) {
  const spec::Spec base = adse::testing::SmallScenario();
  const std::string root = TempDir("hostile");
  const std::string scenario_dir = TempDir("hostile-scenario");
  const std::string out = root + "/campaign";
  const std::string evil = root + "/evil";  // must never appear
  Team team;
  nlohmann::json with_output = nlohmann::json::parse(PointJson(kP1));
  with_output["output"] = evil;
  team.dse = {{200, with_output.dump()},
              {200, PointJson(kP1, "$(touch " + evil + "); rm -rf ~ `touch " +
                                       evil + "`")}};
  team.command = [&](const ReceivedRequest&) -> FakeAnswer {
    nlohmann::json j = {
        {"world",
         {{"map", "../../" + evil},
          {"traffic_seed", 3},
          {"weather", "clear; touch " + evil}}},
        {"platform", {{"platform.cores", 16}}},
        {"tracing", {{"record", {"callbacks"}}, {"output", evil + ".h5"}}}};
    return {200, j.dump()};
  };
  Result<std::unique_ptr<FakeLlmServer>> server =
      FakeLlmServer::Start(Script(base, &team));
  ASSERT_TRUE(server.ok());
  campaign::CampaignOptions options = Options(out, 1);
  options.use_cache = false;  // nothing at all outside the output folder
  Result<campaign::CampaignSummary> s = campaign::RunCampaign(
      LlmScenario(scenario_dir, (*server)->url()), options);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(Points(*s), std::vector<spec::DesignPoint>{kP1});
  // Only the campaign folder was created under root; no file was touched.
  std::set<std::string> entries;
  for (const auto& e : fs::directory_iterator(root))
    entries.insert(e.path().string());
  EXPECT_EQ(entries, std::set<std::string>{out});
  EXPECT_FALSE(fs::exists(evil));
  EXPECT_FALSE(fs::exists(evil + ".h5"));
  const std::vector<LlmEvent> events = Events(out);
  EXPECT_EQ(Count(events, "dse", LlmEventKind::kRejected), 1);
  EXPECT_EQ(Count(events, "command", LlmEventKind::kRejected), 2);
  EXPECT_EQ(Count(events, "command", LlmEventKind::kError), 1);
  // The rationale is kept as text only, control characters removed.
  EXPECT_THAT(s->exploration.iterations[0].rationale, HasSubstr("$(touch"));
}

TEST(LlmCampaignTest,
     ASlowAnswerPastTheTimeoutFallsBackAndTheCampaignFinishes) {
  const spec::Spec base = adse::testing::SmallScenario();
  Team team;
  FakeAnswer slow{200, PointJson(kP1)};
  slow.delay_s = 3.0;
  team.dse = {slow};
  Result<std::unique_ptr<FakeLlmServer>> server =
      FakeLlmServer::Start(Script(base, &team));
  ASSERT_TRUE(server.ok());
  const std::string dir = TempDir("slow"), out = dir + "/campaign";
  const spec::Spec spec = LlmScenario(dir, (*server)->url(), "ollama",
                                      "timeout_s: 0.5, retries: 0");
  Result<campaign::CampaignSummary> s =
      campaign::RunCampaign(spec, Options(out, 1));
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(s->exploration.evaluations.size(), 1u);
  const std::vector<LlmEvent> events = Events(out);
  ASSERT_EQ(Count(events, "dse", LlmEventKind::kFallback), 1);
  EXPECT_THAT(Detail(events, "dse", LlmEventKind::kFallback),
              HasSubstr("did not answer within 0.5 s"));
  const std::vector<ExchangeRecord> x = Exchanges(out);
  ASSERT_FALSE(x.empty());
  EXPECT_FALSE(x[0].ok);
  EXPECT_EQ(x[0].error_code, "unavailable");
}

TEST(LlmCampaignTest, AServerErrorThenSuccessIsRetriedOverTheOpenAiApi) {
  const spec::Spec base = adse::testing::SmallScenario();
  Team team;
  team.dse = {{500, "model crashed"}, {200, PointJson(kP1)}};
  Result<std::unique_ptr<FakeLlmServer>> server =
      FakeLlmServer::Start(Script(base, &team));
  ASSERT_TRUE(server.ok());
  const std::string dir = TempDir("retry"), out = dir + "/campaign";
  const spec::Spec spec =
      LlmScenario(dir, (*server)->url(), "openai", "timeout_s: 20, retries: 2");
  Result<campaign::CampaignSummary> s =
      campaign::RunCampaign(spec, Options(out, 1));
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(Points(*s), std::vector<spec::DesignPoint>{kP1});
  const std::vector<ExchangeRecord> x = Exchanges(out);
  ASSERT_FALSE(x.empty());
  EXPECT_TRUE(x[0].ok);
  EXPECT_EQ(x[0].attempts, 2);
  EXPECT_EQ(x[0].backend, "openai");
  EXPECT_EQ(Count(Events(out), "dse", LlmEventKind::kFallback), 0);
  bool image_part = false;
  for (const ReceivedRequest& r : (*server)->requests()) {
    EXPECT_EQ(r.path, "/v1/chat/completions");
    image_part |= r.body.find("data:image/png;base64,") != std::string::npos;
  }
  EXPECT_TRUE(image_part);
}

TEST(LlmCampaignTest, ATenMegabyteAnswerIsRefusedAndTheAgentTakesOver) {
  const spec::Spec base = adse::testing::SmallScenario();
  Team team;
  FakeAnswer huge;
  huge.raw_body = std::string(1 << 20, 'x');
  huge.raw_body_repeat = 10;
  team.dse = {huge};
  Result<std::unique_ptr<FakeLlmServer>> server =
      FakeLlmServer::Start(Script(base, &team));
  ASSERT_TRUE(server.ok());
  const std::string dir = TempDir("huge"), out = dir + "/campaign";
  Result<campaign::CampaignSummary> s = campaign::RunCampaign(
      LlmScenario(dir, (*server)->url()), Options(out, 1));
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(s->exploration.evaluations.size(), 1u);
  const std::vector<LlmEvent> events = Events(out);
  ASSERT_EQ(Count(events, "dse", LlmEventKind::kFallback), 1);
  EXPECT_THAT(Detail(events, "dse", LlmEventKind::kFallback),
              HasSubstr("larger than 4 MiB"));
  // The record holds the refusal, not the 10 MB.
  EXPECT_LT(fs::file_size(ExchangesPath(out)), 200u * 1024);
}

TEST(LlmCampaignTest,
     AVisionAnswerThatContradictsTheMetricsIsRecordedAndTheMetricsWin) {
  const spec::Spec base = adse::testing::SmallScenario();
  Team team;
  team.dse = {{200, PointJson(kP1)}};
  team.vision = [](const ReceivedRequest&) -> FakeAnswer {
    return {200, R"js({"reached_goal": false, "smooth": true, "left_lane": true,
                       "notes": "it crashed"})js"};
  };
  Result<std::unique_ptr<FakeLlmServer>> server =
      FakeLlmServer::Start(Script(base, &team));
  ASSERT_TRUE(server.ok());
  const std::string dir = TempDir("vision"), out = dir + "/campaign";
  Result<campaign::CampaignSummary> s = campaign::RunCampaign(
      LlmScenario(dir, (*server)->url()), Options(out, 1));
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  ASSERT_EQ(s->exploration.evaluations.size(), 1u);
  EXPECT_TRUE(s->exploration.evaluations[0].feasible);
  const std::vector<LlmEvent> events = Events(out);
  ASSERT_EQ(Count(events, "vision", LlmEventKind::kDisagreement), 1);
  EXPECT_THAT(Detail(events, "vision", LlmEventKind::kDisagreement),
              HasSubstr("reached goal: no (metrics: yes)"));
  EXPECT_THAT(Detail(events, "vision", LlmEventKind::kDisagreement),
              HasSubstr("the metrics are kept"));
}

TEST(LlmCampaignTest, AnUnreachableServerIsNamedAndTheAgentCarriesTheCampaign) {
  const std::string dir = TempDir("down"), out = dir + "/campaign";
  // The discard port: nothing listens there.
  const spec::Spec spec = LlmScenario(dir, "http://127.0.0.1:9");
  Result<campaign::CampaignSummary> s =
      campaign::RunCampaign(spec, Options(out, 1));
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(s->exploration.evaluations.size(), 1u);
  const std::vector<LlmEvent> events = Events(out);
  ASSERT_EQ(Count(events, "dse", LlmEventKind::kFallback), 1);
  EXPECT_THAT(Detail(events, "dse", LlmEventKind::kFallback),
              HasSubstr("http://127.0.0.1:9"));
  EXPECT_THAT(Detail(events, "dse", LlmEventKind::kFallback),
              HasSubstr("ollama serve"));
}

}  // namespace
}  // namespace adse::llm
