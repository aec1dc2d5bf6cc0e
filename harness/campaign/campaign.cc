#include "harness/campaign/campaign.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "harness/campaign/pool_evaluator.h"
#include "harness/campaign/run_store.h"
#include "harness/campaign/strategy_factory.h"
#include "harness/pool/worker_pool.h"
#include "harness/spec/design_point.h"
#include "stack/base/files.h"
#include "stack/base/subprocess.h"

namespace adse::campaign {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

// Keeps the folder's views fresh while the campaign runs and forwards
// events. They are written on every proposal, so that `adse status` sees
// what runs while the pool is busy, and after a result at most every few
// seconds; the views are rebuilt in full at the end.
class ViewRefresher : public ExplorerListener {
 public:
  ViewRefresher(const spec::Spec& spec, CampaignSummary* summary,
                ExplorerListener* next, Env* env)
      : spec_(spec), summary_(summary), next_(next), env_(env) {
    summary_->in_progress = true;
  }
  ~ViewRefresher() override {
    summary_->in_progress = false;
    summary_->running.clear();
  }

  void OnProposed(const runfile::IterationRow& iteration,
                  const std::vector<spec::DesignPoint>& points,
                  bool fell_back) override {
    summary_->exploration.iterations.push_back(iteration);
    summary_->running.insert(summary_->running.end(), points.begin(),
                             points.end());
    Write();
    if (next_ != nullptr) next_->OnProposed(iteration, points, fell_back);
  }
  void OnEvaluated(const EvaluationRow& row) override {
    summary_->exploration.evaluations.push_back(row);
    std::vector<spec::DesignPoint>& running = summary_->running;
    auto it = std::find(running.begin(), running.end(), row.point);
    if (it != running.end()) running.erase(it);
    if (Clock::now() - last_write_ > std::chrono::seconds(3)) Write();
    if (next_ != nullptr) next_->OnEvaluated(row);
  }

 private:
  void Write() {
    last_write_ = Clock::now();
    // The runs are safe in runs/; the views are rebuilt at the end, where
    // a failure that lasts is an error. Say it now all the same.
    if (Status s = WriteCampaignViews(spec_, *summary_, env_); !s.ok()) {
      std::fprintf(stderr, "warning: the campaign views are stale: %s\n",
                   s.message().c_str());
    }
  }

  const spec::Spec& spec_;
  CampaignSummary* summary_;
  ExplorerListener* next_;
  Env* env_;
  Clock::time_point last_write_ = Clock::now();
};

}  // namespace

