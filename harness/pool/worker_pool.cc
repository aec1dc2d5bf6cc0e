#include "harness/pool/worker_pool.h"

#include <fcntl.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <mutex>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "harness/pool/cgroup.h"
#include "harness/pool/child.h"
#include "harness/pool/child_log.h"
#include "stack/base/clock.h"

namespace adse::pool {
namespace {

using Clock = std::chrono::steady_clock;

// RLIMIT_AS counts address space, not memory in use: thread stacks (8 MiB
// each) and glibc's per-thread malloc arenas (64 MiB each) are reserved in
// full and mostly never touched. The headroom keeps a worker that stays
// within memory_mb of real use from failing on those reservations.
constexpr int64_t kAddressSpaceHeadroomMb = 512;
constexpr size_t kStderrTailBytes = 2048;
// Without pidfds (Linux < 5.3) Wait polls the children at this interval.
constexpr auto kPollInterval = std::chrono::milliseconds(2);

// ---- Interrupts -----------------------------------------------------------

std::atomic<int> g_interrupt{0};
std::atomic<bool> g_handlers_installed{false};
// Written by the handler so that a Wait blocked in ppoll wakes up.
int g_wake_fds[2] = {-1, -1};
std::mutex g_install_mutex;

void OnInterrupt(int sig) {
  const int saved_errno = errno;
  g_interrupt.store(sig);
  if (g_wake_fds[1] >= 0) {
    [[maybe_unused]] const ssize_t n = ::write(g_wake_fds[1], "!", 1);
  }
  errno = saved_errno;
}

std::atomic<int> g_drain{0};

void OnDrain(int sig) {
  const int saved_errno = errno;
  g_drain.store(sig);
  if (g_wake_fds[1] >= 0) {
    [[maybe_unused]] const ssize_t n = ::write(g_wake_fds[1], "!", 1);
  }
  errno = saved_errno;
}

void ArmHandlers() {
  struct sigaction action {};
  action.sa_handler = OnInterrupt;
  sigemptyset(&action.sa_mask);
  // One-shot, so that a second Ctrl-C still ends a coordinator stuck in
  // cleanup; SA_RESTART so that unrelated blocking calls do not fail.
  action.sa_flags = SA_RESTART | SA_RESETHAND;
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);
}

void DrainWakePipe() {
  char buffer[64];
  while (g_wake_fds[0] >= 0 &&
         ::read(g_wake_fds[0], buffer, sizeof(buffer)) > 0) {
  }
}

// ---- Small helpers --------------------------------------------------------

class UniqueFd {
 public:
  explicit UniqueFd(int fd = -1) : fd_(fd) {}
  UniqueFd(UniqueFd&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  UniqueFd& operator=(UniqueFd&& other) noexcept {
    if (this != &other) {
      Reset();
      fd_ = std::exchange(other.fd_, -1);
    }
    return *this;
  }
  ~UniqueFd() { Reset(); }
  int get() const { return fd_; }
  void Reset() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_;
};

int PidfdOpen(pid_t pid) {
#ifdef SYS_pidfd_open
  return static_cast<int>(::syscall(SYS_pidfd_open, pid, 0));
#else
  (void)pid;
  return -1;
#endif
}

// ---- The child between fork and exec --------------------------------------

// Everything the child needs, made before fork: after fork the child of a
// possibly multithreaded coordinator may only make async-signal-safe calls
// (no allocation, no locks).
struct ChildPlan {
  std::vector<char*> argv;     // null-terminated
  std::vector<int> procs_fds;  // cgroup.procs of each hierarchy's group
  cpu_set_t cpus;
  bool limit_address_space = false;
  struct rlimit address_space {};
  pid_t parent_pid = 0;  // the coordinator, for PR_SET_PDEATHSIG
  int stdin_fd = -1;
  int log_fd = -1;
  int report_fd = -1;  // close-on-exec: EOF tells the parent exec worked
};

enum class ChildStage : int { kJoinCgroup = 1, kAffinity, kRlimit, kExec };

struct ChildFailure {
  ChildStage stage;
  int index;  // which procs file, for kJoinCgroup
  int error;
};

[[noreturn]] void FailChild(const ChildPlan& plan, ChildStage stage,
                            int index) {
  const ChildFailure failure{stage, index, errno};
  [[maybe_unused]] const ssize_t n =
      ::write(plan.report_fd, &failure, sizeof(failure));
  ::_exit(127);
}

[[noreturn]] void RunChild(const ChildPlan& plan) {
  // Join the groups first, so that all the job does is charged to them.
  char digits[16];
  int len = 0;
  for (long pid = ::getpid(); pid > 0 || len == 0; pid /= 10) {
    digits[len++] = static_cast<char>('0' + pid % 10);
  }
  std::reverse(digits, digits + len);
  for (size_t i = 0; i < plan.procs_fds.size(); ++i) {
    if (::write(plan.procs_fds[i], digits, static_cast<size_t>(len)) != len) {
      FailChild(plan, ChildStage::kJoinCgroup, static_cast<int>(i));
    }
  }
  // A coordinator killed outright takes its jobs with it (their unfinished
  // runs are redone on resume) instead of leaving them to run unwatched.
  if (!PrepareChild(plan.parent_pid, SIGKILL, plan.stdin_fd, plan.log_fd))
    ::_exit(127);
  if (::sched_setaffinity(0, sizeof(plan.cpus), &plan.cpus) != 0) {
    FailChild(plan, ChildStage::kAffinity, 0);
  }
  if (plan.limit_address_space &&
      ::setrlimit(RLIMIT_AS, &plan.address_space) != 0) {
    FailChild(plan, ChildStage::kRlimit, 0);
  }
  ::execv(plan.argv[0], plan.argv.data());
  FailChild(plan, ChildStage::kExec, 0);
}

// ---- The pool --------------------------------------------------------------

struct Running {
  Job job;
  pid_t pid = -1;
  UniqueFd pidfd;
  Clock::time_point start;
  std::optional<Clock::time_point> deadline;
  int64_t oom_kills_before = -1;
  // Set when the pool killed it: kTimeout or kCancelled.
  std::optional<Outcome> killed_for;
};

struct Slot {
  std::vector<int> cores;
  std::optional<Running> job;
};

class PoolImpl : public WorkerPool {
 public:
  PoolImpl(const PoolOptions& options, std::vector<Slot> slots)
      : options_(options), slots_(std::move(slots)) {}
  ~PoolImpl() override {
    CancelAll();
    groups_.reset();
  }

