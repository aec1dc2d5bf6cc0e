// Steering for the ground-truth driver: the command whose rollout through
// the car's own model (rate-limited steering, kinematic bicycle) stays
// closest to the path over a short horizon. A corner tighter than the car
// can take is then begun early and left without swinging wide; pure
// pursuit, which cannot see the steering's rate limit, swung 2-4 m off
// the path after such corners on real nets.
#ifndef ADSE_STACK_WORLD_PREDICTIVE_STEERING_H_
#define ADSE_STACK_WORLD_PREDICTIVE_STEERING_H_

#include <vector>

#include "stack/geometry/geometry.h"
#include "stack/world/vehicle_model.h"

namespace adse::world {

struct PredictiveSteeringOptions {
  // The rollout covers at least horizon_m of path and at least
  // horizon_time_s at the current speed: long enough to see a corner
  // before the steering must start to move for it.
  double horizon_m = 8.0;
  double horizon_time_s = 1.5;
  int steps = 20;  // integration steps of a rollout
  // Candidate steering targets per phase, spread evenly over the car's
  // range; a rollout holds one target for its first third, another after.
  int steer_values = 13;
  // Distances past this count with their fourth power: near-minimax
  // tracking where a corner forces some error.
  double soft_bound_m = 0.5;
  // Weight of the rollout's largest distance, squared, against the mean
  // penalty: a corner's error is kept small at its worst, not only on
  // average (10 took a 90 degree corner within 0.96 m, 0 within 1.28 m).
  double worst_weight = 10.0;
  // The heading error at the horizon's end counts as a lateral error of
  // this lever arm: a rollout that ends on the path but across it would
  // overshoot just after the horizon.
  double heading_lever_m = 2.0;
  // Cost of moving the target away from the wheels' angle, per rad^2 (in
  // m^2): keeps the command from chattering between near-equal rollouts.
  double steer_change_weight_m2 = 0.05;
  // The driver's speed controller, which rollouts model: acceleration =
  // gain x (profile speed - speed), within the car's limits.
  double speed_gain_per_s = 1.5;
  // Speed assumed for a car standing or creeping: it is about to move.
  double min_speed_mps = 1.0;
};

// The speed a driver keeps along a path: at most the limit, no faster in
// a curve than its lateral acceleration allows, and slowing for a curve
// ahead at the comfortable deceleration.
struct SpeedProfile {
  double spacing_m = 0.5;
  std::vector<double> v_mps;  // at s = i * spacing_m
  double At(double s_m) const;
};
SpeedProfile CurveSpeedProfile(const geometry::Path2& path,
                               double speed_limit_mps,
                               double max_lateral_accel_mps2,
                               double comfort_decel_mps2);

// The front-wheel angle to command for a car at `ego` whose progress
// along `path` is `s_progress_m` (rear axle, forward driving), and whose
// speed follows `speed` (see speed_gain_per_s).
double PredictiveSteer(const geometry::Path2& path, const SpeedProfile& speed,
                       double s_progress_m, const VehicleState& ego,
                       const VehicleLimits& limits,
                       const PredictiveSteeringOptions& options);

// The ground-truth driver's lane following rehearsed on the car's model
// alone, no traffic and no stops: PredictiveSteer drives it from s0_m (on
// the path, along it, at start_v_mps, its wheels at the path's curvature),
// its speed following `speed`, until its progress passes s1_m, in steps of
// dt_s. Returns its progress and distance from the path at each step.
struct RehearsalSample {
  double s_m = 0.0;
  double distance_m = 0.0;
};
std::vector<RehearsalSample> RehearseFollowing(
    const geometry::Path2& path, const SpeedProfile& speed, double s0_m,
    double s1_m, double start_v_mps, const VehicleLimits& limits,
    const PredictiveSteeringOptions& options, double dt_s);

}  // namespace adse::world

#endif  // ADSE_STACK_WORLD_PREDICTIVE_STEERING_H_
