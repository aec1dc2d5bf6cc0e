// Design points of a spec: parsed from and written as "cores=4,...",
// priced by the cost expression, checked against constraints and applied
// to the platform and stack one run uses.
#ifndef ADSE_HARNESS_SPEC_DESIGN_POINT_H_
#define ADSE_HARNESS_SPEC_DESIGN_POINT_H_

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "harness/spec/expression.h"
#include "harness/spec/spec.h"
#include "stack/base/status.h"

namespace adse::spec {

// The values of `range: [lo, hi]` with `step`: lo, lo + step, ... up to hi
// (within 1e-9 of a step), each cleaned of binary noise (0.1 steps give
// 0.3, not 0.30000000000000004). The caller bounds the count first with
// RangeCount.
double RangeCount(double lo, double hi, double step);
std::vector<double> ExpandRange(double lo, double hi, double step);

// A range that expands to exactly `values` (three or more, evenly spaced),
// as the text the scenario format reads back: {lo, hi, step}. False for
// lists that are not such a progression.
bool RangeOf(const std::vector<double>& values, std::string* lo,
             std::string* hi, std::string* step);

// Parses a command-line point "cores=4,freq_ghz=1.2,lidar_hz=14" against
// the space. Values are snapped to the exact allowed values. Errors name
// unknown parameters (with a suggestion), values not allowed (with the
// allowed ones) and missing parameters.
Result<DesignPoint> ParsePoint(const DesignSpace& space, std::string_view text);

// The inverse of ParsePoint: "cores=4,freq_ghz=1.2,lidar_hz=14", parameters
// in space order (names the space lacks follow in name order), values in
// their shortest exact form.
std::string FormatPoint(const DesignSpace& space, const DesignPoint& point);

// Names the `cost` expression may use: design parameters, `cores`,
// `freq_ghz`.
std::vector<std::string> CostVariableNames(const DesignSpace& space);
// Names constraints may use: known metrics and design parameters.
std::vector<std::string> ConstraintVariableNames(const DesignSpace& space);

// The hardware cost of a point: the spec's cost expression with the point's
// values, and `cores`/`freq_ghz` from the point when bound, else from the
// platform defaults.
Result<double> EvaluateCost(const Spec& spec, const DesignPoint& point);

// Spaces up to this size have their cost checked at every point, and are
// enumerated where every design is counted (the headline's cheaper
// designs).
inline constexpr uint64_t kMaxCostCheckPoints = 100000;

// Calls `visit` with every point of the space and its cost, in
// lexicographic order (the first parameter slowest). The caller bounds the
// space's size first. Errors: the cost expression does not parse, or is
// not finite at a point (named; nothing is visited after it).
Status ForEachPointCost(
    const Spec& spec,
    const std::function<void(const DesignPoint& point, double cost)>& visit);
// Ok when the cost expression is finite at every point of the space (a
// cost of 10 / (cores - 1) over 1 core is not); a space larger than
// kMaxCostCheckPoints is not enumerated, and each run checks its own
// point. The error names the first such point in lexicographic order.
Status CheckCostOverSpace(const Spec& spec);
// Ok unless exploration.confirm_runs asks for a confirm phase over a space
// larger than kMaxCostCheckPoints, where the designs cheaper than the
// answer are not enumerated, so the phase could pick nothing.
Status CheckConfirmRuns(const Spec& spec);

// Whether `metrics` (name -> value; booleans as 0/1) and the point satisfy
// one constraint expression of the spec (true when non-zero).
Result<bool> EvaluateConstraint(const Spec& spec, const std::string& constraint,
                                const std::map<std::string, double>& metrics,
                                const DesignPoint& point);

// The spec's constraints that `metrics` and the point do not satisfy, in
// the spec's order; one that cannot be evaluated (a missing metric) counts
// as not satisfied: nothing shows it holds.
std::vector<std::string> ViolatedConstraints(
    const Spec& spec, const std::map<std::string, double>& metrics,
    const DesignPoint& point);
// How many there are.
int ViolatedConstraintCount(const Spec& spec,
                            const std::map<std::string, double>& metrics,
                            const DesignPoint& point);

// The metrics the spec's constraints read (not its design parameters),
// each once, constraint by constraint (alphabetically within one); a
// constraint that does not parse names none.
std::vector<std::string> ConstraintMetrics(const Spec& spec);

// The spec's constraints parsed once, to check many rows: parsing is most
// of a check (a front over a campaign's rows checks every infeasible one).
// Not thread-safe on one object (muParser keeps state); copies are.
class ConstraintChecker {
 public:
  explicit ConstraintChecker(const Spec& spec);
  // As ViolatedConstraints, and ViolatedConstraintCount.
  std::vector<std::string> Violated(
      const std::map<std::string, double>& metrics,
      const DesignPoint& point) const;
  int ViolatedCount(const std::map<std::string, double>& metrics,
                    const DesignPoint& point) const;

 private:
  std::vector<std::string> texts_;
  // One per constraint; empty where it does not parse (never holds).
  std::vector<std::optional<Expression>> parsed_;
};

// A design point applied to the spec: the platform and stack one run uses.
struct PointConfig {
  PlatformOptions platform;
  StackConfig stack;
};
Result<PointConfig> ApplyPoint(const Spec& spec, const DesignPoint& point);

}  // namespace adse::spec

#endif  // ADSE_HARNESS_SPEC_DESIGN_POINT_H_
