// The cgroup file protocol against temporary folders laid out like
// cgroupfs (v2 delegated subtree, v1 hierarchies), and the parsers. Needs
// neither root nor cgroups: the jobs really run, and write their pid into
// the fake cgroup.procs files as they would into real ones.
#include "harness/pool/cgroup.h"

#include <unistd.h>

#include <filesystem>

#include <gtest/gtest.h>

#include "harness/pool/worker_pool.h"
#include "tests/harness/pool/pool_test_util.h"

namespace adse::pool {
namespace {

namespace fs = std::filesystem;
using testing::FakeJob;
using testing::ReadText;
using testing::TempDir;
using testing::Trimmed;
using testing::WaitAll;
using testing::WaitForNumber;
using testing::WriteText;

const std::string kSelf = std::to_string(::getpid());

// A v2 hierarchy mounted at <tmp>/cgroup, this process in
// /user.slice/app.scope, offered `controllers`.
struct FakeV2 {
  explicit FakeV2(const std::string& controllers,
                  const std::string& procs = kSelf + "\n") {
    own = tmp.path() + "/cgroup/user.slice/app.scope";
    WriteText(own + "/cgroup.controllers", controllers + "\n");
    WriteText(own + "/cgroup.subtree_control", "\n");
    WriteText(own + "/cgroup.procs", procs);
    WriteText(tmp.path() + "/mountinfo",
              "22 1 8:1 / / rw,relatime - ext4 /dev/root rw\n"
              "30 22 0:26 / " +
                  tmp.path() +
                  "/cgroup rw,nosuid - cgroup2 cgroup2 rw,nsdelegate\n");
    WriteText(tmp.path() + "/self_cgroup", "0::/user.slice/app.scope\n");
  }
  PoolOptions Options(int workers = 1) const {
    PoolOptions options;
    options.workers = workers;
    options.memory_mb = 64;
    options.pids_max = 32;
    options.isolation = Isolation::kCgroup;
    options.cgroup_root = tmp.path() + "/cgroup";
    options.proc_self_cgroup = tmp.path() + "/self_cgroup";
    options.proc_self_mountinfo = tmp.path() + "/mountinfo";
    return options;
  }
  TempDir tmp;
  std::string own;
};

TEST(CgroupParseTest, FindsHybridMountsBelowTheRoot) {
  const std::string text =
      "31 23 0:28 / /sys/fs/cgroup rw,relatime - tmpfs tmpfs rw,mode=755\n"
      "32 31 0:29 / /sys/fs/cgroup/cpu rw,relatime - cgroup cgroup rw,cpu\n"
      "34 31 0:31 / /sys/fs/cgroup/cpuset rw,relatime - cgroup cgroup "
      "rw,cpuset\n"
      "35 31 0:32 / /sys/fs/cgroup/memory rw,relatime shared:9 - cgroup "
      "cgroup rw,memory\n"
      "39 31 0:36 /outer /sys/fs/cgroup/pids rw - cgroup cgroup rw,pids\n"
      "41 31 0:38 / /sys/fs/cgroup/uni\\040fied rw - cgroup2 cgroup2 rw\n"
      "50 22 0:40 / /elsewhere/cgroup rw - cgroup2 cgroup2 rw\n";
  std::vector<internal::CgroupMount> mounts =
      internal::ParseMountInfo(text, "/sys/fs/cgroup/");
  ASSERT_EQ(mounts.size(), 5u);
  EXPECT_EQ(mounts[0].version, 1);
  EXPECT_EQ(mounts[0].controllers, (std::vector<std::string>{"rw", "cpu"}));
  EXPECT_EQ(mounts[2].mount_point, "/sys/fs/cgroup/memory");
  EXPECT_EQ(mounts[3].root, "/outer");
  EXPECT_EQ(mounts[4].version, 2);
  EXPECT_EQ(mounts[4].mount_point, "/sys/fs/cgroup/uni fied");
}

TEST(CgroupParseTest, ReadsTheProcessGroups) {
  std::map<std::string, std::string> groups = internal::ParseProcCgroup(
      "9:name=systemd:/\n4:memory:/process_api/c41\n2:cpu,cpuacct:/a:b\n"
      "0::/user.slice/x.scope\n");
  EXPECT_EQ(groups["memory"], "/process_api/c41");
  EXPECT_EQ(groups["cpu"], "/a:b");
  EXPECT_EQ(groups["cpuacct"], "/a:b");
  EXPECT_EQ(groups["name=systemd"], "/");
  EXPECT_EQ(groups[""], "/user.slice/x.scope");
}

TEST(CgroupParseTest, FormatsCpuListsAndGroupNames) {
  EXPECT_EQ(internal::FormatCpuList({6, 0, 1, 2, 3}), "0-3,6");
  EXPECT_EQ(internal::FormatCpuList({5}), "5");
  EXPECT_EQ(internal::GroupNamePid("adse-123"), 123);
  EXPECT_EQ(internal::GroupNamePid("adse-run-7"), 7);
  EXPECT_EQ(internal::GroupNamePid("session-3"), -1);
  EXPECT_EQ(internal::GroupNamePid("adse-"), -1);
  EXPECT_EQ(internal::GroupNamePid("adse-12x"), -1);
}

TEST(CgroupFakeTest, CgroupIsolationRefusesWithoutAMemoryController) {
  FakeV2 fake("hugetlb");
  Result<std::unique_ptr<WorkerPool>> pool = WorkerPool::Create(fake.Options());
  ASSERT_FALSE(pool.ok());
  EXPECT_EQ(pool.status().code(), Status::Code::kUnavailable);
  const std::string& message = pool.status().message();
  EXPECT_NE(message.find("no memory controller"), std::string::npos) << message;
  EXPECT_NE(message.find("cgroup.controllers: 'hugetlb'"), std::string::npos)
      << message;
  EXPECT_NE(message.find("systemd-run --user --scope -p Delegate=yes"),
            std::string::npos)
      << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
}

TEST(CgroupFakeTest, AutoFallsBackToAffinityAndSaysWhy) {
  FakeV2 fake("cpu io");
  PoolOptions options = fake.Options();
  options.isolation = Isolation::kAuto;
  Result<std::unique_ptr<WorkerPool>> pool = WorkerPool::Create(options);
  ASSERT_TRUE(pool.ok()) << pool.status().ToString();
  EXPECT_EQ((*pool)->isolation_description().rfind("affinity + rlimits", 0),
            0u);
  const std::string reason = (*pool)->fallback_reason();
  EXPECT_EQ(reason.rfind("cgroups unavailable: cgroup v2", 0), 0u) << reason;
  EXPECT_EQ(reason.find('\n'), std::string::npos);
}

TEST(CgroupFakeTest, NoCgroupMountedIsUnavailable) {
  FakeV2 fake("cpuset memory pids");
  PoolOptions options = fake.Options();
  options.cgroup_root = fake.tmp.path() + "/elsewhere";
  Result<std::unique_ptr<WorkerPool>> pool = WorkerPool::Create(options);
  ASSERT_FALSE(pool.ok());
  EXPECT_NE(pool.status().message().find("no cgroup filesystem is mounted"),
            std::string::npos)
      << pool.status().message();
}

TEST(CgroupFakeTest, AffinityIsolationNeverTouchesCgroups) {
  FakeV2 fake("cpuset memory pids");
  PoolOptions options = fake.Options();
  options.isolation = Isolation::kAffinity;
  {
    Result<std::unique_ptr<WorkerPool>> pool = WorkerPool::Create(options);
    ASSERT_TRUE(pool.ok());
    EXPECT_FALSE(fs::exists(fake.own + "/adse-" + kSelf));
  }
  EXPECT_EQ(Trimmed(ReadText(fake.own + "/cgroup.subtree_control")), "");
}

TEST(CgroupFakeTest, V2DelegatedSubtreeFileProtocol) {
  FakeV2 fake("cpuset cpu io memory pids");
  const std::string parent = fake.own + "/adse-" + kSelf;
  const int workers = std::min(2, testing::AllowedCores());
  {
    Result<std::unique_ptr<WorkerPool>> created =
        WorkerPool::Create(fake.Options(workers));
    ASSERT_TRUE(created.ok()) << created.status().ToString();
    WorkerPool& pool = **created;
    EXPECT_EQ(pool.isolation_description(),
              "cgroup v2 (cpuset, memory, pids) under " + parent);
    // The own group held this process: it moved into a leaf first, then
    // enabled the controllers for the sub-groups.
    EXPECT_EQ(ReadText(parent + "/coordinator/cgroup.procs"), kSelf);
    // cpu too, for a real-time stack's quota inside a worker.
    EXPECT_EQ(ReadText(fake.own + "/cgroup.subtree_control"),
              "+cpuset +cpu +memory +pids");
    EXPECT_EQ(ReadText(parent + "/cgroup.subtree_control"),
              "+cpuset +cpu +memory +pids");
    for (int i = 0; i < workers; ++i) {
      const std::string slot = parent + "/worker-" + std::to_string(i);
      EXPECT_EQ(ReadText(slot + "/memory.max"), std::to_string(64 << 20));
      EXPECT_EQ(ReadText(slot + "/pids.max"), "32");
      EXPECT_FALSE(ReadText(slot + "/cpuset.cpus").empty());
    }
    if (workers == 2) {
      EXPECT_NE(ReadText(parent + "/worker-0/cpuset.cpus"),
                ReadText(parent + "/worker-1/cpuset.cpus"));
    }

    const std::string log = fake.tmp.path() + "/job.log";
    ASSERT_TRUE(pool.Submit(FakeJob(1, log, {"pid"})).ok());
    std::vector<JobResult> results = WaitAll(pool);
    ASSERT_EQ(results.size(), 1u);
    EXPECT_EQ(results[0].outcome, Outcome::kOk);
    EXPECT_EQ(ReadText(parent + "/worker-0/cgroup.procs"),
              std::to_string(WaitForNumber(log, "pid")))
        << "the child joins its group itself, before exec";
  }
  // Removed, and the coordinator moved back with controllers handed back.
  EXPECT_FALSE(fs::exists(parent));
  EXPECT_EQ(ReadText(fake.own + "/cgroup.procs"), kSelf);
  EXPECT_EQ(ReadText(fake.own + "/cgroup.subtree_control"),
            "-cpuset -cpu -memory -pids");
}

TEST(CgroupFakeTest, V2WithoutCpusetKeepsCoresApartByAffinity) {
  FakeV2 fake("memory pids");
  Result<std::unique_ptr<WorkerPool>> pool = WorkerPool::Create(fake.Options());
  ASSERT_TRUE(pool.ok()) << pool.status().ToString();
  EXPECT_NE((*pool)->isolation_description().find("cgroup v2 (memory, pids)"),
            std::string::npos);
  EXPECT_NE((*pool)->isolation_description().find("by CPU affinity"),
            std::string::npos);
  EXPECT_FALSE(
      fs::exists(fake.own + "/adse-" + kSelf + "/worker-0/cpuset.cpus"));
}

TEST(CgroupFakeTest, V2RefusesAnOwnGroupSharedWithOtherProcesses) {
  FakeV2 fake("cpuset memory pids", "1\n" + kSelf + "\n4242\n");
  Result<std::unique_ptr<WorkerPool>> pool = WorkerPool::Create(fake.Options());
  ASSERT_FALSE(pool.ok());
  const std::string& message = pool.status().message();
  EXPECT_NE(message.find("also holds other processes (pid 1, 4242)"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("systemd-run --user --scope -p Delegate=yes"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(fake.own + "/adse-" + kSelf)) << "cleaned up";
}

TEST(CgroupFakeTest, StaleGroupsOfDeadCoordinatorsAreRemoved) {
  FakeV2 fake("memory");
  WriteText(fake.own + "/adse-111/worker-0/cgroup.procs", "");
  WriteText(fake.own + "/adse-111/worker-0/memory.max", "1000");
  WriteText(fake.own + "/adse-111/coordinator/cgroup.procs", "");
  WriteText(fake.own + "/adse-222/worker-0/cgroup.procs", "");
  WriteText(fake.own + "/other-333/cgroup.procs", "");
  PoolOptions options = fake.Options();
  options.pid_alive = [](int pid) { return pid == 222; };
  Result<std::unique_ptr<WorkerPool>> pool = WorkerPool::Create(options);
  ASSERT_TRUE(pool.ok()) << pool.status().ToString();
  EXPECT_FALSE(fs::exists(fake.own + "/adse-111"));
  EXPECT_TRUE(fs::exists(fake.own + "/adse-222/worker-0"));
  EXPECT_TRUE(fs::exists(fake.own + "/other-333"));
}

TEST(CgroupFakeTest, V1HierarchiesFileProtocol) {
  TempDir tmp;
  const std::string root = tmp.path() + "/cgroup";
  WriteText(tmp.path() + "/mountinfo",
            "31 23 0:28 / " + root +
                " rw - tmpfs tmpfs rw\n"
                "34 31 0:31 / " +
                root +
                "/cpuset rw - cgroup cgroup rw,cpuset\n"
                "35 31 0:32 / " +
                root +
                "/memory rw - cgroup cgroup rw,memory\n"
                "39 31 0:36 / " +
                root +
                "/pids rw - cgroup cgroup rw,pids\n"
                "41 31 0:38 / " +
                root + "/unified rw - cgroup2 cgroup2 rw\n");
  WriteText(tmp.path() + "/self_cgroup",
            "8:pids:/\n4:memory:/process_api/c41\n3:cpuset:/\n0::/\n");
  WriteText(root + "/unified/cgroup.controllers", "hugetlb\n");
  WriteText(root + "/cpuset/cpuset.mems", "0\n");
  fs::create_directories(root + "/memory/process_api/c41");
  fs::create_directories(root + "/pids");
  PoolOptions options;
  options.workers = 1;
  options.memory_mb = 64;
  options.pids_max = 32;
  options.isolation = Isolation::kCgroup;
  options.cgroup_root = root;
  options.proc_self_cgroup = tmp.path() + "/self_cgroup";
  options.proc_self_mountinfo = tmp.path() + "/mountinfo";
  const std::string name = "adse-" + kSelf;
  const std::string cpuset = root + "/cpuset/" + name;
  const std::string memory = root + "/memory/process_api/c41/" + name;
  const std::string pids = root + "/pids/" + name;
  {
    Result<std::unique_ptr<WorkerPool>> created = WorkerPool::Create(options);
    ASSERT_TRUE(created.ok()) << created.status().ToString();
    WorkerPool& pool = **created;
    EXPECT_EQ(pool.isolation_description(),
              "cgroup v1 (cpuset, memory, pids) under " + cpuset + ", " +
                  memory + ", " + pids);
    EXPECT_FALSE(ReadText(cpuset + "/cpuset.cpus").empty());
    EXPECT_EQ(ReadText(cpuset + "/cpuset.mems"), "0");
    EXPECT_EQ(ReadText(cpuset + "/worker-0/cpuset.mems"), "0");
    EXPECT_EQ(ReadText(memory + "/worker-0/memory.limit_in_bytes"),
              std::to_string(64 << 20));
    EXPECT_EQ(ReadText(pids + "/worker-0/pids.max"), "32");

    const std::string log = tmp.path() + "/job.log";
    ASSERT_TRUE(pool.Submit(FakeJob(1, log, {"pid", "exit", "2"})).ok());
    std::vector<JobResult> results = WaitAll(pool);
    ASSERT_EQ(results.size(), 1u);
    EXPECT_EQ(results[0].outcome, Outcome::kExitError);
    const std::string pid = std::to_string(WaitForNumber(log, "pid"));
    for (const std::string& dir : {cpuset, memory, pids}) {
      EXPECT_EQ(ReadText(dir + "/worker-0/cgroup.procs"), pid) << dir;
    }
  }
  EXPECT_FALSE(fs::exists(cpuset));
  EXPECT_FALSE(fs::exists(memory));
  EXPECT_FALSE(fs::exists(pids));
  EXPECT_TRUE(fs::exists(root + "/memory/process_api/c41"));
}

}  // namespace
}  // namespace adse::pool
