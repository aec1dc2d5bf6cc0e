// End to end: campaigns of the small robotaxi scenario on real `adse
// worker` processes — the folder's views, resume after a clean stop and
// after SIGKILL of the coordinator, the lock, the shared cache, failures
// with their reasons and retries, and replay against a recording.
#include "harness/campaign/campaign.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "analysis/runfile/campaign_file.h"
#include "analysis/runfile/run_file.h"
#include "harness/campaign/evaluation.h"
#include "harness/campaign/replay.h"
#include "harness/campaign/run_store.h"
#include "harness/report/run_report.h"
#include "harness/spec/design_point.h"
#include "harness/spec/spec_parser.h"
#include "stack/base/files.h"
#include "tests/harness/testing/small_scenario.h"
#include "tests/testing/temp_files.h"

namespace adse::campaign {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

const std::string kAdse = std::string(ADSE_BINARY_DIR) + "/bin/adse";

std::string TempDir(const std::string& name) {
  return adse::testing::FreshTempDir("adse-campaign", name);
}

CampaignOptions Options(const std::string& out, const std::string& strategy,
                        int budget) {
  CampaignOptions o;
  o.output_dir = out;
  o.strategy = strategy;
  o.budget = budget;
  o.workers = 2;
  o.use_cache = false;
  o.worker_command = {kAdse, "worker"};
  return o;
}

std::set<std::string> RunFiles(const std::string& folder) {
  std::set<std::string> keys;
  if (!fs::is_directory(folder + "/runs")) return keys;
  for (const auto& e : fs::directory_iterator(folder + "/runs")) {
    const std::string name = e.path().filename().string();
    if (name.size() == 64 + 3 && name.substr(64) == ".h5")
      keys.insert(name.substr(0, 64));
  }
  return keys;
}

std::vector<std::string> IndexKeys(const std::string& folder) {
  Result<runfile::CampaignIndex> index =
      runfile::ReadCampaignIndex(folder + "/campaign.h5");
  EXPECT_TRUE(index.ok()) << index.status().message();
  std::vector<std::string> keys;
  if (index.ok()) {
    for (const auto& row : index->evaluations) keys.push_back(row.content_key);
  }
  return keys;
}

TEST(CampaignTest,
     ExhaustiveCampaignWritesEveryViewAndASecondRunRepeatsNothing) {
  const spec::Spec spec = adse::testing::SmallScenario();
  const std::string out = TempDir("exhaustive");
  Result<CampaignSummary> first =
      RunCampaign(spec, Options(out, "exhaustive", 12));
  ASSERT_TRUE(first.ok()) << first.status().message();
  EXPECT_EQ(first->exploration.evaluations.size(), 12u);
  EXPECT_EQ(first->simulated, 12);
  EXPECT_EQ(first->failed, 0);
  EXPECT_EQ(RunFiles(out).size(), 12u);
  EXPECT_FALSE(first->pareto_front.empty());
  for (const char* view :
       {"campaign.h5", "report.md", "summary.json", "pareto.png"}) {
    EXPECT_TRUE(fs::is_regular_file(out + "/" + view)) << view;
  }
  const std::string report = ReadFile(out + "/report.md").value();
  EXPECT_THAT(report, HasSubstr("## Pareto front"));
  EXPECT_THAT(report, HasSubstr("## Iterations"));
  EXPECT_THAT(report, HasSubstr("cores=16,freq_ghz=2.1"));
  // Both tables show each metric the objectives and constraints read
  // (`completed` is only a constraint's here).
  std::vector<std::string> metrics = spec::ConstraintMetrics(spec);
  EXPECT_THAT(metrics, ::testing::Contains("completed"));
  for (const spec::Objective& o : spec.objectives) metrics.push_back(o.metric);
  for (const char* table : {"## Pareto front", "## All evaluations"}) {
    const size_t at = report.find("| # | point |", report.find(table));
    ASSERT_NE(at, std::string::npos) << table;
    const std::string header = report.substr(at, report.find('\n', at) - at);
    for (const std::string& metric : metrics) {
      EXPECT_THAT(header, HasSubstr("| " + metric + " |")) << table;
    }
  }
  // Starved (1 core, 1 GHz) points are infeasible; generous ones feasible.
  int feasible = 0;
  for (const EvaluationRow& row : first->exploration.evaluations) {
    feasible += row.feasible;
    EXPECT_TRUE(
        fs::exists(out + "/images/" + row.content_key + "/trajectory.png"));
    if (row.point.at("cores") == 1 && row.point.at("freq_ghz") == 1.0) {
      EXPECT_FALSE(row.feasible);
    }
    if (row.point.at("cores") == 16) {
      EXPECT_TRUE(row.feasible) << row.reason;
    }
  }
  EXPECT_GT(feasible, 0);
  EXPECT_EQ(IndexKeys(out).size(), 12u);
  // Each run's analysis (the worker's, which the campaign takes instead of
  // analysing again) agrees with a fresh analysis of its run file.
  for (const std::string& key : RunFiles(out)) {
    const std::string path = out + "/runs/" + key;
    Result<std::string> text = ReadFile(path + ".report.json");
    ASSERT_TRUE(text.ok()) << key;
    Result<EvaluationRow> stored = RowFromReportJson(*text, path);
    Result<runfile::RunData> run = runfile::ReadRunFile(path + ".h5");
    ASSERT_TRUE(stored.ok() && run.ok()) << key;
    Result<report::RunReport> fresh =
        report::AnalyzeRun(*run, path + ".h5", {});
    ASSERT_TRUE(fresh.ok()) << fresh.status().message();
    const EvaluationRow again = RowFromReport(*fresh);
    EXPECT_EQ(stored->content_key, key);
    EXPECT_EQ(stored->feasible, again.feasible) << key;
    ASSERT_EQ(stored->metrics.size(), again.metrics.size()) << key;
    for (const auto& [name, value] : again.metrics) {
      EXPECT_NEAR(stored->metrics.at(name), value,
                  1e-9 * std::max(1.0, std::abs(value)))
          << key << " " << name;
    }
  }

  Result<CampaignSummary> second =
      RunCampaign(spec, Options(out, "exhaustive", 12));
  ASSERT_TRUE(second.ok()) << second.status().message();
  EXPECT_EQ(second->simulated, 0);
  EXPECT_EQ(second->reused, 12);
  ASSERT_EQ(second->exploration.evaluations.size(), 12u);
  for (size_t i = 0; i < 12; ++i) {
    EXPECT_EQ(second->exploration.evaluations[i].content_key,
              first->exploration.evaluations[i].content_key);
    EXPECT_EQ(second->exploration.evaluations[i].metrics,
              first->exploration.evaluations[i].metrics);
    // What each run took survives the resume (runs/<key>.cost.json).
    EXPECT_EQ(second->exploration.evaluations[i].source, "campaign");
    EXPECT_GT(first->exploration.evaluations[i].wall_s, 0.0);
    EXPECT_EQ(second->exploration.evaluations[i].wall_s,
              first->exploration.evaluations[i].wall_s);
    EXPECT_EQ(second->exploration.evaluations[i].attempts,
              first->exploration.evaluations[i].attempts);
  }

  // A report an older adse left (version 3, without localization_lost_s)
  // is not taken: its run is analysed again and the report rewritten.
  {
    size_t i = 0;
    while (!first->exploration.evaluations[i].feasible) ++i;  // not censored
    const std::string key = first->exploration.evaluations[i].content_key;
    const std::string report_path = out + "/runs/" + key + ".report.json";
    nlohmann::json old = nlohmann::json::parse(ReadFile(report_path).value());
    old["report_version"] = 3;
    old["metrics"].erase("localization_lost_s");
    ASSERT_TRUE(WriteFileAtomic(report_path, old.dump(1)).ok());
    Result<CampaignSummary> third =
        RunCampaign(spec, Options(out, "exhaustive", 12));
    ASSERT_TRUE(third.ok()) << third.status().message();
    EXPECT_EQ(third->simulated, 0);
    EXPECT_EQ(third->exploration.evaluations[i].metrics,
              first->exploration.evaluations[i].metrics);
    EXPECT_EQ(
        third->exploration.evaluations[i].metrics.count("localization_lost_s"),
        1u);
    const nlohmann::json rewritten =
        nlohmann::json::parse(ReadFile(report_path).value());
    EXPECT_EQ(rewritten["report_version"], report::kReportVersion);
  }

  // Replay of the agent over this recording proposes exactly what a live
  // agent campaign does when every run comes from the recording's cache,
  // confirm phase included.
  const std::string cache = TempDir("replay-cache");
  for (const std::string& key : RunFiles(out)) {
    ASSERT_TRUE(RunCache(cache).Insert(key, out + "/runs/" + key + ".h5").ok());
  }
  Result<Recording> recording = LoadRecording(out);
  ASSERT_TRUE(recording.ok()) << recording.status().message();
  int confirming = 0;
  for (const char* strategy : {"agent", "ga", "random"}) {
    Result<ReplayRun> replay =
        Replay(*recording, strategy, spec.exploration.seed, 5, 4);
    ASSERT_TRUE(replay.ok()) << replay.status().message();
    EXPECT_EQ(replay->missing, 0);
    CampaignOptions live =
        Options(TempDir(std::string("live-") + strategy), strategy, 5);
    live.confirm_runs = 4;
    live.use_cache = true;
    live.cache_dir = cache;
    Result<CampaignSummary> s = RunCampaign(spec, live);
    ASSERT_TRUE(s.ok()) << s.status().message();
    EXPECT_EQ(s->simulated, 0) << strategy << ": every run is in the cache";
    std::vector<spec::DesignPoint> proposed;
    for (const EvaluationRow& row : s->exploration.evaluations)
      proposed.push_back(row.point);
    EXPECT_EQ(proposed, replay->proposals) << strategy;
    EXPECT_EQ(proposed.size(), 5u + replay->confirm_evaluations) << strategy;
    // The views say how many confirm runs it took.
    const nlohmann::json summary = nlohmann::json::parse(
        ReadFile(s->output_dir + "/summary.json").value());
    EXPECT_EQ(summary.at("confirm_runs"), 4);
    EXPECT_THAT(ReadFile(s->output_dir + "/report.md").value(),
                HasSubstr(fmt::format("budget 5 and up to 4 confirm runs ({} "
                                      "used)",
                                      replay->confirm_evaluations)));
    confirming += replay->confirm_evaluations;
  }
  EXPECT_GT(confirming, 0) << "no strategy left a cheaper design untried";
}

// Reads the folder's views each time the campaign proposes, after they
// were written for that proposal.
class ViewsWatcher : public ExplorerListener {
 public:
  explicit ViewsWatcher(std::string folder) : folder_(std::move(folder)) {}
  void OnProposed(const runfile::IterationRow& /*iteration*/,
                  const std::vector<spec::DesignPoint>& points,
                  bool /*fell_back*/) override {
    Seen seen;
    seen.summary = nlohmann::json::parse(
        ReadFile(folder_ + "/summary.json").value(), nullptr, false);
    seen.report = ReadFile(folder_ + "/report.md").value();
    seen.proposed = points;
    seen_.push_back(std::move(seen));
  }
  struct Seen {
    nlohmann::json summary;
    std::string report;
    std::vector<spec::DesignPoint> proposed;
  };
  const std::vector<Seen>& seen() const { return seen_; }

