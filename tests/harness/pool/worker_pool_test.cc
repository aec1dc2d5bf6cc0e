// The pool under affinity isolation (no cgroups needed): outcomes, timeouts,
// memory limits by RLIMIT_AS, interrupts and cancellation.
#include "harness/pool/worker_pool.h"

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "tests/harness/pool/pool_test_util.h"

namespace adse::pool {
namespace {

using testing::FakeJob;
using testing::ProcessGone;
using testing::TempDir;
using testing::WaitAll;
using testing::WaitForNumber;
using Clock = std::chrono::steady_clock;

std::unique_ptr<WorkerPool> AffinityPool(int workers = 1,
                                         int memory_mb = 4096) {
  PoolOptions options;
  options.workers = workers;
  options.memory_mb = memory_mb;
  options.isolation = Isolation::kAffinity;
  Result<std::unique_ptr<WorkerPool>> pool = WorkerPool::Create(options);
  EXPECT_TRUE(pool.ok()) << pool.status().ToString();
  return pool.ok() ? std::move(pool).value() : nullptr;
}

JobResult RunOne(WorkerPool& pool, const Job& job) {
  Status submitted = pool.Submit(job);
  EXPECT_TRUE(submitted.ok()) << submitted.ToString();
  std::vector<JobResult> results = WaitAll(pool);
  EXPECT_EQ(results.size(), 1u);
  return results.empty() ? JobResult{} : results[0];
}

TEST(WorkerPoolTest, DefaultsToOneSlotPerAllowedCore) {
  PoolOptions options;
  options.isolation = Isolation::kAffinity;
  Result<std::unique_ptr<WorkerPool>> pool = WorkerPool::Create(options);
  ASSERT_TRUE(pool.ok()) << pool.status().ToString();
  EXPECT_EQ((*pool)->slots(), testing::AllowedCores());
  EXPECT_EQ((*pool)->idle_slots(), (*pool)->slots());
  EXPECT_EQ((*pool)->isolation_description().rfind("affinity + rlimits", 0),
            0u);
  EXPECT_EQ((*pool)->fallback_reason(), "");
}

TEST(WorkerPoolTest, RefusesMoreCoresThanTheProcessMayUse) {
  PoolOptions options;
  options.isolation = Isolation::kAffinity;
  options.workers = testing::AllowedCores() + 1;
  Result<std::unique_ptr<WorkerPool>> pool = WorkerPool::Create(options);
  ASSERT_FALSE(pool.ok());
  EXPECT_EQ(pool.status().code(), Status::Code::kInvalidArgument);
  EXPECT_NE(pool.status().message().find("may use only"), std::string::npos)
      << pool.status().message();
}

TEST(WorkerPoolTest, RefusesAGroupNameWithoutPid) {
  PoolOptions options;
  options.isolation = Isolation::kAffinity;
  options.group_name = "campaign";
  Result<std::unique_ptr<WorkerPool>> pool = WorkerPool::Create(options);
  ASSERT_FALSE(pool.ok());
  EXPECT_EQ(pool.status().code(), Status::Code::kInvalidArgument);
}

TEST(WorkerPoolTest, ExitStatusesBecomeOutcomes) {
  TempDir dir;
  auto pool = AffinityPool();
  ASSERT_TRUE(pool);
  JobResult ok =
      RunOne(*pool, FakeJob(1, dir.path() + "/ok.log", {"exit", "0"}));
  EXPECT_EQ(ok.id, 1u);
  EXPECT_EQ(ok.outcome, Outcome::kOk);
  EXPECT_EQ(ok.exit_code, 0);
  EXPECT_EQ(ok.slot, 0);
  JobResult failed =
      RunOne(*pool, FakeJob(2, dir.path() + "/failed.log", {"exit", "7"}));
  EXPECT_EQ(failed.outcome, Outcome::kExitError);
  EXPECT_EQ(failed.exit_code, 7);
  EXPECT_EQ(failed.signal, 0);
  JobResult oom =
      RunOne(*pool, FakeJob(3, dir.path() + "/oom.log",
                            {"exit", std::to_string(kExitOutOfMemory)}));
  EXPECT_EQ(oom.outcome, Outcome::kOutOfMemory);
}

TEST(WorkerPoolTest, CrashReportsItsSignal) {
  TempDir dir;
  auto pool = AffinityPool();
  ASSERT_TRUE(pool);
  JobResult segv =
      RunOne(*pool, FakeJob(1, dir.path() + "/segv.log", {"crash", "segv"}));
  EXPECT_EQ(segv.outcome, Outcome::kCrashed);
  EXPECT_EQ(segv.signal, SIGSEGV);
  EXPECT_EQ(segv.exit_code, -1);
  JobResult abrt =
      RunOne(*pool, FakeJob(2, dir.path() + "/abort.log", {"crash", "abort"}));
  EXPECT_EQ(abrt.outcome, Outcome::kCrashed);
  EXPECT_EQ(abrt.signal, SIGABRT);
}

TEST(WorkerPoolTest, StderrTailHoldsTheEndOfTheLog) {
  TempDir dir;
  auto pool = AffinityPool();
  ASSERT_TRUE(pool);
  JobResult r = RunOne(*pool, FakeJob(1, dir.path() + "/job.log",
                                      {"stderr-bytes", "10000", "stderr",
                                       "the last words", "exit", "1"}));
  EXPECT_EQ(r.outcome, Outcome::kExitError);
  EXPECT_LE(r.stderr_tail.size(), 2048u);
  EXPECT_GT(r.stderr_tail.size(), 1500u);
  EXPECT_EQ(r.stderr_tail.rfind("line ", 0), 0u) << "starts at a line start";
  EXPECT_NE(r.stderr_tail.find("the last words\n"), std::string::npos);
}

TEST(WorkerPoolTest, JobIsPinnedToItsSlotCores) {
  TempDir dir;
  const int workers = std::min(2, testing::AllowedCores());
  auto pool = AffinityPool(workers);
  ASSERT_TRUE(pool);
  for (int i = 0; i < workers; ++i) {
    ASSERT_TRUE(
        pool->Submit(FakeJob(i, dir.path() + "/" + std::to_string(i) + ".log",
                             {"affinity", "sleep", "0.2"}))
            .ok());
  }
  EXPECT_EQ(pool->idle_slots(), 0);
  std::vector<JobResult> results = WaitAll(*pool);
  ASSERT_EQ(results.size(), static_cast<size_t>(workers));
  std::vector<std::string> cpus;
  for (const JobResult& r : results) {
    EXPECT_EQ(r.outcome, Outcome::kOk);
    const int core =
        WaitForNumber(dir.path() + "/" + std::to_string(r.id) + ".log", "cpus");
    EXPECT_GE(core, 0);
    cpus.push_back(std::to_string(core));
  }
  if (workers == 2) {
    EXPECT_NE(cpus[0], cpus[1]) << "disjoint cores";
  }
}

TEST(WorkerPoolTest, JobPastItsTimeoutIsKilledWithItsProcessGroup) {
  TempDir dir;
  auto pool = AffinityPool();
  ASSERT_TRUE(pool);
  const std::string log = dir.path() + "/job.log";
  const auto start = Clock::now();
  ASSERT_TRUE(
      pool->Submit(FakeJob(1, log, {"grandchild", "30", "sleep", "30"}, 0.3))
          .ok());
  const int grandchild = WaitForNumber(log, "grandchild");
  ASSERT_GT(grandchild, 0);
  std::vector<JobResult> results = WaitAll(*pool);
  const double elapsed =
      std::chrono::duration<double>(Clock::now() - start).count();
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].outcome, Outcome::kTimeout);
  EXPECT_EQ(results[0].signal, SIGKILL);
  EXPECT_GE(results[0].wall_s, 0.3);
  EXPECT_LT(elapsed, 2.0);
  EXPECT_TRUE(ProcessGone(grandchild));
}

