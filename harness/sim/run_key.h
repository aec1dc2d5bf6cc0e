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

// 64 hex characters. Files the run reads (a given net, its polygons, the
// calibration) enter by content, so editing one changes the key. Fails
// only when such a file cannot be read.
Result<std::string> RunKey(const spec::Spec& spec,
                           const spec::DesignPoint& point, uint64_t seed);

// The seed of a point's replica `replica` (harness.replicas; 0-based). It
// seeds everything random in the run: traffic, cost sampling, sensor noise.
// Replica 0 runs with the scenario's traffic seed, so a point run once keeps
// its key; replica r > 0 with a seed derived from it.
uint64_t ReplicaSeed(const spec::Spec& spec, int replica);

// The content keys of the point's harness.replicas runs, in replica order.
Result<std::vector<std::string>> ReplicaKeys(const spec::Spec& spec,
                                             const spec::DesignPoint& point);

}  // namespace adse::sim

#endif  // ADSE_HARNESS_SIM_RUN_KEY_H_