 private:
  std::string folder_;
  std::vector<Seen> seen_;
};

TEST(CampaignTest,
     ViewsWrittenWhileTheCampaignRunsSayItIsInProgressAndWhatRuns) {
  const spec::Spec spec = adse::testing::SmallScenario();
  const std::string out = TempDir("in-progress");
  ViewsWatcher watcher(out);
  CampaignOptions o = Options(out, "agent", 3);
  o.listener = &watcher;
  Result<CampaignSummary> s = RunCampaign(spec, o);
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_GE(watcher.seen().size(), 2u);
  for (size_t i = 0; i < watcher.seen().size(); ++i) {
    const ViewsWatcher::Seen& seen = watcher.seen()[i];
    ASSERT_TRUE(seen.summary.is_object()) << i;
    EXPECT_TRUE(seen.summary["in_progress"].get<bool>()) << i;
    EXPECT_FALSE(seen.summary["complete"].get<bool>()) << i;
    // The agent proposes one point per round, after the last one's result.
    const std::string point =
        spec::FormatPoint(spec.design_space, seen.proposed.at(0));
    EXPECT_EQ(seen.summary["running"], nlohmann::json::array({point})) << i;
    EXPECT_EQ(seen.summary["evaluations"].size(), i) << i;
    EXPECT_THAT(seen.report,
                HasSubstr(fmt::format("> **In progress:** {} of 3 evaluations "
                                      "so far, running `{}`",
                                      i, point)));
  }
  EXPECT_THAT(watcher.seen()[0].report,
              HasSubstr("## Answer\n\nNo evaluation has a result yet."));
  // The end's views are the answer.
  const nlohmann::json summary =
      nlohmann::json::parse(ReadFile(out + "/summary.json").value());
  EXPECT_FALSE(summary["in_progress"].get<bool>());
  EXPECT_TRUE(summary["complete"].get<bool>());
  EXPECT_TRUE(summary["running"].empty());
  EXPECT_THAT(ReadFile(out + "/report.md").value(),
              ::testing::Not(HasSubstr("In progress")));
}

TEST(CampaignTest, ASecondCampaignOnALockedFolderIsRefused) {
  const spec::Spec spec = adse::testing::SmallScenario();
  const std::string out = TempDir("locked");
  Result<CampaignLock> held = CampaignLock::Acquire(out);
  ASSERT_TRUE(held.ok());
  Result<CampaignSummary> s = RunCampaign(spec, Options(out, "exhaustive", 2));
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.status().code(), Status::Code::kUnavailable);
  EXPECT_THAT(s.status().message(), HasSubstr("another adse run"));
  EXPECT_FALSE(fs::exists(out + "/campaign.h5")) << "nothing was written";
}

