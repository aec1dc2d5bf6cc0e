#include "stack/world/vehicle_model.h"

#include <gtest/gtest.h>

#include <cmath>

namespace adse::world {
namespace {

TEST(BicycleModelTest, ConstantSteerTracesCircleOfRadiusLOverTanDelta) {
  VehicleLimits lim;  // wheelbase 2.7 m
  BicycleModel model(lim);
  const double delta = 0.3, v = 5.0, dt = 0.01;
  VehicleState s;
  s.v_mps = v;
  s.steer_rad = delta;
  model.Reset(s);
  const double radius = lim.wheelbase_m / std::tan(delta);  // 8.74 m
  const Eigen::Vector2d centre(0.0, radius);  // turning left from yaw 0
  const int steps = static_cast<int>(std::lround(2 * M_PI * radius / v / dt));
  double worst = 0.0;
  for (int i = 0; i < steps; ++i) {
    model.Step({0.0, delta}, dt);
    const Eigen::Vector2d p(model.state().x_m, model.state().y_m);
    worst = std::max(worst, std::abs((p - centre).norm() - radius));
  }
  EXPECT_LT(worst, 1e-3);  // forward Euler would drift outwards by > 1 m
  // One full loop brings it back to the start, heading east again.
  EXPECT_NEAR(model.state().x_m, 0.0, v * dt);
  EXPECT_NEAR(model.state().y_m, 0.0, v * dt);
  EXPECT_NEAR(std::remainder(model.state().yaw_rad, 2 * M_PI), 0.0, 0.01);
  EXPECT_DOUBLE_EQ(model.state().v_mps, v);
}

TEST(BicycleModelTest, SteeringIsRateLimitedAndClamped) {
  VehicleLimits lim;  // 0.6 rad max, 0.8 rad/s
  BicycleModel model(lim);
  model.Step({0.0, 1.0}, 0.1);
  EXPECT_NEAR(model.state().steer_rad, 0.08, 1e-12);
  for (int i = 0; i < 100; ++i) model.Step({0.0, 1.0}, 0.1);
  EXPECT_NEAR(model.state().steer_rad, 0.6, 1e-12);
  model.Step({0.0, -5.0}, 0.1);
  EXPECT_NEAR(model.state().steer_rad, 0.52, 1e-12);
  for (int i = 0; i < 100; ++i) model.Step({0.0, -5.0}, 0.1);
  EXPECT_NEAR(model.state().steer_rad, -0.6, 1e-12);
  // Small corrections within the rate limit land exactly.
  model.Step({0.0, -0.59}, 0.1);
  EXPECT_NEAR(model.state().steer_rad, -0.59, 1e-12);
}

TEST(BicycleModelTest, AccelerationAndSpeedAreClamped) {
  VehicleLimits lim;  // +2.5 / -6 m/s^2, 20 m/s
  BicycleModel model(lim);
  model.Step({10.0, 0.0}, 0.1);
  EXPECT_NEAR(model.state().v_mps, 0.25, 1e-12);
  EXPECT_NEAR(model.state().accel_mps2, 2.5, 1e-12);
  for (int i = 0; i < 200; ++i) model.Step({10.0, 0.0}, 0.1);
  EXPECT_DOUBLE_EQ(model.state().v_mps, 20.0);
  EXPECT_NEAR(model.state().accel_mps2, 0.0, 1e-12);
  model.Step({-100.0, 0.0}, 0.1);
  EXPECT_NEAR(model.state().v_mps, 19.4, 1e-12);
  // Straight line: no lateral motion, heading kept.
  EXPECT_DOUBLE_EQ(model.state().y_m, 0.0);
  EXPECT_DOUBLE_EQ(model.state().yaw_rad, 0.0);
}

TEST(BicycleModelTest, BrakingStopsWithoutReversing) {
  VehicleLimits lim;
  BicycleModel model(lim);
  VehicleState s;
  s.v_mps = 1.0;
  model.Reset(s);
  // Stops within the first step of 0.2 s (1 / 6 s): distance v^2 / 2a.
  model.Step({-6.0, 0.0}, 0.2);
  EXPECT_EQ(model.state().v_mps, 0.0);
  EXPECT_NEAR(model.state().x_m, 1.0 / 12.0, 1e-12);
  for (int i = 0; i < 50; ++i) model.Step({-6.0, 0.3}, 0.1);
  EXPECT_EQ(model.state().v_mps, 0.0);
  EXPECT_NEAR(model.state().x_m, 1.0 / 12.0, 1e-12);
  EXPECT_EQ(model.state().accel_mps2, 0.0);
  EXPECT_EQ(model.state().yaw_rad, 0.0);  // steering at rest turns nothing
  // Braking in reverse stops the car too, never driving it forwards.
  s.v_mps = -1.0;
  model.Reset(s);
  model.Step({-6.0, 0.0, true}, 0.2);
  EXPECT_EQ(model.state().v_mps, 0.0);
  EXPECT_NEAR(model.state().x_m, -1.0 / 12.0, 1e-12);
  s.v_mps = 0.0;
  model.Reset(s);
  // Non-positive steps change nothing.
  model.Step({2.0, 0.0}, 0.0);
  model.Step({2.0, 0.0}, -1.0);
  EXPECT_EQ(model.state().v_mps, 0.0);
}

TEST(BicycleModelTest, ReverseGearDrivesBackwardsUpToItsSpeedLimit) {
  VehicleLimits lim;
  lim.max_reverse_speed_mps = 2.0;
  BicycleModel model(lim);
  model.Reset(VehicleState{});
  for (int i = 0; i < 100; ++i) model.Step({1.0, 0.0, true}, 0.1);
  EXPECT_DOUBLE_EQ(model.state().v_mps, -2.0);
  // 2 s to reach 2 m/s (2 m), then 8 s at 2 m/s: 18 m behind the start.
  EXPECT_NEAR(model.state().x_m, -18.0, 1e-9);
  EXPECT_DOUBLE_EQ(model.state().yaw_rad, 0.0);
  // Steering left while backing turns the nose right (clockwise).
  model.Step({0.0, 0.3, true}, 0.5);
  model.Step({0.0, 0.3, true}, 0.5);
  EXPECT_LT(model.state().yaw_rad, -0.05);
}

TEST(BicycleModelTest, DrivingAgainstTheMotionSlowsThenReverses) {
  VehicleLimits lim;
  BicycleModel model(lim);
  VehicleState s;
  s.v_mps = 1.0;
  model.Reset(s);
  // Reverse gear with 1 m/s^2 while rolling forwards at 1 m/s: through a
  // standstill at t = 1 s and backwards after, as a real car would.
  for (int i = 0; i < 10; ++i) model.Step({1.0, 0.0, true}, 0.1);
  EXPECT_NEAR(model.state().v_mps, 0.0, 1e-12);
  EXPECT_NEAR(model.state().x_m, 0.5, 1e-12);
  for (int i = 0; i < 10; ++i) model.Step({1.0, 0.0, true}, 0.1);
  EXPECT_NEAR(model.state().v_mps, -1.0, 1e-12);
  EXPECT_NEAR(model.state().x_m, 0.0, 1e-12);
}

TEST(BicycleModelTest, BodyIsCentredHalfAWheelbaseAheadOfTheRearAxle) {
  VehicleLimits lim;
  BicycleModel model(lim);
  VehicleState s;
  s.x_m = 10.0;
  s.y_m = -4.0;
  s.yaw_rad = M_PI / 2;
  model.Reset(s);
  const geometry::OrientedBox body = model.Body();
  EXPECT_NEAR(body.center.x(), 10.0, 1e-12);
  EXPECT_NEAR(body.center.y(), -4.0 + 1.35, 1e-12);
  EXPECT_DOUBLE_EQ(body.yaw_rad, M_PI / 2);
  EXPECT_DOUBLE_EQ(body.length_m, lim.length_m);
  EXPECT_DOUBLE_EQ(body.width_m, lim.width_m);
  EXPECT_DOUBLE_EQ(body.height_m, lim.height_m);
}

}  // namespace
}  // namespace adse::world