  int slots() const override { return static_cast<int>(slots_.size()); }
  int idle_slots() const override {
    return static_cast<int>(std::count_if(
        slots_.begin(), slots_.end(), [](const Slot& s) { return !s.job; }));
  }
  std::string isolation_description() const override {
    if (groups_) return groups_->Describe();
    return fmt::format("affinity + rlimits (address space {} MB per job)",
                       options_.memory_mb + kAddressSpaceHeadroomMb);
  }
  std::string fallback_reason() const override { return fallback_reason_; }

  Status Submit(const Job& job) override;
  std::vector<JobResult> Wait(double max_wait_s) override;
  std::vector<JobResult> CancelAll() override;

  std::unique_ptr<internal::CampaignGroups> groups_;
  std::string fallback_reason_;

 private:
  // Whether the job's process has ended (not yet reaped).
  bool Ended(const Running& r) const;
  // Kills the job's process, its process group and its cgroup's tasks.
  void Kill(int slot, Outcome reason);
  // Kills what is left of an ended or killed job, reaps it, frees the slot.
  JobResult Reap(int slot);

  PoolOptions options_;
  std::vector<Slot> slots_;
};

Status PoolImpl::Submit(const Job& job) {
  if (job.argv.empty() || job.argv[0].empty() || job.argv[0][0] != '/') {
    return Status::InvalidArgument(
        fmt::format("job {}: argv[0] must be an absolute path, got '{}'",
                    job.id, job.argv.empty() ? "" : job.argv[0]));
  }
  const auto idle = std::find_if(slots_.begin(), slots_.end(),
                                 [](const Slot& s) { return !s.job; });
  if (idle == slots_.end()) {
    return Status::Unavailable(fmt::format(
        "job {}: no idle slot, all {} run jobs", job.id, slots_.size()));
  }
  const int slot = static_cast<int>(idle - slots_.begin());

  UniqueFd log(::open(job.log_path.c_str(),
                      O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644));
  if (log.get() < 0) {
    return Status::IoError(fmt::format("job {}: cannot create log {}: {}",
                                       job.id, job.log_path,
                                       std::strerror(errno)));
  }
  UniqueFd null(::open("/dev/null", O_RDONLY | O_CLOEXEC));
  std::vector<UniqueFd> procs;
  ChildPlan plan;
  plan.parent_pid = ::getpid();
  if (groups_) {
    const int flags =
        O_WRONLY | O_CLOEXEC | (groups_->fake() ? O_CREAT | O_TRUNC : 0);
    for (const std::string& file : groups_->procs_files(slot)) {
      procs.emplace_back(::open(file.c_str(), flags, 0644));
      if (procs.back().get() < 0) {
        return Status::IoError(fmt::format("job {}: cannot open {}: {}", job.id,
                                           file, std::strerror(errno)));
      }
      plan.procs_fds.push_back(procs.back().get());
    }
  }
  int report_fds[2];
  if (::pipe2(report_fds, O_CLOEXEC) != 0) {
    return Status::IoError(
        fmt::format("job {}: pipe: {}", job.id, std::strerror(errno)));
  }
  UniqueFd report_read(report_fds[0]);
  UniqueFd report_write(report_fds[1]);

  std::vector<std::string> argv = job.argv;
  for (std::string& arg : argv) plan.argv.push_back(arg.data());
  plan.argv.push_back(nullptr);
  CPU_ZERO(&plan.cpus);
  for (int core : slots_[slot].cores) CPU_SET(core, &plan.cpus);
  if (!groups_) {
    plan.limit_address_space = true;
    rlim_t bytes =
        static_cast<rlim_t>(options_.memory_mb + kAddressSpaceHeadroomMb) << 20;
    // Only root may raise a hard limit; below one, stay under it.
    struct rlimit current;
    if (::getrlimit(RLIMIT_AS, &current) == 0 && current.rlim_max < bytes) {
      bytes = current.rlim_max;
    }
    plan.address_space = {bytes, bytes};
  }
  plan.stdin_fd = null.get();
  plan.log_fd = log.get();
  plan.report_fd = report_write.get();

  Running running;
  running.job = job;
  running.oom_kills_before = groups_ ? groups_->OomKills(slot) : -1;
  running.start = Clock::now();
  if (job.timeout_s > 0) {
    running.deadline = running.start + SteadyFromSeconds(job.timeout_s);
  }
  const pid_t pid = ::fork();
  if (pid < 0) {
    return Status::IoError(
        fmt::format("job {}: fork: {}", job.id, std::strerror(errno)));
  }
  if (pid == 0) RunChild(plan);

  // Also here, so that killpg works whichever of the two runs first.
  ::setpgid(pid, pid);
  report_write.Reset();
  ChildFailure failure{};
  ssize_t n;
  do {
    n = ::read(report_read.get(), &failure, sizeof(failure));
  } while (n < 0 && errno == EINTR);
  if (n == static_cast<ssize_t>(sizeof(failure))) {
    int status;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    std::string what;
    switch (failure.stage) {
      case ChildStage::kJoinCgroup:
        what = "joining cgroup " + groups_->procs_files(slot)[failure.index];
        break;
      case ChildStage::kAffinity:
        what = "setting CPU affinity " +
               internal::FormatCpuList(slots_[slot].cores);
        break;
      case ChildStage::kRlimit:
        what = "setting RLIMIT_AS";
        break;
      case ChildStage::kExec:
        what = "executing " + job.argv[0];
        break;
    }
    return Status::IoError(fmt::format("job {}: cannot start: {}: {}", job.id,
                                       what, std::strerror(failure.error)));
  }
  running.pid = pid;
  running.pidfd = UniqueFd(PidfdOpen(pid));
  slots_[slot].job = std::move(running);
  return Status::Ok();
}

bool PoolImpl::Ended(const Running& r) const {
  siginfo_t info{};
  const int rc = ::waitid(P_PID, static_cast<id_t>(r.pid), &info,
                          WEXITED | WNOHANG | WNOWAIT);
  // ECHILD: reaped behind our back (SIGCHLD set to SIG_IGN); Reap copes.
  return rc != 0 ? errno == ECHILD : info.si_pid != 0;
}

void PoolImpl::Kill(int slot, Outcome reason) {
  Running& r = *slots_[slot].job;
  if (!r.killed_for) r.killed_for = reason;
  ::kill(r.pid, SIGKILL);
  ::killpg(r.pid, SIGKILL);
  if (groups_) groups_->KillTasks(slot, r.pid);
}

JobResult PoolImpl::Reap(int slot) {
  Running& r = *slots_[slot].job;
  // The job's process has ended, so the pid is a zombie and still names
  // its process group: whatever the job left behind goes with it.
  ::killpg(r.pid, SIGKILL);
  if (groups_) groups_->KillTasks(slot, r.pid);
  int status = 0;
  pid_t waited;
  do {
    waited = ::waitpid(r.pid, &status, 0);
  } while (waited < 0 && errno == EINTR);
  const auto end = Clock::now();

  JobResult result;
  result.id = r.job.id;
  result.slot = slot;
  result.wall_s = SteadySeconds(end - r.start);
  result.stderr_tail = ReadLogTail(r.job.log_path, kStderrTailBytes);
  if (waited < 0) {
    result.outcome = r.killed_for.value_or(Outcome::kExitError);
    result.stderr_tail +=
        "\n(exit status lost: the process was reaped "
        "elsewhere; is SIGCHLD ignored?)";
  } else {
    if (WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
    if (WIFSIGNALED(status)) result.signal = WTERMSIG(status);
    if (r.killed_for) {
      result.outcome = *r.killed_for;
    } else if (WIFEXITED(status)) {
      result.outcome = result.exit_code == 0 ? Outcome::kOk
                       : result.exit_code == kExitOutOfMemory
                           ? Outcome::kOutOfMemory
                           : Outcome::kExitError;
    } else {
      const int64_t oom_kills = groups_ ? groups_->OomKills(slot) : -1;
      const bool oom = result.signal == SIGKILL && r.oom_kills_before >= 0 &&
                       oom_kills > r.oom_kills_before;
      result.outcome = oom ? Outcome::kOutOfMemory : Outcome::kCrashed;
    }
  }
  slots_[slot].job.reset();
  return result;
}

std::vector<JobResult> PoolImpl::Wait(double max_wait_s) {
  const auto until = Clock::now() + SteadyFromSeconds(max_wait_s);
  for (;;) {
    std::vector<JobResult> done;
    for (size_t i = 0; i < slots_.size(); ++i) {
      if (slots_[i].job && Ended(*slots_[i].job)) {
        done.push_back(Reap(static_cast<int>(i)));
      }
    }
    if (!done.empty() || idle_slots() == slots() || InterruptRequested()) {
      return done;
    }
    const auto now = Clock::now();
    // Wake at the next job deadline, or at `until`, whichever is first.
    auto wake = until;
    bool poll_children = false;
    std::vector<pollfd> fds;
    for (size_t i = 0; i < slots_.size(); ++i) {
      if (!slots_[i].job) continue;
      Running& r = *slots_[i].job;
      if (r.deadline && !r.killed_for) {
        if (now >= *r.deadline) {
          Kill(static_cast<int>(i), Outcome::kTimeout);
        } else {
          wake = std::min(wake, *r.deadline);
        }
      }
      if (r.pidfd.get() >= 0) {
        fds.push_back({r.pidfd.get(), POLLIN, 0});
      } else {
        poll_children = true;
      }
    }
    if (now >= until) return done;
    // Without a wake pipe an interrupt is only seen by polling too.
    if (g_handlers_installed.load() && g_wake_fds[0] < 0) poll_children = true;
    if (poll_children) wake = std::min(wake, now + kPollInterval);
    if (g_wake_fds[0] >= 0) fds.push_back({g_wake_fds[0], POLLIN, 0});
    const auto wait = std::max(Clock::duration::zero(), wake - now);
    const auto secs = std::chrono::duration_cast<std::chrono::seconds>(wait);
    const timespec timeout{
        static_cast<time_t>(secs.count()),
        static_cast<long>(
            std::chrono::duration_cast<std::chrono::nanoseconds>(wait - secs)
                .count())};
    ::ppoll(fds.data(), fds.size(), &timeout, nullptr);
    DrainWakePipe();
  }
}

std::vector<JobResult> PoolImpl::CancelAll() {
  std::vector<JobResult> results;
  for (size_t i = 0; i < slots_.size(); ++i) {
    if (!slots_[i].job) continue;
    if (!Ended(*slots_[i].job)) Kill(static_cast<int>(i), Outcome::kCancelled);
    results.push_back(Reap(static_cast<int>(i)));
  }
  return results;
}

// The CPUs this process may use, in order.
Result<std::vector<int>> AllowedCpus() {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (::sched_getaffinity(0, sizeof(allowed), &allowed) != 0) {
    return Status::IoError(std::string("sched_getaffinity: ") +
                           std::strerror(errno));
  }
  std::vector<int> cores;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &allowed)) cores.push_back(cpu);
  }
  return cores;
}

