// The stack's thread group: its file protocol against folders laid out like
// cgroupfs (v1 hierarchies, a v2 threaded subtree), its refusals, and, as
// root where cgroup v1 is mounted, the real thing: threads of this process
// confined to a cpuset and a CPU quota, and removed again.
#include "harness/pool/thread_group.h"

#include <sched.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "tests/harness/pool/pool_test_util.h"

namespace adse::pool {
namespace {

namespace fs = std::filesystem;
using testing::ReadText;
using testing::TempDir;
using testing::Trimmed;
using testing::WriteText;

const std::string kPid = std::to_string(::getpid());

std::string Tid() { return std::to_string(::syscall(SYS_gettid)); }

// Options that look for cgroups under `tmp` (<tmp>/cgroup, mountinfo,
// self_cgroup) rather than the machine's.
ThreadGroupOptions FakeOptions(const TempDir& tmp, std::vector<int> cpus) {
  ThreadGroupOptions o;
  o.cpus = std::move(cpus);
  o.cgroup_root = tmp.path() + "/cgroup";
  o.proc_self_cgroup = tmp.path() + "/self_cgroup";
  o.proc_self_mountinfo = tmp.path() + "/mountinfo";
  return o;
}

// cpuset and cpu v1 hierarchies at <tmp>/cgroup/{cpuset,cpu}, this process
// in /jobs/7 of both.
struct FakeV1 {
  explicit FakeV1(bool with_cpu = true) {
    WriteText(tmp.path() + "/cgroup/cpuset/jobs/7/cpuset.mems", "0\n");
    WriteText(tmp.path() + "/cgroup/cpuset/jobs/7/tasks", Tid() + "\n");
    std::string mounts = "22 1 8:1 / / rw - ext4 /dev/root rw\n";
    mounts += "34 22 0:31 / " + tmp.path() +
              "/cgroup/cpuset rw - cgroup cgroup rw,cpuset\n";
    std::string self = "3:cpuset:/jobs/7\n";
    if (with_cpu) {
      WriteText(tmp.path() + "/cgroup/cpu/jobs/7/tasks", Tid() + "\n");
      mounts += "32 22 0:29 / " + tmp.path() +
                "/cgroup/cpu rw - cgroup cgroup rw,cpu,cpuacct\n";
      self += "2:cpu,cpuacct:/jobs/7\n";
    }
    WriteText(tmp.path() + "/mountinfo", mounts);
    WriteText(tmp.path() + "/self_cgroup", self);
  }
  ThreadGroupOptions Options() const { return FakeOptions(tmp, {2, 3}); }
  std::string Own(const char* controller) const {
    return tmp.path() + "/cgroup/" + controller + "/jobs/7";
  }
  TempDir tmp;
};

TEST(ThreadGroupFakeTest, V1SetsTheCpusetAndQuotaAndTakesTheCallingThread) {
  FakeV1 fake;
  ThreadGroupOptions options = fake.Options();
  options.cpu_quota = 0.5;
  Result<std::unique_ptr<ThreadGroup>> group = ThreadGroup::Create(options);
  ASSERT_TRUE(group.ok()) << group.status().ToString();
  EXPECT_EQ((*group)->version(), 1);
  const std::string set = fake.Own("cpuset") + "/adse-stack-" + kPid;
  const std::string cpu = fake.Own("cpu") + "/adse-stack-" + kPid;
  EXPECT_EQ((*group)->dirs(), (std::vector<std::string>{set, cpu}));
  EXPECT_EQ(Trimmed(ReadText(set + "/cpuset.cpus")), "2-3");
  EXPECT_EQ(Trimmed(ReadText(set + "/cpuset.mems")), "0");
  EXPECT_EQ(Trimmed(ReadText(cpu + "/cpu.cfs_period_us")), "10000");
  EXPECT_EQ(Trimmed(ReadText(cpu + "/cpu.cfs_quota_us")), "5000");
  EXPECT_NE((*group)->Describe().find("cgroup v1 cpuset 2-3, cpu quota 0.5 "
                                      "CPUs per 10 ms"),
            std::string::npos)
      << (*group)->Describe();

  std::string tid;
  std::thread t([&] {
    tid = Tid();
    EXPECT_TRUE((*group)->AddCurrentThread().ok());
  });
  t.join();
  EXPECT_EQ(Trimmed(ReadText(set + "/tasks")), tid);
  EXPECT_EQ(Trimmed(ReadText(cpu + "/tasks")), tid);

  group->reset();
  EXPECT_FALSE(fs::exists(set));
  EXPECT_FALSE(fs::exists(cpu));
  EXPECT_TRUE(fs::exists(fake.Own("cpuset")));
}

TEST(ThreadGroupFakeTest, V1WithoutAQuotaNeedsNoCpuHierarchy) {
  FakeV1 fake(/*with_cpu=*/false);
  Result<std::unique_ptr<ThreadGroup>> group =
      ThreadGroup::Create(fake.Options());
  ASSERT_TRUE(group.ok()) << group.status().ToString();
  EXPECT_EQ((*group)->dirs().size(), 1u);

  // A quota does need it, and the half-made group does not stay behind.
  group->reset();
  ThreadGroupOptions options = fake.Options();
  options.cpu_quota = 1.0;
  Result<std::unique_ptr<ThreadGroup>> refused = ThreadGroup::Create(options);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), Status::Code::kUnavailable);
  EXPECT_NE(refused.status().message().find("cgroup v1 cpu controller"),
            std::string::npos)
      << refused.status().message();
  EXPECT_FALSE(fs::exists(fake.Own("cpuset") + "/adse-stack-" + kPid));
}

