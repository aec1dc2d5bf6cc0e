// The campaign index (`campaign.h5`): one row per evaluation of a campaign
// — design point, status, metrics, feasibility, content key — plus each
// round's proposal and rationale. It is rebuilt from the run files at any
// time, so it is a convenience for h5py/pandas users and for replay, never
// the only copy of a result. Layout: results-schema/campaign.schema.json.
#ifndef ADSE_ANALYSIS_RUNFILE_CAMPAIGN_FILE_H_
#define ADSE_ANALYSIS_RUNFILE_CAMPAIGN_FILE_H_

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "analysis/runfile/run_data.h"
#include "stack/base/env.h"
#include "stack/base/status.h"

namespace adse::runfile {

inline constexpr int kCampaignSchemaVersion = 1;

struct EvaluationRow {
  int64_t index = 0;        // evaluation number, 0-based, in proposal order
  int64_t iteration = 0;    // the round that proposed it
  std::string content_key;  // 64 hex; the run file is runs/<key>.h5
  // kRunComplete (a run file exists) | kRunFailed (no run after retries)
  std::string status;
  // complete: the run's termination_reason (goal_reached, timeout, ...);
  // failed: the last attempt's outcome (timeout, out_of_memory, crashed,
  // exit_error) and its detail.
  std::string reason;
  // "simulated" | "campaign" (already in runs/) | "cache" (shared cache)
  std::string source;
  int64_t attempts = 0;
  double wall_s = 0.0;  // worker wall time of the last attempt
  bool feasible = false;
  uint64_t seed = 0;
  std::map<std::string, double> point;    // design parameter -> value
  std::map<std::string, double> metrics;  // NaN where a run lacks one
  // The diagnosis as JSON text ([{kind,node,remedy,remedies,severity}, ...];
  // remedies: [{kind,target}, ...], see harness/campaign/evaluation.h).
  std::string bottlenecks_json;
  // Replica number (harness.replicas): 0 for an evaluation; in `replicas`,
  // the run's number, which its seed is derived from.
  int64_t replica = 0;
  // The case of the scenario's task.cases the run drove (0 without cases);
  // for an evaluation, its representative run's.
  int64_t task_case = 0;
  // Feasibility differs across the point's replicas.
  bool unstable = false;
  // A point run more than once (harness.replicas > 1, or task.cases): its
  // runs, each a row of its own (index and iteration the evaluation's,
  // `task_case` and `replica` its numbers), of which this row is the
  // aggregate (harness/campaign/replicas.h). Empty for a point run once,
  // whose row is its run.
  std::vector<EvaluationRow> replicas;

  bool complete() const { return status == kRunComplete; }
};

struct IterationRow {
  int64_t iteration = 0;
  std::string strategy;
  std::string rationale;
  std::vector<std::string> content_keys;  // the points proposed
};

// One exchange with a language model (strategy `llm`), as recorded in the
// campaign's llm/exchanges.jsonl.
struct LlmExchangeRow {
  int64_t seq = 0;
  int64_t iteration = -1;
  std::string agent, model, backend, request_sha256;
  std::string prompt;
  std::string image_sha256;  // ','-joined
  bool ok = true;
  std::string answer;  // when ok
  std::string error;   // when not: "<code>: <message>"
  int64_t prompt_tokens = -1, completion_tokens = -1;  // -1: not reported
  double latency_s = 0.0;
  int64_t attempts = 0;
};

struct CampaignIndex {
  std::string scenario_name;
  std::string scenario_text;  // the exact YAML the campaign ran
  std::string strategy;
  uint64_t exploration_seed = 0;
  int64_t budget = 0;
  std::string isolation;  // how workers were confined, in words
  std::string adse_version;
  // Parameter and metric names (columns), in a stable order.
  std::vector<std::string> parameters;
  std::vector<std::string> metrics;
  std::vector<EvaluationRow> evaluations;
  std::vector<IterationRow> iterations;
  std::vector<LlmExchangeRow> llm_exchanges;  // empty unless strategy llm
};

// Writes the index atomically (temporary name, fsync, rename), so a reader
// sees the old or the new file. Columns: /evaluations/<field> and
// /evaluations/point/<parameter>, /evaluations/metrics/<metric> as
// equal-length 1-D datasets (pandas: one Series per dataset). Every
// evaluation's replicas go to /replicas, a table with the same columns plus
// `replica`, whose `index` names the evaluation they belong to.
// A row's point/metrics entry missing from its map is stored as NaN.
// InvalidArgument (nothing written) if a parameter or metric name is empty,
// ".", holds '/' or is listed twice; if a row's point or metrics has a name
// not in `parameters`/`metrics` (it would be lost); if an iteration's
// content key is empty or holds ','; or if a string holds a NUL byte.
// IoError if the file cannot be written (no temporary is left).
Status WriteCampaignIndex(const std::string& path, const CampaignIndex& index,
                          Env* env = Env::Default());

// NotFound / Corruption (naming the file and object) like ReadRunFile:
// Corruption also for a file whose `kind` is not "adse-campaign" (e.g. a run
// file), another schema_version, a missing dataset or columns of unequal
// length. NaN point/metric values are left out of the rows' maps, so a
// write/read round trip is exact except for explicit NaN entries.
Result<CampaignIndex> ReadCampaignIndex(const std::string& path);

}  // namespace adse::runfile

#endif  // ADSE_ANALYSIS_RUNFILE_CAMPAIGN_FILE_H_
