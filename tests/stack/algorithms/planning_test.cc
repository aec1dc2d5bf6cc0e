#include "stack/algorithms/planning.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/stack/algorithms/testing/planning_chain.h"

namespace adse::algorithms {
namespace {

constexpr double kPi = 3.14159265358979323846;

geometry::Path2 Polyline(std::vector<Eigen::Vector2d> points) {
  geometry::Path2 path;
  path.points = std::move(points);
  path.UpdateArcLength();
  return path;
}

geometry::Path2 Straight(double length_m, double step_m) {
  std::vector<Eigen::Vector2d> pts;
  for (double x = 0.0; x <= length_m + 1e-9; x += step_m)
    pts.emplace_back(x, 0);
  return Polyline(pts);
}

PlannerObstacle Car(int id, double x, double y) {
  PlannerObstacle ob;
  ob.id = id;
  ob.position = {x, y};
  ob.length_m = 4.5;
  ob.width_m = 1.8;
  return ob;
}

TEST(PathPlanner, FreeRoadAtSpeedLimit) {
  PathPlanner planner;
  planner.SetRoute(Straight(200, 5));
  const PlannedPath path = planner.Plan(geometry::Pose2{10.2, 0.3, 0});
  ASSERT_EQ(path.points.size(), 51u);
  EXPECT_NEAR(path.ego_s_m, 10.2, 1e-9);
  EXPECT_NEAR(path.lateral_offset_m, 0.3, 1e-9);
  EXPECT_NEAR(path.points.front().s_m, 10.2, 1e-9);
  EXPECT_NEAR(path.points.back().s_m, 60.2, 1e-9);
  EXPECT_NEAR(path.points[5].x_m, 15.2, 1e-9);
  EXPECT_FALSE(path.ends_at_goal);
  for (const PlannedPoint& p : path.points) {
    EXPECT_DOUBLE_EQ(p.v_mps, planner.params().speed_limit_mps);
  }
  EXPECT_EQ(path.work_units, 51);
  // The later stages leave a straight, free road at the limit.
  const testing::ChainedPlan chained =
      testing::PlanChain(&planner, geometry::Pose2{10.2, 0.3, 0}, {});
  EXPECT_FALSE(chained.obstacle.stop);
  for (const PlannedPoint& p : chained.points) {
    EXPECT_DOUBLE_EQ(p.v_mps, planner.params().speed_limit_mps);
  }
}

TEST(PathPlanner, EndsAtGoalAndVelocityPlannerStopsThere) {
  PathPlanner planner;
  planner.SetRoute(Straight(100, 5));
  const testing::ChainedPlan plan =
      testing::PlanChain(&planner, geometry::Pose2{70, 0, 0}, {});
  EXPECT_TRUE(plan.path.ends_at_goal);
  ASSERT_FALSE(plan.points.empty());
  EXPECT_NEAR(plan.points.back().s_m, 100.0, 1e-9);
  EXPECT_EQ(plan.points.back().v_mps, 0.0);
  EXPECT_GT(plan.points[plan.points.size() - 2].v_mps, 0.0);
  // Past the goal: one point, speed 0.
  const testing::ChainedPlan after =
      testing::PlanChain(&planner, geometry::Pose2{103, 0, 0}, {});
  EXPECT_TRUE(after.path.ends_at_goal);
  ASSERT_EQ(after.points.size(), 1u);
  EXPECT_EQ(after.points[0].v_mps, 0.0);
}

TEST(PathPlanner, GoalPointProjectedOnRoute) {
  PathPlanner planner;
  planner.SetRoute(Straight(100, 5), Eigen::Vector2d(60.0, 0.4));
  EXPECT_NEAR(planner.goal_s_m(), 60.0, 1e-9);
  const testing::ChainedPlan plan =
      testing::PlanChain(&planner, geometry::Pose2{30, 0, 0}, {});
  EXPECT_TRUE(plan.path.ends_at_goal);
  EXPECT_NEAR(plan.points.back().s_m, 60.0, 1e-9);
  EXPECT_EQ(plan.points.back().v_mps, 0.0);
}

TEST(ObstacleStopPlanner, StopsBeforeObstacleInCorridor) {
  PathPlanner planner;
  planner.SetRoute(Straight(200, 5));
  const ObstacleStopParams params;
  const testing::ChainedPlan plan = testing::PlanChain(
      &planner, geometry::Pose2{0, 0, 0}, {Car(7, 40.0, 0.5)});
  EXPECT_TRUE(plan.obstacle.stop);
  EXPECT_FALSE(plan.path.ends_at_goal);
  EXPECT_EQ(plan.obstacle.obstacle_id, 7);
  // Rear-axle stop point: the car's rear (37.75) - margin - ego front.
  const double expected_stop =
      40.0 - 2.25 - params.stop_margin_m - params.ego_front_m;
  EXPECT_NEAR(plan.obstacle.stop_s_m, expected_stop, 1e-9);
  // From the ego's front bumper (3.8 m ahead of the axle) to the car's rear.
  EXPECT_NEAR(plan.obstacle.gap_m, 37.75 - params.ego_front_m, 1e-9);
  bool saw_zero_at_stop = false;
  for (const PlannedPoint& p : plan.points) {
    // The ego front at this point is p.s + ego_front: standing still there
    // leaves at least the margin to the obstacle's rear.
    if (p.s_m + params.ego_front_m >=
        40.0 - 2.25 - params.stop_margin_m - 1e-6) {
      EXPECT_EQ(p.v_mps, 0.0) << "at s " << p.s_m;
    } else {
      EXPECT_GT(p.v_mps, 0.0) << "at s " << p.s_m;
    }
    if (std::abs(p.s_m - expected_stop) < 1e-9) saw_zero_at_stop = true;
  }
  EXPECT_TRUE(saw_zero_at_stop);  // an exact point at the stop line
  EXPECT_GT(plan.obstacle.work_units, 0);
}

TEST(ObstacleStopPlanner, IgnoresObstaclesOutsideCorridorOrBehind) {
  PathPlanner planner;
  planner.SetRoute(Straight(200, 5));
  // Next lane (3.5 m over: 3.5 - 0.9 > 1.4) and behind the ego.
  const testing::ChainedPlan plan =
      testing::PlanChain(&planner, geometry::Pose2{20, 0, 0},
                         {Car(1, 40.0, 3.5), Car(2, 5.0, 0.0)});
  EXPECT_FALSE(plan.obstacle.stop);
  EXPECT_EQ(plan.obstacle.obstacle_id, -1);
  for (const PlannedPoint& p : plan.points) EXPECT_GT(p.v_mps, 0.0);
  // A crossing car (across the path) reaches further sideways.
  PlannerObstacle crossing = Car(3, 40.0, 3.0);
  crossing.yaw_rad = kPi / 2;  // 2.25 m half extent across the path
  EXPECT_TRUE(
      testing::PlanChain(&planner, geometry::Pose2{20, 0, 0}, {crossing})
          .obstacle.stop);
}

TEST(ObstacleStopPlanner, ACarWaitingInTheCrossLaneOfALeftTurnDoesNotBlockIt) {
  // The east end of a parking-lot aisle (eastbound, y = 46.25) turning left
  // onto the ring road's northbound lane (x = 170.75), as the reference
  // study drives it. A car heading south in the ring road's other lane
  // (x = 167.25) waits 3 m short of the junction for the ego.
  const geometry::Path2 turn = Polyline({{150.0, 46.25},
                                         {161.43, 46.25},
                                         {165.39, 46.81},
                                         {168.41, 48.54},
                                         {170.18, 51.54},
                                         {170.75, 55.5},
                                         {170.75, 90.0}});
  const geometry::Pose2 ego{164.2, 46.75, 0.23};
  PlannerObstacle waiting = Car(4261, 167.25, 54.6);
  waiting.length_m = 5.0;
  waiting.yaw_rad = kPi / 2;  // along the ring road
  PathPlanner planner;
  planner.SetRoute(turn);
  EXPECT_FALSE(testing::PlanChain(&planner, ego, {waiting}).obstacle.stop);
  // The same car taken as a box along the map's x axis reaches 2.5 m
  // sideways, into the turn's corridor: the stand-off that tracked objects
  // without their heading caused.
  waiting.yaw_rad = 0.0;
  planner.SetRoute(turn);
  const testing::ChainedPlan blocked =
      testing::PlanChain(&planner, ego, {waiting});
  ASSERT_TRUE(blocked.obstacle.stop);
  EXPECT_EQ(blocked.obstacle.obstacle_id, 4261);
}

// A tight left turn: north along x = 0, a quarter circle of 5 m radius
// round (-5, 0), then west along y = 5. The car's front corner on the
// outside swings out to 7.5 m from the circle's centre, 2.5 m off the rear
// axle's path, where the corridor around that path (1.5 m) does not look.
TEST(ObstacleStopPlanner, SeesWhatTheFrontCornerWouldSweepInATightTurn) {
  std::vector<Eigen::Vector2d> route = {{0.0, -40.0}, {0.0, 0.0}};
  for (int k = 1; k <= 18; ++k) {
    const double a = kPi / 2 * k / 18;
    route.emplace_back(-5.0 + 5.0 * std::cos(a), 5.0 * std::sin(a));
  }
  route.emplace_back(-60.0, 5.0);
  PathPlanner planner;
  planner.SetRoute(Polyline(route));
  const ObstacleStopParams params;
  PlannerObstacle post = Car(9, -2.9, 7.1);  // 2.4 m outside the arc
  post.length_m = post.width_m = 0.5;
  std::vector<PlannedPoint> points =
      planner.Plan(geometry::Pose2{0.0, -12.0, kPi / 2}).points;
  const ObstacleStop stop = InsertObstacleStop(&points, {post}, {}, params);
  ASSERT_TRUE(stop.stop);
  EXPECT_EQ(stop.obstacle_id, 9);
  // The corner reaches it with the rear axle about 40 deg round the arc,
  // which starts at route s = 40 (the car is at 28); the car stops the
  // margin short of that.
  EXPECT_GT(stop.stop_s_m, 40.0 - params.stop_margin_m);
  EXPECT_LT(stop.stop_s_m, 40.0 + 3.9 - params.stop_margin_m);
  // 1.5 m further out the corner misses it.
  post.position = {-2.9 + 1.1, 7.1 + 1.1};
  points = planner.Plan(geometry::Pose2{0.0, -12.0, kPi / 2}).points;
  EXPECT_FALSE(InsertObstacleStop(&points, {post}, {}, params).stop);
}

// A junction of A10KW's (x - 1500, y - 1950): the route comes west, turns
// south round a sharp corner at (11.8, 7.5) and leaves east. The car, half
// way round and 0.5 m inside the corner, stood for a SUMO car that had
// stopped beside it 0.8 m off its right side, while the driver waited for
// the car's body in its path: the corridor along the path, which swings
// out to the corner, took the car beside it for one in its way. Driving
// off, the car turns away from it.
TEST(ObstacleStopPlanner, ACarWaitingBesideTheCarInItsTurnDoesNotHoldIt) {
  PathPlanner planner;
  planner.SetRoute(
      Polyline({{23.76, 16.30}, {22.78, 16.30}, {21.87, 15.89}, {20.96, 15.48},
                {20.05, 15.07}, {19.14, 14.66}, {18.23, 14.25}, {17.32, 13.84},
                {16.41, 13.42}, {15.50, 13.01}, {14.74, 12.39}, {14.08, 11.65},
                {13.47, 10.86}, {12.86, 10.07}, {12.25, 9.27},  {11.91, 8.35},
                {11.78, 7.87},  {11.81, 7.45},  {12.22, 7.16},  {12.63, 6.88},
                {13.62, 6.94},  {14.61, 7.02},  {15.60, 7.17},  {16.58, 7.38},
                {17.56, 7.58},  {18.53, 7.78},  {19.51, 7.98},  {20.49, 8.13},
                {21.49, 8.06},  {22.49, 8.00},  {23.48, 7.94},  {60.0, 7.0}}));
  const geometry::Pose2 ego{12.54, 8.76, -1.70};
  PlannerObstacle waiting = Car(3, 8.28, 9.13);
  waiting.length_m = 4.9;
  waiting.width_m = 1.8;
  waiting.yaw_rad = -0.716;
  const testing::ChainedPlan plan =
      testing::PlanChain(&planner, ego, {waiting});
  EXPECT_FALSE(plan.obstacle.stop) << "gap " << plan.obstacle.gap_m;
  // Without the car's own way off, only the path's: it passes 0.1 m from
  // the waiting car's corner.
  std::vector<PlannedPoint> points = planner.Plan(ego).points;
  EXPECT_TRUE(InsertObstacleStop(&points, {waiting}, {}, {}).stop);
  // A car 1 m nearer, within the clearance of the car's way off, holds it
  // where it stands.
  waiting.position.x() += 1.0;
  const testing::ChainedPlan held =
      testing::PlanChain(&planner, ego, {waiting});
  ASSERT_TRUE(held.obstacle.stop);
  EXPECT_EQ(held.obstacle.obstacle_id, 3);
  EXPECT_LE(held.obstacle.stop_s_m, held.points.front().s_m);
}

// Beside the car on a straight road, 1.4 m off its path (within the 1.5 m
// corridor, clear of the body and the drive-off clearance): a car passing
// there and edging in stops it, as it did before the drive-off check (on
// joined, a flow's car overtaking at 14.7 m/s cut in, and the car, which
// no longer counted it, ran into its rear); the same car standing there
// does not.
TEST(ObstacleStopPlanner,
     ARoadUserMovingAlongsideStopsTheCarOneStandingThereDoesNot) {
  PathPlanner planner;
  planner.SetRoute(Straight(200, 5));
  PlannerObstacle beside = Car(5, 22.0, 2.3);
  beside.velocity = {14.0, -0.5};
  const testing::ChainedPlan cutting_in =
      testing::PlanChain(&planner, geometry::Pose2{20, 0, 0}, {beside});
  ASSERT_TRUE(cutting_in.obstacle.stop);
  EXPECT_EQ(cutting_in.obstacle.obstacle_id, 5);
  beside.velocity = Eigen::Vector2d::Zero();
  EXPECT_FALSE(testing::PlanChain(&planner, geometry::Pose2{20, 0, 0}, {beside})
                   .obstacle.stop);
}

TEST(ObstacleStopPlanner, SeesAnObstacleJustPastThePathsEnd) {
  // The path ends at the horizon (50 m); a car 4 m past it still sets a
  // stop inside it, as it would on the full route.
  PathPlanner planner;
  planner.SetRoute(Straight(200, 5));
  const testing::ChainedPlan plan = testing::PlanChain(
      &planner, geometry::Pose2{0, 0, 0}, {Car(4, 54.0 + 2.25, 0.0)});
  ASSERT_TRUE(plan.obstacle.stop);
  EXPECT_NEAR(plan.obstacle.stop_s_m,
              54.0 - ObstacleStopParams().stop_margin_m - 3.8, 1e-9);
}

// A straight road east along y = 0 and a car 12 m north of it at x = 30,
// driving south across it at 7 m/s: its box (4.5 m along its heading)
// enters the corridor after 1.2 s and leaves it after 2.2 s.
struct CrossingCase {
  std::vector<PlannedPoint> points;
  PlannerObstacle car = Car(5, 30.0, 12.0);
};

// The obstacle planner's parameters the cases below are worked out for.
ObstacleStopParams CaseStop() {
  ObstacleStopParams params;
  params.corridor_half_width_m = 1.4;
  params.stop_margin_m = 3.0;
  return params;
}

CrossingCase Crossing(double ego_x_m) {
  PathPlanner planner;
  planner.SetRoute(Straight(200, 5));
  CrossingCase c;
  c.points = planner.Plan(geometry::Pose2{ego_x_m, 0, 0}).points;
  c.car.velocity = {0.0, -7.0};
  c.car.yaw_rad = -kPi / 2;
  c.car.age = 10;
  return c;
}

TEST(CrossingYield, StopsBeforeACarAboutToCrossWhileTheEgoWouldBeThere) {
  // Ego front at 18.8 m, 10.3 m from the crossing's near edge (29.1): at
  // 5 m/s it would be there after 2.1 s, while the car crosses.
  CrossingCase c = Crossing(15.0);
  const ObstacleStopParams stop = CaseStop();
  const ObstacleStop yield =
      InsertCrossingYield(&c.points, {c.car}, 5.0, stop, CrossingYieldParams());
  ASSERT_TRUE(yield.stop);
  EXPECT_EQ(yield.obstacle_id, 5);
  EXPECT_NEAR(yield.stop_s_m, 29.1 - stop.stop_margin_m - stop.ego_front_m,
              1e-6);
  EXPECT_NEAR(yield.gap_m, 29.1 - 18.8, 1e-6);
  for (const PlannedPoint& p : c.points) {
    EXPECT_EQ(p.v_mps == 0.0, p.s_m >= yield.stop_s_m - 1e-6) << p.s_m;
  }
  EXPECT_GT(yield.work_units, 0);
}

TEST(CrossingYield, LetsTheCarCrossWhenTheEgoWouldArriveAfterIt) {
  // From x = 0 the ego's front needs 5.1 s at 5 m/s; the car is gone at 2.2.
  CrossingCase c = Crossing(0.0);
  EXPECT_FALSE(InsertCrossingYield(&c.points, {c.car}, 5.0, CaseStop(),
                                   CrossingYieldParams())
                   .stop);
  // At walking pace (the ego's speed counts as at least 1 m/s) from 15 m
  // back it would be there after 10 s: no yield either.
  c = Crossing(15.0);
  CrossingYieldParams slow = CrossingYieldParams();
  slow.min_ego_speed_mps = 1.0;
  EXPECT_FALSE(
      InsertCrossingYield(&c.points, {c.car}, 0.0, CaseStop(), slow).stop);
}

TEST(CrossingYield, CountsOnTheEgoSpeedingUpTowardsTheCrossing) {
  // At 2 m/s, 13.3 m short of the crossing: at that speed it would arrive
  // after 6.7 s, long after the car; speeding up at 1.5 m/s^2 towards the
  // 8.3 m/s it plans, after 3.1 s, within a second of the car leaving.
  CrossingCase c = Crossing(12.0);
  EXPECT_TRUE(InsertCrossingYield(&c.points, {c.car}, 2.0, CaseStop(),
                                  CrossingYieldParams())
                  .stop);
  c = Crossing(12.0);
  CrossingYieldParams steady = CrossingYieldParams();
  steady.max_accel_mps2 = 0.0;
  EXPECT_FALSE(
      InsertCrossingYield(&c.points, {c.car}, 2.0, CaseStop(), steady).stop);
}

TEST(CrossingYield, DrivesThroughACrossingItCanNoLongerStopBefore) {
  // Ego front at 23.8 m: the yield line (22.3) is 2.3 m ahead of the rear
  // axle, short of the 5 m it needs to stop from 5 m/s at 2.5 m/s^2.
  CrossingCase c = Crossing(20.0);
  EXPECT_FALSE(InsertCrossingYield(&c.points, {c.car}, 5.0, CaseStop(),
                                   CrossingYieldParams())
                   .stop);
  // Unless it was yielding already: braking for crossing traffic, it stops.
  c = Crossing(20.0);
  EXPECT_TRUE(InsertCrossingYield(&c.points, {c.car}, 5.0, CaseStop(),
                                  CrossingYieldParams(), /*yielding=*/true)
                  .stop);
  // At 2 m/s it stops in 0.8 m and is there after 2.7 s: it yields.
  c = Crossing(20.0);
  EXPECT_TRUE(InsertCrossingYield(&c.points, {c.car}, 2.0, CaseStop(),
                                  CrossingYieldParams())
                  .stop);
}

TEST(CrossingYield, FollowingOncomingSlowNewAndPresentTracksAreNotYieldedTo) {
  CrossingCase c = Crossing(15.0);
  PlannerObstacle ahead = Car(1, 40.0, 0.0);  // in the lane, driving away
  ahead.velocity = {6.0, 0.0};
  PlannerObstacle oncoming = Car(2, 60.0, 3.5);  // next lane, towards us
  oncoming.velocity = {-8.0, 0.0};
  PlannerObstacle creeping = c.car;  // the crossing car, at 2 m/s
  creeping.id = 3;
  creeping.velocity = {0.0, -2.0};
  PlannerObstacle young = c.car;  // a track of 2 updates: speed unknown
  young.id = 7;
  young.age = 2;
  PlannerObstacle crossing_now = c.car;  // already in the corridor
  crossing_now.id = 4;
  crossing_now.position = {30.0, 1.0};
  for (const PlannerObstacle& ob :
       {ahead, oncoming, creeping, young, crossing_now}) {
    std::vector<PlannedPoint> points = c.points;
    EXPECT_FALSE(InsertCrossingYield(&points, {ob}, 5.0, CaseStop(),
                                     CrossingYieldParams())
                     .stop)
        << "obstacle " << ob.id;
  }
  // A horizon of 0 yields to nothing.
  CrossingYieldParams never = CrossingYieldParams();
  never.horizon_s = 0.0;
  EXPECT_FALSE(
      InsertCrossingYield(&c.points, {c.car}, 5.0, CaseStop(), never).stop);
}

TEST(CrossingYield, AYieldIsHeldUntilTheWayHasBeenClearForTheMargin) {
  CrossingYielder yielder{CrossingYieldParams()};  // transit margin 1 s
  const ObstacleStopParams stop = CaseStop();
  CrossingCase c = Crossing(15.0);
  const ObstacleStop first = yielder.Plan(&c.points, {c.car}, 5.0, 10.0, stop);
  ASSERT_TRUE(first.stop);
  // A second car crossing further on (x = 35) is a reason to yield too,
  // but does not move the line forward.
  c = Crossing(15.0);
  PlannerObstacle later = c.car;
  later.id = 6;
  later.position = {35.0, 12.0};
  const ObstacleStop kept = yielder.Plan(&c.points, {later}, 5.0, 10.5, stop);
  ASSERT_TRUE(kept.stop);
  EXPECT_EQ(kept.obstacle_id, 5);
  EXPECT_NEAR(kept.stop_s_m, first.stop_s_m, 1e-9);
  // The tracks break up: for 1 s after that no track says a car is
  // crossing, and the stop line stays where it was, for the same car.
  for (double t : {11.0, 11.5}) {
    c = Crossing(15.0);
    const ObstacleStop held = yielder.Plan(&c.points, {}, 3.0, t, stop);
    ASSERT_TRUE(held.stop) << t;
    EXPECT_EQ(held.obstacle_id, 5);
    EXPECT_NEAR(held.stop_s_m, first.stop_s_m, 1e-9);
    EXPECT_NEAR(held.gap_m, first.gap_m, 1e-9);
    EXPECT_EQ(c.points.back().v_mps, 0.0);
  }
  // Clear for longer than the margin: it goes.
  c = Crossing(15.0);
  EXPECT_FALSE(yielder.Plan(&c.points, {}, 0.0, 11.6, stop).stop);
  for (const PlannedPoint& p : c.points) EXPECT_GT(p.v_mps, 0.0);
}

// A route that turns left onto a road (x = 44, northbound) and 16 m on
// left off it again, across the southbound lane (x = 40.7) both times, as
// the reference study's does from one aisle to the next. A southbound car
// at 8 m/s stands in the path's corridor where the route leaves the road
// (that is the stop planner's), and will cross where it joins, 2.4 s on,
// while the ego, 16 m short, would be there too: it is yielded to. Before,
// the yield skipped any car in the corridor now; held only by the stop for
// the farther crossing, the ego drove on to the nearer one at 6 m/s and
// then could not stop before it (a collision at (12, 1.8, 7), run key
// v16 with the tracker of then).
TEST(CrossingYield,
     ACarInAFartherPartOfThePathIsYieldedToWhereItCrossesNearer) {
  std::vector<Eigen::Vector2d> route;
  for (double x = 0; x < 40; x += 1.0) route.emplace_back(x, 0);
  for (int a = -90; a < 0; a += 10) {
    const double th = a * kPi / 180;
    route.emplace_back(40 + 4 * std::cos(th), 4 + 4 * std::sin(th));
  }
  for (double y = 4; y < 16; y += 1.0) route.emplace_back(44, y);
  for (int a = 0; a < 90; a += 10) {
    const double th = a * kPi / 180;
    route.emplace_back(40 + 4 * std::cos(th), 16 + 4 * std::sin(th));
  }
  for (double x = 40; x >= 0; x -= 1.0) route.emplace_back(x, 20);
  PathPlanner planner;
  planner.SetRoute(Polyline(route));
  std::vector<PlannedPoint> points =
      planner.Plan(geometry::Pose2{20.0, 0.0, 0.0}).points;
  PlannerObstacle car = Car(9, 40.7, 23.0);
  car.velocity = {0.0, -8.0};
  car.yaw_rad = -kPi / 2;
  car.age = 10;
  const ObstacleStopParams stop = CaseStop();
  std::vector<PlannedPoint> in_path = points;
  const ObstacleStop far = InsertObstacleStop(&in_path, {car}, {}, stop);
  ASSERT_TRUE(far.stop);  // for where the route leaves the road
  const ObstacleStop yield =
      InsertCrossingYield(&points, {car}, 6.0, stop, CrossingYieldParams());
  ASSERT_TRUE(yield.stop);
  EXPECT_EQ(yield.obstacle_id, 9);
  // Short of where the route joins the road (s 40-44), nearer than the
  // stop for the farther crossing.
  EXPECT_LT(yield.stop_s_m + stop.stop_margin_m + stop.ego_front_m, 42.0);
  EXPECT_LT(yield.stop_s_m, far.stop_s_m - 20.0);
  // Gone past where the route joins the road, it is not yielded to.
  car.position = {40.7, -6.0};
  std::vector<PlannedPoint> later =
      planner.Plan(geometry::Pose2{20.0, 0.0, 0.0}).points;
  EXPECT_FALSE(
      InsertCrossingYield(&later, {car}, 6.0, stop, CrossingYieldParams())
          .stop);
}

TEST(CrossingYield, TheNearerOfTwoStopsHoldsTheCar) {
  ObstacleStop far, near, none;
  far.stop = near.stop = true;
  far.stop_s_m = 40.0;
  far.obstacle_id = 1;
  near.stop_s_m = 20.0;
  near.obstacle_id = 2;
  EXPECT_EQ(NearerStop(far, near).obstacle_id, 2);
  EXPECT_EQ(NearerStop(near, far).obstacle_id, 2);
  EXPECT_EQ(NearerStop(none, far).obstacle_id, 1);
  EXPECT_EQ(NearerStop(far, none).obstacle_id, 1);
  EXPECT_FALSE(NearerStop(none, none).stop);
}

TEST(VelocityPlanner, CurvatureLimitsSpeedInCurve) {
  // 50 m straight, a quarter circle of radius 10 m (1 m chords), straight.
  std::vector<Eigen::Vector2d> pts;
  for (double x = 0; x <= 50; x += 5) pts.emplace_back(x, 0);
  for (int i = 1; i <= 16; ++i) {
    const double a = -kPi / 2 + i * (kPi / 2) / 16;
    pts.emplace_back(50 + 10 * std::cos(a), 10 + 10 * std::sin(a));
  }
  for (double y = 15; y <= 60; y += 5) pts.emplace_back(60, y);
  PathPlanner planner;
  planner.SetRoute(Polyline(pts));
  const VelocityLimitParams limits;
  const testing::ChainedPlan plan =
      testing::PlanChain(&planner, geometry::Pose2{30, 0, 0}, {}, limits);
  const double v_curve = std::sqrt(limits.max_lateral_accel_mps2 / 0.1);
  bool checked_curve = false;
  for (const PlannedPoint& p : plan.points) {
    if (p.s_m < 45) {
      EXPECT_DOUBLE_EQ(p.v_mps, planner.params().speed_limit_mps);
    }
    if (p.s_m > 54 && p.s_m < 62) {  // well inside the arc
      EXPECT_NEAR(p.curvature_1pm, 0.1, 0.01);
      EXPECT_NEAR(p.v_mps, v_curve, 0.2);
      checked_curve = true;
    }
  }
  EXPECT_TRUE(checked_curve);
  // The limit never asks for less than min_curve_speed_mps.
  std::vector<PlannedPoint> tight(3);
  for (PlannedPoint& p : tight) {
    p.v_mps = 8.0;
    p.curvature_1pm = 100.0;
  }
  EXPECT_EQ(LimitVelocity(&tight, false, limits), 3);
  for (const PlannedPoint& p : tight) {
    EXPECT_DOUBLE_EQ(p.v_mps, limits.min_curve_speed_mps);
  }
}

TEST(PathPlanner, ProjectionStaysOnItsLegOfAUTurn) {
  // Out along y = 0 and back along y = 3: the return leg is closer to a
  // pose at y = 1.6 but the ego is on the way out.
  PathPlanner planner;
  planner.SetRoute(Polyline({{0, 0}, {50, 0}, {50, 3}, {0, 3}}));
  planner.Plan(geometry::Pose2{0, 0, 0});
  for (double x = 2; x <= 30; x += 2) {
    const PlannedPath path = planner.Plan(geometry::Pose2{x, 1.6, 0});
    EXPECT_NEAR(path.ego_s_m, x, 1e-9);
  }
  // Backward jitter does not move progress back.
  EXPECT_NEAR(planner.Plan(geometry::Pose2{29.5, 0, 0}).ego_s_m, 30.0, 1e-9);
  // Far from the window (e.g. after a relocalization): global search.
  EXPECT_NEAR(planner.Plan(geometry::Pose2{10, 3.2, kPi}).ego_s_m, 93.0, 1e-9);
}

TEST(PathPlanner, ALegEndsAtItsTurnAndTheNextGoesOnFromTheTurnsEnd) {
  // Out along y = 0 to a dead end, round in several moves, back along
  // y = 3: the first leg ends at x = 90, short of the U-turn.
  PathPlanner planner;
  planner.SetRoute(Polyline({{0, 0}, {100, 0}, {100, 3}, {0, 3}}));
  planner.EndAt(90.0);
  const PlannedPath before = planner.Plan(geometry::Pose2{0, 0, 0});
  EXPECT_FALSE(before.ends_at_goal);  // 90 m away, the horizon is 50 m
  const PlannedPath at = planner.Plan(geometry::Pose2{45, 0, 0});
  EXPECT_TRUE(at.ends_at_goal);
  EXPECT_NEAR(at.points.back().s_m, 90.0, 1e-9);
  EXPECT_NEAR(planner.Plan(geometry::Pose2{89.9, 0, 0}).ego_s_m, 89.9, 1e-9);
  // Turning: wherever the car goes, the progress stays at the leg's end.
  for (const geometry::Pose2& turning :
       {geometry::Pose2{95, 1, 1.5}, geometry::Pose2{98, 2.5, 3.0},
        geometry::Pose2{94, 3, kPi}}) {
    EXPECT_NEAR(planner.Plan(turning).ego_s_m, 90.0, 1e-9);
  }
  // Turned, 10 m along the way back (s = 103 + 10): on to the route's end.
  planner.ResumeAt(113.0);
  const PlannedPath after = planner.Plan(geometry::Pose2{90, 3, kPi});
  EXPECT_NEAR(after.ego_s_m, 113.0, 1e-9);
  EXPECT_NEAR(after.points.back().s_m, 163.0, 1e-9);
  EXPECT_FALSE(after.ends_at_goal);
  EXPECT_NEAR(planner.Plan(geometry::Pose2{70, 3, kPi}).ego_s_m, 133.0, 1e-9);
  EXPECT_TRUE(planner.Plan(geometry::Pose2{40, 3, kPi}).ends_at_goal);
}

TEST(PathPlanner, EmptyWithoutRoute) {
  PathPlanner planner;
  EXPECT_TRUE(planner.Plan(geometry::Pose2{}).points.empty());
  std::vector<PlannedPoint> none;
  EXPECT_EQ(LimitVelocity(&none, true, {}), 0);
  EXPECT_FALSE(InsertObstacleStop(&none, {Car(1, 0, 0)}, {}, {}).stop);
}

TEST(StopReason, OneNamePerValueAndBack) {
  const std::vector<std::string> names = StopReasonNames();
  ASSERT_EQ(names.size(), 8u);
  // The codes stored in run files never change; new ones come last.
  EXPECT_EQ(names[4], "no_trajectory");
  EXPECT_EQ(names[5], "red_light");
  EXPECT_EQ(names[6], "lane_change");
  EXPECT_EQ(names[7], "turnaround");
  EXPECT_TRUE(StopReasonNamesTrack(StopReason::kObstacle));
  EXPECT_TRUE(StopReasonNamesTrack(StopReason::kLaneChange));
  EXPECT_FALSE(StopReasonNamesTrack(StopReason::kRedLight));
  for (size_t i = 0; i < names.size(); ++i) {
    StopReason reason = StopReason::kNone;
    ASSERT_TRUE(StringToStopReason(names[i], &reason)) << names[i];
    // Codes are stored in run files: the table is in code order.
    EXPECT_EQ(static_cast<size_t>(reason), i) << names[i];
    EXPECT_EQ(StopReasonToString(reason), names[i]);
  }
  StopReason unchanged = StopReason::kGoal;
  EXPECT_FALSE(StringToStopReason("red light", &unchanged));
  EXPECT_EQ(unchanged, StopReason::kGoal);
}

TEST(DecideStop, FreeRoadDoesNotStop) {
  PathPlanner planner;
  planner.SetRoute(Straight(200, 5));
  testing::ChainedPlan plan =
      testing::PlanChain(&planner, geometry::Pose2{10, 0, 0}, {});
  const StopDecision d =
      DecideStop(&plan.points, plan.path.ends_at_goal, false, plan.obstacle);
  EXPECT_EQ(d.reason, StopReason::kNone);
  EXPECT_EQ(d.distance_m, -1);
  EXPECT_EQ(d.obstacle_id, -1);
  for (const PlannedPoint& p : plan.points) EXPECT_GT(p.v_mps, 0.0);
}

TEST(DecideStop, GoalAheadWithItsDistance) {
  PathPlanner planner;
  planner.SetRoute(Straight(100, 5));
  testing::ChainedPlan plan =
      testing::PlanChain(&planner, geometry::Pose2{70, 0, 0}, {});
  const StopDecision d =
      DecideStop(&plan.points, plan.path.ends_at_goal, false, plan.obstacle);
  EXPECT_EQ(d.reason, StopReason::kGoal);
  EXPECT_NEAR(d.distance_m, 30.0, 1e-9);
  // At the goal: the stop is where the car is.
  testing::ChainedPlan there =
      testing::PlanChain(&planner, geometry::Pose2{100, 0, 0}, {});
  const StopDecision at =
      DecideStop(&there.points, there.path.ends_at_goal, false, there.obstacle);
  EXPECT_EQ(at.reason, StopReason::kGoal);
  EXPECT_NEAR(at.distance_m, 0.0, 1e-9);
}

TEST(DecideStop, ObstacleBeforeTheGoalWithTrackGapAndStructure) {
  PathPlanner planner;
  planner.SetRoute(Straight(100, 5));
  const ObstacleStopParams params;
  PlannerObstacle wall_corner = Car(12, 90.0, 0.3);
  wall_corner.static_structure = true;
  // The goal (100) and a car (track 12) before it at 90 are both within
  // the horizon from 60: the car's stop is nearer and holds the car.
  testing::ChainedPlan plan = testing::PlanChain(
      &planner, geometry::Pose2{60, 0, 0}, {wall_corner}, {}, params);
  ASSERT_TRUE(plan.path.ends_at_goal);
  const StopDecision d =
      DecideStop(&plan.points, plan.path.ends_at_goal, false, plan.obstacle);
  EXPECT_EQ(d.reason, StopReason::kObstacle);
  EXPECT_EQ(d.obstacle_id, 12);
  EXPECT_TRUE(d.static_structure);
  const double rear_edge = 90.0 - 2.25;
  EXPECT_NEAR(d.obstacle_gap_m, rear_edge - (60.0 + params.ego_front_m), 1e-9);
  EXPECT_NEAR(d.distance_m,
              rear_edge - params.stop_margin_m - params.ego_front_m - 60.0,
              1e-9);
  // Traffic (not map structure) says so; standing at the stop line, the
  // distance is 0.
  PathPlanner close;
  close.SetRoute(Straight(100, 5));
  const double stop_line =
      rear_edge - params.stop_margin_m - params.ego_front_m;
  testing::ChainedPlan at_line =
      testing::PlanChain(&close, geometry::Pose2{stop_line + 0.2, 0, 0},
                         {Car(3, 90.0, 0.3)}, {}, params);
  const StopDecision held = DecideStop(
      &at_line.points, at_line.path.ends_at_goal, false, at_line.obstacle);
  EXPECT_EQ(held.reason, StopReason::kObstacle);
  EXPECT_EQ(held.obstacle_id, 3);
  EXPECT_FALSE(held.static_structure);
  EXPECT_EQ(held.distance_m, 0.0);
  for (const PlannedPoint& p : at_line.points) EXPECT_EQ(p.v_mps, 0.0);
}

TEST(DecideStop, LostLocalizationHoldsTheCarWhereItIs) {
  PathPlanner planner;
  planner.SetRoute(Straight(200, 5));
  testing::ChainedPlan plan = testing::PlanChain(
      &planner, geometry::Pose2{10, 0, 0}, {Car(5, 40.0, 0.0)});
  ASSERT_TRUE(plan.obstacle.stop);
  const StopDecision d =
      DecideStop(&plan.points, plan.path.ends_at_goal, true, plan.obstacle);
  // The pose is not trusted, so neither is an obstacle's place relative
  // to it: the lost pose is the reason.
  EXPECT_EQ(d.reason, StopReason::kLocalizationLost);
  EXPECT_EQ(d.distance_m, 0.0);
  EXPECT_EQ(d.obstacle_id, -1);
  ASSERT_FALSE(plan.points.empty());
  for (const PlannedPoint& p : plan.points) EXPECT_EQ(p.v_mps, 0.0);
}

TEST(DecideStop, NoPathIsNoTrajectory) {
  std::vector<PlannedPoint> none;
  const StopDecision d = DecideStop(&none, false, false, ObstacleStop{});
  EXPECT_EQ(d.reason, StopReason::kNoTrajectory);
  EXPECT_EQ(d.distance_m, 0.0);
  // Even with the pose lost: there is nothing to hold.
  EXPECT_EQ(DecideStop(&none, false, true, ObstacleStop{}).reason,
            StopReason::kNoTrajectory);
}

TEST(SmoothVelocity, RespectsAccelAndDecelLimits) {
  PathPlanner planner;
  planner.SetRoute(Straight(200, 5));
  testing::ChainedPlan traj = testing::PlanChain(
      &planner, geometry::Pose2{0, 0, 0}, {Car(1, 45.0, 0.0)});
  const std::vector<PlannedPoint> raw = traj.points;
  SmootherParams params;
  SmoothVelocity(&traj.points, 0.0, params);
  ASSERT_EQ(traj.points.size(), raw.size());
  EXPECT_DOUBLE_EQ(traj.points[0].v_mps, params.start_speed_mps);
  double peak = 0.0;
  for (size_t i = 0; i < raw.size(); ++i) {
    const PlannedPoint& p = traj.points[i];
    EXPECT_LE(p.v_mps, raw[i].v_mps + 1e-12);  // never raised
    if (raw[i].v_mps == 0.0) {
      EXPECT_EQ(p.v_mps, 0.0);
    }
    peak = std::max(peak, p.v_mps);
    if (i == 0) continue;
    const PlannedPoint& q = traj.points[i - 1];
    const double ds = p.s_m - q.s_m;
    const double dv2 = p.v_mps * p.v_mps - q.v_mps * q.v_mps;
    EXPECT_LE(dv2, 2 * params.max_accel_mps2 * ds + 1e-9) << "at " << i;
    EXPECT_GE(dv2, -2 * params.max_decel_mps2 * ds - 1e-9) << "at " << i;
  }
  EXPECT_GT(peak, 4.0);  // it does speed up in between
  // Moving fast towards a near stop: the profile brakes from the start.
  PathPlanner near_planner;
  near_planner.SetRoute(Straight(200, 5));
  testing::ChainedPlan near = testing::PlanChain(
      &near_planner, geometry::Pose2{0, 0, 0}, {Car(1, 20.0, 0.0)});
  SmoothVelocity(&near.points, 10.0, params);
  EXPECT_NEAR(near.points[0].v_mps,
              std::sqrt(2 * params.max_decel_mps2 * near.obstacle.stop_s_m),
              1e-6);
  EXPECT_LT(near.points[0].v_mps, 10.0);
  SmoothVelocity(nullptr, 1.0, params);  // no crash
}

}  // namespace
}  // namespace adse::algorithms
