// End to end on a real one-node Slurm (testing/slurm_cluster.h): campaigns
// of the small robotaxi scenario submitted with `adse submit` as a user
// would — a static sweep as a job array plus its index job, an adaptive
// campaign's coordinator running its runs as job steps — cancelled,
// warned of their time limit, requeued and resubmitted; `adse status`
// followed along.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <thread>

#include <nlohmann/json.hpp>

#include "analysis/runfile/campaign_file.h"
#include "harness/slurm/client.h"
#include "tests/harness/slurm/testing/adse_commands.h"
#include "tests/harness/slurm/testing/slurm_cluster.h"

namespace adse::slurm::testing {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using Clock = std::chrono::steady_clock;
using nlohmann::json;

// Generous: a run of the small scenario takes 2-15 s on 2 shared cores.
constexpr double kJobTimeoutS = 240;

class CampaignOnSlurmTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (std::string why = SlurmSkipReason(); !why.empty()) {
      GTEST_SKIP() << why;
    }
    Result<std::unique_ptr<SlurmCluster>> cluster = SlurmCluster::Start();
    ASSERT_TRUE(cluster.ok()) << cluster.status().message();
    cluster_ = std::move(cluster).value();
    folder_ = std::make_unique<TestFolder>(
        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    dir_ = folder_->path();
  }

  // `adse submit --json --no-cache`; what it submitted.
  json Submit(const std::string& scenario, const std::string& out) {
    const AdseRun run =
        Adse({"submit", scenario, "-o", out, "--json", "--no-cache"});
    EXPECT_EQ(run.exit_code, 0) << run.output;
    const json j = json::parse(
        run.output.substr(std::min(run.output.find('{'), run.output.size())),
        nullptr, false);
    EXPECT_FALSE(j.is_discarded()) << run.output;
    return j.is_discarded() ? json::object() : j;
  }

  static std::string JobOf(const json& submitted, const std::string& kind) {
    for (const json& s : submitted.value("scripts", json::array())) {
      if (s["kind"] == kind) return s["job_id"].get<std::string>();
    }
    return "";
  }

  void WaitForJob(const std::string& id) {
    ASSERT_FALSE(id.empty());
    ::adse::Status s = cluster_->WaitForJobEnd(id, kJobTimeoutS);
    ASSERT_TRUE(s.ok()) << s.message();
  }

  static json ReadJson(const std::string& path) {
    Result<std::string> text = ReadFile(path);
    EXPECT_TRUE(text.ok()) << text.status().message();
    return text.ok() ? json::parse(*text, nullptr, false) : json();
  }

  static json StatusOf(const std::string& out) {
    const AdseRun run = Adse({"status", out, "--json"});
    EXPECT_EQ(run.exit_code, 0) << run.output;
    return json::parse(run.output, nullptr, false);
  }

