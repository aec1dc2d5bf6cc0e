// How a static sweep is cut into array tasks. Cluster sites want jobs that
// run for at least several minutes (scheduling a job costs the scheduler
// more than a few seconds of work is worth) and cap array sizes
// (MaxArraySize, commonly 1001: task ids 0..1000). The rule:
//
//   shard_size = max(ceil(min_task_s * steps_per_task / run_estimate_s),
//                    ceil(points / max_array_size))
//
// capped at the number of points, unless harness.slurm.shard_size fixes it.
#ifndef ADSE_HARNESS_SLURM_SHARDING_H_
#define ADSE_HARNESS_SLURM_SHARDING_H_

#include <cstdint>
#include <string>
#include <vector>

namespace adse::slurm {

// Shortest sensible array task, in seconds of work.
inline constexpr double kMinTaskSeconds = 600.0;
// MaxArraySize when the cluster does not say (Slurm's default).
inline constexpr int kDefaultMaxArraySize = 1001;

struct ShardingInput {
  int64_t points = 0;
  int steps_per_task = 1;        // runs each task has going at once
  double run_estimate_s = 60.0;  // harness.slurm.run_estimate_s
  int max_array_size = kDefaultMaxArraySize;
  int fixed_shard_size = 0;  // harness.slurm.shard_size; 0: the rule
};

struct Sharding {
  int shard_size = 1;
  int shards = 0;
  // One sentence: which rule gave the size, with the numbers.
  std::string explanation;
};

Sharding ChooseSharding(const ShardingInput& input);

// The --array value for these task ids (ascending): "0-3", "1,4-6",
// with "%<max_parallel>" when max_parallel > 0.
std::string ArraySpec(const std::vector<int>& tasks, int max_parallel);

}  // namespace adse::slurm

#endif  // ADSE_HARNESS_SLURM_SHARDING_H_