TEST(CampaignTest, TheSharedCacheLetsAnotherCampaignReuseEveryRun) {
  const spec::Spec spec = adse::testing::SmallScenario();
  const std::string cache = TempDir("cache");
  CampaignOptions a = Options(TempDir("cache-a"), "random", 3);
  a.use_cache = true;
  a.cache_dir = cache;
  Result<CampaignSummary> first = RunCampaign(spec, a);
  ASSERT_TRUE(first.ok()) << first.status().message();
  EXPECT_EQ(first->simulated, 3);
  CampaignOptions b = a;
  b.output_dir = TempDir("cache-b");
  Result<CampaignSummary> second = RunCampaign(spec, b);
  ASSERT_TRUE(second.ok()) << second.status().message();
  EXPECT_EQ(second->simulated, 0);
  EXPECT_EQ(second->reused, 3);
  for (const EvaluationRow& row : second->exploration.evaluations)
    EXPECT_EQ(row.source, "cache");
  // --no-cache neither reads it nor fills it.
  CampaignOptions c = b;
  c.output_dir = TempDir("cache-c");
  c.use_cache = false;
  c.budget = 1;
  Result<CampaignSummary> third = RunCampaign(spec, c);
  ASSERT_TRUE(third.ok());
  EXPECT_EQ(third->simulated, 1);
}

