// A WorkerPool whose jobs are Slurm job steps: each job's command runs as
//   srun --jobid=<job> --exact -n1 -c<cores> --mem=<memory_mb>M -J <name> ...
// inside the allocation the coordinator runs in, as many at once as the
// allocation holds. The steps are confined by Slurm's own limits (its
// task/cgroup plugin where the cluster configures it); adse adds no cgroups
// or rlimits of its own. A timed-out or cancelled step is ended through
// srun (one SIGINT with --quit-on-interrupt makes srun cancel its step),
// never by killing srun alone, which would leave the step running.
#ifndef ADSE_HARNESS_SLURM_STEP_POOL_H_
#define ADSE_HARNESS_SLURM_STEP_POOL_H_

#include <memory>
#include <string>
#include <vector>

#include "harness/pool/worker_pool.h"
#include "harness/spec/spec.h"
#include "stack/base/status.h"

namespace adse::slurm {

struct StepPoolOptions {
  // The allocation the steps run in (srun --jobid).
  std::string job_id;
  // Steps running at once (the pool's slots), >= 1.
  int slots = 1;
  // CPUs per step (srun -c) and memory per step in MB (srun --mem).
  int cores_per_step = 1;
  int memory_mb = 4096;
  // The srun program: a path, or a name searched on PATH.
  std::string srun = "srun";
  // More srun options, placed before the command.
  std::vector<std::string> extra_args;
  // What describes the allocation in isolation_description().
  std::string allocation_description;
  // How long srun gets to cancel its step after SIGINT before it is
  // killed itself (SIGKILL; the step may then outlive it until its own
  // --time limit, which the pool sets just above the job's timeout).
  double cancel_grace_s = 15.0;
};

// Checks the options and finds srun. InvalidArgument for bad options,
// NotFound when srun is not on PATH.
Result<std::unique_ptr<pool::WorkerPool>> CreateStepPool(
    const StepPoolOptions& options);

// The pool of the allocation this process runs in (SLURM_JOB_ID): steps of
// harness.cores_per_worker CPUs and memory_mb each, as many at once as the
// allocation holds (at most harness.workers when that is set). A campaign's
// make_pool for `harness.executor: slurm`. InvalidArgument naming the
// field when not inside an allocation, when harness.isolation asks adse to
// confine runs itself, or when not even one step fits.
Result<std::unique_ptr<pool::WorkerPool>> CreateAllocationPool(
    const spec::Spec& spec);

// The srun command line of `job` (before its argv), for the logs and tests.
std::vector<std::string> SrunCommand(const StepPoolOptions& options,
                                     const std::string& srun_path,
                                     const pool::Job& job);

// How a step ended, from srun's exit status (or the signal that ended
// srun) and its output. srun reports an out-of-memory kill and a step time
// limit only as text ("task 0: Out Of Memory", "oom-kill event", "DUE TO
// TIME LIMIT") and exits 1 after an OOM kill; a task killed by signal N
// makes it exit 128 + N. Sets result->outcome, exit_code and signal.
void ClassifyStepEnd(int wait_status, const std::string& output,
                     pool::JobResult* result);

}  // namespace adse::slurm

#endif  // ADSE_HARNESS_SLURM_STEP_POOL_H_