namespace {

// The spec with the options' overrides applied, or why it cannot run.
Result<spec::Spec> Overridden(const spec::Spec& input,
                              const CampaignOptions& options) {
  spec::Spec spec = input;
  if (!options.strategy.empty()) spec.exploration.strategy = options.strategy;
  if (options.budget >= 0) spec.exploration.budget = options.budget;
  if (options.confirm_runs >= 0) {
    spec.exploration.confirm_runs = options.confirm_runs;
  }
  ADSE_RETURN_IF_ERROR(spec::CheckConfirmRuns(spec));
  if (!options.isolation.empty()) spec.harness.isolation = options.isolation;
  if (options.workers >= 0) spec.harness.workers = options.workers;

  if (spec.harness.executor != "local" && !options.make_pool) {
    return Status::InvalidArgument(
        spec.Where("harness.executor") + "harness.executor: '" +
        spec.harness.executor +
        "' runs need a pool for it: adse run --executor slurm inside a Slurm "
        "allocation, or adse submit");
  }
  if (!options.make_pool) {
    // Said of the flag or field that asked, before anything is written.
    std::string asked = spec.Where("harness.workers") + "harness.workers";
    if (spec.harness.workers == 0) {  // auto: as many as its width allows
      asked =
          spec.Where("harness.cores_per_worker") + "harness.cores_per_worker";
    } else if (options.workers > 0) {
      asked = fmt::format("--workers {}", options.workers);
    }
    ADSE_RETURN_IF_ERROR(pool::CheckWorkersFit(spec.harness.workers,
                                               spec.harness.cores_per_worker)
                             .WithContext(asked));
  }
  return spec;
}

// The pool the campaign's runs go to; fills the summary's pool fields.
Result<std::unique_ptr<pool::WorkerPool>> MakePool(
    const spec::Spec& spec, const CampaignOptions& options,
    CampaignSummary* summary) {
  Result<std::unique_ptr<pool::WorkerPool>> pool =
      Status::Internal("no pool made");
  if (options.make_pool) {
    pool = options.make_pool(spec);
  } else {
    Result<pool::Isolation> isolation =
        pool::ParseIsolation(spec.harness.isolation);
    if (!isolation.ok()) return isolation.status();
    pool::PoolOptions pool_options = options.pool;
    pool_options.workers = spec.harness.workers;
    pool_options.cores_per_worker = spec.harness.cores_per_worker;
    pool_options.memory_mb = spec.harness.memory_mb;
    pool_options.isolation = *isolation;
    pool = pool::WorkerPool::Create(pool_options);
  }
  if (!pool.ok()) return pool.status();
  summary->isolation = (*pool)->isolation_description();
  summary->isolation_note = (*pool)->fallback_reason();
  summary->workers = (*pool)->slots();
  if (options.on_pool_ready) {
    options.on_pool_ready(summary->workers, summary->isolation,
                          summary->isolation_note);
  }
  pool::InstallInterruptHandlers();
  if (options.drain_signal != 0) {
    pool::InstallDrainHandler(options.drain_signal);
  }
  return pool;
}

Status OpenCache(const spec::Spec& spec, const CampaignOptions& options,
                 std::optional<RunCache>* cache) {
  if (!options.use_cache) return Status::Ok();
  std::string dir = options.cache_dir;
  if (dir.empty()) dir = spec.harness.cache_dir;
  if (dir.empty()) dir = DefaultCacheDir() + "/runs";
  ADSE_RETURN_IF_ERROR(MakeDirs(dir, options.env));
  cache->emplace(dir, options.env);
  return Status::Ok();
}

PoolEvaluatorOptions EvaluatorOptions(const spec::Spec& spec,
                                      const CampaignOptions& options,
                                      const std::optional<RunCache>& cache) {
  PoolEvaluatorOptions evaluator_options;
  evaluator_options.worker_command = options.worker_command;
  if (evaluator_options.worker_command.empty()) {
    // Local workers run the coordinator's own executable, through the
    // link the kernel keeps to it: rebuilding adse during a campaign
    // replaces the file, and each job started while the linker wrote it
    // failed ("Permission denied"), or would run another adse than the
    // campaign's. Steps on a Slurm allocation may run on other nodes:
    // they get the path.
    evaluator_options.worker_command = {
        options.make_pool ? SelfExecutable()
                          : fmt::format("/proc/{}/exe", ::getpid()),
        "worker"};
  }
  std::error_code ec;
  evaluator_options.scenario_path =
      fs::absolute(spec.source_path, ec).lexically_normal().string();
  evaluator_options.retries = spec.harness.retries;
  evaluator_options.run_timeout_s = spec.harness.run_timeout_s;
  evaluator_options.memory_mb = spec.harness.memory_mb;
  evaluator_options.retry_failed = options.retry_failed;
  evaluator_options.cache = cache ? &*cache : nullptr;
  evaluator_options.on_attempt_failed = options.on_attempt_failed;
  evaluator_options.drain_grace_s = options.drain_grace_s;
  return evaluator_options;
}

// The signal that stopped a session early: an interrupt, else a drain.
int StopSignal() {
  const int interrupt = pool::InterruptRequested();
  return interrupt != 0 ? interrupt : pool::DrainRequested();
}

// Why a campaign stops when its first run was refused as bad input
// (PoolEvaluator::refused), or nullopt; runs that landed meanwhile stay in
// runs/.
std::optional<std::string> RefusalReason(PoolEvaluator& evaluator) {
  if (!evaluator.refused()) return std::nullopt;
  evaluator.Cancel();
  return fmt::format(
      "its first run was refused as bad input, as every run would be: {}",
      *evaluator.refused());
}

Status Refusal(PoolEvaluator& evaluator) {
  std::optional<std::string> reason = RefusalReason(evaluator);
  if (!reason) return Status::Ok();
  return Status::InvalidArgument("the campaign stopped: " + *reason);
}

// The views of a folder that hold another scenario's campaign, or more
// evaluations than this campaign's budget, are about to become this
// campaign's; say so. The runs stay (content keys never collide).
void WarnOfViewsReplaced(const spec::Spec& spec, const CampaignFolder& folder) {
  Result<std::string> text = ReadFile(folder.Path("summary.json"));
  if (!text.ok()) return;
  const nlohmann::json j = nlohmann::json::parse(*text, nullptr, false);
  if (!j.is_object() || !j.contains("scenario") || !j["scenario"].is_string()) {
    return;
  }
  const std::string other = j["scenario"];
  const std::string views =
      "report.md, summary.json, campaign.h5 and pareto.png";
  if (other != spec.name) {
    std::fprintf(stderr,
                 "warning: %s holds the campaign of another scenario, '%s' "
                 "(%s); its runs stay in runs/, but %s become those of "
                 "'%s'\n",
                 folder.root().c_str(), other.c_str(),
                 j.value("scenario_file", std::string("?")).c_str(),
                 views.c_str(), spec.name.c_str());
    return;
  }
  const size_t before = j.contains("evaluations") && j["evaluations"].is_array()
                            ? j["evaluations"].size()
                            : 0;
  // The confirm phase's runs come on top of the budget.
  const int64_t most =
      static_cast<int64_t>(std::max(0, spec.exploration.budget)) +
      std::max(0, spec.exploration.confirm_runs);
  if (static_cast<int64_t>(before) > most) {
    const std::string limit =
        spec.exploration.confirm_runs > 0
            ? fmt::format("budget of {} and {} confirm runs",
                          spec.exploration.budget,
                          spec.exploration.confirm_runs)
            : fmt::format("budget of {}", spec.exploration.budget);
    std::fprintf(stderr,
                 "warning: %s holds %zu evaluations, more than this "
                 "campaign's %s; their runs stay in runs/, but %s become "
                 "those of this campaign's %lld at most\n",
                 folder.root().c_str(), before, limit.c_str(), views.c_str(),
                 static_cast<long long>(most));
  }
}

}  // namespace