Status WorkersFit(int workers, int per, const std::vector<int>& cores) {
  if (static_cast<size_t>(workers) * per > cores.size()) {
    return Status::InvalidArgument(fmt::format(
        "{} workers x {} cores per worker need {} cores, but this process "
        "may use only {} ({})",
        workers, per, static_cast<int64_t>(workers) * per, cores.size(),
        internal::FormatCpuList(cores)));
  }
  return Status::Ok();
}

}  // namespace

Status CheckWorkersFit(int workers, int cores_per_worker) {
  Result<std::vector<int>> cores = AllowedCpus();
  if (!cores.ok()) return cores.status();
  const int per = std::max(1, cores_per_worker);
  return WorkersFit(workers > 0
                        ? workers
                        : std::max(1, static_cast<int>(cores->size()) / per),
                    per, *cores);
}

Result<std::unique_ptr<WorkerPool>> WorkerPool::Create(
    const PoolOptions& options) {
  if (options.workers < 0 || options.cores_per_worker < 1 ||
      options.memory_mb < 1 || options.pids_max < 1) {
    return Status::InvalidArgument(fmt::format(
        "pool: workers ({}) must be >= 0, cores_per_worker ({}), memory_mb "
        "({}) and pids_max ({}) >= 1",
        options.workers, options.cores_per_worker, options.memory_mb,
        options.pids_max));
  }
  Result<std::vector<int>> allowed = AllowedCpus();
  if (!allowed.ok()) return allowed.status().WithContext("pool");
  const std::vector<int>& cores = *allowed;
  const int per = options.cores_per_worker;
  const int workers = options.workers > 0
                          ? options.workers
                          : std::max(1, static_cast<int>(cores.size()) / per);
  ADSE_RETURN_IF_ERROR(WorkersFit(workers, per, cores).WithContext("pool"));
  const std::string name = options.group_name.empty()
                               ? fmt::format("adse-{}", ::getpid())
                               : options.group_name;
  if (internal::GroupNamePid(name) <= 0 ||
      name.find('/') != std::string::npos) {
    return Status::InvalidArgument(
        fmt::format("pool: group name '{}' must start with 'adse' and end in "
                    "'-<pid>' (e.g. adse-{})",
                    name, ::getpid()));
  }

  std::vector<Slot> slots(static_cast<size_t>(workers));
  internal::GroupLimits limits;
  for (int i = 0; i < workers; ++i) {
    slots[i].cores.assign(cores.begin() + i * per,
                          cores.begin() + (i + 1) * per);
    limits.slot_cores.push_back(slots[i].cores);
  }
  limits.memory_bytes = static_cast<int64_t>(options.memory_mb) << 20;
  limits.pids_max = options.pids_max;
  auto pool = std::make_unique<PoolImpl>(options, std::move(slots));

  if (options.isolation != Isolation::kAffinity) {
    Result<internal::Layout> layout = internal::DetectLayout(options);
    Status why = layout.status();
    if (layout.ok()) {
      Result<std::unique_ptr<internal::CampaignGroups>> groups =
          internal::CampaignGroups::Create(*layout, name, limits,
                                           options.pid_alive
                                               ? options.pid_alive
                                               : internal::DefaultPidAlive);
      if (groups.ok()) {
        pool->groups_ = std::move(groups).value();
      } else {
        why = groups.status();
      }
    }
    if (!why.ok()) {
      if (options.isolation == Isolation::kCgroup) {
        return Status::Unavailable("isolation cgroup: " + why.message());
      }
      pool->fallback_reason_ = "cgroups unavailable: " + why.message();
    }
  }
  return std::unique_ptr<WorkerPool>(std::move(pool));
}

