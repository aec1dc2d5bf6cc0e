#include "stack/world/manoeuvre_tracker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "stack/algorithms/parking_control.h"

namespace adse::world {
namespace {

using algorithms::GearedPose;

struct Drive {
  bool finished = false;
  double max_error_m = 0.0;  // from the path's polyline
  double time_s = 0.0;
  VehicleState end;
};

// Drives the car model through `path` with the tracker at the world's
// 20 Hz from the path's first pose, standing, wheels straight.
Drive DriveThrough(const std::vector<GearedPose>& path) {
  const VehicleLimits limits;
  BicycleModel car(limits);
  VehicleState start;
  start.x_m = path.front().pose.x_m;
  start.y_m = path.front().pose.y_m;
  start.yaw_rad = path.front().pose.yaw_rad;
  car.Reset(start);
  ManoeuvreTracker tracker(path, limits);
  Drive drive;
  const double dt = 0.05;
  for (int step = 0; step < 4000 && !tracker.finished(); ++step) {
    const VehicleState& ego = car.state();
    drive.max_error_m = std::max(
        drive.max_error_m,
        algorithms::DistanceFromPath(path, Eigen::Vector2d(ego.x_m, ego.y_m)));
    car.Step(tracker.Update(ego), dt);
    drive.time_s += dt;
  }
  drive.finished = tracker.finished();
  drive.end = car.state();
  return drive;
}

// The shortest Reeds-Shepp manoeuvre from `from` to `to` at `radius_m`.
std::vector<GearedPose> Manoeuvre(const geometry::Pose2& from,
                                  const geometry::Pose2& to, double radius_m) {
  const auto paths = algorithms::ReedsSheppCandidates(from, to, radius_m);
  EXPECT_FALSE(paths.empty());
  return algorithms::SampleReedsShepp(from, paths.front(), radius_m, 0.1);
}

int Moves(const std::vector<GearedPose>& path) {
  int moves = 1;
  for (size_t i = 1; i < path.size(); ++i) {
    moves += path[i].reverse != path[i - 1].reverse;
  }
  return moves;
}

void ExpectEndsAt(const Drive& drive, const geometry::Pose2& goal) {
  EXPECT_TRUE(drive.finished);
  EXPECT_NEAR(drive.end.x_m, goal.x_m, 0.15);
  EXPECT_NEAR(drive.end.y_m, goal.y_m, 0.15);
  EXPECT_NEAR(std::remainder(drive.end.yaw_rad - goal.yaw_rad, 2 * M_PI), 0.0,
              0.06);
  EXPECT_LT(std::abs(drive.end.v_mps), 0.05);
}

TEST(ManoeuvreTrackerTest, ATurnInThreeMovesIsDrivenCloseToItsPath) {
  // Round between lanes 4 m apart, half the width the car's circle needs.
  const geometry::Pose2 from{0.0, 0.0, 0.0};
  const geometry::Pose2 to{0.0, 4.0, M_PI};
  const std::vector<GearedPose> path = Manoeuvre(from, to, 4.5);
  ASSERT_GE(Moves(path), 2);
  const Drive drive = DriveThrough(path);
  ExpectEndsAt(drive, to);
  EXPECT_LT(drive.max_error_m, 0.25);
}

TEST(ManoeuvreTrackerTest, MovesShorterThanAPurePursuitLookaheadAreFollowed) {
  // A sideways shift of 1.2 m with the heading kept: short moves at the
  // minimum radius, the kind the stack's parking controller (2 m
  // lookahead) strayed from on real nets' turns.
  const VehicleLimits limits;
  const double radius = limits.wheelbase_m / std::tan(limits.max_steer_rad);
  const geometry::Pose2 from{0.0, 0.0, 0.0};
  const geometry::Pose2 to{0.5, 1.2, 0.0};
  const std::vector<GearedPose> path = Manoeuvre(from, to, radius * 1.05);
  ASSERT_GE(Moves(path), 3);
  const Drive drive = DriveThrough(path);
  ExpectEndsAt(drive, to);
  EXPECT_LT(drive.max_error_m, 0.3);
}

TEST(ManoeuvreTrackerTest, AnEmptyPathIsFinishedAtOnce) {
  ManoeuvreTracker tracker({}, VehicleLimits{});
  EXPECT_TRUE(tracker.finished());
  const ControlCommand c = tracker.Update(VehicleState{});
  EXPECT_LT(c.accel_mps2, 0.0);
}

}  // namespace
}  // namespace adse::world
