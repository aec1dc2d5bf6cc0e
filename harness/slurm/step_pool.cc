#include "harness/slurm/step_pool.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <sstream>
#include <utility>

#include <fmt/format.h>

#include "harness/pool/child.h"
#include "harness/pool/child_log.h"
#include "harness/slurm/allocation.h"
#include "harness/slurm/client.h"
#include "stack/base/clock.h"
#include "stack/base/subprocess.h"

extern char** environ;

namespace adse::slurm {
namespace {

using Clock = std::chrono::steady_clock;

constexpr size_t kStderrTailBytes = 2048;
// srun's own messages come last; this much of the log is searched for them.
constexpr size_t kClassifyTailBytes = 16384;
// Wait checks its steps this often (runs last seconds to hours; srun
// itself takes ~0.1 s to launch a step).
constexpr auto kPollInterval = std::chrono::milliseconds(20);

// Whether any line of the log that is srun's or slurmstepd's (the
// worker's own output is never taken for theirs) contains one of `marks`.
bool SlurmSays(const std::string& output,
               std::initializer_list<const char*> marks) {
  size_t at = 0;
  while (at < output.size()) {
    size_t end = output.find('\n', at);
    if (end == std::string::npos) end = output.size();
    const std::string line = output.substr(at, end - at);
    at = end + 1;
    if (line.rfind("srun:", 0) != 0 && line.rfind("slurmstepd", 0) != 0)
      continue;
    for (const char* mark : marks) {
      if (line.find(mark) != std::string::npos) return true;
    }
  }
  return false;
}

// Whether srun's output says Slurm itself ended the step or refused it:
// cancelled, its job gone.
bool SlurmEndedStep(const std::string& output) {
  return SlurmSays(output, {"CANCELLED AT", "has expired",
                            "Expired or invalid job", "already completing",
                            "Job step aborted", "Unable to create step"});
}

// Whether the job is no longer running (cancelled, timed out, completing)
// or unknown, as slurmctld has it: it changes the job's state before it
// signals the job's processes.
bool AllocationEnding(const std::string& job_id) {
  // %A is the job's own id; for an array task's job, --jobs may also list
  // the array's other tasks.
  Result<ProcessResult> r = RunProcess(
      {"squeue", "--noheader", "--jobs=" + job_id, "--format=%A %T"});
  if (!r.ok()) return false;           // cannot tell: treat the step as failed
  if (r->exit_code != 0) return true;  // "Invalid job id": it is gone
  std::istringstream lines(r->output);
  std::string id, state;
  while (lines >> id >> state) {
    if (id == job_id) return state != "RUNNING";
  }
  return true;
}

struct ExecFailure {
  int error;
};

// Everything the child needs, made before fork (after fork only
// async-signal-safe calls are allowed in the child of a threaded parent).
struct ChildPlan {
  std::vector<char*> argv;
  std::vector<char*> envp;
  pid_t parent_pid = 0;
  int stdin_fd = -1;
  int log_fd = -1;
  int report_fd = -1;
};

[[noreturn]] void RunChild(const ChildPlan& plan) {
  // A coordinator that dies takes its steps with it: on SIGTERM srun
  // cancels its step (on SIGKILL it could not, and the step would run on).
  if (!pool::PrepareChild(plan.parent_pid, SIGTERM, plan.stdin_fd,
                          plan.log_fd)) {
    ::_exit(127);
  }
  ::execve(plan.argv[0], plan.argv.data(), plan.envp.data());
  const ExecFailure failure{errno};
  [[maybe_unused]] const ssize_t n =
      ::write(plan.report_fd, &failure, sizeof(failure));
  ::_exit(127);
}

struct Running {
  pool::Job job;
  pid_t pid = -1;
  Clock::time_point start;
  std::optional<Clock::time_point> deadline;
  std::optional<pool::Outcome> killed_for;  // kTimeout or kCancelled
  std::optional<Clock::time_point> cancel_sent;
  bool srun_killed = false;
  // Set once waitpid has collected it.
  std::optional<int> wait_status;
};

class StepPool : public pool::WorkerPool {
 public:
  StepPool(StepPoolOptions options, std::string srun_path)
      : options_(std::move(options)),
        srun_path_(std::move(srun_path)),
        slots_(static_cast<size_t>(options_.slots)) {}
  ~StepPool() override { CancelAll(); }

  int slots() const override { return static_cast<int>(slots_.size()); }
  int idle_slots() const override {
    return static_cast<int>(
        std::count_if(slots_.begin(), slots_.end(),
                      [](const std::optional<Running>& s) { return !s; }));
  }
  std::string isolation_description() const override {
    return fmt::format("Slurm job steps (srun --exact -n1 -c{} --mem={}M){}",
                       options_.cores_per_step, options_.memory_mb,
                       options_.allocation_description.empty()
                           ? ""
                           : " in " + options_.allocation_description);
  }
  std::string fallback_reason() const override { return ""; }