void CountSources(CampaignSummary* summary) {
  for (const EvaluationRow& row : summary->exploration.evaluations) {
    if (!row.complete()) ++summary->failed;
    if (row.source == "simulated") {
      ++summary->simulated;
    } else {
      ++summary->reused;
    }
  }
}

Result<CampaignSummary> RunCampaign(const spec::Spec& input,
                                    const CampaignOptions& options) {
  const auto started = Clock::now();
  Result<spec::Spec> overridden = Overridden(input, options);
  if (!overridden.ok()) return overridden.status();
  const spec::Spec& spec = *overridden;
  ADSE_RETURN_IF_ERROR(CheckStrategyName(spec.exploration.strategy));
  if (!options.make_pool) {
    Result<pool::Isolation> isolation =
        pool::ParseIsolation(spec.harness.isolation);
    if (!isolation.ok()) return isolation.status();
  }

  CampaignSummary summary;
  summary.output_dir =
      options.output_dir.empty() ? spec.ResolvedOutput() : options.output_dir;
  summary.strategy = spec.exploration.strategy;
  const CampaignFolder folder(summary.output_dir, options.env);
  ADSE_RETURN_IF_ERROR(folder.Create());
  Result<CampaignLock> lock = CampaignLock::Acquire(folder.root());
  if (!lock.ok()) return lock.status();
  WarnOfViewsReplaced(spec, folder);
  // Created under the lock: the llm strategy records into the folder.
  Result<std::unique_ptr<explore::Strategy>> strategy =
      CreateCampaignStrategy(spec, folder.root(), /*record=*/true, options.env);
  if (!strategy.ok()) return strategy.status();

  Result<std::unique_ptr<pool::WorkerPool>> pool =
      MakePool(spec, options, &summary);
  if (!pool.ok()) return pool.status();
  std::optional<RunCache> cache;
  ADSE_RETURN_IF_ERROR(OpenCache(spec, options, &cache));
  PoolEvaluator evaluator(spec, folder, pool->get(),
                          EvaluatorOptions(spec, options, cache));

  ExplorationResult result;
  {
    ViewRefresher refresher(spec, &summary, options.listener, options.env);
    result = Explore(spec, **strategy, evaluator, &refresher);
  }
  if (std::optional<std::string> refused = RefusalReason(evaluator)) {
    // The views written on the way said it was running; now they say why
    // it stopped, with no answer.
    summary.exploration = std::move(result);
    summary.stopped_because = *refused;
    if (Status s = WriteCampaignViews(spec, summary, options.env); !s.ok()) {
      std::fprintf(stderr, "warning: the campaign views are stale: %s\n",
                   s.message().c_str());
    }
    return Status::InvalidArgument("the campaign stopped: " + *refused);
  }
  if (result.interrupted) {
    summary.interrupted_by = StopSignal();
    for (EvaluationRow& row : evaluator.Cancel()) {
      result.evaluations.push_back(std::move(row));
    }
    std::sort(result.evaluations.begin(), result.evaluations.end(),
              [](const EvaluationRow& a, const EvaluationRow& b) {
                return a.index < b.index;
              });
    // A drain that came after the last proposal stopped nothing.
    const uint64_t planned = std::min<uint64_t>(
        static_cast<uint64_t>(std::max(0, spec.exploration.budget)),
        spec.design_space.Size());
    if (pool::InterruptRequested() == 0 && !result.confirm_cut &&
        result.evaluations.size() >= planned) {
      summary.interrupted_by = 0;
    }
  }
  summary.exploration = std::move(result);
  CountSources(&summary);
  summary.pareto_front = ParetoFrontOf(spec, summary.exploration.evaluations);
  summary.wall_s =
      std::chrono::duration<double>(Clock::now() - started).count();
  ADSE_RETURN_IF_ERROR(WriteCampaignViews(spec, summary, options.env));
  if (Status failed = (*strategy)->failure(); !failed.ok()) {
    return failed.WithContext(
        fmt::format("the {} strategy cannot go on ({} evaluations kept in {})",
                    summary.strategy, summary.exploration.evaluations.size(),
                    summary.output_dir));
  }
  return summary;
}