// A worker wrapper, `dir`/`name`: the shell `case` arms `arms` on the
// point ($3; $1 is the scenario, $2 --point), and otherwise the real worker.
std::string WorkerWrapper(const std::string& dir, const std::string& name,
                          const std::string& arms) {
  const std::string path = dir + "/" + name;
  std::ofstream(path) << "#!/bin/sh\ncase \"$3\" in\n" + arms + "esac\nexec " +
                             kAdse + " worker \"$@\"\n";
  fs::permissions(path, fs::perms::owner_all);
  return path;
}

// Misbehaves for chosen points: `kill -9` itself, sleep past the timeout,
// or allocate far past the memory limit.
std::string MisbehavingWorker(const std::string& dir) {
  return WorkerWrapper(
      dir, "worker.sh",
      "  cores=4,freq_ghz=1,lidar_hz=7) kill -9 $$ ;;\n"
      "  cores=4,freq_ghz=1,lidar_hz=14) exec sleep 300 ;;\n"
      "  cores=4,freq_ghz=2.1,lidar_hz=7) exec python3 -c "
      "'a = bytearray(1 << 30); a[::4096] = b\"x\" * len(a[::4096]); "
      "import time; time.sleep(30)' ;;\n");
}

TEST(CampaignTest,
     CrashTimeoutAndOutOfMemoryAreRecordedRetriedAndDoNotStopTheCampaign) {
  spec::Spec spec = adse::testing::SmallScenario();
  // Four quick points (4 cores take ~3.5 s each on an idle machine; the
  // timeout leaves room for one loaded by two parallel builds, where 12 s
  // was seen to be too little); the worker still checks them against the
  // file's space, which holds them.
  spec.design_space.parameters[0].values = {4};
  spec.harness.run_timeout_s = 30;
  spec.harness.retries = 1;
  spec.harness.memory_mb = 400;
  const std::string out = TempDir("failures");
  CampaignOptions o = Options(out, "exhaustive", 4);
  o.worker_command = {"/bin/sh", MisbehavingWorker(out)};
  std::vector<std::string> attempts;
  o.on_attempt_failed = [&attempts](const EvalRequest& /*request*/,
                                    int /*attempt*/, const std::string& d) {
    attempts.push_back(d);
  };
  Result<CampaignSummary> s = RunCampaign(spec, o);
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->exploration.evaluations.size(), 4u);
  std::map<std::string, EvaluationRow> by_point;
  for (const EvaluationRow& row : s->exploration.evaluations) {
    by_point[spec::FormatPoint(spec.design_space, row.point)] = row;
  }
  const EvaluationRow& crashed = by_point.at("cores=4,freq_ghz=1,lidar_hz=7");
  EXPECT_EQ(crashed.status, "failed");
  EXPECT_THAT(crashed.reason, HasSubstr("crashed"));
  EXPECT_THAT(crashed.reason, HasSubstr("signal 9"));
  EXPECT_EQ(crashed.attempts, 2);
  const EvaluationRow& slow = by_point.at("cores=4,freq_ghz=1,lidar_hz=14");
  EXPECT_THAT(slow.reason, HasSubstr("timeout"));
  EXPECT_EQ(slow.attempts, 2);
  const EvaluationRow& hungry = by_point.at("cores=4,freq_ghz=2.1,lidar_hz=7");
  EXPECT_THAT(hungry.reason, HasSubstr("out_of_memory"));
  EXPECT_EQ(hungry.attempts, 2);
  const EvaluationRow& fine = by_point.at("cores=4,freq_ghz=2.1,lidar_hz=14");
  EXPECT_EQ(fine.status, "complete") << fine.reason;
  EXPECT_EQ(s->failed, 3);
  EXPECT_EQ(attempts.size(), 3u)
      << "each failure was retried once, as it happened";
  for (const char* key_of :
       {"cores=4,freq_ghz=1,lidar_hz=7", "cores=4,freq_ghz=1,lidar_hz=14"}) {
    Result<FailureRecord> record = ReadFailureRecord(
        out + "/runs/" + by_point.at(key_of).content_key + ".failed.json");
    ASSERT_TRUE(record.ok()) << record.status().message();
    EXPECT_EQ(record->attempts, 2);
  }
  EXPECT_THAT(ReadFile(out + "/report.md").value(), HasSubstr("## Failures"));

  // Failed for good means recorded: a resumed campaign does not rerun
  // them unless asked to.
  Result<CampaignSummary> again = RunCampaign(spec, o);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->simulated, 0);
  EXPECT_EQ(again->failed, 3);
}

