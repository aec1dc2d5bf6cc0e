// Internal to the worker pool: finds the cgroup hierarchies this process
// lives in (v1 or v2) and manages the campaign's groups in them.
//
// Layout. v2: <own>/<name>/worker-<i>, where <own> is the process's group
// from /proc/self/cgroup ("0::/path"). A cgroup that holds processes cannot
// give controllers to sub-groups, so when <own> holds only this process,
// the coordinator first moves itself into the leaf <own>/<name>/coordinator
// and then enables the controllers; it moves back when the groups are
// removed. v1: <own in that hierarchy>/<name>/worker-<i> in each of the
// cpuset, memory and pids hierarchies (v1 has no such rule).
//
// Fake roots. Tests point the pool at a temporary folder laid out like
// cgroupfs. The file protocol is the same; the only differences, decided
// per hierarchy by statfs(), are that control files are created when
// written (O_CREAT) and removed before rmdir (cgroupfs refuses both).
#ifndef ADSE_HARNESS_POOL_CGROUP_H_
#define ADSE_HARNESS_POOL_CGROUP_H_

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "harness/pool/worker_pool.h"
#include "stack/base/status.h"

namespace adse::pool::internal {

// ---- Control files, shared by the pool's campaign groups and ThreadGroup.
std::string Trim(const std::string& s);
std::vector<std::string> Split(const std::string& s, char sep);
bool Contains(const std::vector<std::string>& v, const std::string& s);
bool Exists(const std::string& path);
// The whole file, read to EOF (cgroupfs reports sizes of 0 or 4096).
Result<std::string> ReadControl(const std::string& path);
// Writes `value` to `path` opened O_WRONLY | `extra_flags`; 0 or the errno
// of the failure (a short write is EIO).
int WriteValueErrno(const std::string& path, const std::string& value,
                    int extra_flags);
// Writes `value`; 0 or the errno of the failure. `fake` (a test folder)
// creates the file.
int WriteControlErrno(const std::string& path, const std::string& value,
                      bool fake);
// InvalidArgument ("cpus: ...") unless `cpus` lists at least one CPU, each
// non-negative and once.
Status ValidateCpuList(const std::vector<int>& cpus);
// The same as Unavailable naming the version, value, file and error.
Status WriteControl(int version, const std::string& path,
                    const std::string& value, bool fake);
// mkdir, with advice on how to get permission when it is refused.
Status MakeGroup(int version, const std::string& dir);
// Whether `dir` is on cgroupfs (false: a test folder laid out like it).
bool IsCgroupFs(const std::string& dir);
// Kills the tasks of `dir` and its sub-groups (never this process) and
// removes them, children first, retrying until `until`. False (with a
// warning on stderr) when something stays.
bool RemoveTree(const std::string& dir, bool fake,
                std::chrono::steady_clock::time_point until);

// A cgroup filesystem mount from /proc/self/mountinfo.
struct CgroupMount {
  int version = 1;          // 1: fstype "cgroup", 2: "cgroup2"
  std::string root;         // the mount's root inside its hierarchy
  std::string mount_point;  // octal escapes (\040) decoded
  std::vector<std::string> controllers;  // v1: named in the super options
};

// The cgroup mounts of mountinfo `text` at or below the folder `under`.
std::vector<CgroupMount> ParseMountInfo(const std::string& text,
                                        const std::string& under);

// /proc/self/cgroup: each controller to the process's path in its
// hierarchy; the v2 path under the key "" ("0::/path").
std::map<std::string, std::string> ParseProcCgroup(const std::string& text);

// The process's group directory in `mount` for its path `path` from
// /proc/self/cgroup; *is_root when that is the mount's root.
Result<std::string> OwnDir(const CgroupMount& mount, const std::string& path,
                           bool* is_root);

// "0-3,6" for {0, 1, 2, 3, 6}.
std::string FormatCpuList(const std::vector<int>& cpus);

// The pid in a campaign group name ("adse-123", "adse-x-123"), or -1 when
// `name` does not follow the rule (starts with "adse", ends in "-<pid>").
int GroupNamePid(const std::string& name);

// One hierarchy the campaign uses, and the process's own group in it.
struct Hierarchy {
  std::string own_dir;
  std::vector<std::string> controllers;  // of cpuset/(v2: cpu)/memory/pids
  bool own_is_root = false;  // exempt from v2's no-internal-process rule
  bool fake = false;         // not cgroupfs: a test folder
};

struct Layout {
  int version = 0;                     // 1 or 2
  std::vector<Hierarchy> hierarchies;  // v2: exactly one
  // Controllers in use; memory is required, cpuset and pids are used when
  // available (without cpuset, cores are kept apart by affinity alone).
  bool cpuset = false;
  bool pids = false;
};

// Reads the mounts and the process's groups (paths from `options`). Prefers
// v2 when its hierarchy offers the memory controller to the process's
// group, else v1. Unavailable saying what is missing and how to grant it.
Result<Layout> DetectLayout(const PoolOptions& options);

struct GroupLimits {
  std::vector<std::vector<int>> slot_cores;  // one entry per slot
  int64_t memory_bytes = 0;
  int pids_max = 0;
};

// Whether a coordinator pid still runs.
using PidAlive = std::function<bool(int pid)>;
bool DefaultPidAlive(int pid);

// Removes, under `dir`, the campaign groups (GroupNamePid) whose pid is not
// alive: kills their tasks, then removes them, children first.
void RemoveStaleGroups(const std::string& dir, bool fake,
                       const PidAlive& pid_alive);

// The campaign parent group and one group per slot. Removed (tasks killed)
// by the destructor.
class CampaignGroups {
 public:
  static Result<std::unique_ptr<CampaignGroups>> Create(
      const Layout& layout, const std::string& name, const GroupLimits& limits,
      const PidAlive& pid_alive);
  ~CampaignGroups();
  CampaignGroups(const CampaignGroups&) = delete;
  CampaignGroups& operator=(const CampaignGroups&) = delete;

  // The files a child writes its pid to, one per hierarchy.
  const std::vector<std::string>& procs_files(int slot) const {
    return slots_[slot].procs_files;
  }
  // Whether procs files must be created on open (a fake root).
  bool fake() const;
  // OOM kills counted in the slot's group so far; -1 when unknown.
  int64_t OomKills(int slot) const;
  // SIGKILLs every task of the slot's group but `spare` (the job's own
  // process, which the pool kills and reaps itself) until none is left,
  // for at most about a second.
  void KillTasks(int slot, pid_t spare) const;
  // "cgroup v1 (cpuset, memory, pids) under <dir>, <dir>".
  std::string Describe() const;

 private:
  struct Slot {
    std::vector<std::string> dirs;  // one per hierarchy
    std::vector<std::string> procs_files;
  };
  CampaignGroups() = default;
  Status Setup(const GroupLimits& limits, const PidAlive& pid_alive);
  Status SetupV2(const GroupLimits& limits, const PidAlive& pid_alive);
  Status SetupV1(const GroupLimits& limits, const PidAlive& pid_alive);
  void Remove();

  Layout layout_;
  std::string name_;
  std::vector<std::string> parents_;  // <own>/<name>, one per hierarchy
  std::vector<Slot> slots_;
  int memory_index_ = 0;  // the hierarchy holding the memory controller
  // v2: the coordinator moved itself into <parent>/coordinator, and the
  // controllers it enabled in its own group ("+memory +pids").
  bool moved_self_ = false;
  std::string enabled_in_own_;
  std::string enabled_in_parent_;
};

}  // namespace adse::pool::internal

#endif  // ADSE_HARNESS_POOL_CGROUP_H_