TEST(ThreadGroupFakeTest, StaleGroupsOfDeadProcessesAreRemovedFirst) {
  FakeV1 fake;
  // A group of a process that no longer runs (pid 2^22 + 1 is above any
  // pid_max), with a control file, and one of a live process.
  const std::string stale = fake.Own("cpuset") + "/adse-stack-4194305";
  WriteText(stale + "/cpuset.cpus", "1\n");
  const std::string live = fake.Own("cpuset") + "/adse-stack-1";
  WriteText(live + "/cpuset.cpus", "1\n");
  Result<std::unique_ptr<ThreadGroup>> group =
      ThreadGroup::Create(fake.Options());
  ASSERT_TRUE(group.ok()) << group.status().ToString();
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(live));
}

TEST(ThreadGroupFakeTest, V2MakesAThreadedChildAndUndoesWhatItEnabled) {
  TempDir tmp;
  const std::string own = tmp.path() + "/cgroup/user.slice/run.scope";
  WriteText(own + "/cgroup.controllers", "cpuset cpu io memory pids\n");
  WriteText(own + "/cgroup.subtree_control", "\n");
  WriteText(own + "/cgroup.procs", kPid + "\n");
  WriteText(tmp.path() + "/mountinfo",
            "22 1 8:1 / / rw - ext4 /dev/root rw\n30 22 0:26 / " + tmp.path() +
                "/cgroup rw - cgroup2 cgroup2 rw\n");
  WriteText(tmp.path() + "/self_cgroup", "0::/user.slice/run.scope\n");
  ThreadGroupOptions options = FakeOptions(tmp, {1});
  options.cpu_quota = 0.25;
  Result<std::unique_ptr<ThreadGroup>> group = ThreadGroup::Create(options);
  ASSERT_TRUE(group.ok()) << group.status().ToString();
  EXPECT_EQ((*group)->version(), 2);
  const std::string dir = own + "/adse-stack-" + kPid;
  EXPECT_EQ(Trimmed(ReadText(own + "/cgroup.subtree_control")), "+cpuset +cpu");
  EXPECT_EQ(Trimmed(ReadText(dir + "/cgroup.type")), "threaded");
  EXPECT_EQ(Trimmed(ReadText(dir + "/cpuset.cpus")), "1");
  EXPECT_EQ(Trimmed(ReadText(dir + "/cpu.max")), "2500 10000");
  ASSERT_TRUE((*group)->AddCurrentThread().ok());
  EXPECT_EQ(Trimmed(ReadText(dir + "/cgroup.threads")), Tid());

  group->reset();
  EXPECT_FALSE(fs::exists(dir));
  // The thread went back to the own group, and the controllers were
  // handed back.
  EXPECT_EQ(Trimmed(ReadText(own + "/cgroup.threads")), Tid());
  EXPECT_EQ(Trimmed(ReadText(own + "/cgroup.subtree_control")), "-cpuset -cpu");
}

TEST(ThreadGroupFakeTest, V2WithoutTheCpusetControllerIsRefusedNamingIt) {
  TempDir tmp;
  const std::string own = tmp.path() + "/cgroup/app.scope";
  WriteText(own + "/cgroup.controllers", "memory pids\n");
  WriteText(tmp.path() + "/mountinfo",
            "30 22 0:26 / " + tmp.path() + "/cgroup rw - cgroup2 cgroup2 rw\n");
  WriteText(tmp.path() + "/self_cgroup", "0::/app.scope\n");
  Result<std::unique_ptr<ThreadGroup>> group =
      ThreadGroup::Create(FakeOptions(tmp, {0}));
  ASSERT_FALSE(group.ok());
  EXPECT_EQ(group.status().code(), Status::Code::kUnavailable);
  EXPECT_NE(
      group.status().message().find("offers no cpuset controller to " + own),
      std::string::npos)
      << group.status().message();
  EXPECT_FALSE(fs::exists(own + "/adse-stack-" + kPid));
}

TEST(ThreadGroupFakeTest, WithoutAnyCgroupMountItRefusesNamingWhatIsMissing) {
  TempDir tmp;
  WriteText(tmp.path() + "/mountinfo", "22 1 8:1 / / rw - ext4 /dev/root rw\n");
  WriteText(tmp.path() + "/self_cgroup", "");
  Result<std::unique_ptr<ThreadGroup>> group =
      ThreadGroup::Create(FakeOptions(tmp, {0}));
  ASSERT_FALSE(group.ok());
  EXPECT_NE(group.status().message().find("needs the cpuset controller"),
            std::string::npos)
      << group.status().message();
  EXPECT_NE(group.status().message().find("no v1 cpuset hierarchy"),
            std::string::npos);
}

