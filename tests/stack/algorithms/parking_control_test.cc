#include "stack/algorithms/parking_control.h"

#include <gtest/gtest.h>

#include <cmath>

#include "stack/algorithms/freespace_planner.h"
#include "stack/world/vehicle_model.h"
#include "tests/stack/algorithms/testing/parking_row.h"

namespace adse::algorithms {
namespace {

using geometry::Pose2;

struct Drive {
  Pose2 end;
  int motion_reversals = 0;  // sign changes of the car's speed
  double max_lateral_error_m = 0.0;
  double time_s = 0.0;
  bool finished = false;
  bool collided = false;
};

// Drives the ego's bicycle model along `path` with the parking follower at
// 30 Hz, as the stack's control timer does, until it reports finished.
Drive DrivePath(const FreespacePath& path, const testing::Lot& lot) {
  world::BicycleModel car{world::VehicleLimits{}};
  world::VehicleState s;
  s.x_m = path.poses.front().pose.x_m;
  s.y_m = path.poses.front().pose.y_m;
  s.yaw_rad = path.poses.front().pose.yaw_rad;
  car.Reset(s);
  ParkingFollower follower;
  follower.SetPath(path.poses);
  Drive drive;
  const double dt = 1.0 / 30.0;
  int last_sign = 0;
  world::ControlCommand command;
  for (int i = 0; i < 30 * 120 && !drive.finished; ++i) {
    const world::VehicleState& st = car.state();
    const ParkingCommand c =
        follower.Update({st.x_m, st.y_m, st.yaw_rad}, st.v_mps, dt);
    drive.finished = c.finished;
    drive.max_lateral_error_m =
        std::max(drive.max_lateral_error_m, std::abs(c.lateral_error_m));
    command = {c.accel_mps2, c.steer_rad, c.reverse};
    car.Step(command, dt);
    const int sign = car.state().v_mps > 1e-3    ? 1
                     : car.state().v_mps < -1e-3 ? -1
                                                 : 0;
    if (sign != 0 && last_sign != 0 && sign != last_sign) {
      ++drive.motion_reversals;
    }
    if (sign != 0) last_sign = sign;
    for (const geometry::OrientedBox& b : lot.boxes) {
      drive.collided = drive.collided || geometry::BoxesOverlap(car.Body(), b);
    }
    drive.time_s += dt;
  }
  drive.end = {car.state().x_m, car.state().y_m, car.state().yaw_rad};
  return drive;
}

void ExpectParks(bool nose_in) {
  const testing::Lot lot = testing::MakeLot();
  FreespacePlanner planner({}, testing::Footprint());
  const Pose2 goal = testing::SlotGoal(nose_in);
  const Result<FreespacePath> path =
      planner.Plan(testing::kStart, goal, lot.Outlines());
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  const Drive drive = DrivePath(*path, lot);
  EXPECT_TRUE(drive.finished);
  EXPECT_FALSE(drive.collided);
  EXPECT_LT(std::hypot(drive.end.x_m - goal.x_m, drive.end.y_m - goal.y_m),
            0.3);
  EXPECT_LT(
      std::abs(std::remainder(drive.end.yaw_rad - goal.yaw_rad, 2 * M_PI)),
      0.1);
  // The car shifted where the path does, and no more.
  EXPECT_EQ(drive.motion_reversals, path->gear_changes);
  EXPECT_LT(drive.max_lateral_error_m, 0.35);
  EXPECT_LT(drive.time_s, 90.0);
}

TEST(ParkingFollower, ParksNoseInOnThePlannedPath) { ExpectParks(true); }

TEST(ParkingFollower, BacksIntoTheSlotOnThePlannedPath) { ExpectParks(false); }

TEST(ParkingFollower, SplitsThePathAtGearChanges) {
  std::vector<GearedPose> poses;
  for (int i = 0; i <= 4; ++i) poses.push_back({{0.5 * i, 0, 0}, false});
  for (int i = 1; i <= 4; ++i) poses.push_back({{2.0 - 0.5 * i, 0, 0}, true});
  ParkingFollower follower;
  follower.SetPath(poses);
  EXPECT_EQ(follower.segments(), 2);
  // At the start, standing: forwards, speeding up.
  ParkingCommand c = follower.Update({0, 0, 0}, 0.0, 0.05);
  EXPECT_FALSE(c.reverse);
  EXPECT_GT(c.accel_mps2, 0);
  EXPECT_NEAR(c.remaining_m, 2.0, 1e-9);
  // At the cusp but still rolling: brake, no shift yet.
  c = follower.Update({2.0, 0, 0}, 0.3, 0.05);
  EXPECT_FALSE(c.reverse);
  EXPECT_LT(c.accel_mps2, 0);
  // Standing at the cusp: shift to reverse and drive the second segment.
  c = follower.Update({2.0, 0, 0}, 0.0, 0.05);
  EXPECT_TRUE(c.reverse);
  EXPECT_EQ(c.segment, 1);
  EXPECT_GT(c.accel_mps2, 0);
  EXPECT_NEAR(c.steer_rad, 0.0, 1e-9);
  // Standing at the end: finished, holding.
  c = follower.Update({0.0, 0, 0}, 0.0, 0.05);
  EXPECT_TRUE(c.finished);
  EXPECT_LT(c.accel_mps2, 0);
  // Finished stays finished, wherever the pose estimate moves next.
  c = follower.Update({0.5, 0.1, 0}, 0.0, 0.05);
  EXPECT_TRUE(c.finished);
  EXPECT_LT(c.accel_mps2, 0);
  EXPECT_TRUE(c.reverse);
  // A new path starts over.
  follower.SetPath(poses);
  EXPECT_FALSE(follower.Update({0, 0, 0}, 0.0, 0.05).finished);
}

TEST(ParkingFollower, ReverseSteeringTurnsTowardsThePath) {
  // Backing along -x with the path 0.5 m to the car's left (y > 0, the car
  // facing +x): backing up with the wheels turned left swings the rear to
  // the left, towards the path (and the nose right).
  std::vector<GearedPose> poses;
  for (int i = 0; i <= 20; ++i) poses.push_back({{-0.5 * i, 0.5, 0}, true});
  ParkingFollower follower;
  follower.SetPath(poses);
  const ParkingCommand c = follower.Update({0, 0, 0}, -0.5, 0.05);
  EXPECT_TRUE(c.reverse);
  EXPECT_GT(c.steer_rad, 0.05);
}

TEST(ParkingFollower, OffItsCourseItBrakesAndHoldsUntilANewPath) {
  // A straight path forwards along y = 0, course out beyond 1 m.
  std::vector<GearedPose> poses;
  for (int i = 0; i <= 20; ++i) poses.push_back({{0.5 * i, 0.0, 0}, false});
  ParkingFollowerParams params;
  params.course_out_m = 1.0;
  ParkingFollower follower(params);
  follower.SetPath(poses);
  // On course (0.8 m off): it drives.
  ParkingCommand c = follower.Update({2.0, 0.8, 0}, 1.0, 0.05);
  EXPECT_FALSE(c.course_out);
  EXPECT_GT(c.target_speed_mps, 0.0);
  // 1.2 m off, moving: full brake; standing: holds; never finished.
  c = follower.Update({2.5, 1.2, 0}, 1.0, 0.05);
  EXPECT_TRUE(c.course_out);
  EXPECT_DOUBLE_EQ(c.accel_mps2, -params.max_brake_mps2);
  EXPECT_FALSE(c.finished);
  c = follower.Update({2.6, 1.2, 0}, 0.0, 0.05);
  EXPECT_TRUE(c.course_out);
  EXPECT_LT(c.accel_mps2, 0.0);
  EXPECT_FALSE(c.finished);
  // A path from where it stands: it drives again.
  std::vector<GearedPose> from_here;
  for (int i = 0; i <= 20; ++i)
    from_here.push_back({{2.6 + 0.5 * i, 1.2, 0}, false});
  follower.SetPath(from_here);
  c = follower.Update({2.6, 1.2, 0}, 0.0, 0.05);
  EXPECT_FALSE(c.course_out);
  EXPECT_GT(c.accel_mps2, 0.0);
  // course_out_m 0: never off course.
  ParkingFollower lenient;
  lenient.SetPath(poses);
  EXPECT_FALSE(lenient.Update({2.5, 5.0, 0}, 1.0, 0.05).course_out);
}

// A shuffle that turns the car on the spot: eight moves of 0.6 m at full
// lock, forwards to the left and backwards to the right, each turning the
// car 0.15 rad counter-clockwise, as the freespace planner plans in a tight
// U-turn. Returns the heading at the end less the planned one.
double ShuffleHeadingError(double steer_rate_rad_per_s, double* time_s) {
  const world::VehicleLimits limits;
  const double k = std::tan(limits.max_steer_rad) / limits.wheelbase_m;
  std::vector<GearedPose> poses;
  Pose2 p{0, 0, 0};
  poses.push_back({p, false});
  for (int move = 0; move < 8; ++move) {
    const bool reverse = move % 2 == 1;
    for (int i = 0; i < 6; ++i) {
      const double ds = reverse ? -0.1 : 0.1;
      p.x_m += ds * std::cos(p.yaw_rad);
      p.y_m += ds * std::sin(p.yaw_rad);
      p.yaw_rad += 0.1 * k;
      poses.push_back({p, reverse});
    }
  }
  ParkingFollowerParams params;
  params.steer_rate_rad_per_s = steer_rate_rad_per_s;
  ParkingFollower follower(params);
  follower.SetPath(poses);
  world::BicycleModel car{limits};
  car.Reset(world::VehicleState{});
  const double dt = 1.0 / 30.0;
  *time_s = 0.0;
  for (int i = 0; i < 30 * 120; ++i) {
    const world::VehicleState& st = car.state();
    const ParkingCommand c =
        follower.Update({st.x_m, st.y_m, st.yaw_rad}, st.v_mps, dt);
    if (c.finished) break;
    car.Step({c.accel_mps2, c.steer_rad, c.reverse}, dt);
    *time_s += dt;
  }
  return std::remainder(car.state().yaw_rad - p.yaw_rad, 2 * M_PI);
}

TEST(ParkingFollower, ShortMovesTurnTheCarAsPlannedWhenItSteersStanding) {
  // The wheels swing lock to lock in 1.5 s; steered on the way, a 0.6 m
  // move is half over before they reach the lock it was planned at.
  double steered_standing_s = 0.0, steered_moving_s = 0.0;
  const double standing = ShuffleHeadingError(
      world::VehicleLimits{}.max_steer_rate_rad_per_s, &steered_standing_s);
  const double moving = ShuffleHeadingError(0.0, &steered_moving_s);
  // Steered on the way the shuffle loses 0.79 rad of its 1.22; steered
  // standing, 0.31 (each move still ends within its 0.1 m tolerance,
  // short of its end).
  EXPECT_GT(std::abs(moving), 0.6);
  EXPECT_LT(std::abs(standing), 0.5 * std::abs(moving));
  // Each of the 7 shifts waits about a lock-to-lock swing, 1.5 s.
  EXPECT_GT(steered_standing_s - steered_moving_s, 7 * 1.0);
}

TEST(DistanceFromPath, IsTheDistanceToTheNearestStretchOfThePolyline) {
  const std::vector<GearedPose> poses = {
      {{0, 0, 0}, false}, {{4, 0, 0}, false}, {{4, 3, 0}, true}};
  EXPECT_NEAR(DistanceFromPath(poses, {2, 1}), 1.0, 1e-12);
  EXPECT_NEAR(DistanceFromPath(poses, {5, 2}), 1.0, 1e-12);
  EXPECT_NEAR(DistanceFromPath(poses, {-3, 4}), 5.0, 1e-12);
  EXPECT_NEAR(DistanceFromPath({poses[0]}, {3, 4}), 5.0, 1e-12);
  EXPECT_TRUE(std::isinf(DistanceFromPath({}, {0, 0})));
}

}  // namespace
}  // namespace adse::algorithms
