// A cost profile: what each callback costs per invocation on a reference
// machine, as measured on a production stack (e.g. a CARET report of
// Autoware), for the `counted` cost model. The file format and its importer
// live in harness/profile; this is the part the executor needs.
#ifndef ADSE_STACK_RUNTIME_COST_PROFILE_H_
#define ADSE_STACK_RUNTIME_COST_PROFILE_H_

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "stack/base/status.h"

namespace adse::stack {

// One point of a cost distribution: the cost at quantile q of invocations.
struct CostQuantile {
  double q = 0.0;       // in [0, 1]
  double cost_s = 0.0;  // seconds at CostProfile::reference_ghz
};

// The cost of one callback ("<node>/<callback>").
struct CallbackCost {
  // Empirical quantiles of one invocation's cost, q strictly increasing from
  // exactly 0 (the minimum) to exactly 1 (the maximum), costs non-decreasing
  // and finite >= 0. An invocation draws u uniformly and takes the piecewise
  // linear inverse CDF through these points (SampleCost).
  std::vector<CostQuantile> quantiles;
  // Work units (points in the scan) that the quantiles were measured at: an
  // invocation reporting `units` costs draw * units / reference_units. 0:
  // the cost does not depend on the work.
  double reference_units = 0.0;
  // cost is proportional to (reference_ghz / freq_ghz)^freq_exponent; 1 for
  // compute-bound code, lower for memory-bound code whose time the core
  // clock changes less.
  double freq_exponent = 1.0;
  // Amdahl fraction of the cost that more threads speed up (replaces the
  // callback's own WorkReport's), and the most threads that part can use
  // (the executor takes the smaller of this and the WorkReport's).
  double parallel_fraction = 0.0;
  int max_threads = 1;
};

struct CostProfile {
  // Clock of the machine the costs were measured on (GHz, > 0).
  double reference_ghz = 0.0;
  std::map<std::string, CallbackCost> callbacks;
};

// The cost at quantile u in [0, 1] (clamped): linear between the two
// neighbouring quantile points.
double SampleCost(const CallbackCost& cost, double u);

// Uniform in [0, 1) for draw `i` of a callback's stream seeded `seed`
// (SplitMix64 of seed and i): a draw depends only on its own callback's
// seed and count, never on how often other callbacks ran.
double InvocationUniform(uint64_t seed, uint64_t i);

// One invocation's profiled cost at the reference clock on one core: the
// draw at `u`, times units / reference_units when the entry has reference
// units (a negative or non-finite `units` counts as 0).
double DrawnCostS(const CallbackCost& cost, double u, double units);

// The factor every profiled cost of `cost` takes at `freq_ghz`:
// (reference_ghz / freq_ghz)^freq_exponent * cost_scale.
double FrequencyFactor(const CallbackCost& cost, double reference_ghz,
                       double freq_ghz, double cost_scale);

// Amdahl: the time of `serial_s` whose fraction p (clamped to [0, 1]) runs
// on k >= 1 threads.
inline double AmdahlS(double serial_s, double p, int k) {
  p = p < 0.0 ? 0.0 : (p > 1.0 ? 1.0 : p);
  return serial_s * (1.0 - p + p / (k < 1 ? 1 : k));
}

// InvalidArgument naming the callback and the field when the profile breaks
// the rules above (also: reference_units finite >= 0, freq_exponent finite
// in [0, 4], parallel_fraction in [0, 1], max_threads >= 1).
Status ValidateCostProfile(const CostProfile& profile);

}  // namespace adse::stack

#endif  // ADSE_STACK_RUNTIME_COST_PROFILE_H_