TEST(WorkerPoolTest, AllocationPastTheLimitIsOutOfMemoryUnderAffinity) {
  TempDir dir;
  auto pool = AffinityPool(1, /*memory_mb=*/64);
  ASSERT_TRUE(pool);
  // RLIMIT_AS is memory_mb plus headroom for address space reservations.
  JobResult r =
      RunOne(*pool, FakeJob(1, dir.path() + "/job.log", {"alloc", "2048"}));
  EXPECT_EQ(r.outcome, Outcome::kOutOfMemory);
  EXPECT_EQ(r.exit_code, kExitOutOfMemory);
  EXPECT_NE(r.stderr_tail.find("allocation failed"), std::string::npos);
  JobResult fits =
      RunOne(*pool, FakeJob(2, dir.path() + "/fits.log", {"alloc", "32"}));
  EXPECT_EQ(fits.outcome, Outcome::kOk);
}

TEST(WorkerPoolTest, JobKilledFromOutsideIsACrash) {
  TempDir dir;
  auto pool = AffinityPool();
  ASSERT_TRUE(pool);
  const std::string log = dir.path() + "/job.log";
  ASSERT_TRUE(pool->Submit(FakeJob(1, log, {"pid", "sleep", "30"})).ok());
  const int pid = WaitForNumber(log, "pid");
  ASSERT_GT(pid, 0);
  ASSERT_EQ(::kill(pid, SIGKILL), 0);
  std::vector<JobResult> results = WaitAll(*pool);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].outcome, Outcome::kCrashed);
  EXPECT_EQ(results[0].signal, SIGKILL);
}

