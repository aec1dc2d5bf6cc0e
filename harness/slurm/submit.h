// `adse submit`: a campaign handed to Slurm from a login node.
//  - An adaptive strategy (agent, llm, ga, nsga2) becomes one batch job
//    running the coordinator (`adse run --executor slurm`) in an allocation
//    sized from the scenario; each run is a job step inside it.
//  - A static sweep (exhaustive, random) becomes a job array, one task per
//    shard of the planned points (`adse shard`), plus a job that builds the
//    campaign's index and report once the array has ended (`adse index`,
//    --dependency=afterany).
// Submitting again continues the campaign: finished runs are found by
// content key, and a sweep submits only the shards with unfinished points.
#ifndef ADSE_HARNESS_SLURM_SUBMIT_H_
#define ADSE_HARNESS_SLURM_SUBMIT_H_

#include <string>
#include <vector>

#include "harness/slurm/records.h"
#include "harness/spec/spec.h"
#include "stack/base/status.h"

namespace adse::slurm {

// Memory asked for the coordinator process, on top of its steps' (MB).
inline constexpr int kCoordinatorMemoryMb = 1024;
// Memory asked for an array task's own process (it only starts steps).
inline constexpr int kShardProcessMemoryMb = 512;
// Memory of the index job (reads run files, draws the Pareto plot).
inline constexpr int kIndexMemoryMb = 2048;
// A job stopped by the time-limit warning requeues itself at most this
// often (SLURM_RESTART_COUNT), so a run longer than the time limit cannot
// requeue forever.
inline constexpr int kMaxRequeues = 10;

struct SubmitOptions {
  std::string output_dir;  // campaign folder; empty: the scenario's output
  std::string strategy;    // overrides exploration.strategy
  int budget = -1;         // overrides exploration.budget
  int confirm_runs = -1;   // overrides exploration.confirm_runs
  bool use_cache = true;   // false: --no-cache for every job
  std::string cache_dir;   // overrides harness.cache_dir
  // Print the scripts; write, plan and submit nothing.
  bool dry_run = false;
  // More sbatch options for every script, as #SBATCH lines after adse's
  // own (a later #SBATCH line wins, so these can override adse's sizes).
  std::vector<std::string> sbatch_args;
  // The adse executable the jobs run; empty: this one (it must be at the
  // same path on the compute nodes, as on a shared filesystem).
  std::string adse_path;
};

struct SubmittedScript {
  JobKind kind = JobKind::kCoordinator;
  std::string path;  // where it was written; empty in a dry run
  std::string text;
  std::string job_id;  // empty in a dry run
};

struct SubmitResult {
  std::string output_dir;  // absolute
  bool adaptive = false;
  std::vector<SubmittedScript> scripts;
  // Static sweeps: planned points, how many already have a result, the
  // shards and those submitted (with unfinished points), and why that size.
  int points = 0;
  int finished_points = 0;
  int shards = 0;
  std::vector<int> submitted_shards;
  int shard_size = 0;
  std::string sharding;
  // Adaptive: steps the allocation runs at once.
  int steps_at_once = 0;
  std::vector<std::string> notes;  // warnings worth printing
};

// InvalidArgument (naming the field or flag) for input adse cannot submit;
// NotFound when sbatch is missing (not in a dry run); Unavailable when jobs
// of an earlier submission are still queued or running; IoError when
// sbatch refuses a script (its message included).
Result<SubmitResult> Submit(const spec::Spec& spec,
                            const SubmitOptions& options);

// Seconds in a Slurm time limit ("2-03:04:05", "90", ...); 0 for
// UNLIMITED/INFINITE; -1 when malformed.
long TimeLimitSeconds(const std::string& limit);

}  // namespace adse::slurm

#endif  // ADSE_HARNESS_SLURM_SUBMIT_H_
