#include "harness/slurm/sweep.h"

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>

#include <fmt/format.h>

#include "harness/campaign/campaign.h"
#include "harness/campaign/replicas.h"
#include "harness/campaign/run_store.h"
#include "harness/sim/run_key.h"
#include "harness/slurm/allocation.h"
#include "harness/slurm/records.h"
#include "harness/slurm/step_pool.h"
#include "harness/spec/spec_parser.h"

namespace adse::slurm {
namespace fs = std::filesystem;

namespace {

struct LoadedPlan {
  SweepPlan plan;
  spec::Spec spec;
  std::vector<campaign::EvalRequest> requests;  // all points, plan order
};

// The plan and its scenario, checked to still give the planned keys (of
// the points in [begin, end), or of all).
Result<LoadedPlan> LoadPlan(const std::string& campaign_dir, size_t begin,
                            size_t end) {
  Result<SweepPlan> plan = ReadSweepPlan(campaign_dir);
  if (!plan.ok()) {
    if (plan.status().code() == Status::Code::kNotFound) {
      return Status::InvalidArgument(
          plan.status().message() +
          ": adse shard and adse index work on a sweep submitted with adse "
          "submit");
    }
    return plan.status();
  }
  Result<spec::Spec> spec = spec::LoadSpec(plan->scenario);
  if (!spec.ok()) return spec.status();
  // The plan's strategy and budget, which adse submit may have overridden.
  spec->exploration.strategy = plan->strategy;
  spec->exploration.budget = plan->budget;
  LoadedPlan loaded{*plan, *spec, {}};
  end = std::min(end, plan->points.size());
  for (size_t i = 0; i < plan->points.size(); ++i) {
    const PlannedPoint& p = plan->points[i];
    Result<spec::DesignPoint> point =
        spec::ParsePoint(spec->design_space, p.point);
    if (!point.ok()) {
      return Status::InvalidArgument(fmt::format(
          "{} no longer has the planned point {}: {}; restore it, or submit "
          "the campaign again to another folder",
          plan->scenario, p.point, point.status().message()));
    }
    if (i >= begin && i < end) {
      Result<std::vector<std::string>> keys = sim::PointRunKeys(*spec, *point);
      if (!keys.ok()) return keys.status();
      if (*keys != p.replica_keys) {
        return Status::InvalidArgument(fmt::format(
            "{} changed since adse submit planned the sweep (point {}: "
            "content key {} and {} replica(s) planned, {} and {} now); "
            "restore it, or submit the campaign again to another folder",
            plan->scenario, p.point, p.key.substr(0, 12), p.replica_keys.size(),
            keys->front().substr(0, 12), keys->size()));
      }
    }
    loaded.requests.push_back(
        {p.index, static_cast<int64_t>(i) / plan->shard_size, *point});
  }
  return loaded;
}

}  // namespace

Result<ShardSummary> RunShard(const ShardOptions& options) {
  Result<SweepPlan> peek = ReadSweepPlan(options.campaign_dir);
  int task = options.task;
  if (task < 0) {
    const char* id = std::getenv("SLURM_ARRAY_TASK_ID");
    if (id == nullptr || *id == '\0') {
      return Status::InvalidArgument(
          "--task: no task given and SLURM_ARRAY_TASK_ID is not set (adse "
          "shard runs as a task of the array adse submit made, or with "
          "--task N)");
    }
    task = std::atoi(id);
  }
  const int shards = peek.ok() ? peek->shards() : 0;
  if (peek.ok() && (task < 0 || task >= shards)) {
    return Status::InvalidArgument(
        fmt::format("--task: expected a shard of {} (0 to {}), found {}",
                    options.campaign_dir, shards - 1, task));
  }
  const auto [begin, end] =
      peek.ok() ? peek->ShardRange(task) : std::pair<size_t, size_t>{0, 0};
  Result<LoadedPlan> loaded = LoadPlan(options.campaign_dir, begin, end);
  if (!loaded.ok()) return loaded.status();
  if (!options.local) {
    Result<std::optional<Allocation>> allocation = CurrentAllocation();
    if (!allocation.ok()) return allocation.status();
    if (!allocation->has_value()) {
      return Status::InvalidArgument(
          "adse shard runs its points as Slurm job steps and needs an "
          "allocation (it is what the job array's tasks run), but "
          "SLURM_JOB_ID is not set: use --local to run the shard's points "
          "in worker processes here");
    }
  }

  ShardSummary summary;
  summary.task = task;
  summary.shards = shards;
  summary.scenario_name = loaded->spec.name;
  summary.points.assign(loaded->requests.begin() + begin,
                        loaded->requests.begin() + end);

  spec::Spec spec = loaded->spec;
  campaign::CampaignOptions o;
  o.output_dir = options.campaign_dir;
  o.strategy = loaded->plan.strategy;
  o.use_cache = loaded->plan.use_cache;
  o.cache_dir = loaded->plan.cache_dir;
  o.listener = options.listener;
  o.on_attempt_failed = options.on_attempt_failed;
  o.on_pool_ready = options.on_pool_ready;
  o.worker_command = options.worker_command;
  if (options.local) {
    spec.harness.executor = "local";
  } else {
    spec.harness.executor = "slurm";
    o.make_pool = CreateAllocationPool;
    o.drain_signal = SIGUSR1;
    o.drain_grace_s = std::max(0, spec.harness.slurm.signal_lead_s - 30);
  }
  Result<campaign::CampaignSummary> done =
      campaign::EvaluatePoints(spec, summary.points, o);
  if (!done.ok()) return done.status();
  summary.campaign = *done;
  std::map<std::string, ShardResult> results;
  for (const campaign::EvaluationRow& row : done->exploration.evaluations) {
    // One entry per run: a point with replicas has several.
    for (const campaign::EvaluationRow& run :
         row.replicas.empty() ? std::vector<campaign::EvaluationRow>{row}
                              : row.replicas) {
      results[run.content_key] = {run.source, static_cast<int>(run.attempts),
                                  run.wall_s};
    }
  }
  if (Status s = WriteShardResults(options.campaign_dir, task, results);
      !s.ok()) {
    // Only the index's sources and wall times depend on it.
    std::fprintf(stderr, "warning: %s\n", s.message().c_str());
  }
  return summary;
}

Result<campaign::CampaignSummary> BuildSweepIndex(
    const std::string& campaign_dir, spec::Spec* spec_out) {
  Result<LoadedPlan> loaded = LoadPlan(campaign_dir, 0, SIZE_MAX);
  if (!loaded.ok()) return loaded.status();
  const SweepPlan& plan = loaded->plan;
  const spec::Spec& spec = loaded->spec;
  Result<campaign::CampaignLock> lock =
      campaign::CampaignLock::Acquire(campaign_dir);
  if (!lock.ok()) return lock.status();

  campaign::CampaignSummary summary;
  summary.output_dir = campaign_dir;
  summary.strategy = plan.strategy;
  summary.workers = plan.steps_per_task;
  summary.isolation = fmt::format(
      "Slurm job array of {} task(s) of {} point(s), each running its points "
      "as job steps (srun --exact -n1 -c{} --mem={}M), {} at once",
      plan.shards(), plan.shard_size, spec.harness.cores_per_worker,
      spec.harness.memory_mb, plan.steps_per_task);
  std::map<int, std::map<std::string, ShardResult>> shard_results;
  std::vector<std::string> missing;
  for (int shard = 0; shard < plan.shards(); ++shard) {
    shard_results[shard] = ReadShardResults(campaign_dir, shard);
    const auto [begin, end] = plan.ShardRange(shard);
    runfile::IterationRow it;
    it.iteration = shard;
    it.strategy = plan.strategy;
    it.rationale = fmt::format(
        "array task {}: points {} to {} of the {} planned by {} (seed {})",
        shard, begin, end - 1, plan.points.size(), plan.strategy, plan.seed);
    for (size_t i = begin; i < end; ++i) {
      const campaign::EvalRequest& request = loaded->requests[i];
      std::optional<campaign::EvaluationRow> row =
          campaign::RecordedRow(spec, campaign_dir, request);
      if (!row) {
        missing.push_back(plan.points[i].point);
        continue;
      }
      // Each run as its shard recorded it; a point of several runs is
      // aggregated again from its runs so recorded.
      auto as_recorded = [&](campaign::EvaluationRow* run) {
        run->source = "campaign";
        auto known = shard_results[shard].find(run->content_key);
        if (known != shard_results[shard].end()) {
          run->source = known->second.source;
          run->attempts = known->second.attempts;
          run->wall_s = known->second.wall_s;
        }
      };
      if (row->replicas.empty()) {
        as_recorded(&*row);
      } else {
        std::vector<campaign::EvaluationRow> runs = std::move(row->replicas);
        for (campaign::EvaluationRow& run : runs) as_recorded(&run);
        row = campaign::AggregatePoint(spec, std::move(runs));
      }
      it.content_keys.push_back(row->content_key);
      summary.exploration.evaluations.push_back(*row);
    }
    summary.exploration.iterations.push_back(it);
  }
  summary.unfinished = static_cast<int>(missing.size());
  // The sweep's span: from the earliest run's start (its file's time less
  // its wall time) to the last run file; tasks keep no clock of their own.
  double first_start = 0, last_end = 0;
  bool any = false;
  for (const campaign::EvaluationRow& row : summary.exploration.evaluations) {
    std::error_code ec;
    const std::string path =
        campaign::CampaignFolder(campaign_dir).RunPath(row.content_key);
    const auto written = fs::last_write_time(path, ec);
    if (ec) continue;
    const double end =
        std::chrono::duration<double>(written.time_since_epoch()).count();
    first_start =
        any ? std::min(first_start, end - row.wall_s) : end - row.wall_s;
    last_end = any ? std::max(last_end, end) : end;
    any = true;
  }
  summary.wall_s = any ? last_end - first_start : 0.0;
  campaign::CountSources(&summary);
  summary.pareto_front =
      campaign::ParetoFrontOf(spec, summary.exploration.evaluations);
  ADSE_RETURN_IF_ERROR(campaign::WriteCampaignViews(spec, summary));
  if (spec_out != nullptr) *spec_out = spec;
  return summary;
}

}  // namespace adse::slurm