// Refuses the points matching the shell pattern `refused` as bad input
// (exit 2, as the worker does a scenario its stack cannot run).
std::string RefusingWorker(const std::string& dir, const std::string& refused) {
  return WorkerWrapper(dir, "refusing.sh",
                       "  " + refused +
                           ") echo 'small.yaml:28:48: error: "
                           "platform.calibration: found none for "
                           "ndt_scan_matcher/points' >&2; exit 2 ;;\n");
}

int FailureRecords(const std::string& folder) {
  int count = 0;
  for (const auto& e : fs::directory_iterator(folder + "/runs")) {
    const std::string name = e.path().filename().string();
    if (name.size() > 12 && name.substr(name.size() - 12) == ".failed.json") {
      ++count;
    }
  }
  return count;
}

TEST(
    CampaignTest,
    ACampaignWhoseFirstRunIsRefusedAsBadInputStopsSayingWhyAndRecordsNoFailure) {
  spec::Spec spec = adse::testing::SmallScenario();
  spec.design_space.parameters[0].values = {4};
  const std::string out = TempDir("refused");
  CampaignOptions o = Options(out, "exhaustive", 4);
  o.worker_command = {"/bin/sh", RefusingWorker(out, "*")};
  Result<CampaignSummary> s = RunCampaign(spec, o);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.status().code(), Status::Code::kInvalidArgument);
  EXPECT_THAT(s.status().message(),
              ::testing::AllOf(
                  HasSubstr("the campaign stopped: its first run was refused "
                            "as bad input, as every run would be: worker "
                            "exited with status 2"),
                  HasSubstr("found none for ndt_scan_matcher/points")));
  // The views say why it stopped and hold no answer; no failure is
  // recorded that a mended scenario would reuse.
  const std::string report = ReadFile(out + "/report.md").value();
  EXPECT_THAT(report, HasSubstr("**Stopped: its first run was refused as bad "
                                "input"));
  EXPECT_THAT(report, ::testing::Not(HasSubstr("## Answer")));
  const nlohmann::json summary =
      nlohmann::json::parse(ReadFile(out + "/summary.json").value());
  EXPECT_FALSE(summary["complete"].get<bool>());
  EXPECT_FALSE(summary["in_progress"].get<bool>());
  EXPECT_THAT(summary["stopped_because"].get<std::string>(),
              HasSubstr("found none for ndt_scan_matcher/points"));
  EXPECT_TRUE(summary["answer"]["cheapest_feasible"].is_null());
  EXPECT_EQ(FailureRecords(out), 0);

  o.worker_command = {kAdse, "worker"};
  Result<CampaignSummary> mended = RunCampaign(spec, o);
  ASSERT_TRUE(mended.ok()) << mended.status().message();
  EXPECT_EQ(mended->simulated, 4);
  EXPECT_EQ(mended->failed, 0);
}

