// The content key of a run: a hash of everything that can change what a
// run does — the scenario's world, task, stack and platform, the design
// point, the seed and the adse version, and the constraints that can end
// the run early — and of nothing else (not the exploration, other harness
// or output settings). Run files are named by it, so
// any campaign can reuse any run with the same key.
#ifndef ADSE_HARNESS_SIM_RUN_KEY_H_
#define ADSE_HARNESS_SIM_RUN_KEY_H_

#include <cstdint>
#include <string>
#include <vector>

#include "harness/spec/spec.h"
#include "stack/base/status.h"

namespace adse::sim {

// 64 hex characters; a spec with task.cases has none (each case's spec,
// spec::ForCase, has one). Files the run reads (a given net, its polygons, the
// calibration) enter by content, so editing one changes the key. Fails
// only when such a file cannot be read.
Result<std::string> RunKey(const spec::Spec& spec,
                           const spec::DesignPoint& point, uint64_t seed);

// Ok unless a design parameter binds a stack knob that acts in none of the
// scenario's runs (a `parking.*` knob outside valet_parking, a
// `traffic_light.*` knob on a map without signals; run keys leave such
// knobs out, so every point would drive alike): then InvalidArgument
// naming the parameter ("design_space.<name>: ..."). Fails also when the
// map cannot be read.
Status CheckKnobsAct(const spec::Spec& spec);

// The seed of a point's replica `replica` (harness.replicas; 0-based). It
// seeds everything random in the run: traffic, cost sampling, sensor noise.
// Replica 0 runs with the scenario's traffic seed, so a point run once keeps
// its key; replica r > 0 with a seed derived from it.
uint64_t ReplicaSeed(const spec::Spec& spec, int replica);

// One run of a point: case `task_case` of task.cases (0 when there are
// none), replica `replica` of harness.replicas.
struct PointRun {
  int task_case = 0;
  int replica = 0;
};

// A point's runs, case by case: each case's harness.replicas runs.
std::vector<PointRun> PointRuns(const spec::Spec& spec);

// The spec a run of case `task_case` drives: spec::ForCase, or `spec`
// itself when it has no cases.
spec::Spec CaseSpec(const spec::Spec& spec, int task_case);

// The content keys of the point's runs, in PointRuns order.
Result<std::vector<std::string>> PointRunKeys(const spec::Spec& spec,
                                              const spec::DesignPoint& point);

}  // namespace adse::sim

#endif  // ADSE_HARNESS_SIM_RUN_KEY_H_
