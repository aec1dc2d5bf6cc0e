// Runs one design point end to end: the SUMO world, the AD stack on the
// virtual platform sized by the point, the vehicle-side command gate, and
// the recording of everything into RunData.
#ifndef ADSE_HARNESS_SIM_SIMULATOR_H_
#define ADSE_HARNESS_SIM_SIMULATOR_H_

#include <cstdint>
#include <functional>
#include <optional>

#include "analysis/runfile/run_data.h"
#include "harness/spec/spec.h"
#include "stack/base/status.h"
#include "stack/world/world.h"

namespace adse::sim {

struct SimulateOptions {
  // Overrides world.traffic.seed (and the sensor noise seeds derived from it).
  std::optional<uint64_t> seed;
  // Other vehicles are recorded at this period.
  double vehicle_record_period_s = 0.5;
  // Called about once per simulated second with (t_s, timeout_s).
  std::function<void(double, double)> progress;
};

// Where the wall time of a run went (for the benchmark and --json).
struct SimulationStats {
  double wall_s = 0.0;                // the whole SimulatePoint call
  double setup_s = 0.0;               // world open, map cloud, stack build
  double stack_and_executor_s = 0.0;  // wall time inside the executor
  // The split of that time, known for the measured cost model only (NaN
  // for counted runs, which do not time their callbacks).
  double stack_cpu_s = 0.0;  // the stack's callbacks (host thread CPU)
  double executor_s = 0.0;   // executor and trace bookkeeping
  double world_s = 0.0;      // SUMO steps and ego dynamics
  double lidar_s = 0.0;      // ray casting
  double simulated_s = 0.0;  // simulated time covered
};

// The world and task of a scenario, ready for World::Open.
world::WorldSetup WorldSetupFromSpec(const spec::Spec& spec);

// Ok when the counted cost model's file reads: platform.profile as a
// profile, or else platform.calibration, when one is named, as a
// calibration (each file's own checks, e.g. a p95 below its p50); said
// before any run, as the first run would refuse it. Whether it costs every
// callback of the route's graph is the run's to check.
Status CheckCostModelFile(const spec::Spec& spec);

// Ok when `platform` (a point's, see spec::ApplyPoint) can run in real
// time here: the counted cost model with a profile, which the real-time
// platform pads every callback to (else InvalidArgument), and a host CPU
// per core of the point (else PlaceOnHost's Unavailable).
Status CheckRealTimePlatform(const spec::PlatformOptions& platform);

// Simulates `point` of `spec`. Bad input (a point outside the space, a
// world that does not load) returns InvalidArgument naming the field.
// A run that ends without reaching the goal is still a successful
// simulation: its RunData says why it ended.
Result<runfile::RunData> SimulatePoint(const spec::Spec& spec,
                                       const spec::DesignPoint& point,
                                       const SimulateOptions& options = {},
                                       SimulationStats* stats = nullptr);

}  // namespace adse::sim

#endif  // ADSE_HARNESS_SIM_SIMULATOR_H_