TEST(CampaignTest,
     APointRefusedAfterARunCameThroughIsRecordedAsFailedWithoutARetry) {
  spec::Spec spec = adse::testing::SmallScenario();
  spec.design_space.parameters[0].values = {4};
  spec.harness.retries = 1;
  const std::string out = TempDir("refused-point");
  // Two workers: the last point starts once one of the first two is in.
  CampaignOptions o = Options(out, "exhaustive", 4);
  o.worker_command = {"/bin/sh",
                      RefusingWorker(out, "cores=4,freq_ghz=2.1,lidar_hz=14")};
  Result<CampaignSummary> s = RunCampaign(spec, o);
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->exploration.evaluations.size(), 4u);
  EXPECT_EQ(s->failed, 1);
  for (const EvaluationRow& row : s->exploration.evaluations) {
    if (spec::FormatPoint(spec.design_space, row.point) !=
        "cores=4,freq_ghz=2.1,lidar_hz=14") {
      EXPECT_EQ(row.status, "complete") << row.reason;
      continue;
    }
    EXPECT_EQ(row.status, "failed");
    EXPECT_THAT(row.reason, HasSubstr("worker exited with status 2"));
    EXPECT_EQ(row.attempts, 1);
  }
  EXPECT_EQ(FailureRecords(out), 1);
}

// Starts `adse run` as a separate process, so that it can be killed.
pid_t StartAdseRun(const std::vector<std::string>& args,
                   const std::string& log) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<char*> argv;
    argv.push_back(const_cast<char*>(kAdse.c_str()));
    for (const std::string& a : args)
      argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    FILE* f = std::freopen(log.c_str(), "w", stderr);
    (void)f;
    ::execv(kAdse.c_str(), argv.data());
    ::_exit(127);
  }
  return pid;
}

