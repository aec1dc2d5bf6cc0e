#include "stack/algorithms/control.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <iostream>

#include "stack/algorithms/planning.h"
#include "stack/world/vehicle_model.h"
#include "tests/stack/algorithms/testing/planning_chain.h"

namespace adse::algorithms {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::vector<PlannedPoint> Line(double y, double v, int n) {
  std::vector<PlannedPoint> pts;
  for (int i = 0; i < n; ++i) {
    PlannedPoint p;
    p.x_m = i;
    p.y_m = y;
    p.s_m = i;
    p.v_mps = v;
    pts.push_back(p);
  }
  return pts;
}

TEST(PurePursuit, KnownGeometry) {
  PurePursuitParams params;
  params.min_lookahead_m = 4.0;
  PurePursuit pp(params);
  // Trajectory 1 m to the left: the lookahead point is (sqrt(15), 1).
  const PurePursuitOutput out =
      pp.Compute(geometry::Pose2{0, 0, 0}, 0.0, Line(1.0, 5.0, 30));
  ASSERT_TRUE(out.valid);
  EXPECT_NEAR(out.lookahead_m, 4.0, 1e-12);
  EXPECT_NEAR(out.target.x(), std::sqrt(15.0), 1e-9);
  EXPECT_NEAR(out.target.y(), 1.0, 1e-9);
  EXPECT_NEAR(out.curvature_1pm, 2.0 * 1.0 / 16.0, 1e-9);
  EXPECT_NEAR(out.steer_rad, std::atan(2.7 * 0.125), 1e-9);
  EXPECT_NEAR(out.lateral_error_m, -1.0, 1e-9);  // we are right of it
  // Lookahead grows with speed and is clamped.
  EXPECT_NEAR(pp.Compute(geometry::Pose2{}, 10.0, Line(0, 5, 30)).lookahead_m,
              8.0, 1e-12);
  EXPECT_NEAR(pp.Compute(geometry::Pose2{}, 50.0, Line(0, 5, 30)).lookahead_m,
              15.0, 1e-12);
  // Steering is limited.
  const PurePursuitOutput sharp =
      pp.Compute(geometry::Pose2{0, 0, -kPi / 2}, 0.0, Line(0, 5, 30));
  EXPECT_NEAR(sharp.steer_rad, params.max_steer_rad, 1e-12);
  EXPECT_FALSE(pp.Compute(geometry::Pose2{}, 0.0, {}).valid);
}

TEST(PurePursuit, PastTheEndExtrapolates) {
  PurePursuit pp;
  const auto line = Line(0.0, 0.0, 5);  // x = 0 .. 4
  const PurePursuitOutput out =
      pp.Compute(geometry::Pose2{6, 0.5, 0}, 0.0, line);
  EXPECT_TRUE(out.past_end);
  EXPECT_GT(out.target.x(), 6.0);  // ahead, on the extended line
  EXPECT_NEAR(out.target.y(), 0.0, 1e-9);
  EXPECT_LT(out.steer_rad, 0.0);  // back towards the line
}

TEST(PurePursuit, UTurnTrajectoryKeepsItsFirstLeg) {
  // Out along y = 0 for 40 m, back along y = 2.5: at y = 1.4 the return leg
  // is nearer, but the ego is at the start of the trajectory.
  std::vector<PlannedPoint> traj = Line(0.0, 3.0, 41);
  for (int i = 40; i >= 0; --i) {
    PlannedPoint p;
    p.x_m = i;
    p.y_m = 2.5;
    p.s_m = 43.5 + (40 - i);
    traj.push_back(p);
  }
  PurePursuit pp;
  const PurePursuitOutput out =
      pp.Compute(geometry::Pose2{2, 1.4, 0}, 0.0, traj);
  EXPECT_LE(out.nearest_index, 3u);
  EXPECT_NEAR(out.lateral_error_m, 1.4, 1e-9);
  EXPECT_LT(out.steer_rad, 0.0);  // back down to the first leg
}

// Standing 1 m right of a straight trajectory, the car's way off turns it
// left onto it: the lateral error shrinks, after 8 m (two lookaheads) it
// is back within 0.2 m, and the poses are one step apart.
TEST(PurePursuit, RolloutDrivesOffOntoTheTrajectory) {
  const PurePursuit pp;
  const std::vector<geometry::Pose2> way =
      pp.Rollout(geometry::Pose2{0, -1.0, 0}, Line(0.0, 5.0, 30), 8.0, 0.25);
  ASSERT_EQ(way.size(), 33u);
  EXPECT_EQ(way.front().y_m, -1.0);
  for (size_t i = 1; i < way.size(); ++i) {
    EXPECT_NEAR(
        std::hypot(way[i].x_m - way[i - 1].x_m, way[i].y_m - way[i - 1].y_m),
        0.25, 1e-3);
    EXPECT_GE(way[i].y_m, way[i - 1].y_m - 1e-9) << i;  // never away
  }
  EXPECT_GT(way.back().y_m, -0.2);
  EXPECT_LT(way.back().y_m, 0.2);
  // Past the trajectory's end it stops.
  EXPECT_LT(pp.Rollout(geometry::Pose2{25, 0, 0}, Line(0.0, 5.0, 30), 8.0, 0.25)
                .size(),
            33u);
}

TEST(Pid, ReachesTargetOnAFirstOrderPlant) {
  PidParams params;
  Pid pid(params);
  double v = 0.0;
  const double dt = 0.02;
  for (int k = 0; k < 1500; ++k) {
    // A drag term the integral has to cancel.
    const double u = pid.Update(5.0 - v, dt);
    EXPECT_LE(u, params.max_accel_mps2 + 1e-12);
    EXPECT_GE(u, -params.max_decel_mps2 - 1e-12);
    v += (u - 0.05 * v) * dt;
  }
  EXPECT_NEAR(v, 5.0, 0.02);
  EXPECT_LE(std::abs(pid.integral()), params.integral_limit_m);
  pid.Reset();
  EXPECT_EQ(pid.integral(), 0.0);
  // Saturated output: the integral does not wind up.
  for (int k = 0; k < 100; ++k) pid.Update(100.0, 0.1);
  EXPECT_EQ(pid.integral(), 0.0);
}

// Closed loop: planner + smoother + follower driving a kinematic bicycle.
struct Sim {
  world::BicycleModel car{world::VehicleLimits()};
  PathPlanner planner;
  ObstacleStopParams stop;
  TrajectoryFollower follower;
  SmootherParams smoother;
  double max_lat_error_after_settle = 0.0;

