// Calibration of the `counted` cost model: per-callback linear costs
// (fixed + per work unit, at the reference frequency) fitted from the host
// CPU times of measured runs, stored as JSON so that counted runs are
// bit-reproducible on any machine.
#ifndef ADSE_HARNESS_SIM_CALIBRATION_H_
#define ADSE_HARNESS_SIM_CALIBRATION_H_

#include <map>
#include <string>
#include <vector>

#include "analysis/runfile/run_data.h"
#include "stack/base/status.h"
#include "stack/runtime/executor.h"

namespace adse::sim {

using Calibration = std::map<std::string, stack::CountedCost>;

// Least-squares fit of host_cpu_s = fixed_s + per_unit_s * work_units for
// every callback of the runs (non-negative coefficients). A callback of
// the runs' graph that never ran in them has nothing to fit: an error
// naming it, since a counted run would otherwise charge it a default.
Result<Calibration> FitCalibration(
    const std::vector<const runfile::RunData*>& runs);

// JSON: {"adse_calibration": 1, "host": ..., "callbacks": {name: {fixed_s,
// per_unit_s, samples}}}. Written atomically.
Status WriteCalibration(const std::string& path, const Calibration& calibration,
                        const std::string& host);
// Errors name the file and the broken entry.
Result<Calibration> LoadCalibration(const std::string& path);

}  // namespace adse::sim

#endif  // ADSE_HARNESS_SIM_CALIBRATION_H_