TEST(WorkerPoolTest, SubmitNeedsAnIdleSlot) {
  TempDir dir;
  auto pool = AffinityPool();
  ASSERT_TRUE(pool);
  ASSERT_TRUE(
      pool->Submit(FakeJob(1, dir.path() + "/1.log", {"sleep", "30"})).ok());
  Status second =
      pool->Submit(FakeJob(2, dir.path() + "/2.log", {"exit", "0"}));
  EXPECT_EQ(second.code(), Status::Code::kUnavailable);
  std::vector<JobResult> cancelled = pool->CancelAll();
  ASSERT_EQ(cancelled.size(), 1u);
  EXPECT_EQ(cancelled[0].outcome, Outcome::kCancelled);
}

TEST(WorkerPoolTest, SubmitSaysWhyAJobCannotStart) {
  TempDir dir;
  auto pool = AffinityPool();
  ASSERT_TRUE(pool);
  Job missing = FakeJob(1, dir.path() + "/1.log", {});
  missing.argv[0] = dir.path() + "/no-such-program";
  Status s = pool->Submit(missing);
  EXPECT_EQ(s.code(), Status::Code::kIoError);
  EXPECT_NE(s.message().find("executing " + missing.argv[0] + ": No such file"),
            std::string::npos)
      << s.message();
  EXPECT_EQ(pool->idle_slots(), 1);

  Job relative = FakeJob(2, dir.path() + "/2.log", {});
  relative.argv[0] = "fake_worker";
  EXPECT_EQ(pool->Submit(relative).code(), Status::Code::kInvalidArgument);

  Status no_log = pool->Submit(FakeJob(3, dir.path() + "/missing/3.log", {}));
  EXPECT_EQ(no_log.code(), Status::Code::kIoError);
  EXPECT_NE(no_log.message().find("cannot create log"), std::string::npos);
  EXPECT_EQ(pool->idle_slots(), 1);
}

TEST(WorkerPoolTest, WaitReturnsPromptlyWhenAJobExits) {
  TempDir dir;
  auto pool = AffinityPool();
  ASSERT_TRUE(pool);
  const auto idle_start = Clock::now();
  EXPECT_TRUE(pool->Wait(5.0).empty()) << "nothing runs: returns at once";
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - idle_start).count(),
            0.1);

  ASSERT_TRUE(
      pool->Submit(FakeJob(1, dir.path() + "/job.log", {"sleep", "0.05"}))
          .ok());
  const auto start = Clock::now();
  std::vector<JobResult> results = pool->Wait(10.0);
  const double waited =
      std::chrono::duration<double>(Clock::now() - start).count();
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].outcome, Outcome::kOk);
  EXPECT_LT(waited, 1.0) << "the exit wakes Wait, not its 10 s limit";
}

