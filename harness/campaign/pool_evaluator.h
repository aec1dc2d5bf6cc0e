// The live Evaluator: finds a point's run by content key in the campaign
// folder or the shared cache, and otherwise runs `adse worker` for it on
// the pool, retrying failed attempts and recording the ones that fail for
// good. Internal to harness/campaign.
#ifndef ADSE_HARNESS_CAMPAIGN_POOL_EVALUATOR_H_
#define ADSE_HARNESS_CAMPAIGN_POOL_EVALUATOR_H_

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "harness/campaign/explorer.h"
#include "harness/campaign/run_store.h"
#include "harness/pool/worker_pool.h"
#include "harness/sim/run_key.h"
#include "harness/spec/spec.h"

namespace adse::campaign {

struct PoolEvaluatorOptions {
  std::vector<std::string> worker_command;  // before the worker's arguments
  std::string scenario_path;                // absolute
  int retries = 1;
  double run_timeout_s = 900.0;
  int memory_mb = 4096;
  bool retry_failed = false;
  const RunCache* cache = nullptr;  // null: no shared cache
  // After a drain request (pool::DrainRequested) running attempts may
  // finish for this long; then they are cancelled like after an interrupt.
  double drain_grace_s = 0.0;
  std::function<void(const EvalRequest&, int attempt, const std::string&)>
      on_attempt_failed;
};

class PoolEvaluator : public Evaluator {
 public:
  PoolEvaluator(const spec::Spec& spec, const CampaignFolder& folder,
                pool::WorkerPool* pool, PoolEvaluatorOptions options);

  int capacity() const override;
  void Start(const EvalRequest& request) override;
  int outstanding() const override;
  std::vector<EvaluationRow> Wait() override;
  bool interrupted() const override;

  // Why the first run refused as bad input (the worker's exit 2) was
  // refused, when no run had come through before it: every run is likely
  // refused the same way (a calibration or profile that lacks a callback
  // the stack runs, a map it cannot read), so from then on the evaluator
  // counts as interrupted and the campaign stops with this error rather
  // than record one refusal per point.
  const std::optional<std::string>& refused() const { return refused_; }

  // Kills running attempts (their points stay unevaluated: no failure
  // record) and forgets queued ones. Returns the rows that were complete
  // but not yet returned by Wait, including runs whose file landed just
  // before the stop.
  std::vector<EvaluationRow> Cancel();

  // The row of a point whose runs (or failure records) are all already in
  // the folder (nothing is started; the pool may be null), else nullopt.
  std::optional<EvaluationRow> Recorded(const EvalRequest& request);

 private:
  // One run of a point: its run `run` (an index into sim::PointRuns), of
  // case `task_case` and replica `replica`.
  struct Pending {
    EvalRequest request;
    int run = 0;
    int task_case = 0;
    int replica = 0;
    std::string key;
    uint64_t seed = 0;
    int attempt = 0;  // 1-based once started
  };

  // Fills `p` for run `run` of `request`; returns the run's row when it is
  // already known (in the folder, or the key cannot be computed).
  std::optional<EvaluationRow> Prepare(const EvalRequest& request, int run,
                                       Pending* p);
  // Takes a finished run's row; once all of its point's runs are in, the
  // point's row (AggregatePoint) is ready.
  void Deliver(const Pending& p, EvaluationRow row);
  // A row from an existing run file; nullopt when the file is unusable
  // (then it is moved aside and the point simulated again).
  std::optional<EvaluationRow> LoadRun(const Pending& p,
                                       const std::string& source);
  // LoadRun of a run a worker has just written, with what it took
  // (attempts, wall time), which is also kept beside the run file.
  std::optional<EvaluationRow> LoadSimulated(const Pending& p, double wall_s);
  EvaluationRow FailedRow(const Pending& p, const FailureRecord& record,
                          const std::string& source) const;
  void Dispatch();
  void Finish(const pool::JobResult& result);

  const spec::Spec& spec_;
  const CampaignFolder& folder_;
  pool::WorkerPool* pool_;
  PoolEvaluatorOptions options_;
  // The runs each point takes (cases x replicas).
  std::vector<sim::PointRun> runs_;
  // The spec of each case (spec::ForCase), which its runs' keys hash.
  std::vector<spec::Spec> case_specs_;
  // Points started and not yet ready: their runs' rows so far.
  std::map<int64_t, std::vector<std::optional<EvaluationRow>>> points_;
  std::deque<Pending> queued_;
  std::map<uint64_t, Pending> running_;  // job id -> attempt
  uint64_t next_job_ = 1;
  std::vector<EvaluationRow> ready_;
  // When a drain request stops waiting for running attempts.
  std::optional<std::chrono::steady_clock::time_point> drain_deadline_;
  bool any_run_came_through_ = false;  // a run file delivered, not a failure
  std::optional<std::string> refused_;
};

}  // namespace adse::campaign

#endif  // ADSE_HARNESS_CAMPAIGN_POOL_EVALUATOR_H_
