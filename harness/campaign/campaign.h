// `adse run`: a whole campaign. Explores the scenario's design space with
// its strategy within the budget, runs each point in a worker process of
// the pool, and keeps the campaign folder's views (campaign.h5, report.md,
// summary.json, pareto.png) rebuilt from the run files. Killed at any
// moment and started again, it loses nothing and repeats nothing.
#ifndef ADSE_HARNESS_CAMPAIGN_CAMPAIGN_H_
#define ADSE_HARNESS_CAMPAIGN_CAMPAIGN_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "harness/campaign/evaluation.h"
#include "harness/campaign/explorer.h"
#include "harness/pool/worker_pool.h"
#include "harness/spec/spec.h"
#include "stack/base/env.h"
#include "stack/base/status.h"

namespace adse::campaign {

struct CampaignOptions {
  // Campaign folder; empty: the scenario's output.
  std::string output_dir;
  // Overrides of the scenario's exploration settings (empty / < 0: keep).
  std::string strategy;
  int budget = -1;
  int confirm_runs = -1;
  // Overrides of the scenario's harness settings (empty / < 0: keep).
  std::string isolation;
  int workers = -1;
  // Read and fill the shared evaluation cache.
  bool use_cache = true;
  // Cache folder; empty: harness.cache_dir, else <user cache>/runs.
  std::string cache_dir;
  // Run again points whose runs failed for good in an earlier session.
  bool retry_failed = false;
  // The worker command line before its arguments; empty: this executable
  // with "worker". Tests substitute wrappers that misbehave on purpose.
  std::vector<std::string> worker_command;
  // Pool settings not in the scenario (tests point cgroup_root elsewhere).
  pool::PoolOptions pool;
  // Progress events (may be null).
  ExplorerListener* listener = nullptr;
  // Told each failed attempt as it happens: (row so far, attempt, detail).
  std::function<void(const EvalRequest&, int attempt, const std::string&)>
      on_attempt_failed;
  // Told once the pool is up: its slots, how workers are confined, and why
  // auto fell back to affinity (empty when it did not).
  std::function<void(int workers, const std::string& isolation,
                     const std::string& fallback)>
      on_pool_ready;
  // Makes the pool runs go to, from the spec with the overrides above
  // applied; empty: the local pool (harness.workers, isolation). adse run
  // --executor slurm passes harness/slurm's job-step pool.
  std::function<Result<std::unique_ptr<pool::WorkerPool>>(const spec::Spec&)>
      make_pool;
  // A signal (e.g. SIGUSR1) asking for a graceful stop: propose nothing
  // more, let running runs finish for up to drain_grace_s, then stop as
  // after Ctrl-C. 0: none.
  int drain_signal = 0;
  double drain_grace_s = 0.0;
  // Everything the coordinator writes (views, failure records, derived
  // reports, pictures, cache copies) goes through it; tests inject faults.
  // Worker processes write their run files through the real filesystem.
  Env* env = Env::Default();
};

struct CampaignSummary {
  std::string output_dir;
  std::string strategy;
  std::string isolation;       // how workers were confined
  std::string isolation_note;  // why auto fell back, if it did
  int workers = 0;
  ExplorationResult exploration;
  std::vector<int> pareto_front;  // indices into exploration.evaluations
  int simulated = 0, reused = 0, failed = 0;
  double wall_s = 0.0;
  // The signal that stopped the campaign early, or 0.
  int interrupted_by = 0;
  // Points planned but without a result (a static sweep whose array tasks
  // have not all finished); 0 for a campaign run by adse run.
  int unfinished = 0;
  // Set while the campaign runs, for the views written on the way (they are
  // not the answer yet): the points proposed and not yet evaluated.
  bool in_progress = false;
  std::vector<spec::DesignPoint> running;
  // Why the campaign stopped with no answer (its first run refused as bad
  // input), or empty.
  std::string stopped_because;
  // An analysis of a campaign folder without summary.json: whether the
  // campaign finished is not recorded.
  bool finished_unknown = false;
  // Said in the report and summary.json (an analysis' unreadable runs).
  std::vector<std::string> notes;
};

// Runs (or resumes) the campaign of `spec`. Errors: InvalidArgument for
// bad options, Unavailable when the folder is locked by another run or
// `isolation: cgroup` cannot be had, IoError when the folder cannot be
// written. Failed runs do not make it fail: they are in the summary.
Result<CampaignSummary> RunCampaign(const spec::Spec& spec,
                                    const CampaignOptions& options);

// Evaluates a fixed list of points (each request's index and iteration are
// kept) like a campaign does — from the folder, the shared cache, or the
// pool, with retries and failure records — but without a strategy, lock or
// views: a shard of a static sweep, where array tasks share the folder.
// Rows come back by index; points an interrupt or drain left unevaluated
// have none (summary.interrupted_by says why).
Result<CampaignSummary> EvaluatePoints(const spec::Spec& spec,
                                       const std::vector<EvalRequest>& points,
                                       const CampaignOptions& options);

// The row of a point whose run (or failure record, unless retry_failed) is
// already in `folder`, found by content key; nullopt when there is none.
std::optional<EvaluationRow> RecordedRow(const spec::Spec& spec,
                                         const std::string& folder,
                                         const EvalRequest& request,
                                         bool retry_failed = false);

// Rebuilds campaign.h5, report.md, summary.json and pareto.png from an
// exploration's rows (also done by RunCampaign as it goes).
Status WriteCampaignViews(const spec::Spec& spec,
                          const CampaignSummary& summary,
                          Env* env = Env::Default());

// The views that answer the question (summary.json, report.md, pareto.png),
// led by the headline (harness/campaign/headline.h), written into `dir`;
// `image_dir` is where the rows' trajectory pictures are, relative to
// `dir`. WriteCampaignViews writes them into the campaign folder; adse
// analyze into an analysis version.
Status WriteAnswerViews(const spec::Spec& spec, const CampaignSummary& summary,
                        const std::string& dir, const std::string& image_dir,
                        Env* env = Env::Default());

// Adds up how the summary's evaluations were got: failed, and simulated by
// the campaign or reused (from its folder or the shared cache), as every
// command that reports a campaign counts them.
void CountSources(CampaignSummary* summary);

}  // namespace adse::campaign

#endif  // ADSE_HARNESS_CAMPAIGN_CAMPAIGN_H_
