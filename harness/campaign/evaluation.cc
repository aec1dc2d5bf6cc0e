#include "harness/campaign/evaluation.h"

#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>

namespace adse::campaign {

EvaluationRow RowFromReport(const report::RunReport& report) {
  EvaluationRow row;
  row.content_key = report.content_key;
  row.status = report.status == "complete" ? "complete" : "failed";
  row.reason = report.termination_reason;
  row.seed = report.seed;
  row.point = report.point;
  row.metrics = report.metrics;
  row.feasible = report.feasible;
  nlohmann::json bottlenecks = nlohmann::json::array();
  for (const report::FindingSummary& f : report.findings) {
    auto deficit = f.rates_hz.find("deficit");
    bottlenecks.push_back(
        {{"kind", f.kind},
         {"node", f.node},
         {"remedy", f.remedy},
         {"severity", deficit == f.rates_hz.end() ? 0.0 : deficit->second}});
  }
  row.bottlenecks_json = bottlenecks.dump();
  return row;
}

explore::Observation ObservationFromRow(const EvaluationRow& row) {
  explore::Observation o;
  o.point = row.point;
  o.failed = row.status != "complete";
  if (o.failed) return o;
  for (const auto& [name, value] : row.metrics) {
    if (!std::isnan(value)) o.metrics[name] = value;
  }
  o.feasible = row.feasible;
  // The diagnosis is advisory: a row whose JSON does not parse (written by
  // hand, or damaged) is simply told without it.
  const nlohmann::json j =
      nlohmann::json::parse(row.bottlenecks_json, nullptr, false);
  if (j.is_array()) {
    for (const nlohmann::json& b : j) {
      if (!b.is_object()) continue;
      explore::BottleneckHint hint;
      hint.kind = b.value("kind", "");
      hint.node = b.value("node", "");
      hint.remedy = b.value("remedy", "");
      hint.severity = b.value("severity", 0.0);
      o.bottlenecks.push_back(hint);
    }
  }
  return o;
}

analysis::Evaluation ParetoEvaluation(const spec::Spec& spec,
                                      const EvaluationRow& row) {
  const explore::Observation o = ObservationFromRow(row);
  analysis::Evaluation input;
  input.point = row.point;
  input.objectives = explore::MinimizationObjectives(spec, o);
  input.violation = explore::ConstraintViolation(spec, o);
  input.feasible = o.feasible && !o.failed;
  for (double& v : input.objectives) {
    // Unplaceable rows still take part, ranked behind every placed one.
    if (!std::isfinite(v)) {
      input.feasible = false;
      v = std::numeric_limits<double>::max();
    }
  }
  if (!std::isfinite(input.violation)) input.violation = 1e9;
  if (!input.feasible && input.violation == 0.0) input.violation = 1.0;
  return input;
}

std::vector<int> ParetoFrontOf(const spec::Spec& spec,
                               const std::vector<EvaluationRow>& rows) {
  std::vector<analysis::Evaluation> evals;
  for (const EvaluationRow& row : rows) {
    evals.push_back(ParetoEvaluation(spec, row));
  }
  return analysis::ParetoFront(evals);
}

}  // namespace adse::campaign
