// The real-time platform end to end: the small robotaxi scenario with its
// stack's threads in a cgroup of one host CPU in real time, the world on
// another, and the host placement that decides which. Real time is noisy, so
// the run is checked for what must hold under any load, never for a measured
// duration.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <string>
#include <thread>

#include "harness/pool/thread_group.h"
#include "harness/sim/host_placement.h"
#include "harness/sim/simulator.h"
#include "tests/harness/testing/small_scenario.h"

namespace adse::sim {
namespace {

using adse::testing::SmallPoint;
using adse::testing::SmallScenario;

TEST(HostPlacementTest, TheStackTakesTheLastCpusAndTheWorldTheRest) {
  Result<HostPlacement> p = PlaceOnCpus(2, {0, 1, 2, 3});
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  EXPECT_EQ(p->stack_cpus, (std::vector<int>{2, 3}));
  EXPECT_EQ(p->world_cpus, (std::vector<int>{0, 1}));
  EXPECT_NE(p->description.find("world on 0,1"), std::string::npos);

  Result<HostPlacement> shared = PlaceOnCpus(2, {4, 7});
  ASSERT_TRUE(shared.ok());
  EXPECT_EQ(shared->stack_cpus, (std::vector<int>{4, 7}));
  EXPECT_TRUE(shared->world_cpus.empty());
  EXPECT_NE(shared->description.find("shared with the world"),
            std::string::npos);
}

TEST(HostPlacementTest, MoreCoresThanTheHostGivesAreRefusedNamingBoth) {
  Result<HostPlacement> p = PlaceOnCpus(4, {0, 1});
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.status().code(), Status::Code::kUnavailable);
  EXPECT_NE(p.status().message().find("4 here"), std::string::npos)
      << p.status().message();
  EXPECT_NE(p.status().message().find("may use only 2 (CPUs 0,1)"),
            std::string::npos)
      << p.status().message();
}

// Whether this process may make a stack thread group here; under CI, whose
// machine runs the tests as root with cgroup v1, it must.
bool CgroupsHere(std::string* why) {
  pool::ThreadGroupOptions options;
  options.cpus = {0};
  Result<std::unique_ptr<pool::ThreadGroup>> group =
      pool::ThreadGroup::Create(options);
  if (!group.ok()) *why = group.status().message();
  return group.ok();
}

#define REQUIRE_CGROUPS()                                           \
  do {                                                              \
    std::string why;                                                \
    if (!CgroupsHere(&why)) {                                       \
      if (std::getenv("CI") != nullptr) FAIL() << why;              \
      GTEST_SKIP() << "no cgroup for the stack's threads: " << why; \
    }                                                               \
  } while (0)

// Reads the stack's group (v1 cpuset and cpu) while a run goes on.
class GroupWatcher {
 public:
  GroupWatcher()
      : name_("/adse-stack-" + std::to_string(::getpid())),
        thread_([this] { Loop(); }) {}
  ~GroupWatcher() { Stop(); }
  void Stop() {
    done_ = true;
    if (thread_.joinable()) thread_.join();
  }
  size_t max_tasks = 0;
  std::string cpus, quota_us;
  std::set<pid_t> processes;  // cgroup.procs: the processes with threads in it

