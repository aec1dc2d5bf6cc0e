// Slurm's client commands as adse uses them: sbatch to submit, squeue (and
// sacct where the cluster keeps accounting) to see jobs and steps, scontrol
// for the cluster's limits. Every call runs the real program and parses
// its machine-readable output; nothing here talks to slurmctld directly.
#ifndef ADSE_HARNESS_SLURM_CLIENT_H_
#define ADSE_HARNESS_SLURM_CLIENT_H_

#include <optional>
#include <string>
#include <vector>

#include "stack/base/status.h"

namespace adse::slurm {

// The absolute path of `name` (searched on PATH unless it holds a '/'),
// or nullopt when there is no such executable.
std::optional<std::string> FindProgram(const std::string& name);

// Submits a batch script with `sbatch --parsable`; returns the job id.
// NotFound when sbatch is not on PATH; IoError with sbatch's message when
// it refuses the script.
Result<std::string> SubmitBatchScript(const std::string& script_path);

struct JobState {
  std::string id;         // as squeue shows it: "123", or "123_4" for a task
  std::string job_id;     // the unique job id (an array task has its own)
  std::string state;      // PENDING, RUNNING, COMPLETED, CANCELLED, ...
  std::string reason;     // why pending, or "None"
  std::string elapsed;    // run time so far
  std::string exit_code;  // "0:0" (only from sacct)
};

// The states of jobs (array jobs expanded into their tasks) that Slurm
// still knows: squeue (which lists finished jobs for MinJobAge, 5 minutes
// by default), then sacct for the rest where accounting is enabled. An id
// found by neither is left out. NotFound when squeue is not on PATH.
Result<std::vector<JobState>> QueryJobs(const std::vector<std::string>& ids);

struct StepState {
  std::string id;    // "123.4" or "123_4.0"
  std::string name;  // srun --job-name: adse-<key prefix>
  std::string elapsed;
  std::string nodes;
};

// The running steps of the given jobs (and their array tasks).
Result<std::vector<StepState>> QuerySteps(const std::vector<std::string>& ids);

// The content-key prefix a run's step carries in its name ("adse-<prefix>",
// set by the campaign's pool evaluator), or "" for any other step.
std::string StepKeyPrefix(const StepState& step);

// Whether a job state means the job may still run (pending, running,
// requeued, suspended, completing ...).
bool IsActiveState(const std::string& state);

// The cluster's MaxArraySize (`scontrol show config`), or nullopt.
std::optional<int> MaxArraySize();

}  // namespace adse::slurm

#endif  // ADSE_HARNESS_SLURM_CLIENT_H_
