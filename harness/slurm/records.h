// What a campaign submitted to Slurm keeps in <campaign>/slurm/, so that
// array tasks, the index job, a resubmission and `adse status` all read the
// same facts from the shared filesystem:
//   plan.json         a static sweep's points in order, their content keys
//                     and the shard size (written once, by adse submit)
//   jobs.json         every job submitted for the campaign
//   shards/<i>.json   what array task i did: per key, where the result came
//                     from, attempts and wall time (for the index's counts)
//   <n>-<kind>.sbatch the scripts as submitted; logs/ their output
// Every file is written to a temporary name and renamed.
#ifndef ADSE_HARNESS_SLURM_RECORDS_H_
#define ADSE_HARNESS_SLURM_RECORDS_H_

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "stack/base/status.h"

namespace adse::slurm {

// <campaign>/slurm
std::string SlurmDir(const std::string& campaign_dir);

struct PlannedPoint {
  int64_t index = 0;
  std::string point;  // spec::FormatPoint text
  std::string key;    // content key of its first run
  // Content keys of all its runs (each case's harness.replicas runs, as
  // sim::PointRuns orders them), key first.
  std::vector<std::string> replica_keys;
};

struct SweepPlan {
  std::string scenario;  // absolute path of the scenario file
  std::string strategy;
  uint64_t seed = 0;
  int budget = 0;
  int shard_size = 1;      // points per array task
  int steps_per_task = 1;  // steps each task runs at once
  bool use_cache = true;
  std::string cache_dir;  // empty: the scenario's / the user's default
  std::vector<PlannedPoint> points;

  int shards() const;
  // [begin, end) into points of shard `shard` (empty when out of range).
  std::pair<size_t, size_t> ShardRange(int shard) const;
};

Status WriteSweepPlan(const std::string& campaign_dir, const SweepPlan& plan);
// NotFound when the campaign has no plan; Corruption naming the file when
// it cannot be read as one.
Result<SweepPlan> ReadSweepPlan(const std::string& campaign_dir);

// What a submitted job does. A new kind needs its token in records.cc's
// JobKindTerms.
enum class JobKind {
  kCoordinator,  // an adaptive campaign's coordinator, one allocation
  kArray,        // a static sweep's shards, one array task each
  kIndex,        // indexes the sweep's runs once the array has ended
};
// The token of a kind ("array"), as slurm/jobs.json and the JSON output
// store it and the scripts' file names carry it.
const char* JobKindToString(JobKind kind);
// False when `name` is no kind's token; `kind` is then unchanged.
bool StringToJobKind(std::string_view name, JobKind* kind);
// Every token, in enum order.
std::vector<std::string> JobKindNames();

struct SubmittedJob {
  int submission = 0;  // 1 for the first adse submit, 2 for the next, ...
  std::string time;    // UTC, ISO 8601
  JobKind kind = JobKind::kCoordinator;
  std::string job_id;
  std::string script;       // path relative to the campaign folder
  std::vector<int> shards;  // array tasks submitted (JobKind::kArray)
};

struct JobLog {
  std::string scenario;  // as submitted
  std::string strategy;
  int budget = 0;
  std::vector<SubmittedJob> jobs;
  int last_submission() const;
};

// An empty log when the campaign has none yet.
Result<JobLog> ReadJobLog(const std::string& campaign_dir);
Status WriteJobLog(const std::string& campaign_dir, const JobLog& log);

struct ShardResult {
  std::string source;  // simulated | campaign | cache
  int attempts = 0;
  double wall_s = 0.0;
};
// key -> result, for shard `task`; empty when the task wrote none.
std::map<std::string, ShardResult> ReadShardResults(
    const std::string& campaign_dir, int task);
// Merges `results` into the task's record (a requeued task adds to it).
Status WriteShardResults(const std::string& campaign_dir, int task,
                         const std::map<std::string, ShardResult>& results);

}  // namespace adse::slurm

#endif  // ADSE_HARNESS_SLURM_RECORDS_H_