TEST(
    CampaignTest,
    CoordinatorKilledMidCampaignThenRestartedEndsWithTheSameRunsAsAnUninterruptedOne) {
  const std::string scenario = adse::testing::SmallScenarioPath();
  const std::string killed = TempDir("killed");
  const std::string whole = TempDir("whole");
  const std::vector<std::string> common = {
      "--strategy", "agent", "--budget",   "7",
      "--workers",  "2",     "--no-cache", "--quiet"};
  auto args = [&](const std::string& out) {
    std::vector<std::string> a = {"run", scenario, "-o", out};
    a.insert(a.end(), common.begin(), common.end());
    return a;
  };
  const pid_t coordinator =
      StartAdseRun(args(killed), killed + "/stderr-1.log");
  ASSERT_GT(coordinator, 0);
  // Kill it once some runs are on disk.
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::seconds(240);
  while (RunFiles(killed).size() < 3 &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_GE(RunFiles(killed).size(), 3u);
  ::kill(coordinator, SIGKILL);
  int status = 0;
  ::waitpid(coordinator, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));
  const std::set<std::string> before = RunFiles(killed);

  const pid_t resumed = StartAdseRun(args(killed), killed + "/stderr-2.log");
  ::waitpid(resumed, &status, 0);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0)
      << ReadFile(killed + "/stderr-2.log").value();
  const pid_t uninterrupted = StartAdseRun(args(whole), whole + "/stderr.log");
  ::waitpid(uninterrupted, &status, 0);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);

  const std::set<std::string> after = RunFiles(killed);
  EXPECT_EQ(after, RunFiles(whole));
  EXPECT_EQ(after.size(), 7u);
  for (const std::string& key : before)
    EXPECT_TRUE(after.count(key)) << "nothing lost";
  const std::vector<std::string> index = IndexKeys(killed);
  EXPECT_EQ(index, IndexKeys(whole)) << "same proposals in the same order";
  EXPECT_EQ(std::set<std::string>(index.begin(), index.end()).size(),
            index.size())
      << "no duplicates";
  // The resumed coordinator simulated only what was missing.
  Result<std::string> summary = ReadFile(killed + "/summary.json");
  ASSERT_TRUE(summary.ok());
  EXPECT_THAT(*summary,
              HasSubstr("\"simulated\": " + std::to_string(7 - before.size())));
}

TEST(CampaignTest,
     SigtermStopsTheCampaignKeepsFinishedRunsAndRemovesItsGroups) {
  const std::string out = TempDir("sigterm");
  const pid_t coordinator = StartAdseRun(
      {"run", adse::testing::SmallScenarioPath(), "-o", out, "--strategy",
       "exhaustive", "--workers", "2", "--no-cache", "--quiet"},
      (adse::testing::TestScratch() / "stderr.log").string());
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::seconds(240);
  while (RunFiles(out).empty() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_FALSE(RunFiles(out).empty());
  ::kill(coordinator, SIGTERM);
  int status = 0;
  ::waitpid(coordinator, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "ends by itself, not by the signal";
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM);
  const std::string summary = ReadFile(out + "/summary.json").value();
  EXPECT_THAT(summary, HasSubstr("\"complete\": false"));
  EXPECT_THAT(ReadFile(out + "/report.md").value(),
              HasSubstr("stopped early by signal 15"));
  const std::vector<std::string> index = IndexKeys(out);
  EXPECT_EQ(std::set<std::string>(index.begin(), index.end()), RunFiles(out))
      << "the index lists exactly the finished runs";
  // No cgroup of that coordinator is left, whichever hierarchy it used:
  // its groups would sit under this process's own group in each (the
  // coordinator inherited it). Checked by name, not by walking the tree,
  // which other tests change concurrently.
  const std::string group = "adse-" + std::to_string(coordinator);
  std::ifstream self("/proc/self/cgroup");
  std::string line;
  while (std::getline(self, line)) {
    const size_t a = line.find(':'), b = line.find(':', a + 1);
    if (a == std::string::npos || b == std::string::npos) continue;
    std::string controllers = line.substr(a + 1, b - a - 1);
    const std::string own = line.substr(b + 1);
    if (controllers.rfind("name=", 0) == 0) continue;
    controllers = controllers.substr(0, controllers.find(','));
    for (const std::string& mount : {"/sys/fs/cgroup/" + controllers,
                                     std::string("/sys/fs/cgroup/unified"),
                                     std::string("/sys/fs/cgroup")}) {
      for (const std::string& parent : {own, std::string("/")}) {
        const fs::path left = fs::path(mount + parent) / group;
        std::error_code ec;
        EXPECT_FALSE(fs::exists(left, ec)) << left;
      }
    }
  }
}

}  // namespace
}  // namespace adse::campaign