Result<CampaignSummary> EvaluatePoints(const spec::Spec& input,
                                       const std::vector<EvalRequest>& points,
                                       const CampaignOptions& options) {
  const auto started = Clock::now();
  Result<spec::Spec> overridden = Overridden(input, options);
  if (!overridden.ok()) return overridden.status();
  const spec::Spec& spec = *overridden;

  CampaignSummary summary;
  summary.output_dir =
      options.output_dir.empty() ? spec.ResolvedOutput() : options.output_dir;
  summary.strategy = spec.exploration.strategy;
  const CampaignFolder folder(summary.output_dir, options.env);
  ADSE_RETURN_IF_ERROR(folder.Create());
  Result<std::unique_ptr<pool::WorkerPool>> pool =
      MakePool(spec, options, &summary);
  if (!pool.ok()) return pool.status();
  std::optional<RunCache> cache;
  ADSE_RETURN_IF_ERROR(OpenCache(spec, options, &cache));
  PoolEvaluator evaluator(spec, folder, pool->get(),
                          EvaluatorOptions(spec, options, cache));

  std::vector<EvaluationRow>& rows = summary.exploration.evaluations;
  auto take = [&](std::vector<EvaluationRow> done) {
    for (EvaluationRow& row : done) {
      if (options.listener != nullptr) options.listener->OnEvaluated(row);
      rows.push_back(std::move(row));
    }
  };
  // Start them all: the evaluator queues what the pool cannot take yet.
  for (const EvalRequest& request : points) {
    if (evaluator.interrupted()) break;
    evaluator.Start(request);
  }
  while (evaluator.outstanding() > 0) {
    std::vector<EvaluationRow> done = evaluator.Wait();
    if (done.empty() && evaluator.interrupted()) break;
    take(std::move(done));
  }
  ADSE_RETURN_IF_ERROR(Refusal(evaluator));
  if (evaluator.interrupted()) {
    take(evaluator.Cancel());
    if (rows.size() < points.size()) summary.interrupted_by = StopSignal();
  }
  std::sort(rows.begin(), rows.end(),
            [](const EvaluationRow& a, const EvaluationRow& b) {
              return a.index < b.index;
            });
  CountSources(&summary);
  summary.wall_s =
      std::chrono::duration<double>(Clock::now() - started).count();
  return summary;
}

std::optional<EvaluationRow> RecordedRow(const spec::Spec& spec,
                                         const std::string& folder,
                                         const EvalRequest& request,
                                         bool retry_failed) {
  const CampaignFolder campaign_folder(folder);
  PoolEvaluatorOptions options;
  options.retry_failed = retry_failed;
  // No pool: Recorded only looks at the folder.
  PoolEvaluator evaluator(spec, campaign_folder, nullptr, options);
  return evaluator.Recorded(request);
}

}  // namespace adse::campaign
