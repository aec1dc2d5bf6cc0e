// The worker pool: runs one job (an `adse worker` command line) at a time
// per slot, each in a fresh child process confined to its own cgroup under
// a campaign parent group (disjoint cpuset cores, memory and pids limits),
// or, where cgroups cannot be created, pinned with CPU affinity and
// rlimits. Jobs that overrun their timeout are killed as a whole group;
// out-of-memory kills and crashes are told apart. Groups are removed on
// every exit path the coordinator survives (destructor, Ctrl-C, SIGTERM);
// groups of a coordinator killed outright are removed by the next one.
#ifndef ADSE_HARNESS_POOL_WORKER_POOL_H_
#define ADSE_HARNESS_POOL_WORKER_POOL_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "stack/base/status.h"

namespace adse::pool {

enum class Isolation {
  kAuto,      // cgroups where they can be created, else affinity + rlimits
  kCgroup,    // cgroups or refuse to start
  kAffinity,  // CPU affinity + rlimits only
};

// The names, as the scenario's harness.isolation and --isolation take them.
const char* IsolationToString(Isolation isolation);
bool StringToIsolation(std::string_view name, Isolation* isolation);
std::vector<std::string> IsolationNames();
// StringToIsolation, or InvalidArgument listing the names.
Result<Isolation> ParseIsolation(const std::string& text);

struct PoolOptions {
  // Worker slots; 0 means host cores / cores_per_worker (at least 1).
  int workers = 0;
  // Host cores given to each slot (disjoint cpusets / affinity masks).
  int cores_per_worker = 1;
  // Memory limit per slot: cgroup memory limit, or RLIMIT_AS (+ headroom
  // documented in the .cc) under affinity isolation.
  int memory_mb = 4096;
  // Task limit per slot: pids.max. Not enforced under affinity isolation:
  // RLIMIT_NPROC counts all of the user's processes (and root ignores it).
  int pids_max = 512;
  Isolation isolation = Isolation::kAuto;
  // Name of the campaign parent group; "" means "adse-<coordinator pid>".
  // It must start with "adse" and end in "-<pid>" (InvalidArgument
  // otherwise) for stale-group cleanup to recognise it.
  std::string group_name;
  // Root of the cgroup filesystem (tests point this at a temporary folder
  // laid out like cgroupfs; the file protocol is the same). Only mounts at
  // or below it in proc_self_mountinfo are used.
  std::string cgroup_root = "/sys/fs/cgroup";
  // Where the process's own cgroups are read from.
  std::string proc_self_cgroup = "/proc/self/cgroup";
  std::string proc_self_mountinfo = "/proc/self/mountinfo";
  // Whether the coordinator whose pid a group name carries still runs;
  // empty: kill(pid, 0). Tests substitute it to fake dead coordinators.
  std::function<bool(int pid)> pid_alive;
};

struct Job {
  uint64_t id = 0;                // the caller's handle, echoed back
  std::vector<std::string> argv;  // argv[0] is an absolute path
  // The child's stdout and stderr go here (created/truncated; the folder
  // must exist). stdin is /dev/null.
  std::string log_path;
  double timeout_s = 0.0;  // 0: no limit
  // What a scheduler shows for the job (srun --job-name); "" lets the pool
  // choose. The local pool does not use it.
  std::string name;
};

enum class Outcome {
  kOk,           // exit status 0
  kExitError,    // non-zero exit status (exit_code)
  kCrashed,      // ended by a signal other than an OOM or timeout kill
  kTimeout,      // overran timeout_s; the whole group was killed
  kOutOfMemory,  // killed by the OOM killer, or exited with
                 // kExitOutOfMemory (allocation failed under RLIMIT_AS)
  kCancelled,    // killed by CancelAll (interrupt)
};
// "ok", "exit_error", "crashed", "timeout", "out_of_memory", "cancelled".
const char* OutcomeName(Outcome outcome);

// Exit status a worker uses when an allocation fails (std::bad_alloc).
inline constexpr int kExitOutOfMemory = 3;

struct JobResult {
  uint64_t id = 0;
  Outcome outcome = Outcome::kOk;
  int exit_code = -1;       // when it exited, else -1
  int signal = 0;           // when a signal ended it, else 0
  std::string stderr_tail;  // last ~2 KiB of the log, for reports
  double wall_s = 0.0;
  int slot = -1;
};

// Ok when `workers` (0: as many as fit, at least one) of `cores_per_worker`
// CPUs each fit in the CPUs this process may use; else InvalidArgument "12
// workers x 1 cores per worker need 12 cores, but this process may use only 2
// (0-1)". WorkerPool::Create checks the same; a command checks it first to name
// the flag or field that asked.
Status CheckWorkersFit(int workers, int cores_per_worker);

// Not thread-safe: one thread drives a pool.
class WorkerPool {
 public:
  // Sets up the slots and their groups. Under kAuto, a failure to use
  // cgroups falls back to affinity and says why in fallback_reason(); under
  // kCgroup it is an error (Unavailable) saying what is missing and how to
  // grant it. Also removes groups left by coordinators that no longer run.
  static Result<std::unique_ptr<WorkerPool>> Create(const PoolOptions& options);
  virtual ~WorkerPool() = default;  // kills running jobs, removes groups

