#include "stack/algorithms/lane_change.h"

#include <gtest/gtest.h>

#include <vector>

namespace adse::algorithms {
namespace {

constexpr double kLaneM = 3.2;

// A road along x whose route moves one lane over (left for shift > 0)
// between x = 30 and x = 60.
LaneChangeSection Section(double shift_m = kLaneM) {
  LaneChangeSection section;
  section.start_s_m = 30.0;
  section.end_s_m = 60.0;
  section.shift_m = shift_m;
  section.lane_width_m = kLaneM;
  return section;
}

geometry::Path2 Route(const LaneChangeSection& section) {
  geometry::Path2 route;
  for (double x = 0.0; x <= 300.0 + 1e-9; x += 1.0) {
    route.points.emplace_back(x, section.shift_m * section.Weight(x));
  }
  route.UpdateArcLength();
  return route;
}

// The path ahead from route s `from_s` at the lane's limit (x ~ s: the
// shift bends the route by a few centimetres per metre at most).
std::vector<PlannedPoint> PathFrom(double from_s, double v_mps = 8.33) {
  std::vector<PlannedPoint> points;
  for (double s = from_s; s <= from_s + 50.0 + 1e-9; s += 1.0) {
    PlannedPoint p;
    p.x_m = s;
    p.s_m = s;
    p.v_mps = v_mps;
    points.push_back(p);
  }
  return points;
}

PlannerObstacle Car(int id, double x, double y, double vx) {
  PlannerObstacle ob;
  ob.id = id;
  ob.position = {x, y};
  ob.velocity = {vx, 0.0};
  ob.length_m = 4.5;
  ob.width_m = 1.8;
  ob.age = 20;
  return ob;
}

double SpeedAt(const std::vector<PlannedPoint>& points, double s) {
  for (const PlannedPoint& p : points) {
    if (p.s_m >= s - 1e-9) return p.v_mps;
  }
  return points.back().v_mps;
}

TEST(LaneChangeSection, WeightIsASmoothstepFromStartToEnd) {
  const LaneChangeSection section = Section();
  EXPECT_DOUBLE_EQ(section.Weight(0.0), 0.0);
  EXPECT_DOUBLE_EQ(section.Weight(30.0), 0.0);
  EXPECT_DOUBLE_EQ(section.Weight(45.0), 0.5);
  EXPECT_NEAR(section.Weight(37.5), 0.15625, 1e-12);
  EXPECT_DOUBLE_EQ(section.Weight(60.0), 1.0);
  EXPECT_DOUBLE_EQ(section.Weight(90.0), 1.0);
}

TEST(RssGap, ACarBehindNeedsRoomToReactAndBrakeWhenFaster) {
  LaneChangeParams params;  // ego 3.8 m ahead of its rear axle, 1 m behind
  // 20 m behind the ego's rear bumper, 14 m/s against the ego's 8.
  const LaneChangeGap behind =
      RssGap(100.0, 8.0, 100.0 - 1.0 - 20.0 - 2.25, 14.0, 4.5, params);
  EXPECT_NEAR(behind.gap_m, 20.0, 1e-9);
  // 14 x 2 + 14^2 / 2 - 8^2 / 2 + 14 x 1.
  EXPECT_NEAR(behind.required_m, 28.0 + 98.0 - 32.0 + 14.0, 1e-9);
  // A slower car ahead: the ego is the rear car.
  const LaneChangeGap ahead =
      RssGap(100.0, 8.0, 100.0 + 3.8 + 30.0 + 2.25, 5.0, 4.5, params);
  EXPECT_NEAR(ahead.gap_m, 30.0, 1e-9);
  EXPECT_NEAR(ahead.required_m, 16.0 + 32.0 - 12.5 + 8.0, 1e-9);
  // Beside the car the gap is negative; never less than min_gap_m is asked.
  const LaneChangeGap beside = RssGap(100.0, 8.0, 100.5, 8.0, 4.5, params);
  EXPECT_LT(beside.gap_m, 0.0);
  const LaneChangeGap slow = RssGap(100.0, 8.0, 90.0, 0.0, 4.5, params);
  EXPECT_DOUBLE_EQ(slow.required_m, params.min_gap_m);
}

TEST(LaneChangeGuard, WaitsAtTheSectionForACarOvertakingInTheTargetLane) {
  const LaneChangeSection section = Section();
  LaneChangeGuard guard(Route(section), {section});
  std::vector<PlannedPoint> points = PathFrom(15.0);
  // In the lane to the left, 2 m behind at 10 m/s: alongside when the
  // ego's front reaches the section 1.5 s on.
  const ObstacleStop stop =
      guard.Plan(&points, {Car(7, 13.0, kLaneM, 10.0)}, 8.0, 0.0);
  ASSERT_TRUE(stop.stop);
  EXPECT_EQ(stop.reason, StopReason::kLaneChange);
  EXPECT_EQ(stop.obstacle_id, 7);
  EXPECT_DOUBLE_EQ(stop.stop_s_m, 30.0);
  EXPECT_GT(SpeedAt(points, 29.0), 0.0);
  EXPECT_EQ(SpeedAt(points, 30.0), 0.0);
  EXPECT_GT(stop.work_units, 0);
}

TEST(LaneChangeGuard, GoesWhenOnlyOtherLanesHaveTraffic) {
  const LaneChangeSection section = Section();
  LaneChangeGuard guard(Route(section), {section});
  std::vector<PlannedPoint> points = PathFrom(10.0);
  const std::vector<PlannerObstacle> others = {
      Car(1, 2.0, 0.0, 14.0),           // behind in the lane it leaves
      Car(2, 12.0, 2.0 * kLaneM, 0.0),  // two lanes over, standing
      Car(3, 14.0, -kLaneM, 14.0),      // the lane on the other side
      Car(4, 160.0, kLaneM, 10.0),      // far ahead in the target lane
  };
  const ObstacleStop stop = guard.Plan(&points, others, 8.0, 0.0);
  EXPECT_FALSE(stop.stop);
  for (const PlannedPoint& p : points) EXPECT_DOUBLE_EQ(p.v_mps, 8.33);
}

TEST(LaneChangeGuard, AFastCarFarBehindInTheTargetLaneStillNeedsItsGap) {
  const LaneChangeSection section = Section();
  // 40 m behind at 14 m/s against the ego's 8: the RSS distance is about
  // 100 m while the ego changes lane.
  {
    LaneChangeGuard guard(Route(section), {section});
    std::vector<PlannedPoint> points = PathFrom(10.0);
    EXPECT_TRUE(
        guard.Plan(&points, {Car(1, -30.0, kLaneM, 14.0)}, 8.0, 0.0).stop);
  }
  // The same car at 6 m/s falls back: no reason to wait.
  {
    LaneChangeGuard guard(Route(section), {section});
    std::vector<PlannedPoint> points = PathFrom(10.0);
    EXPECT_FALSE(
        guard.Plan(&points, {Car(1, -30.0, kLaneM, 6.0)}, 8.0, 0.0).stop);
  }
}

TEST(LaneChangeGuard, ChangingRightLooksAtTheLaneOnTheRight) {
  const LaneChangeSection section = Section(-kLaneM);
  LaneChangeGuard right(Route(section), {section});
  std::vector<PlannedPoint> points = PathFrom(15.0);
  EXPECT_TRUE(
      right.Plan(&points, {Car(1, 13.0, -kLaneM, 10.0)}, 8.0, 0.0).stop);
  LaneChangeGuard left_clear(Route(section), {section});
  points = PathFrom(15.0);
  EXPECT_FALSE(
      left_clear.Plan(&points, {Car(1, 13.0, kLaneM, 10.0)}, 8.0, 0.0).stop);
}

TEST(LaneChangeGuard, AStandingCarAheadIsLeftToTheObstacleStop) {
  const LaneChangeSection section = Section();
  LaneChangeGuard guard(Route(section), {section});
  std::vector<PlannedPoint> points = PathFrom(10.0);
  PlannerObstacle parked = Car(1, 70.0, kLaneM, 0.0);
  EXPECT_FALSE(guard.Plan(&points, {parked}, 8.0, 0.0).stop);
  // Map structure taken for an object is no traffic either.
  PlannerObstacle wall = Car(2, 12.0, kLaneM, 14.0);
  wall.static_structure = true;
  EXPECT_FALSE(guard.Plan(&points, {wall}, 8.0, 0.1).stop);
}

TEST(LaneChangeGuard, ACarThatCannotStopBeforeTheSectionIsCommitted) {
  const LaneChangeSection section = Section();
  LaneChangeGuard guard(Route(section), {section});
  // 2 m before the section at 8 m/s: 12.8 m to stop at 2.5 m/s^2.
  std::vector<PlannedPoint> points = PathFrom(28.0);
  EXPECT_FALSE(
      guard.Plan(&points, {Car(1, 26.0, kLaneM, 14.0)}, 8.0, 0.0).stop);
  // Inside the section it goes on as well.
  points = PathFrom(40.0);
  EXPECT_FALSE(
      guard.Plan(&points, {Car(1, 38.0, kLaneM, 14.0)}, 8.0, 0.1).stop);
}

TEST(LaneChangeGuard, HoldsUntilTheGapHasLastedTheTransitMargin) {
  const LaneChangeSection section = Section();
  LaneChangeGuard guard(Route(section), {section});  // margin 1 s
  // Standing 5 m before the section; a car 25 m behind at 10 m/s.
  std::vector<PlannedPoint> points = PathFrom(25.0);
  ASSERT_TRUE(guard.Plan(&points, {Car(5, 0.0, kLaneM, 10.0)}, 0.0, 10.0).stop);
  // The car has gone by; the guard still holds, and names the car it held
  // for, until a second has passed without a reason to wait.
  points = PathFrom(29.9);
  const ObstacleStop held = guard.Plan(&points, {}, 0.0, 10.5);
  EXPECT_TRUE(held.stop);
  EXPECT_EQ(held.obstacle_id, 5);
  EXPECT_EQ(SpeedAt(points, 30.0), 0.0);
  points = PathFrom(29.9);
  EXPECT_FALSE(guard.Plan(&points, {}, 0.0, 11.1).stop);
}

TEST(LaneChangeGuard, AWaitingCarChecksTheGapAsItWouldPullAway) {
  const LaneChangeSection section = Section();
  LaneChangeGuard guard(Route(section), {section});
  // Standing at the section, a car 60 m behind at 14 m/s arrives before
  // the ego, speeding up from 0 at 1.5 m/s^2, has cleared 30 m.
  std::vector<PlannedPoint> points = PathFrom(29.9);
  EXPECT_TRUE(
      guard.Plan(&points, {Car(1, -30.0, kLaneM, 14.0)}, 0.0, 0.0).stop);
}

TEST(LaneChangeGuard, ARouteWithoutLaneChangesNeverStops) {
  LaneChangeGuard guard(Route(Section()), {});
  std::vector<PlannedPoint> points = PathFrom(10.0);
  const ObstacleStop stop =
      guard.Plan(&points, {Car(1, 8.0, kLaneM, 14.0)}, 8.0, 0.0);
  EXPECT_FALSE(stop.stop);
  EXPECT_EQ(stop.work_units, 0);
}

}  // namespace
}  // namespace adse::algorithms