TEST(ThreadGroupFakeTest, BadOptionsAreRefusedNamingTheField) {
  const struct {
    ThreadGroupOptions options;
    const char* field;
  } kCases[] = {
      {{}, "cpus"},
      {{{1, 1}}, "cpus"},
      {{{0}, 1.5}, "cpu_quota"},
      {{{0}, -0.1}, "cpu_quota"},
      {{{0}, 0.5, 100}, "quota_period_us"},
      {{{0}, 0.0, 10000, "stack"}, "name"},
  };
  for (const auto& c : kCases) {
    Result<std::unique_ptr<ThreadGroup>> group = ThreadGroup::Create(c.options);
    ASSERT_FALSE(group.ok()) << c.field;
    EXPECT_EQ(group.status().code(), Status::Code::kInvalidArgument);
    EXPECT_EQ(group.status().message().rfind(c.field, 0), 0u)
        << group.status().message();
  }
}

// ---- The real cgroup v1 hierarchies (root, as in CI) -------------------

bool RealV1CpusetWritable() {
  return ::geteuid() == 0 &&
         ::access("/sys/fs/cgroup/cpuset/cpuset.cpus", W_OK) == 0 &&
         ::access("/sys/fs/cgroup/cpu/cpu.cfs_quota_us", W_OK) == 0;
}

// Skipped where there is no writable v1 cpuset and cpu (not root, a v2-only
// host); under CI, whose machine has them, that is a failure instead.
#define REQUIRE_REAL_V1()                                              \
  do {                                                                 \
    if (!RealV1CpusetWritable()) {                                     \
      if (std::getenv("CI") != nullptr) {                              \
        FAIL() << "CI runs as root with cgroup v1 cpuset and cpu";     \
      }                                                                \
      GTEST_SKIP() << "needs root and cgroup v1 cpuset and cpu under " \
                      "/sys/fs/cgroup";                                \
    }                                                                  \
  } while (0)

TEST(ThreadGroupV1Test, AThreadInTheGroupRunsOnlyOnItsCpusUnderItsQuota) {
  REQUIRE_REAL_V1();
  cpu_set_t mine;
  ASSERT_EQ(sched_getaffinity(0, sizeof(mine), &mine), 0);
  int last = -1;
  for (int c = 0; c < CPU_SETSIZE; ++c) {
    if (CPU_ISSET(c, &mine)) last = c;
  }
  ThreadGroupOptions options;
  options.cpus = {last};
  options.cpu_quota = 0.5;
  Result<std::unique_ptr<ThreadGroup>> group = ThreadGroup::Create(options);
  ASSERT_TRUE(group.ok()) << group.status().ToString();
  const std::string set = (*group)->dirs()[0];
  const std::string cpu = (*group)->dirs()[1];
  EXPECT_EQ(Trimmed(ReadText(cpu + "/cpu.cfs_quota_us")), "5000");

  std::string tid;
  int allowed = -1;
  double share = 1.0;
  std::thread t([&] {
    tid = Tid();
    ASSERT_TRUE((*group)->AddCurrentThread().ok());
    // Joining a v1 cpuset narrows the thread's affinity to it.
    cpu_set_t now;
    sched_getaffinity(0, sizeof(now), &now);
    allowed = CPU_COUNT(&now) == 1 && CPU_ISSET(last, &now) ? last : -2;
    EXPECT_NE(ReadText(set + "/tasks").find(tid), std::string::npos);
    EXPECT_NE(ReadText(cpu + "/tasks").find(tid), std::string::npos);
    // The quota caps the thread at half a CPU however idle the host is
    // (a busy host can only lower its share).
    timespec cpu0, wall0, now_cpu, now_wall;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cpu0);
    clock_gettime(CLOCK_MONOTONIC, &wall0);
    auto seconds = [](const timespec& a, const timespec& b) {
      return (b.tv_sec - a.tv_sec) + 1e-9 * (b.tv_nsec - a.tv_nsec);
    };
    do {
      clock_gettime(CLOCK_MONOTONIC, &now_wall);
    } while (seconds(wall0, now_wall) < 0.3);
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now_cpu);
    share = seconds(cpu0, now_cpu) / seconds(wall0, now_wall);
  });
  t.join();
  EXPECT_EQ(allowed, last);
  EXPECT_LT(share, 0.6) << "a quota of 0.5 CPU";
  // This thread (the world's) stayed outside.
  EXPECT_EQ(ReadText(set + "/tasks").find(Tid()), std::string::npos);

  // A thread that is still inside when the group goes is moved out first.
  ASSERT_TRUE((*group)->AddCurrentThread().ok());
  group->reset();
  EXPECT_FALSE(fs::exists(set));
  EXPECT_FALSE(fs::exists(cpu));
  cpu_set_t after;
  sched_setaffinity(0, sizeof(mine), &mine);
  sched_getaffinity(0, sizeof(after), &after);
  EXPECT_TRUE(CPU_EQUAL(&after, &mine));
}

}  // namespace
}  // namespace adse::pool