  virtual int slots() const = 0;
  virtual int idle_slots() const = 0;
  // "cgroup v1 (cpuset, memory, pids) under /sys/fs/cgroup/.../adse-123"
  // or "affinity + rlimits".
  virtual std::string isolation_description() const = 0;
  // Why kAuto fell back to affinity; empty otherwise.
  virtual std::string fallback_reason() const = 0;

  // Starts a job on an idle slot. FailedPrecondition-like Unavailable when
  // no slot is idle; IoError when the process cannot be started (the log
  // cannot be created, the group not joined, argv[0] not executed);
  // InvalidArgument when argv is empty or argv[0] is not absolute.
  virtual Status Submit(const Job& job) = 0;
  // Waits until at least one job has finished, `max_wait_s` has passed or
  // an interrupt arrived (SIGINT/SIGTERM, see InterruptRequested), killing
  // jobs past their timeout on the way. Returns the finished jobs; returns
  // at once when no job runs.
  virtual std::vector<JobResult> Wait(double max_wait_s) = 0;
  // Kills every running job (whole groups) and reaps them; their results
  // are returned with Outcome::kCancelled (a job that had already ended,
  // or overrun its timeout, keeps its own outcome).
  virtual std::vector<JobResult> CancelAll() = 0;
};

// Installs SIGINT/SIGTERM handlers that record the signal and wake any
// WorkerPool::Wait. Idempotent. One-shot: a second Ctrl-C ends the process
// the default way (the next coordinator removes its groups).
void InstallInterruptHandlers();
// The signal received (SIGINT/SIGTERM), or 0.
int InterruptRequested();
// For tests: forget a recorded interrupt (and re-arm the handlers).
void ClearInterrupt();
// Records an interrupt as if `sig` had arrived and wakes any Wait: for a
// pool that learns that the place its jobs run is going away (a Slurm
// allocation being cancelled) before the signal reaches the coordinator.
void RequestInterrupt(int sig);

// Installs a handler for `sig` that asks for a graceful stop rather than an
// interrupt: propose no more work, let running jobs finish (Slurm's warning
// before a time limit, `sbatch --signal=B:USR1@<s>`). Idempotent; unlike
// the interrupt handlers it stays armed.
void InstallDrainHandler(int sig);
// The drain signal received, or 0.
int DrainRequested();
// For tests: forget a recorded drain request.
void ClearDrain();

}  // namespace adse::pool

#endif  // ADSE_HARNESS_POOL_WORKER_POOL_H_
