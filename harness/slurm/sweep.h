// The two halves of a static sweep on Slurm after `adse submit` planned it
// (slurm/plan.json): each array task evaluates its shard of the points
// (`adse shard`), and a job after the array builds the campaign's views
// from whatever run files exist (`adse index`). Tasks share the campaign
// folder without locks: each writes only its own points' run files (named
// by content key, written to a temporary name and renamed) and its own
// record, slurm/shards/<task>.json.
#ifndef ADSE_HARNESS_SLURM_SWEEP_H_
#define ADSE_HARNESS_SLURM_SWEEP_H_

#include <functional>
#include <string>
#include <vector>

#include "harness/campaign/campaign.h"
#include "stack/base/status.h"

namespace adse::slurm {

struct ShardOptions {
  std::string campaign_dir;
  // The shard to run; -1: SLURM_ARRAY_TASK_ID.
  int task = -1;
  // Run the points in local worker processes (harness.workers, isolation)
  // instead of job steps; no allocation needed.
  bool local = false;
  // Progress and the worker command, as for a campaign (may be empty).
  campaign::ExplorerListener* listener = nullptr;
  std::function<void(const campaign::EvalRequest&, int, const std::string&)>
      on_attempt_failed;
  std::function<void(int, const std::string&, const std::string&)>
      on_pool_ready;
  std::vector<std::string> worker_command;
};

struct ShardSummary {
  int task = 0;
  int shards = 0;
  std::string scenario_name;
  std::vector<campaign::EvalRequest> points;  // the shard's points
  campaign::CampaignSummary campaign;         // rows of those evaluated
};

// Runs one shard: its points that have no result yet are simulated (or
// taken from the shared cache), the rest are skipped. InvalidArgument when
// the folder has no plan, the task is out of range, or the scenario no
// longer gives the planned content keys.
Result<ShardSummary> RunShard(const ShardOptions& options);

// Rebuilds campaign.h5, report.md, summary.json and pareto.png of a
// planned sweep from the run files and failure records in the folder, in
// plan order; points without either are counted in `unfinished` and named
// in the report. Takes the campaign lock while it writes. `spec`, when not
// null, receives the planned scenario (for the headline).
Result<campaign::CampaignSummary> BuildSweepIndex(
    const std::string& campaign_dir, spec::Spec* spec = nullptr);

}  // namespace adse::slurm

#endif  // ADSE_HARNESS_SLURM_SWEEP_H_
