#include "harness/explore/capacity.h"

#include <algorithm>
#include <cmath>

#include "harness/spec/design_point.h"

namespace adse::explore {

int CompareCapacity(const std::vector<spec::KnobRole>& roles,
                    const std::vector<bool>& rate_raised, const Genes& a,
                    const Genes& b, bool coarser_is_capacity) {
  using spec::KnobRole;
  int sign = 0;
  for (size_t d = 0; d < roles.size(); ++d) {
    if (a[d] == b[d]) continue;
    const KnobRole role = roles[d];
    int here = a[d] < b[d] ? -1 : +1;
    const bool raised = d < rate_raised.size() && rate_raised[d];
    if (role == KnobRole::kSensorRate && !raised) {
      here = -here;  // a faster sensor is more load
    } else if (role != KnobRole::kCores && role != KnobRole::kFrequency &&
               !(role == KnobRole::kDownsample && coarser_is_capacity)) {
      return 2;
    }
    if (sign != 0 && sign != here) return 2;
    sign = here;
  }
  return sign;
}

std::vector<CapacityConstraint> CapacityConstraintsOf(const spec::Spec& spec) {
  const std::vector<std::string> parameters = spec.design_space.Names();
  const std::vector<std::string> names =
      spec::ConstraintVariableNames(spec.design_space);
  std::vector<CapacityConstraint> out;
  for (const std::string& text : spec.constraints) {
    Result<spec::Expression> expression = spec::Expression::Parse(text, names);
    if (!expression.ok()) continue;
    bool metric_only = true;
    bool reads_precision = false;
    for (const std::string& variable : expression->variables()) {
      // The cost is the design's, not the run's.
      if (variable == "hardware_cost" ||
          std::find(parameters.begin(), parameters.end(), variable) !=
              parameters.end()) {
        metric_only = false;
        continue;
      }
      for (const spec::MetricInfo& info : spec::KnownMetrics()) {
        if (info.name == variable && info.precision) reads_precision = true;
      }
    }
    out.push_back({std::move(*expression), metric_only, reads_precision});
  }
  return out;
}

bool FailsForCapacity(const std::vector<CapacityConstraint>& constraints,
                      const Observation& observation, bool load_only) {
  if (observation.failed) return false;
  for (const CapacityConstraint& constraint : constraints) {
    if (!constraint.metric_only || (load_only && constraint.reads_precision)) {
      continue;
    }
    if (observation.censored &&
        observation.violated_constraint == constraint.expression.text()) {
      return true;
    }
    bool measured = true;
    for (const std::string& variable : constraint.expression.variables()) {
      auto it = observation.metrics.find(variable);
      measured = measured && it != observation.metrics.end() &&
                 std::isfinite(it->second);
    }
    if (!measured) continue;
    const double v = constraint.expression.Evaluate(observation.metrics);
    if (!std::isfinite(v) || v == 0.0) return true;
  }
  return false;
}

}  // namespace adse::explore
