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

#include "harness/spec/spec.h"
#include "stack/base/status.h"

namespace adse::sim {

// 64 hex characters. Files the run reads (a given net, its polygons, the
// calibration) enter by content, so editing one changes the key. Fails
// only when such a file cannot be read.
Result<std::string> RunKey(const spec::Spec& spec,
                           const spec::DesignPoint& point, uint64_t seed);

}  // namespace adse::sim

#endif  // ADSE_HARNESS_SIM_RUN_KEY_H_
