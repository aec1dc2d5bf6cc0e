// A cgroup for some threads of this process or of its children: the
// real-time stack's process, confined to a cpuset of N host cores and,
// optionally, to a CPU quota that stands for a slower clock. This process
// (the world) stays in its own group.
//
// v1: a group <own>/<name>-<pid> in the cpuset hierarchy (and the cpu
// hierarchy for a quota); threads join by writing their id to `tasks`.
// v2: the process's own group becomes a threaded domain and the group a
// threaded child of it (cgroup.type "threaded"); threads join through
// `cgroup.threads`. cpuset and cpu are threaded controllers, so they may be
// enabled below a group that holds processes.
//
// A group is named after its process, so the next one created under the
// same parent removes groups whose process is gone (a SIGKILLed worker).
#ifndef ADSE_HARNESS_POOL_THREAD_GROUP_H_
#define ADSE_HARNESS_POOL_THREAD_GROUP_H_

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "stack/base/status.h"

namespace adse::pool {
namespace internal {
struct CgroupMount;
}  // namespace internal

struct ThreadGroupOptions {
  // Host CPUs of the group's cpuset; required, each listed once.
  std::vector<int> cpus;
  // CPU time granted per period, in CPUs (v1 cpu.cfs_quota_us, v2
  // cpu.max); 0: no quota.
  double cpu_quota = 0.0;
  // The quota's period. Short, so that a throttled thread waits
  // milliseconds rather than the kernel's default tenth of a second.
  int quota_period_us = 10000;
  // The group's name is "<name>-<pid>"; it must start with "adse".
  std::string name = "adse-stack";
  // Where to look; tests point these at a folder laid out like cgroupfs.
  std::string cgroup_root = "/sys/fs/cgroup";
  std::string proc_self_cgroup = "/proc/self/cgroup";
  std::string proc_self_mountinfo = "/proc/self/mountinfo";
};

class ThreadGroup {
 public:
  // Creates the group (after removing stale ones of dead processes).
  // InvalidArgument naming the field for bad options; Unavailable naming
  // what is missing (no cpuset controller, no cpu controller for a quota,
  // no permission) and how to get it.
  static Result<std::unique_ptr<ThreadGroup>> Create(
      const ThreadGroupOptions& options);
  // Moves this process's threads still in the group back to its own group
  // and removes the group (and, on v2, the controllers it enabled).
  ~ThreadGroup();
  ThreadGroup(const ThreadGroup&) = delete;
  ThreadGroup& operator=(const ThreadGroup&) = delete;

  // Moves the calling thread into the group. Thread-safe.
  Status AddCurrentThread() const;
  // The directories of the group, one per hierarchy.
  const std::vector<std::string>& dirs() const { return dirs_; }
  int version() const { return version_; }
  // "cgroup v1 cpuset 1, cpu quota 0.48 CPUs per 10 ms: <dirs>".
  std::string Describe() const;

 private:
  ThreadGroup() = default;
  // `mounts` from mountinfo, `groups` from /proc/self/cgroup.
  using Groups = std::map<std::string, std::string>;
  Status SetupV1(const ThreadGroupOptions& options,
                 const std::vector<internal::CgroupMount>& mounts,
                 const Groups& groups);
  Status SetupV2(const ThreadGroupOptions& options,
                 const std::vector<internal::CgroupMount>& mounts,
                 const Groups& groups);
  void Remove();

  struct Place {
    std::string own_dir;       // the process's group in this hierarchy
    std::string dir;           // the thread group
    std::string threads_file;  // v1: tasks; v2: cgroup.threads
    bool fake = false;
  };
  int version_ = 0;
  std::vector<Place> places_;
  std::vector<std::string> dirs_;
  std::string description_;
  std::string enabled_in_own_;  // v2: "+cpuset +cpu" enabled by Create
};

}  // namespace adse::pool

#endif  // ADSE_HARNESS_POOL_THREAD_GROUP_H_