TEST(WorkerPoolTest, WaitReturnsAfterItsLimit) {
  TempDir dir;
  auto pool = AffinityPool();
  ASSERT_TRUE(pool);
  ASSERT_TRUE(
      pool->Submit(FakeJob(1, dir.path() + "/job.log", {"sleep", "30"})).ok());
  const auto start = Clock::now();
  EXPECT_TRUE(pool->Wait(0.2).empty());
  const double waited =
      std::chrono::duration<double>(Clock::now() - start).count();
  EXPECT_GE(waited, 0.19);
  EXPECT_LT(waited, 1.0);
  EXPECT_EQ(pool->idle_slots(), 0);
}

TEST(WorkerPoolTest, InterruptMakesWaitReturnEarly) {
  TempDir dir;
  auto pool = AffinityPool();
  ASSERT_TRUE(pool);
  InstallInterruptHandlers();
  InstallInterruptHandlers();  // idempotent
  ASSERT_EQ(InterruptRequested(), 0);
  const std::string log = dir.path() + "/job.log";
  ASSERT_TRUE(pool->Submit(FakeJob(1, log, {"pid", "sleep", "30"})).ok());
  const int pid = WaitForNumber(log, "pid");
  ASSERT_GT(pid, 0);
  std::thread interrupter([] {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    ::kill(::getpid(), SIGTERM);
  });
  const auto start = Clock::now();
  std::vector<JobResult> results = pool->Wait(10.0);
  const double waited =
      std::chrono::duration<double>(Clock::now() - start).count();
  interrupter.join();
  EXPECT_TRUE(results.empty());
  EXPECT_LT(waited, 2.0);
  EXPECT_EQ(InterruptRequested(), SIGTERM);
  // The job is the coordinator's to cancel; the signal did not reach it.
  EXPECT_FALSE(ProcessGone(pid, 0.0));
  std::vector<JobResult> cancelled = pool->CancelAll();
  ASSERT_EQ(cancelled.size(), 1u);
  EXPECT_EQ(cancelled[0].outcome, Outcome::kCancelled);
  EXPECT_TRUE(ProcessGone(pid));
  ClearInterrupt();
  EXPECT_EQ(InterruptRequested(), 0);
  // Re-armed: a second signal is recorded too, not fatal.
  ::raise(SIGINT);
  EXPECT_EQ(InterruptRequested(), SIGINT);
  ClearInterrupt();
}

TEST(WorkerPoolTest, CancelAllKillsEveryJobAndFreesTheSlots) {
  TempDir dir;
  const int workers = std::min(2, testing::AllowedCores());
  auto pool = AffinityPool(workers);
  ASSERT_TRUE(pool);
  std::vector<int> grandchildren;
  for (int i = 0; i < workers; ++i) {
    const std::string log = dir.path() + "/" + std::to_string(i) + ".log";
    ASSERT_TRUE(
        pool->Submit(FakeJob(i, log, {"grandchild", "30", "sleep", "30"}))
            .ok());
    grandchildren.push_back(WaitForNumber(log, "grandchild"));
  }
  std::vector<JobResult> cancelled = pool->CancelAll();
  ASSERT_EQ(cancelled.size(), static_cast<size_t>(workers));
  for (const JobResult& r : cancelled)
    EXPECT_EQ(r.outcome, Outcome::kCancelled);
  for (int pid : grandchildren) EXPECT_TRUE(ProcessGone(pid));
  EXPECT_EQ(pool->idle_slots(), workers);
  EXPECT_TRUE(pool->CancelAll().empty());
}

TEST(WorkerPoolTest, DestructorKillsRunningJobs) {
  TempDir dir;
  auto pool = AffinityPool();
  ASSERT_TRUE(pool);
  const std::string log = dir.path() + "/job.log";
  ASSERT_TRUE(
      pool->Submit(FakeJob(1, log, {"pid", "grandchild", "30", "sleep", "30"}))
          .ok());
  const int pid = WaitForNumber(log, "pid");
  const int grandchild = WaitForNumber(log, "grandchild");
  pool.reset();
  EXPECT_TRUE(ProcessGone(pid));
  EXPECT_TRUE(ProcessGone(grandchild));
}

}  // namespace
}  // namespace adse::pool
