// What the knobs' roles say of capacity, shared by the built-in agent and
// the campaign's headline: more cores or a faster clock never slow the
// stack, and a faster sensor never lightens it. So a design with no more
// capacity than a run that failed for lack of it fails too, and one with
// no less than a feasible run's holds (the order holds on every recording
// in tests/data; see docs/agent_development.md, "Capacity order").
#ifndef ADSE_HARNESS_EXPLORE_CAPACITY_H_
#define ADSE_HARNESS_EXPLORE_CAPACITY_H_

#include <vector>

#include "harness/explore/strategy.h"
#include "harness/spec/expression.h"
#include "harness/spec/spec.h"

namespace adse::explore {

// -1, 0 or +1: whether `a` has at most, the same or at least `b`'s
// capacity by the knobs' roles (one per parameter, in space order); 2 when
// neither. A knob of no capacity role must be equal; so must a sensor rate
// the diagnosis asked to raise (`rate_raised`, per knob; may be empty) and,
// unless `coarser_is_capacity`, a downsample knob (coarser data sheds load
// but costs precision).
int CompareCapacity(const std::vector<spec::KnobRole>& roles,
                    const std::vector<bool>& rate_raised, const Genes& a,
                    const Genes& b, bool coarser_is_capacity);

// One of the scenario's constraints, as capacity can decide it.
struct CapacityConstraint {
  spec::Expression expression;  // its text() as the scenario writes it
  // It reads measured metrics only: no cost, no knob. Only such a
  // constraint follows capacity (`hardware_cost <= 20` does not).
  bool metric_only = false;
  // It reads a precision metric (spec::MetricInfo::precision), which finer
  // data can rescue.
  bool reads_precision = false;
};

// The scenario's constraints that parse, in its order.
std::vector<CapacityConstraint> CapacityConstraintsOf(const spec::Spec& spec);

// Whether a run shows a lack of capacity: it completed, or was stopped
// early, and a metric-only constraint does not hold (with `load_only`, one
// that reads no precision metric). A failed run (no metrics) shows nothing.
bool FailsForCapacity(const std::vector<CapacityConstraint>& constraints,
                      const Observation& observation, bool load_only);

}  // namespace adse::explore

#endif  // ADSE_HARNESS_EXPLORE_CAPACITY_H_
