// The SUMO world on the real networks Debian's sumo-tools ships: routes
// of the real-nets bench, whose corners, lane shapes and U-turns the world
// turns into a path the car can drive, the roadside poles of a bare net,
// and SUMO's drivers yielding to the car at a signalised junction. Each
// TEST runs in its own process (gtest_discover_tests), which libsumo needs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "stack/world/ideal_driver.h"
#include "stack/world/world.h"
#include "tests/stack/world/testing/real_nets.h"

namespace adse::world {
namespace {

using testing::BenchRoute;
using testing::CacheDir;
using testing::DriveToTheGoal;
using testing::kA10kwNet;
using testing::kAcostaNet;
using testing::kDrtNet;
using testing::kPasubioNet;
using testing::kSquareNet;
using testing::OpenBenchRoute;
using testing::OpenOnSumoToolsNet;

TEST(WorldTest, RealOsmNetworkFromSumoToolsLoadsAndRoutes) {
  ASSERT_TRUE(std::filesystem::exists(kDrtNet))
      << "sumo-tools is not installed";
  WorldSetup setup;
  setup.world.map.net_path = kDrtNet;
  setup.task.start = Location::Xy(899.9, 400.8);
  setup.task.goal = Location::Xy(1100.0, 232.0);
  setup.cache_dir = CacheDir();
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  EXPECT_GE((*world)->route_edges().size(), 5u);
  // At least the straight-line distance, at most SUMO's route length.
  EXPECT_GT((*world)->ideal_path().length_m(), 240.0);
  EXPECT_LT((*world)->ideal_path().length_m(), 640.0);
  EXPECT_LT((*world)->ideal_path_max_join_gap_m(), 0.5);
  EXPECT_LT((*world)->ideal_path().MaxGap(), 0.51);
  // A bare net gets roadside poles for the LiDAR.
  EXPECT_GT((*world)->scene().obstacles().size(), 100u);
}

// The real-nets bench's route DRT-0: SUMO's shortest route (701 m) turns
// around at a junction, where the ideal driver swung 4.9 m wide; adse's
// goes round the blocks (about 1.2 km) and the driver stays on it.
TEST(WorldTest, OnARealTownTheRouteAvoidsAUTurnTheCarCannotDrive) {
  Result<std::unique_ptr<World>> world =
      OpenBenchRoute(kDrtNet, Location::OnEdge("142575704#14", 10.0, 1),
                     Location::OnEdge("142575674#3", 20.1, 1));
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  EXPECT_NEAR((*world)->ideal_path().length_m(), 1228.0, 20.0);
  const IdealDriveReport report = DriveToTheGoal(**world, 40.0, 400.0);
  // Issue 17's 1 m, junctions included (0.54 m measured).
  EXPECT_LT(report.max_lateral_error_m, 1.0);
}

// The real-nets bench's route acosta-1: the lane shape of edge 224[1]
// starts 9 m past its corner and folds back; the ideal path took the fold
// and the ideal driver ended 9 m off it. The path drops the fold.
TEST(WorldTest, OnARealTownALaneShapeThatFoldsBackIsDrivenAsTheCorner) {
  Result<std::unique_ptr<World>> world =
      OpenBenchRoute(kAcostaNet, Location::OnEdge("224[0]", 10.0, 0),
                     Location::OnEdge("2", 22.2, 0));
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  // Nowhere does the path turn back on itself.
  const geometry::Path2& path = (*world)->ideal_path();
  for (size_t i = 1; i + 1 < path.points.size(); ++i) {
    const Eigen::Vector2d in = path.points[i] - path.points[i - 1];
    const Eigen::Vector2d out = path.points[i + 1] - path.points[i];
    ASSERT_GT(in.dot(out), -0.5 * in.norm() * out.norm())
        << "folds at (" << path.points[i].x() << ", " << path.points[i].y()
        << ")";
  }
  const IdealDriveReport report = DriveToTheGoal(**world, 40.0, 400.0);
  EXPECT_LT(report.max_lateral_error_m, 1.0);  // 0.84 m measured
}

// The real-nets bench's route pasubio-2: corners of 90-150 degrees where
// junctions meet, which the car (3.95 m turning radius, steering at 0.8
// rad/s) cannot take on the polyline. Pure pursuit, blind to the
// steering's rate limit, swung wide and wove back: 5.88 m off the path.
TEST(WorldTest, OnARealTownTheIdealDriverTakesSharpCornersWithoutSwingingWide) {
  Result<std::unique_ptr<World>> world =
      OpenBenchRoute(kPasubioNet, Location::OnEdge("22[0]", 10.0, 0),
                     Location::OnEdge("39[1][1][0]", 100.7, 0));
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  const IdealDriveReport report = DriveToTheGoal(**world, 40.0, 900.0);
  // Junctions included: 1.63 m measured (0.87 m outside them, issue 17's
  // bound, by tests/bench/ideal_path_error.py).
  EXPECT_LT(report.max_lateral_error_m, 1.8);
}

// A10KW's junction 59909485: a left turn of 143 degrees between roads
// that meet 4.6 m apart, which SUMO calls a left turn, not a U-turn. The
// ideal driver, rehearsed along the lanes, strays 3.1 m there (the real-
// nets bench's A10KW-2 measured 3.11 m before); the car turns in several
// moves within the lanes and the junction instead, and the driver
// follows that within issue 17's 1 m.
TEST(WorldTest, OnARealTownACornerSharperThanTheCarIsTurnedInSeveralMoves) {
  Result<std::unique_ptr<World>> world =
      OpenBenchRoute(kA10kwNet, Location::OnEdge("225981818#2", 30.0, 0),
                     Location::OnEdge("-256366931#3", 40.0, 0));
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  ASSERT_EQ((*world)->route_turnarounds().size(), 1u);
  const RouteTurnaround& turn = (*world)->route_turnarounds()[0];
  EXPECT_GE(ManoeuvreMoves(turn.reference), 2);
  // It ends on the road part past the corner, heading along it.
  const geometry::Path2& road = (*world)->road_path();
  EXPECT_NEAR(turn.goal.yaw_rad, road.HeadingAt(turn.end_s_m), 1e-9);
  EXPECT_LT(turn.end_s_m, road.length_m());
  const IdealDriveReport report = DriveToTheGoal(**world, 40.0, 300.0);
  EXPECT_EQ(report.collisions, 0);
  EXPECT_LT(report.max_lateral_error_m, 1.0);
}

// The start of the real-nets bench's A10KW-2 of seed 3: two 90 degree
// corners 12 m apart, 30 m from where the car starts standing. Each bend
// was rehearsed from 25 m before it at the speed limit's profile, so the
// first looked drivable (0.90 m); the car, still speeding up from its
// start, met it faster and strayed 1.05 m. Rehearsed as it drives, from
// standing, the stretch is turned in moves, and the second corner, met
// standing at that turn's end, joins the same manoeuvre.
TEST(WorldTest, OnARealTownACornerNearTheStartIsRehearsedFromStanding) {
  Result<std::unique_ptr<World>> world =
      OpenBenchRoute(kA10kwNet, Location::OnEdge("6272844#3", 10.0, 0),
                     Location::OnEdge("5067107#4", 10.0, 0));
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  ASSERT_EQ((*world)->route_turnarounds().size(), 1u);
  const RouteTurnaround& turn = (*world)->route_turnarounds()[0];
  EXPECT_TRUE(turn.corner);
  EXPECT_GE(ManoeuvreMoves(turn.reference), 2);
  // Both corners: the stretch reaches past the second (s = 70 m).
  EXPECT_LT(turn.start_s_m, 45.0);
  EXPECT_GT(turn.end_s_m, 70.0);
  const IdealDriveReport report = DriveToTheGoal(**world, 40.0, 300.0);
  EXPECT_EQ(report.collisions, 0);
  // Junctions included (0.10 m measured; 1.25 m with the corners
  // rehearsed from the speed limit).
  EXPECT_LT(report.max_lateral_error_m, 1.0);
}

// acosta's edges 93 and 48: one-way streets of one 3.2 m lane that meet
// at a 134 degree corner. No turn in several moves fits in the lanes and
// the junction; the ideal driver kept its lanes there, strayed 2.79 m,
// and the stack touched a roadside pole (the real-nets bench's acosta-1
// of seed 4 at run key v21). On the streets' shoulders the car turns in
// three moves.
TEST(WorldTest, OnARealTownACornerOfSingleLanesIsTurnedOnTheirShoulders) {
  Result<std::unique_ptr<World>> world =
      OpenBenchRoute(kAcostaNet, Location::OnEdge("93", 10.0, 0),
                     Location::OnEdge("48", 60.0, 0));
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  ASSERT_EQ((*world)->route_turnarounds().size(), 1u);
  const RouteTurnaround& turn = (*world)->route_turnarounds()[0];
  EXPECT_TRUE(turn.corner);
  EXPECT_TRUE(turn.on_shoulders);
  EXPECT_GE(ManoeuvreMoves(turn.reference), 2);
  const IdealDriveReport report = DriveToTheGoal(**world, 40.0, 300.0);
  EXPECT_EQ(report.collisions, 0);
  EXPECT_LT(report.max_lateral_error_m, 1.0);
}

TEST(WorldTest, AOneWayStreetOfABareNetHasPolesOnBothSides) {
  // Edge 69 of sumo-tools' acosta: a one-way, two-lane street. With poles
  // on its right side only, NDT saw too little structure and got lost.
  ASSERT_TRUE(std::filesystem::exists(kAcostaNet))
      << "sumo-tools is not installed";
  WorldSetup setup;
  setup.world.map.net_path = kAcostaNet;
  setup.task.start = Location::OnEdge("69", 10.0);
  setup.task.goal = Location::OnEdge("69", 160.0);
  setup.cache_dir = CacheDir();
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  const geometry::Path2& path = (*world)->ideal_path();
  int left = 0, right = 0;
  for (const Obstacle& o : (*world)->scene().obstacles()) {
    if (o.kind != ObstacleKind::kPole) continue;
    const Eigen::Vector2d c = 0.25 * (o.footprint[0] + o.footprint[1] +
                                      o.footprint[2] + o.footprint[3]);
    // Nearest path point, and on which side of the path the pole stands.
    double best = INFINITY, side = 0.0, s_best = 0.0;
    for (size_t i = 0; i + 1 < path.points.size(); ++i) {
      const Eigen::Vector2d a = path.points[i], ab = path.points[i + 1] - a;
      const double t = std::clamp(
          (c - a).dot(ab) / std::max(ab.squaredNorm(), 1e-12), 0.0, 1.0);
      const Eigen::Vector2d r = c - (a + t * ab);
      if (r.norm() < best) {
        best = r.norm();
        side = ab.x() * r.y() - ab.y() * r.x();
        s_best = path.s_m[i] + t * ab.norm();
      }
    }
    if (best > 10.0 || s_best < 5.0 || s_best > path.length_m() - 5.0) continue;
    (side > 0 ? left : right) += 1;
  }
  // 150 m of street, a pole every 20 m on each side.
  EXPECT_GE(right, 5);
  EXPECT_GE(left, 5);
}

// square's signalised junction B1: the car turns right from A1B1 into
// B1B0 on green; a flow's drivers from right1B1 turn left into the same
// lane, their link yielding ('g'). Such a driver waits at its turn's
// waiting point in the junction; the next part of its turn has a link
// with the right of way of its own ('M'). A driver that crept past the
// waiting point was taken to have the right of way and turned in front
// of the car (the bench's square-0 collision); it now waits for the car.
TEST(WorldTest, ADriverPastItsLeftTurnsWaitingPointStillYieldsToTheCar) {
  WorldSetup setup = BenchRoute(kSquareNet, Location::OnEdge("A1B1", 60.0),
                                Location::OnEdge("B1B0", 40.0));
  setup.world.traffic.seed = 1;
  setup.world.traffic.flows = {{"right1B1", "B1B0", 1200.0}};
  Result<std::unique_ptr<World>> world = OpenOnSumoToolsNet(setup);
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  World& w = **world;
  // Standing until the signal's green (45 s into its cycle), then along
  // the route at 1.5 m/s.
  const SpeedProfile speed = CurveSpeedProfile(w.road_path(), 1.5, 1.5, 2.0);
  // When the car and the first of the drivers came into B1B0 (beyond the
  // junction's south edge, y = 292.8).
  double ego_in_s = INFINITY;
  double driver_in_s = INFINITY;
  while (w.time_s() < 120.0 && w.road_progress_m() < 60.0) {
    ControlCommand command;
    command.steer_rad =
        PredictiveSteer(w.road_path(), speed, w.road_progress_m(), w.ego(),
                        w.ego_limits(), PredictiveSteeringOptions());
    const double target_mps =
        w.time_s() < 45.0 ? 0.0 : speed.At(w.road_progress_m());
    command.accel_mps2 = w.ego().v_mps < target_mps ? 1.0 : -2.0;
    ASSERT_TRUE(w.Step(command).ok());
    if (w.ego().y_m < 292.8) ego_in_s = std::min(ego_in_s, w.time_s());
    for (const OtherVehicle& v : w.others()) {
      if (v.box.center.y() < 292.8 && std::abs(v.box.center.x() - 298.4) < 2) {
        driver_in_s = std::min(driver_in_s, w.time_s());
      }
    }
  }
  ASSERT_LT(ego_in_s, 100.0);
  // A driver came (one turned in front of the car without the fix, at
  // 64.35 s against the car's 69.5 s) and waited for the car.
  EXPECT_LT(driver_in_s, 100.0);
  EXPECT_LT(ego_in_s, driver_in_s);
  EXPECT_EQ(w.collisions(), 0);
}

}  // namespace
}  // namespace adse::world
