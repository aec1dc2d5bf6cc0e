// The pool on the machine's real cgroup v1 hierarchies (cpuset, memory,
// pids), as on hybrid hosts and in CI's root container. Skipped, saying
// why, where those are not mounted or not writable (not root).
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <map>

#include <gtest/gtest.h>

#include "harness/pool/cgroup.h"
#include "harness/pool/worker_pool.h"
#include "tests/harness/pool/pool_test_util.h"

namespace adse::pool {
namespace {

namespace fs = std::filesystem;
using testing::FakeJob;
using testing::ProcessGone;
using testing::ReadText;
using testing::TempDir;
using testing::Trimmed;
using testing::WaitAll;
using testing::WaitForNumber;

const char* const kControllers[] = {"cpuset", "memory", "pids"};

class CgroupV1Test : public ::testing::Test {
 protected:
  void SetUp() override {
    if (::geteuid() != 0) GTEST_SKIP() << "needs root for cgroup v1";
    const auto mounts = internal::ParseMountInfo(
        ReadText("/proc/self/mountinfo"), "/sys/fs/cgroup");
    auto groups = internal::ParseProcCgroup(ReadText("/proc/self/cgroup"));
    for (const char* c : kControllers) {
      for (const internal::CgroupMount& m : mounts) {
        const bool has = std::find(m.controllers.begin(), m.controllers.end(),
                                   c) != m.controllers.end();
        if (m.version == 1 && has && m.root == "/" && groups.count(c)) {
          own_[c] = m.mount_point + (groups[c] == "/" ? "" : groups[c]);
        }
      }
      if (!own_.count(c) || ::access(own_[c].c_str(), W_OK) != 0) {
        GTEST_SKIP() << "needs a writable cgroup v1 " << c
                     << " hierarchy under /sys/fs/cgroup";
      }
    }
    // A v2 tree offering memory would be preferred: not this test's case.
    for (const internal::CgroupMount& m : mounts) {
      if (m.version == 2 &&
          ReadText(m.mount_point + "/cgroup.controllers").find("memory") !=
              std::string::npos) {
        GTEST_SKIP() << "cgroup v2 offers memory here; v1 would not be used";
      }
    }
  }

  std::unique_ptr<WorkerPool> Pool(int workers = 1, int memory_mb = 64) {
    PoolOptions options;
    options.workers = workers;
    options.memory_mb = memory_mb;
    options.pids_max = 64;
    options.isolation = Isolation::kCgroup;
    Result<std::unique_ptr<WorkerPool>> pool = WorkerPool::Create(options);
    EXPECT_TRUE(pool.ok()) << pool.status().ToString();
    return pool.ok() ? std::move(pool).value() : nullptr;
  }

  std::string Group(const char* controller, int slot = -1) {
    std::string dir = own_[controller] + "/adse-" + std::to_string(::getpid());
    if (slot >= 0) dir += "/worker-" + std::to_string(slot);
    return dir;
  }

  std::map<std::string, std::string> own_;
  TempDir tmp_;
};

TEST_F(CgroupV1Test, GroupsGetTheSlotLimitsAndAreRemovedByTheDestructor) {
  const int workers = std::min(2, testing::AllowedCores());
  auto pool = Pool(workers);
  ASSERT_TRUE(pool);
  EXPECT_EQ(pool->isolation_description(),
            "cgroup v1 (cpuset, memory, pids) under " + Group("cpuset") + ", " +
                Group("memory") + ", " + Group("pids"));
  EXPECT_EQ(pool->fallback_reason(), "");
  std::vector<std::string> cpus;
  for (int i = 0; i < workers; ++i) {
    cpus.push_back(Trimmed(ReadText(Group("cpuset", i) + "/cpuset.cpus")));
    EXPECT_FALSE(cpus.back().empty());
    EXPECT_FALSE(
        Trimmed(ReadText(Group("cpuset", i) + "/cpuset.mems")).empty());
    EXPECT_EQ(Trimmed(ReadText(Group("memory", i) + "/memory.limit_in_bytes")),
              std::to_string(64 << 20));
    if (fs::exists(Group("memory", i) + "/memory.memsw.limit_in_bytes")) {
      EXPECT_EQ(Trimmed(ReadText(Group("memory", i) +
                                 "/memory.memsw.limit_in_bytes")),
                std::to_string(64 << 20));
    }
    EXPECT_EQ(Trimmed(ReadText(Group("pids", i) + "/pids.max")), "64");
  }
  if (workers == 2) {
    EXPECT_NE(cpus[0], cpus[1]);
  }
  pool.reset();
  for (const char* c : kControllers) {
    EXPECT_FALSE(fs::exists(Group(c))) << Group(c);
  }
}

TEST_F(CgroupV1Test, JobRunsInsideItsSlotGroups) {
  auto pool = Pool();
  ASSERT_TRUE(pool);
  const std::string log = tmp_.path() + "/job.log";
  ASSERT_TRUE(pool->Submit(FakeJob(1, log, {"cgroup", "affinity"})).ok());
  std::vector<JobResult> results = WaitAll(*pool);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].outcome, Outcome::kOk);
  const auto groups = internal::ParseProcCgroup(ReadText(log));
  const std::string suffix =
      "/adse-" + std::to_string(::getpid()) + "/worker-0";
  for (const char* c : kControllers) {
    ASSERT_TRUE(groups.count(c)) << ReadText(log);
    const std::string& path = groups.at(c);
    EXPECT_EQ(path.substr(path.size() - std::min(path.size(), suffix.size())),
              suffix)
        << c << ": " << path;
  }
  EXPECT_EQ("cpus " + Trimmed(ReadText(Group("cpuset", 0) + "/cpuset.cpus")),
            Trimmed(ReadText(log).substr(ReadText(log).find("cpus "))))
      << "affinity agrees with the cpuset";
}