  Status Submit(const pool::Job& job) override;
  std::vector<pool::JobResult> Wait(double max_wait_s) override;
  std::vector<pool::JobResult> CancelAll() override;

 private:
  // Collects the step's srun if it has ended; true when it has.
  bool Collect(Running& r);
  void Cancel(Running& r, pool::Outcome reason);
  pool::JobResult Reap(size_t slot);

  StepPoolOptions options_;
  std::string srun_path_;
  std::vector<std::optional<Running>> slots_;
};

Status StepPool::Submit(const pool::Job& job) {
  if (job.argv.empty() || job.argv[0].empty() || job.argv[0][0] != '/') {
    return Status::InvalidArgument(
        fmt::format("job {}: argv[0] must be an absolute path, got '{}'",
                    job.id, job.argv.empty() ? "" : job.argv[0]));
  }
  const auto idle =
      std::find_if(slots_.begin(), slots_.end(),
                   [](const std::optional<Running>& s) { return !s; });
  if (idle == slots_.end()) {
    return Status::Unavailable(fmt::format(
        "job {}: no idle slot, all {} run steps", job.id, slots_.size()));
  }
  const int log = ::open(job.log_path.c_str(),
                         O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log < 0) {
    return Status::IoError(fmt::format("job {}: cannot create log {}: {}",
                                       job.id, job.log_path,
                                       std::strerror(errno)));
  }
  const int null = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  int report[2];
  if (::pipe2(report, O_CLOEXEC) != 0) {
    const std::string error = std::strerror(errno);
    ::close(log);
    if (null >= 0) ::close(null);
    return Status::IoError(fmt::format("job {}: pipe: {}", job.id, error));
  }

  std::vector<std::string> argv = SrunCommand(options_, srun_path_, job);
  argv.insert(argv.end(), job.argv.begin(), job.argv.end());
  // The allocation's memory variables would clash with the step's --mem
  // (srun refuses SLURM_MEM_PER_CPU together with --mem).
  std::vector<std::string> env;
  for (char** e = environ; e != nullptr && *e != nullptr; ++e) {
    const std::string entry = *e;
    if (entry.rfind("SLURM_MEM_PER_", 0) == 0) continue;
    env.push_back(entry);
  }
  ChildPlan plan;
  for (std::string& a : argv) plan.argv.push_back(a.data());
  plan.argv.push_back(nullptr);
  for (std::string& e : env) plan.envp.push_back(e.data());
  plan.envp.push_back(nullptr);
  plan.parent_pid = ::getpid();
  plan.stdin_fd = null;
  plan.log_fd = log;
  plan.report_fd = report[1];

  Running running;
  running.job = job;
  running.start = Clock::now();
  if (job.timeout_s > 0) {
    running.deadline = running.start + SteadyFromSeconds(job.timeout_s);
  }
  const pid_t pid = ::fork();
  if (pid == 0) RunChild(plan);
  const int fork_error = errno;
  ::close(report[1]);
  ::close(log);
  if (null >= 0) ::close(null);
  if (pid < 0) {
    ::close(report[0]);
    return Status::IoError(
        fmt::format("job {}: fork: {}", job.id, std::strerror(fork_error)));
  }
  ::setpgid(pid, pid);
  ExecFailure failure{};
  ssize_t n;
  do {
    n = ::read(report[0], &failure, sizeof(failure));
  } while (n < 0 && errno == EINTR);
  ::close(report[0]);
  if (n == static_cast<ssize_t>(sizeof(failure))) {
    int status;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return Status::IoError(fmt::format("job {}: cannot start {}: {}", job.id,
                                       srun_path_,
                                       std::strerror(failure.error)));
  }
  running.pid = pid;
  *idle = std::move(running);
  return Status::Ok();
}

bool StepPool::Collect(Running& r) {
  if (r.wait_status) return true;
  int status = 0;
  pid_t got;
  do {
    got = ::waitpid(r.pid, &status, WNOHANG);
  } while (got < 0 && errno == EINTR);
  if (got == r.pid) {
    r.wait_status = status;
    return true;
  }
  if (got < 0) {  // ECHILD: reaped elsewhere (SIGCHLD ignored)
    r.wait_status = -1;
    return true;
  }
  return false;
}

void StepPool::Cancel(Running& r, pool::Outcome reason) {
  if (!r.killed_for) r.killed_for = reason;
  if (!r.cancel_sent) {
    // With --quit-on-interrupt one SIGINT makes srun cancel its step.
    ::kill(r.pid, SIGINT);
    r.cancel_sent = Clock::now();
  }
}

pool::JobResult StepPool::Reap(size_t slot) {
  Running& r = *slots_[slot];
  pool::JobResult result;
  result.id = r.job.id;
  result.slot = static_cast<int>(slot);
  result.wall_s = SteadySeconds(Clock::now() - r.start);
  const std::string output =
      pool::ReadLogTail(r.job.log_path, kClassifyTailBytes);
  result.stderr_tail = output.size() > kStderrTailBytes
                           ? output.substr(output.size() - kStderrTailBytes)
                           : output;
  if (*r.wait_status == -1) {
    result.outcome = r.killed_for.value_or(pool::Outcome::kExitError);
    result.stderr_tail +=
        "\n(exit status lost: srun was reaped elsewhere; is SIGCHLD "
        "ignored?)";
  } else {
    ClassifyStepEnd(*r.wait_status, output, &result);
    if (r.killed_for) {
      result.outcome = *r.killed_for;
    } else if (result.outcome != pool::Outcome::kOk && SlurmEndedStep(output) &&
               AllocationEnding(options_.job_id)) {
      // Slurm cancelled the step with the whole job (scancel, the time
      // limit): stop the campaign now, before the coordinator's own signal
      // arrives, rather than retry into a vanishing allocation and record
      // runs as failed that were merely cut short.
      result.outcome = pool::Outcome::kCancelled;
      pool::RequestInterrupt(SIGTERM);
      std::fprintf(stderr,
                   "Slurm job %s is ending (cancelled or out of time): "
                   "stopping; unfinished runs are redone on resume\n",
                   options_.job_id.c_str());
    }
  }
  if (r.srun_killed) {
    result.stderr_tail += fmt::format(
        "\n(srun did not end {:g} s after SIGINT and was killed; its step "
        "may run on until its --time limit)",
        options_.cancel_grace_s);
  }
  slots_[slot].reset();
  return result;
}

std::vector<pool::JobResult> StepPool::Wait(double max_wait_s) {
  const auto until = Clock::now() + SteadyFromSeconds(max_wait_s);
  for (;;) {
    std::vector<pool::JobResult> done;
    const auto now = Clock::now();
    for (size_t i = 0; i < slots_.size(); ++i) {
      if (!slots_[i]) continue;
      Running& r = *slots_[i];
      if (Collect(r)) {
        done.push_back(Reap(i));
        continue;
      }
      if (r.deadline && !r.killed_for && now >= *r.deadline) {
        Cancel(r, pool::Outcome::kTimeout);
      }
      if (r.cancel_sent && !r.srun_killed &&
          now - *r.cancel_sent >= SteadyFromSeconds(options_.cancel_grace_s)) {
        ::kill(r.pid, SIGKILL);
        r.srun_killed = true;
      }
    }
    if (!done.empty() || idle_slots() == slots() ||
        pool::InterruptRequested() != 0 || Clock::now() >= until) {
      return done;
    }
    auto nap = std::min<Clock::duration>(kPollInterval, until - Clock::now());
    if (nap > Clock::duration::zero()) {
      const auto ns =
          std::chrono::duration_cast<std::chrono::nanoseconds>(nap).count();
      const timespec t{static_cast<time_t>(ns / 1000000000),
                       static_cast<long>(ns % 1000000000)};
      ::nanosleep(&t, nullptr);  // a signal cuts it short, as it should
    }
  }
}

std::vector<pool::JobResult> StepPool::CancelAll() {
  std::vector<pool::JobResult> results;
  for (std::optional<Running>& slot : slots_) {
    if (slot && !Collect(*slot)) Cancel(*slot, pool::Outcome::kCancelled);
  }
  const auto give_up =
      Clock::now() + SteadyFromSeconds(options_.cancel_grace_s);
  for (;;) {
    bool running = false;
    for (size_t i = 0; i < slots_.size(); ++i) {
      if (!slots_[i]) continue;
      if (Collect(*slots_[i])) {
        results.push_back(Reap(i));
      } else {
        running = true;
        if (Clock::now() >= give_up && !slots_[i]->srun_killed) {
          ::kill(slots_[i]->pid, SIGKILL);
          slots_[i]->srun_killed = true;
        }
      }
    }
    if (!running) return results;
    const timespec t{0, 20 * 1000 * 1000};
    ::nanosleep(&t, nullptr);
  }
}

}  // namespace

std::vector<std::string> SrunCommand(const StepPoolOptions& options,
                                     const std::string& srun_path,
                                     const pool::Job& job) {
  std::vector<std::string> argv = {
      srun_path,
      "--jobid=" + options.job_id,
      "--exact",
      "--ntasks=1",
      "--nodes=1",
      fmt::format("--cpus-per-task={}", options.cores_per_step),
      fmt::format("--mem={}M", options.memory_mb),
      "--job-name=" +
          (job.name.empty() ? fmt::format("adse-{}", job.id) : job.name),
      // One SIGINT cancels the step (the pool's timeout and cancel path).
      "--quit-on-interrupt",
  };
  if (job.timeout_s > 0) {
    // A backstop in minutes, should the step outlive its srun.
    argv.push_back(fmt::format(
        "--time={}", static_cast<long>(std::ceil(job.timeout_s / 60.0)) + 1));
  }
  argv.insert(argv.end(), options.extra_args.begin(), options.extra_args.end());
  argv.push_back("--");
  return argv;
}

void ClassifyStepEnd(int wait_status, const std::string& output,
                     pool::JobResult* result) {
  const bool oom = SlurmSays(
      output, {"Out Of Memory", "oom-kill", "oom_kill",
               "Exceeded job memory limit", "Exceeded step memory limit"});
  const bool time_limit = SlurmSays(output, {"DUE TO TIME LIMIT"});
  result->exit_code = -1;
  result->signal = 0;
  if (WIFSIGNALED(wait_status)) {
    result->signal = WTERMSIG(wait_status);
  } else if (WIFEXITED(wait_status)) {
    const int code = WEXITSTATUS(wait_status);
    // srun exits 128 + N when its task died of signal N.
    if (code > 128 && code < 128 + 64) {
      result->signal = code - 128;
    } else {
      result->exit_code = code;
    }
  }
  if (oom || result->exit_code == pool::kExitOutOfMemory) {
    result->outcome = pool::Outcome::kOutOfMemory;
  } else if (time_limit) {
    result->outcome = pool::Outcome::kTimeout;
  } else if (result->exit_code == 0) {
    result->outcome = pool::Outcome::kOk;
  } else if (result->signal != 0) {
    result->outcome = pool::Outcome::kCrashed;
  } else {
    result->outcome = pool::Outcome::kExitError;
  }
}

Result<std::unique_ptr<pool::WorkerPool>> CreateStepPool(
    const StepPoolOptions& options) {
  if (options.job_id.empty() ||
      options.job_id.find_first_not_of("0123456789_") != std::string::npos) {
    return Status::InvalidArgument(fmt::format(
        "step pool: job id '{}' is not a Slurm job id", options.job_id));
  }
  if (options.slots < 1 || options.cores_per_step < 1 ||
      options.memory_mb < 1) {
    return Status::InvalidArgument(fmt::format(
        "step pool: slots ({}), cores_per_step ({}) and memory_mb ({}) must "
        "be >= 1",
        options.slots, options.cores_per_step, options.memory_mb));
  }
  std::optional<std::string> srun = FindProgram(options.srun);
  if (!srun) {
    return Status::NotFound(fmt::format(
        "{} not found on PATH: Slurm's client commands are needed to run "
        "job steps",
        options.srun));
  }
  return std::unique_ptr<pool::WorkerPool>(
      std::make_unique<StepPool>(options, *srun));
}

Result<std::unique_ptr<pool::WorkerPool>> CreateAllocationPool(
    const spec::Spec& spec) {
  const spec::HarnessOptions& h = spec.harness;
  if (h.isolation != "auto") {
    return Status::InvalidArgument(
        spec.Where("harness.isolation") + "harness.isolation: on Slurm, " +
        "runs are confined by Slurm's own limits (srun --exact -c --mem; its "
        "task/cgroup plugin where configured), not by adse; expected 'auto', "
        "found '" +
        h.isolation + "'");
  }
  Result<std::optional<Allocation>> allocation = CurrentAllocation();
  if (!allocation.ok()) return allocation.status();
  if (!allocation->has_value()) {
    return Status::InvalidArgument(
        spec.Where("harness.executor") +
        "harness.executor: 'slurm' runs each design point as a job step "
        "(srun) and needs a Slurm allocation, but SLURM_JOB_ID is not set: "
        "submit the campaign with `adse submit` from a login node, run adse "
        "inside salloc or sbatch, or use --executor local");
  }
  const Allocation& a = **allocation;
  int slots = StepsThatFit(a, h.cores_per_worker, h.memory_mb);
  if (slots < 1) {
    return Status::InvalidArgument(fmt::format(
        "{}harness.cores_per_worker: the allocation ({}) cannot hold one step "
        "of cores_per_worker = {} CPUs and memory_mb = {} MB",
        spec.Where("harness.cores_per_worker"), a.Describe(),
        h.cores_per_worker, h.memory_mb));
  }
  if (h.workers > 0) slots = std::min(slots, h.workers);
  StepPoolOptions options;
  options.job_id = a.job_id;
  options.slots = slots;
  options.cores_per_step = h.cores_per_worker;
  options.memory_mb = h.memory_mb;
  options.allocation_description = a.Describe();
  return CreateStepPool(options);
}

}  // namespace adse::slurm