  // Content key -> (inode, mtime ns) of the complete run files.
  static std::map<std::string, std::pair<ino_t, int64_t>> RunFiles(
      const std::string& out) {
    std::map<std::string, std::pair<ino_t, int64_t>> files;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(out + "/runs", ec)) {
      const std::string name = e.path().filename().string();
      if (name.size() != 64 + 3 || name.substr(64) != ".h5") continue;
      struct stat st;
      if (::stat(e.path().c_str(), &st) == 0) {
        files[name.substr(0, 64)] = {
            st.st_ino, st.st_mtim.tv_sec * 1000000000LL + st.st_mtim.tv_nsec};
      }
    }
    return files;
  }

  static int FailureRecords(const std::string& out) {
    int n = 0;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(out + "/runs", ec)) {
      n += e.path().string().ends_with(".failed.json");
    }
    return n;
  }

  static runfile::CampaignIndex Index(const std::string& out) {
    Result<runfile::CampaignIndex> index =
        runfile::ReadCampaignIndex(out + "/campaign.h5");
    EXPECT_TRUE(index.ok()) << index.status().message();
    return index.ok() ? *index : runfile::CampaignIndex{};
  }

  // Runs `scenario` as a local campaign into `local` and returns its index
  // after checking it has `rows` evaluations, like `slurm_index`, with the
  // same points and, run by run, the same metrics (the counted cost model
  // is deterministic).
  static runfile::CampaignIndex ExpectSameAsLocal(
      const std::string& scenario, const std::string& local,
      const runfile::CampaignIndex& slurm_index, size_t rows) {
    const AdseRun run = Adse(
        {"run", scenario, "-o", local, "--workers", "2", "--no-cache", "-q"});
    EXPECT_EQ(run.exit_code, 0) << run.output;
    const runfile::CampaignIndex local_index = Index(local);
    EXPECT_EQ(slurm_index.evaluations.size(), rows);
    EXPECT_EQ(local_index.evaluations.size(), rows);
    for (size_t i = 0;
         i < std::min(rows, std::min(slurm_index.evaluations.size(),
                                     local_index.evaluations.size()));
         ++i) {
      const runfile::EvaluationRow& a = slurm_index.evaluations[i];
      const runfile::EvaluationRow& b = local_index.evaluations[i];
      EXPECT_EQ(a.content_key, b.content_key) << i;
      EXPECT_EQ(a.point, b.point) << i;
      EXPECT_EQ(a.status, "complete");
      EXPECT_EQ(a.reason, b.reason) << i;
      EXPECT_EQ(a.feasible, b.feasible) << i;
      EXPECT_EQ(a.unstable, b.unstable) << i;
      EXPECT_EQ(a.metrics.size(), b.metrics.size()) << i;
      for (const auto& [name, value] : b.metrics) {
        if (!a.metrics.count(name)) continue;
        EXPECT_NEAR(a.metrics.at(name), value, 1e-9 * (1 + std::abs(value)))
            << i << " " << name;
      }
      EXPECT_EQ(a.replicas.size(), b.replicas.size()) << i;
      for (size_t r = 0; r < std::min(a.replicas.size(), b.replicas.size());
           ++r) {
        EXPECT_EQ(a.replicas[r].content_key, b.replicas[r].content_key)
            << i << " replica " << r;
      }
    }
    return local_index;
  }

  // Polls until `done` holds or the deadline passes.
  template <typename F>
  bool Eventually(F done, double timeout_s, double every_s = 0.1) {
    const auto until = Clock::now() + std::chrono::duration<double>(timeout_s);
    while (Clock::now() < until) {
      if (done()) return true;
      std::this_thread::sleep_for(std::chrono::duration<double>(every_s));
    }
    return done();
  }

  std::unique_ptr<SlurmCluster> cluster_;
  std::unique_ptr<TestFolder> folder_;
  std::string dir_;
};