  explicit Sim(const PathPlannerParams& planner_params = {},
               const FollowerParams& follower_params = {})
      : planner(planner_params), follower(follower_params) {}

  geometry::Pose2 Pose() const {
    return {car.state().x_m, car.state().y_m, car.state().yaw_rad};
  }
  // Runs for duration_s; plans at 10 Hz, controls at 50 Hz.
  void Run(double duration_s, const std::vector<PlannerObstacle>& obstacles,
           const std::function<void(double, const FollowerCommand&)>& check) {
    const double dt = 0.02;
    testing::ChainedPlan traj;
    for (int k = 0; k * dt < duration_s; ++k) {
      if (k % 5 == 0) {
        traj = testing::PlanChain(&planner, Pose(), obstacles, {}, stop);
        SmoothVelocity(&traj.points, car.state().v_mps, smoother);
      }
      const FollowerCommand cmd =
          follower.Update(Pose(), car.state().v_mps, traj.points, dt);
      car.Step(world::ControlCommand{cmd.accel_mps2, cmd.steer_rad}, dt);
      if (check) check(k * dt, cmd);
    }
  }
};

TEST(TrajectoryFollower, TracksACircleOfRadius20) {
  // Three laps of a circle (0.5 m chords) centred at (0, 20).
  geometry::Path2 path;
  const double r = 20.0;
  for (int i = 0; i <= 3 * 252; ++i) {
    const double a = -kPi / 2 + i * 0.025;
    path.points.emplace_back(r * std::cos(a), r + r * std::sin(a));
  }
  path.UpdateArcLength();
  PathPlannerParams pp;
  pp.speed_limit_mps = 5.0;
  Sim sim(pp);
  sim.planner.SetRoute(path);
  world::VehicleState start;
  start.x_m = 0.0;
  start.y_m = 0.5;  // starts half a metre inside the circle
  sim.car.Reset(start);
  double max_err = 0.0, speed_err = 0.0;
  sim.Run(60.0, {}, [&](double t, const FollowerCommand&) {
    if (t < 20.0) return;
    const auto& s = sim.car.state();
    max_err = std::max(max_err, std::abs(std::hypot(s.x_m, s.y_m - r) - r));
    speed_err = std::max(speed_err, std::abs(s.v_mps - 5.0));
  });
  EXPECT_LT(max_err, 0.2);
  EXPECT_LT(speed_err, 0.2);  // the PID holds the target speed
  std::cout << "circle: max lateral error " << max_err << " m, speed error "
            << speed_err << " m/s\n";
}

TEST(TrajectoryFollower, StopsAtGoalAndHolds) {
  geometry::Path2 path;
  for (double x = 0; x <= 40; x += 2) path.points.emplace_back(x, 0);
  path.UpdateArcLength();
  Sim sim;
  sim.planner.SetRoute(path);
  sim.car.Reset(world::VehicleState{});
  bool stopping_at_end = false;
  sim.Run(40.0, {}, [&](double, const FollowerCommand& cmd) {
    stopping_at_end = cmd.stopping;
  });
  EXPECT_TRUE(stopping_at_end);
  EXPECT_NEAR(sim.car.state().v_mps, 0.0, 1e-9);
  EXPECT_NEAR(sim.car.state().x_m, 40.0, 1.0);
  EXPECT_NEAR(sim.car.state().y_m, 0.0, 0.1);
}

TEST(TrajectoryFollower, StopsBeforeObstacleWithMargin) {
  geometry::Path2 path;
  for (double x = 0; x <= 200; x += 5) path.points.emplace_back(x, 0);
  path.UpdateArcLength();
  Sim sim;
  sim.planner.SetRoute(path);
  sim.car.Reset(world::VehicleState{});
  PlannerObstacle car;
  car.position = {60.0, 0.0};
  car.length_m = 4.5;
  car.width_m = 1.8;
  double max_x = 0.0;
  sim.Run(40.0, {car}, [&](double, const FollowerCommand&) {
    max_x = std::max(max_x, sim.car.state().x_m);
  });
  const ObstacleStopParams& p = sim.stop;
  const double front_limit = 60.0 - 2.25 - p.stop_margin_m;
  EXPECT_LE(max_x + p.ego_front_m, front_limit + 0.3);  // small overshoot
  EXPECT_GT(max_x + p.ego_front_m, front_limit - 1.5);  // but got close
  EXPECT_NEAR(sim.car.state().v_mps, 0.0, 1e-9);
}

TEST(TrajectoryFollower, BrakesWithoutTrajectory) {
  FollowerParams params;
  TrajectoryFollower follower(params);
  follower.Update(geometry::Pose2{0, 0.5, 0}, 3.0, Line(0, 5, 20), 0.02);
  const FollowerCommand cmd = follower.Update(geometry::Pose2{}, 3.0, {}, 0.02);
  EXPECT_TRUE(cmd.no_trajectory);
  EXPECT_TRUE(cmd.stopping);
  EXPECT_DOUBLE_EQ(cmd.accel_mps2, -params.no_trajectory_decel_mps2);
  EXPECT_LT(cmd.steer_rad, 0.0);  // held from the last command
  // A trajectory that says stop here: brakes, even at standstill.
  const FollowerCommand hold =
      follower.Update(geometry::Pose2{}, 0.0, Line(0, 0, 20), 0.02);
  EXPECT_TRUE(hold.stopping);
  EXPECT_LT(hold.accel_mps2, 0.0);
}

}  // namespace
}  // namespace adse::algorithms
