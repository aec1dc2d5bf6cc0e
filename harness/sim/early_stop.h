// Early stop: a run ends as soon as one of the scenario's constraints is
// certainly violated, whatever the rest of the run would bring. A starved
// design that would crawl to the timeout is then known infeasible at the
// constraint's bound, not after it.
#ifndef ADSE_HARNESS_SIM_EARLY_STOP_H_
#define ADSE_HARNESS_SIM_EARLY_STOP_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "harness/spec/expression.h"
#include "harness/spec/spec.h"
#include "stack/base/status.h"

namespace adse::sim {

// What is known of a run part-way: the metrics early stop can bound.
struct RunProgress {
  double t_s = 0.0;              // simulated time now; the goal not reached
  int64_t control_commands = 0;  // commands published so far
  int64_t collisions = 0;        // contacts so far
};

// The constraints of `spec` that early stop can decide: each names exactly
// one of the metrics a run accumulates (nav_time_s, ctrl_rate_hz,
// collisions) and otherwise only design parameters and hardware_cost.
// Empty when harness.early_stop is false. They enter the run key.
std::vector<std::string> EarlyStoppableConstraints(const spec::Spec& spec);

class EarlyStop {
 public:
  // `max_control_rate_hz`: the controller's timer rate, the fastest the
  // command count can grow. Fails only if a constraint does not parse.
  static Result<EarlyStop> Create(const spec::Spec& spec,
                                  const spec::DesignPoint& point,
                                  double max_control_rate_hz);

  // The first constraint that no continuation of the run can satisfy, or
  // nothing. Each constraint is evaluated over the interval of final values
  // its metric can still take (nav time: now to the timeout; control rate:
  // no further command to one per controller period until the timeout;
  // collisions: this many or more), at its ends and 15 points between:
  // exact for a constraint monotone in its metric (a bound such as
  // `nav_time_s <= 400`), conservative-leaning for any other.
  std::optional<std::string> Violated(const RunProgress& progress) const;

  bool empty() const { return checks_.empty(); }

 private:
  enum class Metric { kNavTime, kControlRate, kCollisions };
  struct Check {
    spec::Expression expression;
    Metric metric;
  };
  EarlyStop() = default;

  std::vector<Check> checks_;
  std::map<std::string, double> fixed_;  // design parameters, hardware_cost
  double timeout_s_ = 0.0;
  double max_control_rate_hz_ = 0.0;
};

}  // namespace adse::sim

#endif  // ADSE_HARNESS_SIM_EARLY_STOP_H_
