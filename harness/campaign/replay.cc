#include "harness/campaign/replay.h"

#include <algorithm>
#include <filesystem>
#include <limits>

#include <fmt/format.h>

#include "analysis/pareto/pareto.h"
#include "harness/campaign/headline.h"
#include "harness/campaign/strategy_factory.h"
#include "harness/spec/design_point.h"
#include "harness/spec/spec_parser.h"

namespace adse::campaign {
namespace fs = std::filesystem;

Status KeepObjectives(const std::vector<std::string>& metrics,
                      Recording* recording) {
  spec::Spec* spec = &recording->spec;
  std::vector<std::string> have;
  for (const spec::Objective& objective : spec->objectives) {
    have.push_back(objective.metric);
  }
  for (const std::string& metric : metrics) {
    if (std::find(have.begin(), have.end(), metric) == have.end()) {
      return Status::InvalidArgument(
          fmt::format("'{}' is not an objective of the recorded scenario "
                      "(its objectives: {})",
                      metric, fmt::join(have, ", ")));
    }
  }
  std::vector<spec::Objective> kept;
  for (const spec::Objective& objective : spec->objectives) {
    if (std::find(metrics.begin(), metrics.end(), objective.metric) !=
        metrics.end()) {
      kept.push_back(objective);
    }
  }
  if (kept.size() < 2) {
    return Status::InvalidArgument(
        "keep two objectives at least (a front of one objective is a "
        "single point)");
  }
  spec->objectives = std::move(kept);
  return Status::Ok();
}

Result<Recording> LoadRecording(const std::string& folder_or_file) {
  std::error_code ec;
  const std::string path = fs::is_directory(folder_or_file, ec)
                               ? folder_or_file + "/campaign.h5"
                               : folder_or_file;
  Result<runfile::CampaignIndex> index = ReadIndex(path);
  if (!index.ok()) return index.status();
  spec::ParseOptions parse;
  parse.check_files = false;  // only the space, objectives and constraints
  Result<spec::Spec> spec =
      spec::ParseSpec(index->scenario_text,
                      path + " (scenario stored in the index)", "", parse);
  if (!spec.ok()) return spec.status();
  Recording recording{std::move(spec).value(), std::move(index->evaluations),
                      fs::absolute(path, ec).parent_path().string()};
  if (recording.rows.empty()) {
    return Status::InvalidArgument(path + ": the campaign has no evaluations");
  }
  return recording;
}

RecordingEvaluator::RecordingEvaluator(const Recording* recording)
    : recording_(recording) {}

void RecordingEvaluator::Start(const EvalRequest& request) {
  for (const EvaluationRow& recorded : recording_->rows) {
    if (analysis::SameDesignPoint(recorded.point, request.point)) {
      EvaluationRow row = recorded;
      row.index = request.index;
      row.iteration = request.iteration;
      row.source = "recording";
      ready_.push_back(row);
      return;
    }
  }
  ++missing_;
  EvaluationRow row;
  row.index = request.index;
  row.iteration = request.iteration;
  row.point = request.point;
  row.status = runfile::kRunFailed;
  row.reason = "not recorded";
  row.source = "recording";
  row.bottlenecks_json = "[]";
  ready_.push_back(row);
}

std::vector<EvaluationRow> RecordingEvaluator::Wait() {
  std::vector<EvaluationRow> rows;
  rows.swap(ready_);
  return rows;
}

Result<ReplayRun> Replay(const Recording& recording, const std::string& name,
                         uint64_t seed, int budget, int confirm_runs,
                         int initial_points) {
  spec::Spec spec = recording.spec;
  spec.exploration.strategy = name;
  spec.exploration.seed = seed;
  if (budget > 0) spec.exploration.budget = budget;
  if (confirm_runs >= 0) spec.exploration.confirm_runs = confirm_runs;
  if (initial_points >= 0) spec.exploration.initial_points = initial_points;
  ADSE_RETURN_IF_ERROR(spec::CheckConfirmRuns(spec));
  Result<std::unique_ptr<explore::Strategy>> strategy =
      CreateCampaignStrategy(spec, recording.folder, /*record=*/false);
  if (!strategy.ok()) return strategy.status();
  RecordingEvaluator evaluator(&recording);
  const ExplorationResult result = Explore(spec, **strategy, evaluator);
  ADSE_RETURN_IF_ERROR((*strategy)->failure());

  std::vector<analysis::Evaluation> found, reference;
  for (const EvaluationRow& row : result.evaluations) {
    found.push_back(ParetoEvaluation(spec, row));
  }
  for (const EvaluationRow& row : recording.rows) {
    reference.push_back(ParetoEvaluation(spec, row));
  }
  const analysis::SearchQuality quality =
      analysis::CompareToReference(found, reference);

  ReplayRun run;
  run.strategy = name;
  run.seed = seed;
  run.evaluations = static_cast<int>(result.evaluations.size());
  run.confirm_evaluations = ConfirmEvaluations(result);
  run.missing = evaluator.missing();
  run.true_pareto_found = quality.true_pareto_points_found;
  run.front_size = quality.true_front_size;
  run.hypervolume_ratio = quality.hypervolume_ratio;
  // The evaluation at which the first true Pareto point arrived.
  const std::vector<int> true_front = ParetoFrontOf(spec, recording.rows);
  for (size_t i = 0; i < found.size() && run.first_true_pareto_at == 0; ++i) {
    for (int t : true_front) {
      if (reference[t].feasible &&
          analysis::SameDesignPoint(found[i].point, reference[t].point)) {
        run.first_true_pareto_at = static_cast<int>(i) + 1;
        break;
      }
    }
  }
  // Any feasible design at the cheapest feasible cost answers the user's
  // question: designs that tie in cost (a knob that changes nothing, 7 or
  // 14 Hz at one price) are equally cheap.
  const Headline answer = ComputeHeadline(spec, recording.rows);
  const double cheapest =
      answer.cheapest >= 0
          ? analysis::TieKey(
                RowMetric(recording.rows[answer.cheapest], "hardware_cost"))
          : std::numeric_limits<double>::quiet_NaN();
  for (const runfile::IterationRow& row : result.iterations) {
    ReplayIteration iteration;
    iteration.iteration = row.iteration;
    iteration.rationale = row.rationale;
    for (const EvaluationRow& evaluation : result.evaluations) {
      if (evaluation.iteration == row.iteration) {
        iteration.points.push_back(evaluation.point);
      }
    }
    run.iterations.push_back(std::move(iteration));
  }
  for (const EvaluationRow& row : result.evaluations) {
    run.proposals.push_back(row.point);
    run.found_cheapest_feasible =
        run.found_cheapest_feasible ||
        (row.complete() && row.feasible &&
         analysis::TieKey(RowMetric(row, "hardware_cost")) == cheapest);
  }
  if (run.found_cheapest_feasible) {
    const CheaperDesigns& left =
        ComputeHeadline(spec, result.evaluations).cheaper;
    if (left.counted) {
      run.cheaper_left_untried = left.untried_count;
      run.runs_to_settle = left.to_settle_count;
      run.cheapest_confirmed = left.untried_count == 0;
    }
  }
  return run;
}

}  // namespace adse::campaign
