#include "harness/campaign/campaign.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <thread>

#include <fmt/format.h>

#include "harness/campaign/pool_evaluator.h"
#include "harness/campaign/run_store.h"
#include "harness/campaign/strategy_factory.h"
#include "stack/base/files.h"

namespace adse::campaign {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

// The running executable, for the default worker command.
std::string SelfExecutable() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("adse") : self.string();
}

// Keeps the folder's views fresh while the campaign runs (at most every
// few seconds; they are rebuilt in full at the end) and forwards events.
class ViewRefresher : public ExplorerListener {
 public:
  ViewRefresher(const spec::Spec& spec, CampaignSummary* summary,
                ExplorerListener* next)
      : spec_(spec), summary_(summary), next_(next) {}

  void OnProposed(const explore::Strategy& strategy,
                  const runfile::IterationRow& iteration,
                  const std::vector<spec::DesignPoint>& points) override {
    summary_->exploration.iterations.push_back(iteration);
    if (next_ != nullptr) next_->OnProposed(strategy, iteration, points);
  }
  void OnEvaluated(const EvaluationRow& row) override {
    summary_->exploration.evaluations.push_back(row);
    if (next_ != nullptr) next_->OnEvaluated(row);
    const auto now = Clock::now();
    if (now - last_write_ > std::chrono::seconds(3)) {
      last_write_ = now;
      // Views are conveniences; a failure here is reported at the end.
      (void)WriteCampaignViews(spec_, *summary_);
    }
  }

 private:
  const spec::Spec& spec_;
  CampaignSummary* summary_;
  ExplorerListener* next_;
  Clock::time_point last_write_ = Clock::now();
};

}  // namespace

Result<CampaignSummary> RunCampaign(const spec::Spec& input,
                                    const CampaignOptions& options) {
  const auto started = Clock::now();
  spec::Spec spec = input;
  if (!options.strategy.empty()) spec.exploration.strategy = options.strategy;
  if (options.budget >= 0) spec.exploration.budget = options.budget;
  if (!options.isolation.empty()) spec.harness.isolation = options.isolation;
  if (options.workers >= 0) spec.harness.workers = options.workers;

  if (spec.harness.replicas != 1) {
    // Not silently ignored: one run per point is all adse run does yet.
    return Status::InvalidArgument(
        spec.Where("harness.replicas") +
        "harness.replicas: adse run evaluates each point once; expected 1, "
        "found " +
        std::to_string(spec.harness.replicas));
  }
  if (spec.harness.executor != "local") {
    return Status::InvalidArgument(
        spec.Where("harness.executor") +
        "harness.executor: only 'local' is implemented; found '" +
        spec.harness.executor + "'");
  }
  ADSE_RETURN_IF_ERROR(CheckStrategyName(spec.exploration.strategy));
  Result<pool::Isolation> isolation =
      pool::ParseIsolation(spec.harness.isolation);
  if (!isolation.ok()) return isolation.status();

  CampaignSummary summary;
  summary.output_dir =
      options.output_dir.empty() ? spec.ResolvedOutput() : options.output_dir;
  summary.strategy = spec.exploration.strategy;
  const CampaignFolder folder(summary.output_dir);
  ADSE_RETURN_IF_ERROR(folder.Create());
  Result<CampaignLock> lock = CampaignLock::Acquire(folder.root());
  if (!lock.ok()) return lock.status();
  // Created under the lock: the llm strategy records into the folder.
  Result<std::unique_ptr<explore::Strategy>> strategy =
      CreateCampaignStrategy(spec, folder.root(), /*record=*/true);
  if (!strategy.ok()) return strategy.status();

  pool::PoolOptions pool_options = options.pool;
  pool_options.workers = spec.harness.workers;
  pool_options.cores_per_worker = spec.harness.cores_per_worker;
  pool_options.memory_mb = spec.harness.memory_mb;
  pool_options.isolation = *isolation;
  Result<std::unique_ptr<pool::WorkerPool>> pool =
      pool::WorkerPool::Create(pool_options);
  if (!pool.ok()) return pool.status();
  summary.isolation = (*pool)->isolation_description();
  summary.isolation_note = (*pool)->fallback_reason();
  summary.workers = (*pool)->slots();
  if (options.on_pool_ready) {
    options.on_pool_ready(summary.workers, summary.isolation,
                          summary.isolation_note);
  }
  pool::InstallInterruptHandlers();

  std::optional<RunCache> cache;
  if (options.use_cache) {
    std::string dir = options.cache_dir;
    if (dir.empty()) dir = spec.harness.cache_dir;
    if (dir.empty()) dir = DefaultCacheDir() + "/runs";
    ADSE_RETURN_IF_ERROR(MakeDirs(dir));
    cache.emplace(dir);
  }

  PoolEvaluatorOptions evaluator_options;
  evaluator_options.worker_command = options.worker_command;
  if (evaluator_options.worker_command.empty()) {
    evaluator_options.worker_command = {SelfExecutable(), "worker"};
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
  PoolEvaluator evaluator(spec, folder, pool->get(), evaluator_options);

  ViewRefresher refresher(spec, &summary, options.listener);
  ExplorationResult result = Explore(spec, **strategy, evaluator, &refresher);
  if (result.interrupted) {
    summary.interrupted_by = pool::InterruptRequested();
    for (EvaluationRow& row : evaluator.Cancel()) {
      result.evaluations.push_back(std::move(row));
    }
    std::sort(result.evaluations.begin(), result.evaluations.end(),
              [](const EvaluationRow& a, const EvaluationRow& b) {
                return a.index < b.index;
              });
  }
  summary.exploration = std::move(result);
  for (const EvaluationRow& row : summary.exploration.evaluations) {
    if (row.status != "complete") ++summary.failed;
    if (row.source == "simulated") {
      ++summary.simulated;
    } else {
      ++summary.reused;
    }
  }
  summary.pareto_front = ParetoFrontOf(spec, summary.exploration.evaluations);
  summary.wall_s =
      std::chrono::duration<double>(Clock::now() - started).count();
  ADSE_RETURN_IF_ERROR(WriteCampaignViews(spec, summary));
  if (Status failed = (*strategy)->failure(); !failed.ok()) {
    return failed.WithContext(fmt::format(
        "the {} strategy cannot go on ({} evaluations kept in {})", summary.strategy,
        summary.exploration.evaluations.size(), summary.output_dir));
  }
  return summary;
}

}  // namespace adse::campaign