 private:
  void Loop() {
    while (!done_) {
      std::ifstream tasks("/sys/fs/cgroup/cpuset" + name_ + "/tasks");
      size_t n = 0;
      for (std::string line; std::getline(tasks, line);) ++n;
      std::ifstream procs("/sys/fs/cgroup/cpuset" + name_ + "/cgroup.procs");
      for (pid_t pid = 0; procs >> pid;) processes.insert(pid);
      if (n > max_tasks) {
        max_tasks = n;
        std::ifstream("/sys/fs/cgroup/cpuset" + name_ + "/cpuset.cpus") >> cpus;
        std::ifstream("/sys/fs/cgroup/cpu" + name_ + "/cpu.cfs_quota_us") >>
            quota_us;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  std::string name_;
  std::atomic<bool> done_{false};
  std::thread thread_;
};

TEST(RealTimeSimulateTest,
     AOneCoreRealTimeRunDrivesTheStackInACgroupAndRecordsWhereItRan) {
  REQUIRE_CGROUPS();
  spec::Spec spec = SmallScenario();
  spec.platform.kind = spec::PlatformKind::kCgroup;
  spec.task.timeout_s = 12.0;  // 12 s of real time
  GroupWatcher watcher;
  Result<runfile::RunData> run = SimulatePoint(spec, SmallPoint(1, 2.1, 7));
  watcher.Stop();
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_EQ(run->platform.at("kind"), "cgroup");
  const std::string& where = run->platform.at("confinement");
  EXPECT_NE(where.find("cgroup v"), std::string::npos) << where;
  EXPECT_NE(where.find("cpuset"), std::string::npos) << where;
  EXPECT_EQ(run->platform.at("clock_by"), "padding");
  EXPECT_EQ(run->platform.at("time_dilation"), "1");
  EXPECT_TRUE(run->platform.count("world_lag_max_s"));
  // The stack ran in a process of its own, which says what crossed.
  const std::string& process = run->platform.at("stack_process");
  EXPECT_EQ(process.rfind("process ", 0), 0u) << process;
  EXPECT_NE(process.find("over a Unix socket"), std::string::npos) << process;
  EXPECT_EQ(process.find("process " + std::to_string(::getpid()) + ","),
            std::string::npos)
      << process;
  if (where.find("cgroup v1") != std::string::npos) {
    // The stack's process was in the group, its main thread, the executor's
    // thread and its clock, on one CPU, and nothing of this process; the
    // group is gone afterwards.
    ASSERT_EQ(watcher.processes.size(), 1u);
    EXPECT_NE(*watcher.processes.begin(), ::getpid());
    EXPECT_NE(process.find(std::to_string(*watcher.processes.begin())),
              std::string::npos)
        << process;
    EXPECT_EQ(watcher.max_tasks, 3u);
    EXPECT_EQ(watcher.cpus.find_first_of(",-"), std::string::npos)
        << watcher.cpus;
    EXPECT_FALSE(std::filesystem::exists("/sys/fs/cgroup/cpuset/adse-stack-" +
                                         std::to_string(::getpid())));
  }
  // The stack ran: commands reached the car, sensing took scans, and every
  // record is a real interval on the one executor thread.
  // (Bounds that hold however loaded the host is: ctest runs other tests
  // beside this one.)
  EXPECT_GT(run->controls.size(), 3u) << "the loop closed";
  std::set<int> ran;
  for (const stack::CallbackRecord& r : run->trace.callbacks) {
    ran.insert(r.callback);
    EXPECT_GE(r.start_s, r.ready_s - 1e-6);
    EXPECT_GE(r.end_s, r.start_s);
    EXPECT_EQ(r.first_core, 0);
  }
  EXPECT_GT(ran.size(), run->callback_info.size() / 2);
  // Sim time ran with the wall clock to the timeout.
  ASSERT_FALSE(run->ego.empty());
  EXPECT_NEAR(run->ego.back().t_s, 12.0, 0.1);
  EXPECT_GT(run->metrics.at("ctrl_rate_hz"), 0.0);
}

TEST(RealTimeSimulateTest, AQuotaStandsForTheClockAsAShareOfTheHostsCpu) {
  REQUIRE_CGROUPS();
  spec::Spec spec = SmallScenario();
  spec.platform.kind = spec::PlatformKind::kCgroup;
  spec.platform.clock_by = spec::ClockBy::kQuota;
  spec.platform.host_ghz = 2.0;  // 1 GHz is half of it
  spec.task.timeout_s = 4.0;
  GroupWatcher watcher;
  Result<runfile::RunData> run = SimulatePoint(spec, SmallPoint(1, 1.0, 7));
  watcher.Stop();
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  const std::string& clock = run->platform.at("clock_by");
  EXPECT_EQ(clock.rfind("quota (share 0.500 of a 2 GHz host CPU, from "
                        "platform.host_ghz)",
                        0),
            0u)
      << clock;
  EXPECT_NE(run->platform.at("confinement").find("cpu quota 0.5 CPUs"),
            std::string::npos)
      << run->platform.at("confinement");
  if (run->platform.at("confinement").find("cgroup v1") != std::string::npos) {
    EXPECT_EQ(watcher.quota_us, "5000");  // of a 10 ms period
  }
  EXPECT_GT(run->controls.size(), 3u) << "the loop closed";
}

TEST(RealTimeSimulateTest, AQuotaCannotStandForAClockFasterThanTheHost) {
  spec::Spec spec = SmallScenario();
  spec.platform.kind = spec::PlatformKind::kCgroup;
  spec.platform.clock_by = spec::ClockBy::kQuota;
  spec.platform.host_ghz = 1.5;
  Result<runfile::RunData> run = SimulatePoint(spec, SmallPoint(1, 2.1, 7));
  ASSERT_FALSE(run.ok());
  EXPECT_EQ(run.status().code(), Status::Code::kInvalidArgument);
  EXPECT_NE(run.status().message().find("platform.clock_by: quota"),
            std::string::npos)
      << run.status().message();
  EXPECT_NE(run.status().message().find("1.5 GHz (platform.host_ghz)"),
            std::string::npos)
      << run.status().message();
}

TEST(RealTimeSimulateTest, TheRealTimePlatformNeedsACostProfile) {
  spec::Spec spec = SmallScenario();
  spec.platform.kind = spec::PlatformKind::kCgroup;
  spec.platform.cost_model = spec::CostModel::kMeasured;
  spec.platform.profile.clear();
  Result<runfile::RunData> run = SimulatePoint(spec, SmallPoint(1, 2.1, 7));
  ASSERT_FALSE(run.ok());
  EXPECT_NE(run.status().message().find("platform.profile"), std::string::npos)
      << run.status().message();
}

}  // namespace
}  // namespace adse::sim
