#include "stack/world/vehicle_model.h"

#include <algorithm>
#include <cmath>

namespace adse::world {

void BicycleModel::Step(const ControlCommand& command, double dt_s) {
  if (!(dt_s > 0.0)) return;
  const VehicleLimits& lim = limits_;
  const VehicleState s0 = state_;

  // Steering actuator: rate-limited towards the clamped target.
  const double target =
      std::clamp(command.steer_rad, -lim.max_steer_rad, lim.max_steer_rad);
  const double max_delta = lim.max_steer_rate_rad_per_s * dt_s;
  double steer1 =
      s0.steer_rad + std::clamp(target - s0.steer_rad, -max_delta, max_delta);
  steer1 = std::clamp(steer1, -lim.max_steer_rad, lim.max_steer_rad);

  // Longitudinal, signed speed. Driving pushes along the gear (so drive in
  // the gear opposite to the motion first slows the car, as a real one
  // does); braking only ever takes speed off, down to a standstill.
  const double accel =
      std::clamp(command.accel_mps2, -lim.max_decel_mps2, lim.max_accel_mps2);
  const double v0 =
      std::clamp(s0.v_mps, -lim.max_reverse_speed_mps, lim.max_speed_mps);
  double a_eff = 0.0;  // signed acceleration along x of the body
  double v1 = v0;
  if (accel >= 0.0) {
    a_eff = command.reverse ? -accel : accel;
    v1 = std::clamp(v0 + a_eff * dt_s, -lim.max_reverse_speed_mps,
                    lim.max_speed_mps);
  } else if (v0 != 0.0) {
    a_eff = v0 > 0 ? accel : -accel;
    v1 = v0 + a_eff * dt_s;
    if ((v1 > 0) != (v0 > 0)) v1 = 0.0;
  }

  // Midpoint (RK2) step with inputs taken as linear over the step:
  // heading at mid-step from the start yaw rate, then the whole step with
  // mid-step speed, steer and heading. Rear-axle reference, so the velocity
  // is along the heading (no side slip).
  const double L = lim.wheelbase_m;
  const double yaw_rate0 = v0 * std::tan(s0.steer_rad) / L;
  const double yaw_mid = s0.yaw_rad + 0.5 * dt_s * yaw_rate0;
  // Mean speed over the step, exact when the speed reaches 0 or a cap
  // mid-step (then it stays there for the rest of the step).
  double v_mid = 0.5 * (v0 + v1);
  if (a_eff != 0.0 && std::abs(v1 - v0) < std::abs(a_eff) * dt_s) {
    const double t_reach = (v1 - v0) / a_eff;
    v_mid = (0.5 * (v0 + v1) * t_reach + v1 * (dt_s - t_reach)) / dt_s;
  }
  const double steer_mid = 0.5 * (s0.steer_rad + steer1);
  const double yaw_rate_mid = v_mid * std::tan(steer_mid) / L;

  state_.x_m = s0.x_m + dt_s * v_mid * std::cos(yaw_mid);
  state_.y_m = s0.y_m + dt_s * v_mid * std::sin(yaw_mid);
  state_.yaw_rad = std::remainder(s0.yaw_rad + dt_s * yaw_rate_mid, 2.0 * M_PI);
  state_.v_mps = v1;
  state_.steer_rad = steer1;
  // The acceleration actually achieved (zero when held at rest or at the
  // speed cap), as an IMU would report it.
  state_.accel_mps2 = (v1 - v0) / dt_s;
}

geometry::OrientedBox BodyAt(const geometry::Pose2& rear_axle,
                             const VehicleLimits& car) {
  geometry::OrientedBox box;
  const double half_wb = 0.5 * car.wheelbase_m;
  box.center =
      Eigen::Vector2d(rear_axle.x_m + half_wb * std::cos(rear_axle.yaw_rad),
                      rear_axle.y_m + half_wb * std::sin(rear_axle.yaw_rad));
  box.yaw_rad = rear_axle.yaw_rad;
  box.length_m = car.length_m;
  box.width_m = car.width_m;
  box.height_m = car.height_m;
  return box;
}

geometry::OrientedBox BicycleModel::Body() const {
  // The state is the rear axle centre.
  return BodyAt({state_.x_m, state_.y_m, state_.yaw_rad}, limits_);
}

double BicycleModel::yaw_rate_rps() const {
  return state_.v_mps * std::tan(state_.steer_rad) / limits_.wheelbase_m;
}

}  // namespace adse::world
