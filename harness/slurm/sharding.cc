#include "harness/slurm/sharding.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace adse::slurm {

Sharding ChooseSharding(const ShardingInput& in) {
  Sharding s;
  const int64_t points = std::max<int64_t>(in.points, 0);
  const int64_t max_tasks = std::max(1, in.max_array_size);
  if (in.fixed_shard_size > 0) {
    s.shard_size = in.fixed_shard_size;
    s.explanation =
        fmt::format("harness.slurm.shard_size = {}", in.fixed_shard_size);
  } else {
    const double estimate = std::max(in.run_estimate_s, 1e-3);
    const int64_t for_time = static_cast<int64_t>(std::ceil(
        kMinTaskSeconds * std::max(1, in.steps_per_task) / estimate - 1e-9));
    const int64_t for_array = (points + max_tasks - 1) / max_tasks;
    const int64_t size = std::clamp<int64_t>(std::max(for_time, for_array), 1,
                                             std::max<int64_t>(points, 1));
    s.shard_size = static_cast<int>(size);
    s.explanation = fmt::format(
        "max(ceil({:g} s x {} step(s) at once / {:g} s per run) = {}, "
        "ceil({} points / MaxArraySize {}) = {}){}",
        kMinTaskSeconds, std::max(1, in.steps_per_task), estimate, for_time,
        points, max_tasks, for_array,
        size < std::max(for_time, for_array) ? ", capped at the point count"
                                             : "");
  }
  s.shards = points == 0
                 ? 0
                 : static_cast<int>((points + s.shard_size - 1) / s.shard_size);
  if (s.shards > max_tasks) {
    s.explanation +=
        fmt::format("; {} shards exceed MaxArraySize {}: raise shard_size",
                    s.shards, max_tasks);
  }
  return s;
}

std::string ArraySpec(const std::vector<int>& tasks, int max_parallel) {
  std::string spec;
  for (size_t i = 0; i < tasks.size();) {
    size_t j = i;
    while (j + 1 < tasks.size() && tasks[j + 1] == tasks[j] + 1) ++j;
    if (!spec.empty()) spec += ",";
    spec += j == i ? fmt::format("{}", tasks[i])
                   : fmt::format("{}-{}", tasks[i], tasks[j]);
    i = j + 1;
  }
  if (max_parallel > 0) spec += fmt::format("%{}", max_parallel);
  return spec;
}

}  // namespace adse::slurm
