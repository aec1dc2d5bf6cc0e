// The agent's rationale: what the last run showed and why the next point.
#include "harness/explore/internal/agent_strategy.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "harness/spec/spec_parser.h"

namespace adse::explore::internal {

std::string Num(double value) {
  if (!std::isfinite(value)) return std::isnan(value) ? "n/a" : "inf";
  return fmt::format("{:.3g}", value);
}

std::string AgentStrategy::Describe(const spec::DesignPoint& point) const {
  std::vector<std::string> parts;
  for (const Knob& knob : knobs_) {
    auto it = point.find(knob.parameter->name);
    if (it == point.end()) continue;
    if (knob.role == KnobRole::kCores) {
      parts.push_back(fmt::format("{:g} cores", it->second));
    } else if (knob.role == KnobRole::kFrequency) {
      parts.push_back(fmt::format("{:g} GHz", it->second));
    } else {
      parts.push_back(fmt::format("{} {:g}", knob.parameter->name, it->second));
    }
  }
  return fmt::format("{}", fmt::join(parts, ", "));
}

std::string AgentStrategy::LastText() const {
  if (records_.empty()) return {};
  const Record& last = records_.back();
  const std::string where = Describe(last.observation.point);
  if (last.failed) {
    return fmt::format(
        "Last ({}): the run failed; its neighbours are "
        "avoided.",
        where);
  }
  std::vector<std::string> values;
  for (const spec::Objective& objective : spec_->objectives) {
    auto it = last.observation.metrics.find(objective.metric);
    if (it != last.observation.metrics.end()) {
      values.push_back(fmt::format("{} {}", objective.metric, Num(it->second)));
    }
  }
  std::string status = "feasible";
  if (!last.feasible) {
    std::vector<std::string> violated;
    for (const std::string& constraint : spec_->constraints) {
      Result<bool> holds = spec::EvaluateConstraint(
          *spec_, constraint, last.observation.metrics, last.observation.point);
      if (!holds.ok() || !*holds) {
        std::string shown = constraint;
        for (const MetricModel& model : models_) {
          if (constraint.find(model.name) == std::string::npos) continue;
          auto it = last.observation.metrics.find(model.name);
          if (it != last.observation.metrics.end()) {
            shown = fmt::format("{} {} fails {}", model.name, Num(it->second),
                                constraint);
            break;
          }
        }
        violated.push_back(shown);
      }
    }
    status = violated.empty()
                 ? std::string("infeasible")
                 : fmt::format("infeasible ({})", fmt::join(violated, "; "));
    if (last.censored && std::isfinite(last.censored->driven_fraction)) {
      status += fmt::format(
          ", stopped {:.0f} % of the way: at its pace {} {} or more",
          100.0 * last.censored->driven_fraction, last.censored->metric,
          Num(last.censored->paced_bound));
    }
  }
  std::string diagnosis;
  RemedyDirections(last, &diagnosis);
  return fmt::format("Last ({}): {}, {}{}.", where, status,
                     fmt::join(values, ", "),
                     diagnosis.empty() ? "" : "; " + diagnosis);
}

std::string AgentStrategy::Predictions(const std::vector<double>& mean) const {
  std::vector<std::string> predicted;
  for (size_t j = 0; j < spec_->objectives.size(); ++j) {
    const spec::Objective& objective = spec_->objectives[j];
    if (objective.metric != kCostMetric && FittedObjectiveModel(j) == nullptr) {
      // No usable run has measured it (a run that timed out speaks only
      // for the completion flag): there is no prediction to give.
      predicted.push_back(fmt::format(
          "{} not predicted yet (no run measured it)", objective.metric));
      continue;
    }
    const double v = objective.minimize ? mean[j] : -mean[j];
    // A mean over samples of which some never arrive (a rate model's
    // progress at or below 0) is no number to print.
    predicted.push_back(
        std::isfinite(v)
            ? fmt::format("{} {}", objective.metric, Num(v))
            : fmt::format("{} unbounded in some of the model's samples",
                          objective.metric));
  }
  return fmt::format("{}", fmt::join(predicted, ", "));
}

std::string AgentStrategy::ExplainCheapest(const Candidate& pick,
                                           const std::vector<double>& mean,
                                           int usable_runs) const {
  return fmt::format(
      "Looking for the cheapest feasible design: model ({} run{}) predicts "
      "({}), cost {}, feasible with p={:.2f} at {}.",
      usable_runs, usable_runs == 1 ? "" : "s",
      Describe(grid_.ToPoint(pick.genes)), Num(pick.cost), pick.p_feasible,
      Predictions(mean));
}

std::string AgentStrategy::ExplainChoice(const Candidate& pick,
                                         const std::vector<double>& mean,
                                         double base, int usable_runs) const {
  std::string reason;
  if (!pick.hint.empty()) {
    reason = fmt::format(", following {}", pick.hint);
  }
  return fmt::format(
      "Model ({} run{}) predicts ({}) feasible with p={:.2f} at {}; "
      "p={:.2f} it joins the predicted Pareto front, expected hypervolume "
      "gain {:.3g} over {:.3g}{}.",
      usable_runs, usable_runs == 1 ? "" : "s",
      Describe(grid_.ToPoint(pick.genes)), pick.p_feasible, Predictions(mean),
      pick.p_front, pick.gain, base, reason);
}
}  // namespace adse::explore::internal
