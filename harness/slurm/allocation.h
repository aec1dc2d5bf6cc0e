// The Slurm allocation this process runs in, read from the variables
// sbatch, salloc and srun set (SLURM_JOB_ID, SLURM_JOB_CPUS_PER_NODE,
// SLURM_MEM_PER_NODE, ...), and how many job steps of a given size fit in
// it at once.
#ifndef ADSE_HARNESS_SLURM_ALLOCATION_H_
#define ADSE_HARNESS_SLURM_ALLOCATION_H_

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "stack/base/status.h"

namespace adse::slurm {

struct Allocation {
  std::string job_id;         // SLURM_JOB_ID
  std::string array_job_id;   // SLURM_ARRAY_JOB_ID; empty outside arrays
  std::string array_task_id;  // SLURM_ARRAY_TASK_ID; empty outside arrays
  std::string node_list;      // SLURM_JOB_NODELIST, e.g. "node[01-04]"
  // CPUs on each node, expanded from SLURM_JOB_CPUS_PER_NODE ("4(x2),2").
  std::vector<int> cpus_per_node;
  // The job's memory per node or per CPU in MB (SLURM_MEM_PER_NODE /
  // SLURM_MEM_PER_CPU); 0 when the job has no memory limit.
  int64_t memory_per_node_mb = 0;
  int64_t memory_per_cpu_mb = 0;
  int restart_count = 0;  // SLURM_RESTART_COUNT: times requeued

  int TotalCpus() const;
  // "job 1000 on vm: 2 CPUs on 1 node, 3000 MB per node".
  std::string Describe() const;
};

// Reads a variable; returns null when it is not set (std::getenv's shape).
using Environment = std::function<const char*(const char*)>;

// The allocation, or nullopt when SLURM_JOB_ID is not set (not inside
// sbatch, salloc or srun). InvalidArgument naming the variable when one is
// malformed.
Result<std::optional<Allocation>> CurrentAllocation(
    const Environment& env = nullptr);

// "4(x2),2" -> {4, 4, 2}; InvalidArgument otherwise.
Result<std::vector<int>> ParseCpusPerNode(const std::string& text);

// How many steps of `cores_per_step` CPUs and `memory_mb` each fit in the
// allocation at once (steps do not span nodes; memory counts only when the
// job has a limit). 0 when not even one fits.
int StepsThatFit(const Allocation& allocation, int cores_per_step,
                 int memory_mb);

}  // namespace adse::slurm

#endif  // ADSE_HARNESS_SLURM_ALLOCATION_H_