void InstallInterruptHandlers() {
  std::lock_guard<std::mutex> lock(g_install_mutex);
  if (g_handlers_installed.load()) return;
  if (g_wake_fds[0] < 0 && ::pipe2(g_wake_fds, O_CLOEXEC | O_NONBLOCK) != 0) {
    g_wake_fds[0] = g_wake_fds[1] = -1;  // Wait then notices by polling
  }
  ArmHandlers();
  g_handlers_installed.store(true);
}

int InterruptRequested() { return g_interrupt.load(); }

void ClearInterrupt() {
  g_interrupt.store(0);
  DrainWakePipe();
  if (g_handlers_installed.load()) ArmHandlers();
}

void RequestInterrupt(int sig) {
  int expected = 0;
  g_interrupt.compare_exchange_strong(expected, sig);
  if (g_wake_fds[1] >= 0) {
    [[maybe_unused]] const ssize_t n = ::write(g_wake_fds[1], "!", 1);
  }
}

void InstallDrainHandler(int sig) {
  std::lock_guard<std::mutex> lock(g_install_mutex);
  if (g_wake_fds[0] < 0 && ::pipe2(g_wake_fds, O_CLOEXEC | O_NONBLOCK) != 0) {
    g_wake_fds[0] = g_wake_fds[1] = -1;  // Wait then notices by polling
  }
  struct sigaction action {};
  action.sa_handler = OnDrain;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  ::sigaction(sig, &action, nullptr);
}

int DrainRequested() { return g_drain.load(); }

void ClearDrain() { g_drain.store(0); }

}  // namespace adse::pool
