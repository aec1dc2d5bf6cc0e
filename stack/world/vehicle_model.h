// The ego vehicle: a kinematic bicycle model integrating acceleration and
// steering commands with actuator limits, in forward or reverse gear.
#ifndef ADSE_STACK_WORLD_VEHICLE_MODEL_H_
#define ADSE_STACK_WORLD_VEHICLE_MODEL_H_

#include "stack/geometry/geometry.h"

namespace adse::world {

struct VehicleLimits {
  double wheelbase_m = 2.7;
  double length_m = 4.6;
  double width_m = 1.9;
  double height_m = 1.6;
  double max_steer_rad = 0.6;
  double max_steer_rate_rad_per_s = 0.8;
  double max_accel_mps2 = 2.5;
  double max_decel_mps2 = 6.0;  // positive number
  double max_speed_mps = 20.0;
  double max_reverse_speed_mps = 3.0;  // positive number
};

// What the stack's controller asks for.
struct ControlCommand {
  // Positive drives in the gear's direction, negative brakes (towards a
  // standstill, never through it).
  double accel_mps2 = 0.0;
  double steer_rad = 0.0;  // front wheel angle target
  bool reverse = false;    // gear: driving backwards
};

struct VehicleState {
  double x_m = 0.0;  // rear axle centre
  double y_m = 0.0;
  double yaw_rad = 0.0;
  double v_mps = 0.0;  // signed: negative while reversing
  double steer_rad = 0.0;
  double accel_mps2 = 0.0;
};

// Where a car's body stands for a rear-axle pose: centred half a
// wheelbase ahead of it (equal front and rear overhangs).
geometry::OrientedBox BodyAt(const geometry::Pose2& rear_axle,
                             const VehicleLimits& car);

class BicycleModel {
 public:
  explicit BicycleModel(const VehicleLimits& limits) : limits_(limits) {}

  void Reset(const VehicleState& state) { state_ = state; }
  // Integrates one step of dt_s with the command clamped to the limits.
  void Step(const ControlCommand& command, double dt_s);

  const VehicleState& state() const { return state_; }
  const VehicleLimits& limits() const { return limits_; }
  // The body as a box (centre is half a wheelbase ahead of the rear axle).
  geometry::OrientedBox Body() const;
  // How fast it turns now, about its rear axle (counter-clockwise positive).
  double yaw_rate_rps() const;

 private:
  VehicleLimits limits_;
  VehicleState state_;
};

}  // namespace adse::world

#endif  // ADSE_STACK_WORLD_VEHICLE_MODEL_H_