TEST_F(CampaignOnSlurmTest, ArraySweepEndsWithTheSameRunsAsALocalCampaign) {
  const std::string scenario = SmallScenarioIn(
      dir_, "{strategy: random, budget: 4}",
      "{memory_mb: 1024, slurm: {shard_size: 2, max_parallel: 2, "
      "signal_lead_s: 60}}");
  const std::string out = dir_ + "/sweep";
  const json submitted = Submit(scenario, out);
  EXPECT_EQ(submitted["points"], 4);
  EXPECT_EQ(submitted["shards"], 2);
  EXPECT_EQ(submitted["submitted_shards"], json({0, 1}));
  const std::string array = JobOf(submitted, "array");
  const std::string index = JobOf(submitted, "index");
  ASSERT_FALSE(array.empty());
  ASSERT_FALSE(index.empty());
  for (const char* file :
       {"/slurm/plan.json", "/slurm/jobs.json", "/slurm/001-array.sbatch",
        "/slurm/001-index.sbatch"}) {
    EXPECT_TRUE(fs::exists(out + file)) << file << " is on record";
  }

  // While it runs: a second submission is refused; status names the runs.
  AdseRun again = Adse({"submit", scenario, "-o", out, "--no-cache"});
  EXPECT_EQ(again.exit_code, 1) << again.output;
  EXPECT_THAT(again.output, HasSubstr("still queued or running"));
  bool saw_running_point = false;
  while (cluster_->JobState(index) != "COMPLETED" &&
         cluster_->JobState(index) != "FAILED" &&
         cluster_->JobState(index) != "") {
    const json st = StatusOf(out);
    for (const json& r : st.value("running", json::array())) {
      saw_running_point =
          saw_running_point || !r["point"].get<std::string>().empty();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
  }
  WaitForJob(index);
  EXPECT_TRUE(saw_running_point) << "adse status never showed a running step";
  EXPECT_EQ(cluster_->JobState(array), "COMPLETED,COMPLETED");
  EXPECT_EQ(cluster_->JobState(index), "COMPLETED");

  const json summary = ReadJson(out + "/summary.json");
  EXPECT_EQ(summary["complete"], true);
  EXPECT_EQ(summary["counts"]["evaluations"], 4);
  EXPECT_EQ(summary["counts"]["simulated"], 4);
  EXPECT_EQ(summary["counts"]["failed"], 0);
  const json st = StatusOf(out);
  EXPECT_EQ(st["kind"], "sweep");
  EXPECT_EQ(st["counts"],
            json({{"done", 4}, {"failed", 0}, {"running", 0}, {"pending", 0}}));
  ASSERT_EQ(st["jobs"].size(), 2u);
  EXPECT_EQ(st["jobs"][0]["tasks"].size(), 2u);

  // The same sweep as a local campaign: the same runs, in the same order,
  // with the same metrics.
  ExpectSameAsLocal(scenario, dir_ + "/local", Index(out), 4);

  // Submitted again when finished: nothing to simulate, only the index.
  const json resubmitted = Submit(scenario, out);
  EXPECT_EQ(resubmitted["finished_points"], 4);
  EXPECT_TRUE(resubmitted["submitted_shards"].empty());
  EXPECT_TRUE(JobOf(resubmitted, "array").empty());
  WaitForJob(JobOf(resubmitted, "index"));
  EXPECT_EQ(cluster_->JobState(JobOf(resubmitted, "index")), "COMPLETED");
  EXPECT_EQ(ReadJson(out + "/summary.json")["counts"]["evaluations"], 4);
}

TEST_F(CampaignOnSlurmTest, ASweepWithReplicasRunsEveryReplicaAsItsOwnStep) {
  const std::string scenario = SmallScenarioIn(
      dir_, "{strategy: random, budget: 2}",
      "{memory_mb: 1024, replicas: 2, slurm: {shard_size: 1, max_parallel: "
      "2, signal_lead_s: 60}}");
  const std::string out = dir_ + "/sweep";
  const json submitted = Submit(scenario, out);
  EXPECT_EQ(submitted["points"], 2);
  EXPECT_EQ(submitted["shards"], 2);
  WaitForJob(JobOf(submitted, "index"));
  EXPECT_EQ(cluster_->JobState(JobOf(submitted, "array")),
            "COMPLETED,COMPLETED");
  EXPECT_EQ(RunFiles(out).size(), 4u) << "2 points x 2 replicas";
  const json st = StatusOf(out);
  EXPECT_EQ(st["counts"],
            json({{"done", 2}, {"failed", 0}, {"running", 0}, {"pending", 0}}));

  // The same points as a local campaign: the same replicas and medians.
  const runfile::CampaignIndex slurm_index = Index(out);
  ExpectSameAsLocal(scenario, dir_ + "/local", slurm_index, 2);
  for (const runfile::EvaluationRow& row : slurm_index.evaluations) {
    ASSERT_EQ(row.replicas.size(), 2u);
    EXPECT_NE(row.replicas[0].seed, row.replicas[1].seed);
    for (const runfile::EvaluationRow& run : row.replicas) {
      EXPECT_EQ(run.source, "simulated");
    }
  }
  // Submitted again: every replica of every point is finished.
  const json resubmitted = Submit(scenario, out);
  EXPECT_EQ(resubmitted["finished_points"], 2);
  EXPECT_TRUE(JobOf(resubmitted, "array").empty());
}

TEST_F(CampaignOnSlurmTest, ASweepWithCasesRunsEveryCaseAsItsOwnStep) {
  const std::string scenario = SmallScenarioIn(
      dir_, "{strategy: random, budget: 1}",
      "{memory_mb: 1024, slurm: {shard_size: 1, signal_lead_s: 60}}");
  // Two destinations for every point (task.cases).
  std::string text = ReadFile(scenario).value();
  const std::string goal = "  goal: {x: 10.0, y: 29.75}\n";
  const size_t at = text.find(goal);
  ASSERT_NE(at, std::string::npos) << "robotaxi_small.yaml changed";
  text.insert(at + goal.size(),
              "  cases:\n"
              "    - {name: across, goal: {x: 10.0, y: 29.75}}\n"
              "    - {name: along, goal: {x: 40.0, y: -1.75}}\n");
  std::ofstream(scenario) << text;
  const std::string out = dir_ + "/sweep";
  const json submitted = Submit(scenario, out);
  EXPECT_EQ(submitted["points"], 1);
  WaitForJob(JobOf(submitted, "index"));
  EXPECT_EQ(RunFiles(out).size(), 2u) << "1 point x 2 cases";
  EXPECT_EQ(StatusOf(out)["counts"],
            json({{"done", 1}, {"failed", 0}, {"running", 0}, {"pending", 0}}));
  // The same point as a local campaign: the same runs, case by case.
  const runfile::CampaignIndex slurm_index = Index(out);
  ExpectSameAsLocal(scenario, dir_ + "/local", slurm_index, 1);
  ASSERT_EQ(slurm_index.evaluations.size(), 1u);
  const runfile::EvaluationRow& row = slurm_index.evaluations[0];
  ASSERT_EQ(row.replicas.size(), 2u);
  EXPECT_EQ(row.replicas[0].task_case, 0);
  EXPECT_EQ(row.replicas[1].task_case, 1);
  EXPECT_EQ(row.replicas[1].reason, "goal_reached");
}

TEST_F(CampaignOnSlurmTest,
       AdaptiveCampaignInsideAnAllocationRunsTwoStepsAtOnceOnTwoCpus) {
  if (cluster_->cpus() < 2) {
    GTEST_SKIP() << "this machine has " << cluster_->cpus()
                 << " CPU; two steps at once need 2";
  }
  const std::string scenario = SmallScenarioIn(
      dir_, "{strategy: agent, budget: 4, batch: 2}",
      "{workers: 2, memory_mb: 1024, slurm: {signal_lead_s: 60}}");
  const std::string out = dir_ + "/agent";
  const json submitted = Submit(scenario, out);
  EXPECT_EQ(submitted["steps_at_once"], 2);
  const std::string job = JobOf(submitted, "coordinator");
  ASSERT_FALSE(job.empty());
  // Slurm's own view of the job's steps, sampled as it runs.
  size_t most_at_once = 0;
  std::set<std::string> steps_seen;
  while (IsActiveState(cluster_->JobState(job))) {
    Result<std::vector<StepState>> steps = QuerySteps({job});
    ASSERT_TRUE(steps.ok()) << steps.status().message();
    size_t running = 0;
    for (const StepState& s : *steps) {
      if (StepKeyPrefix(s).empty()) continue;
      ++running;
      steps_seen.insert(s.id);
    }
    most_at_once = std::max(most_at_once, running);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  WaitForJob(job);
  EXPECT_EQ(cluster_->JobState(job), "COMPLETED");
  EXPECT_EQ(most_at_once, 2u);
  EXPECT_EQ(steps_seen.size(), 4u) << "one job step per run";
  const json summary = ReadJson(out + "/summary.json");
  EXPECT_EQ(summary["complete"], true);
  EXPECT_EQ(summary["counts"]["simulated"], 4);
  EXPECT_THAT(summary["isolation"].get<std::string>(),
              HasSubstr("Slurm job steps (srun --exact -n1 -c1 --mem=1024M) "
                        "in job " +
                        job));
  EXPECT_EQ(summary["workers"], 2);
}

TEST_F(
    CampaignOnSlurmTest,
    CancellingTheCoordinatorMidCampaignThenResubmittingLosesAndRepeatsNothing) {
  const std::string scenario = SmallScenarioIn(
      dir_, "{strategy: agent, budget: 4, batch: 2}",
      "{workers: 2, memory_mb: 1024, slurm: {signal_lead_s: 60}}");
  const std::string out = dir_ + "/cancelled";
  const std::string first = JobOf(Submit(scenario, out), "coordinator");
  ASSERT_FALSE(first.empty());
  // Cancel once the first round has landed, while the second runs.
  ASSERT_TRUE(
      Eventually([&] { return RunFiles(out).size() >= 2; }, kJobTimeoutS))
      << cluster_->LogTail();
  Result<ProcessResult> cancel = cluster_->Run({"scancel", first});
  ASSERT_TRUE(cancel.ok() && cancel->exit_code == 0);
  WaitForJob(first);
  EXPECT_EQ(cluster_->JobState(first), "CANCELLED");
  const auto before = RunFiles(out);
  ASSERT_GE(before.size(), 2u);
  ASSERT_LT(before.size(), 4u) << "the campaign ended before the cancel";
  EXPECT_EQ(FailureRecords(out), 0)
      << "runs cut short by the cancel are not failures";
  const json stopped = ReadJson(out + "/summary.json");
  EXPECT_EQ(stopped["complete"], false);
  EXPECT_NE(stopped["interrupted_by_signal"], 0);
  json st = StatusOf(out);
  EXPECT_EQ(st["counts"]["done"], static_cast<int>(before.size()));
  EXPECT_EQ(st["counts"]["pending"], 4 - static_cast<int>(before.size()));

  const std::string second = JobOf(Submit(scenario, out), "coordinator");
  ASSERT_FALSE(second.empty());
  WaitForJob(second);
  EXPECT_EQ(cluster_->JobState(second), "COMPLETED");
  const auto after = RunFiles(out);
  EXPECT_EQ(after.size(), 4u);
  for (const auto& [key, file] : before) {
    ASSERT_TRUE(after.count(key)) << key << " was lost";
    EXPECT_EQ(after.at(key), file) << key << " was written again";
  }
  EXPECT_EQ(FailureRecords(out), 0);
  const json summary = ReadJson(out + "/summary.json");
  EXPECT_EQ(summary["complete"], true);
  EXPECT_EQ(summary["counts"]["evaluations"], 4);
  EXPECT_EQ(summary["counts"]["reused"], static_cast<int>(before.size()));
  EXPECT_EQ(summary["counts"]["simulated"],
            4 - static_cast<int>(before.size()));
  std::set<std::string> keys;
  for (const runfile::EvaluationRow& row : Index(out).evaluations) {
    keys.insert(row.content_key);
  }
  EXPECT_EQ(keys.size(), 4u);
  st = StatusOf(out);
  ASSERT_EQ(st["jobs"].size(), 2u);
  EXPECT_EQ(st["jobs"][0]["state"], "CANCELLED");
  EXPECT_EQ(st["jobs"][1]["state"], "COMPLETED");
}

TEST_F(CampaignOnSlurmTest, AStepKilledForMemoryIsRecordedAsOutOfMemory) {
  if (!cluster_->memory_enforced()) {
    GTEST_SKIP() << "no cgroup v1 memory controller here: Slurm cannot "
                    "enforce a step's --mem";
  }
  // 40 MB cannot hold a worker (its SUMO, PCL and OpenCV libraries alone).
  const std::string scenario = SmallScenarioIn(
      dir_, "{strategy: exhaustive, budget: 1}",
      "{memory_mb: 40, retries: 0, slurm: {signal_lead_s: 60}}");
  const std::string out = dir_ + "/oom";
  const json submitted = Submit(scenario, out);
  WaitForJob(JobOf(submitted, "index"));
  EXPECT_EQ(cluster_->JobState(JobOf(submitted, "index")), "COMPLETED");
  const std::string key =
      ReadJson(out + "/slurm/plan.json")["points"][0]["key"];
  const json failure = ReadJson(out + "/runs/" + key + ".failed.json");
  EXPECT_EQ(failure["outcome"], "out_of_memory");
  EXPECT_EQ(failure["detail"], "out of memory (limit memory_mb = 40)");
  EXPECT_THAT(failure["stderr_tail"].get<std::string>(),
              HasSubstr("Out Of Memory"));
  const runfile::CampaignIndex index = Index(out);
  ASSERT_EQ(index.evaluations.size(), 1u);
  EXPECT_EQ(index.evaluations[0].status, "failed");
  EXPECT_THAT(index.evaluations[0].reason, HasSubstr("out_of_memory"));
  EXPECT_EQ(StatusOf(out)["counts"]["failed"], 1);
}

TEST_F(
    CampaignOnSlurmTest,
    TheTimeLimitWarningLetsRunningStepsFinishAndTheRequeuedJobEndsTheCampaign) {
  const std::string scenario = SmallScenarioIn(
      dir_, "{strategy: agent, budget: 6, batch: 2}",
      "{workers: 2, memory_mb: 1024, slurm: {signal_lead_s: 150}}");
  const std::string out = dir_ + "/warned";
  const std::string job = JobOf(Submit(scenario, out), "coordinator");
  ASSERT_FALSE(job.empty());
  // Warn while the second round's steps run. A first-round step can still
  // be listed for a moment after its run file is written, so count only
  // the steps of points that have no run file yet.
  const auto second_round_running = [&] {
    const auto files = RunFiles(out);
    if (files.size() != 2) return false;
    Result<std::vector<StepState>> steps = QuerySteps({job});
    if (!steps.ok()) return false;
    int new_points = 0;
    for (const StepState& step : *steps) {
      const std::string prefix = StepKeyPrefix(step);
      if (prefix.empty()) continue;
      bool has_file = false;
      for (const auto& [key, file] : files) {
        has_file = has_file || key.rfind(prefix, 0) == 0;
      }
      if (!has_file) ++new_points;
    }
    return new_points == 2;
  };
  ASSERT_TRUE(Eventually(second_round_running, kJobTimeoutS, 0.05))
      << cluster_->LogTail();
  // What --signal=B:USR1@<s> does before the time limit.
  Result<ProcessResult> warn =
      cluster_->Run({"scancel", "--batch", "--signal=USR1", job});
  ASSERT_TRUE(warn.ok() && warn->exit_code == 0);
  // The coordinator stops proposing, lets its steps finish, exits 138 and
  // the job requeues itself.
  ASSERT_TRUE(Eventually([&] { return cluster_->JobState(job) == "PENDING"; },
                         kJobTimeoutS, 0.2))
      << cluster_->JobState(job);
  const std::string log =
      ReadFile(out + "/slurm/logs/coordinator-" + job + ".out").value();
  EXPECT_THAT(log, HasSubstr("time-limit warning"));
  EXPECT_THAT(log, HasSubstr("adse: exit status 138"));
  EXPECT_THAT(log, HasSubstr("requeueing " + job));
  const auto at_requeue = RunFiles(out);
  EXPECT_EQ(at_requeue.size(), 4u)
      << "the round running at the warning finishes; no new one starts";
  EXPECT_THAT(log.substr(log.find("time-limit warning")), HasSubstr("[4/6]"));
  EXPECT_EQ(FailureRecords(out), 0);
  // A requeued job waits ~2 minutes before it may start again. Forced to
  // start at once, it must not start within the second slurmd revoked the
  // old instance's credential: slurmd compares at one-second resolution
  // and kills the new batch job ("Job credential revoked"), seen here.
  std::this_thread::sleep_for(std::chrono::seconds(2));
  Result<ProcessResult> now =
      cluster_->Run({"scontrol", "update", "JobId=" + job, "StartTime=now"});
  ASSERT_TRUE(now.ok() && now->exit_code == 0) << now->output;
  WaitForJob(job);
  EXPECT_EQ(cluster_->JobState(job), "COMPLETED") << cluster_->LogTail();
  const auto after = RunFiles(out);
  EXPECT_EQ(after.size(), 6u);
  for (const auto& [key, file] : at_requeue) EXPECT_EQ(after.at(key), file);
  const json summary = ReadJson(out + "/summary.json");
  EXPECT_EQ(summary["complete"], true);
  EXPECT_EQ(summary["counts"]["reused"], static_cast<int>(at_requeue.size()));
  EXPECT_EQ(summary["counts"]["simulated"],
            6 - static_cast<int>(at_requeue.size()));
  EXPECT_THAT(ReadFile(out + "/slurm/logs/coordinator-" + job + ".out").value(),
              HasSubstr("(restart 1)"));
}

}  // namespace
}  // namespace adse::slurm::testing