TEST_F(CgroupV1Test, JobKilledFromOutsideIsACrash) {
  auto pool = Pool();
  ASSERT_TRUE(pool);
  const std::string log = tmp_.path() + "/job.log";
  ASSERT_TRUE(pool->Submit(FakeJob(1, log, {"pid", "sleep", "30"})).ok());
  const int pid = WaitForNumber(log, "pid");
  ASSERT_GT(pid, 0);
  ASSERT_EQ(::kill(pid, SIGKILL), 0);
  std::vector<JobResult> results = WaitAll(*pool);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].outcome, Outcome::kCrashed);
  EXPECT_EQ(results[0].signal, SIGKILL);
}

TEST_F(CgroupV1Test, JobPastItsTimeoutIsKilledAsAWholeGroup) {
  auto pool = Pool();
  ASSERT_TRUE(pool);
  const std::string log = tmp_.path() + "/job.log";
  // The escapee leaves the job's process group: only the cgroup finds it.
  ASSERT_TRUE(
      pool->Submit(FakeJob(1, log,
                           {"grandchild", "30", "escapee", "30", "sleep", "30"},
                           0.3))
          .ok());
  const int grandchild = WaitForNumber(log, "grandchild");
  const int escapee = WaitForNumber(log, "escapee");
  ASSERT_GT(escapee, 0);
  std::vector<JobResult> results = WaitAll(*pool);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].outcome, Outcome::kTimeout);
  EXPECT_LT(results[0].wall_s, 2.0);
  EXPECT_TRUE(ProcessGone(grandchild));
  EXPECT_TRUE(ProcessGone(escapee));
  EXPECT_EQ(Trimmed(ReadText(Group("memory", 0) + "/cgroup.procs")), "");
}

TEST_F(CgroupV1Test, LeftoverProcessesDieWithTheirJob) {
  auto pool = Pool();
  ASSERT_TRUE(pool);
  const std::string log = tmp_.path() + "/job.log";
  ASSERT_TRUE(
      pool->Submit(FakeJob(1, log, {"escapee", "30", "exit", "0"})).ok());
  std::vector<JobResult> results = WaitAll(*pool);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].outcome, Outcome::kOk);
  EXPECT_TRUE(ProcessGone(WaitForNumber(log, "escapee")));
  EXPECT_EQ(Trimmed(ReadText(Group("memory", 0) + "/cgroup.procs")), "");
}

TEST_F(CgroupV1Test, AllocationPastTheLimitIsOutOfMemory) {
  auto pool = Pool(1, /*memory_mb=*/64);
  ASSERT_TRUE(pool);
  ASSERT_TRUE(
      pool->Submit(FakeJob(1, tmp_.path() + "/job.log", {"alloc", "256"}))
          .ok());
  std::vector<JobResult> results = WaitAll(*pool);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].outcome, Outcome::kOutOfMemory);
  EXPECT_EQ(results[0].signal, SIGKILL);
  // The same slot runs the next job normally.
  ASSERT_TRUE(
      pool->Submit(FakeJob(2, tmp_.path() + "/ok.log", {"alloc", "16"})).ok());
  results = WaitAll(*pool);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].outcome, Outcome::kOk);
}

TEST_F(CgroupV1Test, StaleGroupOfADeadCoordinatorIsRemoved) {
  // A coordinator "adse-<dead>" killed outright left a group with a
  // worker still running in it.
  const int dead = 999999;
  const std::string stale = own_["memory"] + "/adse-" + std::to_string(dead);
  ASSERT_EQ(::mkdir(stale.c_str(), 0755), 0) << stale;
  ASSERT_EQ(::mkdir((stale + "/worker-0").c_str(), 0755), 0);
  const pid_t orphan = ::fork();
  if (orphan == 0) {
    ::execl(ADSE_POOL_FAKE_WORKER, ADSE_POOL_FAKE_WORKER, "sleep", "30",
            static_cast<char*>(nullptr));
    ::_exit(127);
  }
  testing::WriteText(stale + "/worker-0/cgroup.procs", std::to_string(orphan));
  ASSERT_EQ(Trimmed(ReadText(stale + "/worker-0/cgroup.procs")),
            std::to_string(orphan));

  PoolOptions options;
  options.workers = 1;
  options.isolation = Isolation::kCgroup;
  options.pid_alive = [dead](int pid) {
    return pid != dead && internal::DefaultPidAlive(pid);
  };
  Result<std::unique_ptr<WorkerPool>> pool = WorkerPool::Create(options);
  ASSERT_TRUE(pool.ok()) << pool.status().ToString();
  EXPECT_FALSE(fs::exists(stale));
  int status = 0;
  ASSERT_EQ(::waitpid(orphan, &status, 0), orphan);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
}

}  // namespace
}  // namespace adse::pool
