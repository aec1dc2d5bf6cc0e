// The job-step pool against a real Slurm: steps in an allocation made with
// `salloc --no-shell`, running the pool tests' fake worker. Exit statuses,
// crashes, memory kills, timeouts and cancellation, each ending its step.
#include "harness/slurm/step_pool.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <regex>
#include <thread>

#include "harness/slurm/client.h"
#include "tests/harness/slurm/testing/adse_commands.h"
#include "tests/harness/slurm/testing/slurm_cluster.h"

namespace adse::slurm::testing {
namespace {

using ::testing::HasSubstr;
using Clock = std::chrono::steady_clock;

class StepPoolTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (std::string why = SlurmSkipReason(); !why.empty()) {
      GTEST_SKIP() << why;
    }
    Result<std::unique_ptr<SlurmCluster>> cluster = SlurmCluster::Start();
    ASSERT_TRUE(cluster.ok()) << cluster.status().message();
    cluster_ = std::move(cluster).value();
    // An allocation of 2 CPUs (or what the node has) that outlives salloc.
    const int cpus = std::min(2, cluster_->cpus());
    Result<ProcessResult> r = cluster_->Run(
        {"salloc", "--no-shell", "--ntasks=" + std::to_string(cpus),
         "--cpus-per-task=1", "--mem=1500M", "--time=10"});
    ASSERT_TRUE(r.ok() && r->exit_code == 0)
        << (r.ok() ? r->output : r.status().message());
    std::smatch m;
    ASSERT_TRUE(
        std::regex_search(r->output, m, std::regex("allocation (\\d+)")))
        << r->output;
    job_ = m[1];
    options_.job_id = job_;
    options_.slots = cpus;
    options_.memory_mb = 100;
    options_.cancel_grace_s = 10;
    folder_ = std::make_unique<TestFolder>("step-pool");
    dir_ = folder_->path();
  }

  pool::Job FakeJob(uint64_t id, std::vector<std::string> ops,
                    double timeout_s = 0) {
    pool::Job job;
    job.id = id;
    job.argv = {ADSE_POOL_FAKE_WORKER};
    job.argv.insert(job.argv.end(), ops.begin(), ops.end());
    job.log_path = dir_ + "/job-" + std::to_string(id) + ".log";
    job.timeout_s = timeout_s;
    job.name = "adse-test-" + std::to_string(id);
    return job;
  }

  // The names of the job's steps Slurm still runs.
  std::vector<std::string> Steps() {
    Result<std::vector<StepState>> steps = QuerySteps({job_});
    EXPECT_TRUE(steps.ok()) << steps.status().message();
    std::vector<std::string> names;
    if (steps.ok()) {
      for (const StepState& s : *steps) names.push_back(s.name);
    }
    return names;
  }

  std::map<uint64_t, pool::JobResult> RunAll(pool::WorkerPool& pool,
                                             std::vector<pool::Job> jobs) {
    std::map<uint64_t, pool::JobResult> results;
    const auto until = Clock::now() + std::chrono::seconds(60);
    size_t next = 0;
    while (results.size() < jobs.size() && Clock::now() < until) {
      while (next < jobs.size() && pool.idle_slots() > 0) {
        EXPECT_TRUE(pool.Submit(jobs[next++]).ok());
      }
      for (pool::JobResult& r : pool.Wait(0.5)) results[r.id] = r;
    }
    return results;
  }

  std::unique_ptr<SlurmCluster> cluster_;
  std::unique_ptr<TestFolder> folder_;
  std::string job_, dir_;
  StepPoolOptions options_;
};

TEST_F(StepPoolTest, StepsEndWithTheirWorkersOutcome) {
  Result<std::unique_ptr<pool::WorkerPool>> pool = CreateStepPool(options_);
  ASSERT_TRUE(pool.ok()) << pool.status().message();
  EXPECT_THAT((*pool)->isolation_description(),
              HasSubstr("srun --exact -n1 -c1 --mem=100M"));
  std::vector<pool::Job> jobs = {FakeJob(1, {"stderr", "hello", "exit", "0"}),
                                 FakeJob(2, {"exit", "5"}),
                                 FakeJob(3, {"crash", "segv"})};
  if (cluster_->memory_enforced()) {
    jobs.push_back(FakeJob(4, {"alloc", "400", "sleep", "1"}));
  }
  std::map<uint64_t, pool::JobResult> r = RunAll(**pool, jobs);
  ASSERT_EQ(r.size(), jobs.size()) << cluster_->LogTail();
  EXPECT_EQ(r[1].outcome, pool::Outcome::kOk) << r[1].stderr_tail;
  EXPECT_THAT(r[1].stderr_tail, HasSubstr("hello"));
  EXPECT_EQ(r[2].outcome, pool::Outcome::kExitError) << r[2].stderr_tail;
  EXPECT_EQ(r[2].exit_code, 5);
  EXPECT_EQ(r[3].outcome, pool::Outcome::kCrashed) << r[3].stderr_tail;
  EXPECT_EQ(r[3].signal, 11);
  if (cluster_->memory_enforced()) {
    EXPECT_EQ(r[4].outcome, pool::Outcome::kOutOfMemory) << r[4].stderr_tail;
  }
  EXPECT_TRUE(Steps().empty());
}

TEST_F(StepPoolTest, AStepPastItsTimeoutIsCancelledThroughSrun) {
  Result<std::unique_ptr<pool::WorkerPool>> pool = CreateStepPool(options_);
  ASSERT_TRUE(pool.ok()) << pool.status().message();
  const auto start = Clock::now();
  std::map<uint64_t, pool::JobResult> r =
      RunAll(**pool, {FakeJob(1, {"sleep", "60"}, 1.5)});
  const double took =
      std::chrono::duration<double>(Clock::now() - start).count();
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[1].outcome, pool::Outcome::kTimeout) << r[1].stderr_tail;
  EXPECT_GE(took, 1.5);
  EXPECT_LT(took, 8.0) << "srun should end its step within seconds";
  EXPECT_TRUE(Steps().empty()) << "the step outlived its srun";
}

TEST_F(StepPoolTest, CancelAllEndsEveryRunningStep) {
  Result<std::unique_ptr<pool::WorkerPool>> pool = CreateStepPool(options_);
  ASSERT_TRUE(pool.ok()) << pool.status().message();
  ASSERT_TRUE((*pool)->Submit(FakeJob(1, {"sleep", "60"})).ok());
  // Running once Slurm lists the step.
  for (auto until = Clock::now() + std::chrono::seconds(20);
       Steps().empty() && Clock::now() < until;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_EQ(Steps(), std::vector<std::string>{"adse-test-1"});
  std::vector<pool::JobResult> r = (*pool)->CancelAll();
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].outcome, pool::Outcome::kCancelled);
  EXPECT_TRUE(Steps().empty());
  EXPECT_EQ((*pool)->idle_slots(), (*pool)->slots());
}

}  // namespace
}  // namespace adse::slurm::testing
