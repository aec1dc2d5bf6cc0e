// The SUMO world end to end: generated and real maps, routing, the ideal
// path, traffic determinism, the ego, LiDAR seeing SUMO vehicles, and the
// errors for bad maps and bad start/goal. Each TEST runs in its own process
// (gtest_discover_tests), which libsumo needs.
#include "stack/world/world.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "stack/base/hash.h"
#include "stack/world/ideal_driver.h"
#include "stack/world/lidar.h"
#include "stack/world/map_cloud.h"
#include "stack/world/predictive_steering.h"
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

// A small parking lot: one aisle between two rows, ring road around it.
// Ring south lane (eastbound) at y = -1.75; north lane (westbound) at
// y = 28 + 1.75.
WorldSetup SmallLot() {
  WorldSetup setup;
  setup.world.map.generator = "parking_lot";
  setup.world.map.generator_params = {{"rows", 2}, {"slots_per_row", 8}};
  setup.world.traffic.seed = 3;
  setup.world.traffic.parked_occupancy = 0.5;
  setup.task.start = Location::Xy(8.0, -1.75);
  setup.task.goal = Location::Xy(10.0, 29.75);
  setup.cache_dir = CacheDir();
  return setup;
}

TEST(WorldTest, GeneratedParkingLotLoadsAndIdealPathIsContinuous) {
  Result<std::unique_ptr<World>> world = World::Open(SmallLot());
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  const World& w = **world;
  const geometry::Path2& path = w.ideal_path();
  // East along the south ring, north on the east side, west on the north ring.
  EXPECT_GE(w.route_edges().size(), 3u);
  EXPECT_GT(path.length_m(), 60.0);
  EXPECT_LT(path.MaxGap(), 0.51);
  EXPECT_LT(w.ideal_path_max_join_gap_m(), 0.5);
  EXPECT_NEAR(path.points.front().x(), 8.0, 0.3);
  EXPECT_NEAR(path.points.front().y(), -1.75, 0.3);
  EXPECT_NEAR(path.points.back().x(), 10.0, 0.3);
  EXPECT_NEAR(path.points.back().y(), 29.75, 0.3);
  // Heading changes smoothly: no kinks from missing junction lanes.
  for (double s = 1.0; s < path.length_m() - 1.0; s += 0.5) {
    double dh = path.HeadingAt(s + 0.5) - path.HeadingAt(s);
    dh = std::atan2(std::sin(dh), std::cos(dh));
    EXPECT_LT(std::abs(dh), 0.5) << "kink at s=" << s;
  }
  EXPECT_EQ(w.scene().parking_slots().size(), 16u);
  int parked = 0;
  for (const auto& slot : w.scene().parking_slots()) parked += slot.occupied;
  EXPECT_GT(parked, 0);
  EXPECT_LT(parked, 16);
  EXPECT_NEAR(w.lane_width_m(), 3.5, 0.01);
  // Its corners are ones the car follows within 1 m: no manoeuvres.
  EXPECT_TRUE(w.route_turnarounds().empty());
}

// A 3 x 3 grid of 100 m one-lane streets, from 10 m into A0B0 to C1C2.
WorldSetup SmallGrid() {
  WorldSetup setup;
  setup.world.map.generator = "grid";
  setup.world.map.generator_params = {
      {"number", 3}, {"length_m", 100}, {"lanes", 1}};
  setup.task.start = Location::OnEdge("A0B0", 10.0);
  setup.task.goal = Location::OnEdge("C1C2", 50.0);
  setup.cache_dir = CacheDir();
  return setup;
}

TEST(WorldTest, GridMapLoadsAndRoutes) {
  const WorldSetup setup = SmallGrid();
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  EXPECT_LT((*world)->ideal_path().MaxGap(), 0.51);
  EXPECT_LT((*world)->ideal_path_max_join_gap_m(), 0.5);
  // 90 + 100 + 100 + 50 m along lanes, plus junction arcs.
  EXPECT_NEAR((*world)->ideal_path().length_m(), 340.0, 15.0);
  EXPECT_EQ((*world)->scene().obstacles().size(), 4u);  // city blocks
}

TEST(WorldTest, DrivingIntoACityBlockIsACollisionTheEgoCaused) {
  Result<std::unique_ptr<World>> world = World::Open(SmallGrid());
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  World& w = **world;
  // Off the road to the left, across the other lane, into the block.
  std::vector<Contact> contacts;
  for (int i = 0; i < 1200 && contacts.empty(); ++i) {
    const double accel = w.ego().v_mps < 4.0 ? 1.0 : 0.0;
    ASSERT_TRUE(w.Step({accel, w.time_s() < 1.5 ? 0.5 : 0.0, false}).ok());
    contacts = w.new_contacts();
  }
  ASSERT_EQ(contacts.size(), 1u) << "never touched the block";
  EXPECT_TRUE(contacts[0].structure);
  EXPECT_TRUE(contacts[0].ego_caused);
  EXPECT_FALSE(contacts[0].id.empty());
  EXPECT_EQ(w.collisions(), 1);
  // Pushing on into it is the same contact.
  for (int i = 0; i < 20; ++i) ASSERT_TRUE(w.Step({1.0, 0.0, false}).ok());
  EXPECT_EQ(w.collisions(), 1);
}

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

std::string TrafficFingerprint(uint64_t seed) {
  WorldSetup setup = SmallLot();
  setup.world.traffic.seed = seed;
  setup.world.traffic.flows = {{"E2_W2", "W0_E0", 1800.0}};
  Result<std::unique_ptr<World>> world = World::Open(setup);
  EXPECT_TRUE(world.ok()) << world.status().ToString();
  if (!world.ok()) return "";
  std::string text;
  for (int i = 0; i < 400; ++i) {
    EXPECT_TRUE((*world)->Step(ControlCommand{}).ok());
    if (i % 20 == 0) {
      for (const OtherVehicle& v : (*world)->others()) {
        text += v.id + ":" +
                std::to_string(std::lround(v.box.center.x() * 1000)) + "," +
                std::to_string(std::lround(v.box.center.y() * 1000)) + ";";
      }
    }
  }
  EXPECT_FALSE(text.empty()) << "no traffic appeared";
  return Sha256Hex(text);
}

TEST(WorldTest, TrafficIsIdenticalForTheSameSeedAndDiffersForAnother) {
  // Worlds opened one after another in one process: libsumo restarts cleanly.
  const std::string a = TrafficFingerprint(11);
  const std::string b = TrafficFingerprint(11);
  const std::string c = TrafficFingerprint(12);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
}

// SUMO inserts a flow's car at the start of its first edge without seeing
// the ego there (it did so onto the ego turning onto the edge); adse holds
// the car back until the ego is clear of where it would enter.
TEST(WorldTest, AFlowsCarEntersOnlyOnceTheEgoIsClearOfWhereItWouldEnter) {
  WorldSetup setup = SmallGrid();
  setup.world.traffic.flows = {{"A0B0", "B0B1", 3600.0}};
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  // The ego stands 10 m into the flow's first edge for 20 s: about 20 cars
  // are drawn, none enters.
  for (int i = 0; i < 400; ++i) {
    ASSERT_TRUE((*world)->Step(ControlCommand{}).ok());
    ASSERT_TRUE((*world)->others().empty())
        << (*world)->others().front().id << " entered at " << (*world)->time_s()
        << " s";
  }
  // Once it drives off they enter behind it, and none runs into it.
  const IdealDriveReport report = DriveToTheGoal(**world, 30, 120);
  EXPECT_EQ(report.collisions, 0);
  int entered = 0;
  for (const OtherVehicle& v : (*world)->others()) {
    entered += v.id.rfind("flow0.", 0) == 0;
  }
  EXPECT_GE(entered, 3);
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

TEST(WorldTest, PerfectControllerReachesTheGoalWithoutCollisions) {
  Result<std::unique_ptr<World>> world = World::Open(SmallLot());
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  LidarParams params;
  LidarSimulator lidar(&(*world)->scene(), params, Weather::kClear, 1);
  IdealDriverOptions options;
  options.timeout_s = 120.0;
  Result<IdealDriveReport> report = DriveIdealPath(**world, &lidar, options);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_TRUE(report->reached_goal);
  EXPECT_EQ(report->collisions, 0);
  // Within issue 17's 1 m, junctions (the lot's right-angle corners, which
  // no car with a turning circle takes on the polyline) included.
  EXPECT_LT(report->max_lateral_error_m, 0.5);
  // About 80 m at up to 8.3 m/s with slow corners.
  EXPECT_GT(report->time_s, 10.0);
  EXPECT_LT(report->time_s, 40.0);
  EXPECT_GT(report->scans, 50);
  EXPECT_GT(report->mean_points_per_scan, 1000.0);
}

TEST(WorldTest, LidarSeesSumoVehicles) {
  WorldSetup setup = SmallLot();
  setup.world.traffic.parked_occupancy = 0.0;
  // Westbound on the south ring: passes the ego on the opposite lane.
  setup.world.traffic.flows = {{"E0_W0", "W2_E2", 1800.0}};
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  World& w = **world;
  // Let traffic in; the ego stands still at the start.
  const OtherVehicle* seen = nullptr;
  for (int i = 0; i < 400 && seen == nullptr; ++i) {
    ASSERT_TRUE(w.Step(ControlCommand{}).ok());
    for (const OtherVehicle& v : w.others()) {
      const double d =
          (v.box.center - Eigen::Vector2d(w.ego().x_m, w.ego().y_m)).norm();
      if (d > 8.0 && d < 25.0) seen = &v;
    }
  }
  ASSERT_NE(seen, nullptr) << "no vehicle came within LiDAR view";
  LidarParams params;
  params.range_noise_stddev_m = 0.0;
  LidarSimulator lidar(&w.scene(), params, Weather::kClear, 1);
  const geometry::Pose2 pose{w.ego().x_m, w.ego().y_m, w.ego().yaw_rad};
  std::vector<geometry::OrientedBox> boxes;
  for (const OtherVehicle& v : w.others()) boxes.push_back(v.box);
  const PointCloud with = lidar.Scan(pose, w.time_s(), boxes);
  int on_vehicle = 0;
  const geometry::OrientedBox box = seen->box;
  for (const Eigen::Vector3f& p : with.points) {
    // Sensor frame -> world frame.
    const double c = std::cos(pose.yaw_rad), s = std::sin(pose.yaw_rad);
    const Eigen::Vector2d world_xy(pose.x_m + c * p.x() - s * p.y(),
                                   pose.y_m + s * p.x() + c * p.y());
    const Eigen::Vector2d local =
        Eigen::Rotation2Dd(-box.yaw_rad) * (world_xy - box.center);
    if (std::abs(local.x()) <= box.length_m / 2 + 0.05 &&
        std::abs(local.y()) <= box.width_m / 2 + 0.05 &&
        p.z() > -params.mount_height_m + 0.1) {
      ++on_vehicle;
    }
  }
  EXPECT_GT(on_vehicle, 10);
}

TEST(WorldTest, MapCloudIsBuiltOnceAndCached) {
  Result<std::unique_ptr<World>> world = World::Open(SmallLot());
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  Result<std::string> path = (*world)->MapCloudPath();
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  const auto first_write = std::filesystem::last_write_time(*path);
  Result<std::vector<Eigen::Vector3f>> cloud = ReadPcd(*path);
  ASSERT_TRUE(cloud.ok());
  EXPECT_GT(cloud->size(), 10000u);
  Result<std::string> again = (*world)->MapCloudPath();
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(*again, *path);
  EXPECT_EQ(std::filesystem::last_write_time(*again), first_write);
}

TEST(WorldTest, CorruptNetIsReportedWithSumosCause) {
  const std::string net =
      (std::filesystem::temp_directory_path() / "adse_corrupt.net.xml")
          .string();
  std::ofstream(net) << "<net version=\"1.9\">\n  <edge id=\"a\"\n";
  WorldSetup setup;
  setup.world.map.net_path = net;
  setup.task.start = Location::Xy(0, 0);
  setup.task.goal = Location::Xy(10, 0);
  setup.cache_dir = CacheDir();
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_FALSE(world.ok());
  EXPECT_EQ(world.status().code(), Status::Code::kInvalidArgument);
  EXPECT_NE(world.status().message().find("world.map.net"), std::string::npos);
  EXPECT_NE(world.status().message().find("adse_corrupt.net.xml"),
            std::string::npos);
  // SUMO's own reason, not a bare "Process Error".
  EXPECT_EQ(world.status().message().find("Process Error"), std::string::npos)
      << world.status().message();
}

TEST(WorldTest, AContactIsTheEgosWhenItClosedOnTheOtherAtLeastAsFast) {
  // The ego heading +x with its body centred at the origin.
  VehicleState ego;
  ego.yaw_rad = 0.0;
  geometry::OrientedBox body;
  body.center = Eigen::Vector2d::Zero();
  auto other_at = [](double x, double y, double yaw, double speed) {
    OtherVehicle v;
    v.id = "v";
    v.box.center = Eigen::Vector2d(x, y);
    v.box.yaw_rad = yaw;
    v.speed_mps = speed;
    return v;
  };
  // Standing, driven into from behind or the side: not the ego's.
  ego.v_mps = 0.0;
  EXPECT_FALSE(EgoCausedContact(ego, 0.0, body, other_at(-4, 0, 0, 10)));
  EXPECT_FALSE(EgoCausedContact(ego, 0.0, body, other_at(-2, -1.5, 0.2, 14)));
  // Braking at 2 m/s, passed by a car at 14 m/s that cuts in: not either.
  ego.v_mps = 2.0;
  EXPECT_FALSE(EgoCausedContact(ego, 0.0, body, other_at(-2, 2, -0.3, 14)));
  // Into a slower car ahead, or a standing one: the ego's.
  ego.v_mps = 8.0;
  EXPECT_TRUE(EgoCausedContact(ego, 0.0, body, other_at(4.5, 0, 0, 3)));
  EXPECT_TRUE(EgoCausedContact(ego, 0.0, body, other_at(4.5, 0.5, 0, 0)));
  // Backing into a standing car behind: the ego's.
  ego.v_mps = -1.0;
  EXPECT_TRUE(EgoCausedContact(ego, 0.0, body, other_at(-4.5, 0, 0, 0)));
  // Head on, both at 5 m/s: the ego closed as fast, so it counts.
  ego.v_mps = 5.0;
  EXPECT_TRUE(EgoCausedContact(ego, 0.0, body, other_at(4.5, 0, M_PI, 5)));
}

TEST(WorldTest, ACarCuttingInWhoseRearSwingsIntoTheBrakingEgoCausedTheContact) {
  // RiLSA2, route 0 of seed 3 at run key v20, 83.45 s: leaving the same
  // green side by side, a flow's car from the lane on the ego's right
  // swung into the ego's lane in the junction, 7 m/s and turning
  // clockwise, while the ego braked through 1.6 m/s turning left, away
  // from it. The two bodies along the line between their centres closed
  // (the ego was behind it), which until v22 made it the ego's.
  VehicleLimits car;
  car.length_m = 4.6;
  car.width_m = 1.9;
  car.wheelbase_m = 2.7;
  VehicleState ego;
  ego.x_m = 502.216;
  ego.y_m = 507.337;
  ego.yaw_rad = -2.916;
  ego.v_mps = 1.60;
  ego.steer_rad = 0.306;
  const double ego_yaw_rate = ego.v_mps * std::tan(ego.steer_rad) / 2.7;
  const geometry::OrientedBox body =
      BodyAt({ego.x_m, ego.y_m, ego.yaw_rad}, car);
  OtherVehicle cutting_in;
  cutting_in.box.center = Eigen::Vector2d(495.988, 508.010);
  cutting_in.box.yaw_rad = -3.005;
  cutting_in.box.length_m = 5.0;
  cutting_in.box.width_m = 1.8;
  cutting_in.speed_mps = 7.03;
  cutting_in.yaw_rate_rps = -0.64;
  ASSERT_TRUE(geometry::BoxesOverlap(body, cutting_in.box));
  EXPECT_FALSE(EgoCausedContact(ego, ego_yaw_rate, body, cutting_in));

  // The same ego swinging its front corner into a car standing beside
  // it: the ego's.
  OtherVehicle standing = cutting_in;
  standing.speed_mps = 0.0;
  standing.yaw_rate_rps = 0.0;
  ego.v_mps = 3.0;
  ego.steer_rad = -0.5;  // turning right, into it
  EXPECT_TRUE(EgoCausedContact(ego, ego.v_mps * std::tan(ego.steer_rad) / 2.7,
                               body, standing));
}

TEST(WorldTest, StartOffTheRoadIsRejected) {
  WorldSetup setup = SmallLot();
  setup.task.start = Location::Xy(15.0, 8.0);  // in the parking rows
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_FALSE(world.ok());
  EXPECT_NE(world.status().message().find("task.start"), std::string::npos);
  EXPECT_NE(world.status().message().find("off the road"), std::string::npos)
      << world.status().message();
}

TEST(WorldTest, AStoppedVehicleOffTheRoadIsRejectedByItsIndex) {
  WorldSetup setup = SmallLot();
  setup.world.traffic.stopped_vehicles = {Location::Xy(20.0, -1.75),
                                          Location::Xy(15.0, 8.0)};
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_FALSE(world.ok());
  EXPECT_NE(world.status().message().find(
                "world.traffic.stopped_vehicles[1]: (15, 8) is off the road"),
            std::string::npos)
      << world.status().message();
}

TEST(WorldTest, UnreachableGoalIsRejected) {
  // Two separate road pieces: no route joins them.
  const auto dir = std::filesystem::temp_directory_path() / "adse_islands";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "n.nod.xml") << R"(<nodes>
  <node id="a" x="0" y="0"/><node id="b" x="100" y="0"/>
  <node id="c" x="0" y="50"/><node id="d" x="100" y="50"/></nodes>)";
  std::ofstream(dir / "e.edg.xml") << R"(<edges>
  <edge id="ab" from="a" to="b" numLanes="1"/><edge id="cd" from="c" to="d" numLanes="1"/></edges>)";
  const std::string net = (dir / "islands.net.xml").string();
  ASSERT_EQ(std::system(("netconvert -n " + (dir / "n.nod.xml").string() +
                         " -e " + (dir / "e.edg.xml").string() + " -o " + net +
                         " --offset.disable-normalization true >/dev/null 2>&1")
                            .c_str()),
            0);
  WorldSetup setup;
  setup.world.map.net_path = net;
  setup.task.start = Location::Xy(10, -1.6);
  setup.task.goal = Location::Xy(90, 48.4);
  setup.cache_dir = CacheDir();
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_FALSE(world.ok());
  EXPECT_NE(world.status().message().find("task.goal"), std::string::npos);
  EXPECT_NE(world.status().message().find("unreachable"), std::string::npos)
      << world.status().message();
}

// A net of two-way, one-lane streets from `streets` (pairs of node ids),
// with netconvert's default turnarounds at every junction and dead end.
// Lanes are netconvert's 3.2 m wide unless `lane_width_m` is given.
std::string TwoWayNet(
    const std::string& name, const std::string& nodes,
    const std::vector<std::pair<std::string, std::string>>& streets,
    double lane_width_m = 0.0) {
  const std::string width =
      lane_width_m > 0 ? " width=\"" + std::to_string(lane_width_m) + "\"" : "";
  const auto dir = std::filesystem::temp_directory_path() / ("adse_" + name);
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "n.nod.xml") << "<nodes>" << nodes << "</nodes>";
  {
    std::ofstream edges(dir / "e.edg.xml");
    edges << "<edges>";
    for (const auto& [a, b] : streets) {
      edges << "<edge id=\"" << a << b << "\" from=\"" << a << "\" to=\"" << b
            << "\" numLanes=\"1\"" << width << "/><edge id=\"" << b << a
            << "\" from=\"" << b << "\" to=\"" << a << "\" numLanes=\"1\""
            << width << "/>";
    }
    edges << "</edges>";
  }
  const std::string net = (dir / (name + ".net.xml")).string();
  const std::string command =
      "netconvert -n " + (dir / "n.nod.xml").string() + " -e " +
      (dir / "e.edg.xml").string() + " -o " + net +
      " --offset.disable-normalization true >/dev/null 2>&1";
  EXPECT_EQ(std::system(command.c_str()), 0);
  return net;
}

// Two blocks side by side, 100 m square; the goal lies 40 m ahead of the
// start on the other side of the street.
WorldSetup TwoBlocksGoalAcrossTheStreet() {
  WorldSetup setup;
  setup.world.map.net_path =
      TwoWayNet("blocks",
                R"(<node id="a" x="0" y="0"/><node id="m" x="100" y="0"/>
         <node id="b" x="200" y="0"/><node id="c" x="200" y="100"/>
         <node id="n" x="100" y="100"/><node id="d" x="0" y="100"/>)",
                {{"a", "m"},
                 {"m", "b"},
                 {"b", "c"},
                 {"c", "n"},
                 {"n", "d"},
                 {"d", "a"},
                 {"m", "n"}});
  setup.task.start = Location::Xy(20, -1.6);  // eastbound
  setup.task.goal = Location::Xy(60, 1.6);    // westbound
  return setup;
}

TEST(WorldTest, ARouteGoesRoundTheBlockRatherThanAUTurnTooTightForTheCar) {
  // SUMO's shortest route turns around at m (3.2 m between the lanes, the
  // car needs 7.9 m); the car drives round a block.
  WorldSetup setup = TwoBlocksGoalAcrossTheStreet();
  setup.cache_dir = CacheDir();
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  // 80 + 4 x 100 + 40 m round either block; the U-turn was about 125 m.
  EXPECT_NEAR((*world)->ideal_path().length_m(), 520.0, 30.0);
  const IdealDriveReport report = DriveToTheGoal(**world, 30.0, 200.0);
  // No U-turn to swing wide of (4.9-10 m on the real nets): about 1.1 m
  // where the right turns at the blocks' corners bend within 2 m.
  EXPECT_LT(report.max_lateral_error_m, 1.5);
}

TEST(WorldTest, PassingTheGoalOnTheOtherSideOfTheStreetDoesNotReachIt) {
  // The round-the-block route above starts by passing its goal 3.2 m
  // away on the other side of the street; with a 5 m tolerance that is
  // near enough, but the car is at the start of its route, not the end.
  WorldSetup setup = TwoBlocksGoalAcrossTheStreet();
  setup.task.goal_tolerance_m = 5.0;
  setup.cache_dir = CacheDir();
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  double nearest_m = 1e9;
  while ((*world)->ego().x_m < 70.0 && (*world)->time_s() < 30.0) {
    ControlCommand straight;
    straight.accel_mps2 = (*world)->ego().v_mps < 5.0 ? 1.0 : 0.0;
    ASSERT_TRUE((*world)->Step(straight).ok());
    nearest_m = std::min(nearest_m, (*world)->distance_to_goal_m());
    EXPECT_FALSE((*world)->goal_reached()) << "at x " << (*world)->ego().x_m;
  }
  EXPECT_LT(nearest_m, 3.5);  // it did pass within the tolerance
  EXPECT_NEAR((*world)->road_progress_m(), 50.0, 2.0);
}

TEST(WorldTest, AGoalBehindTheStartIsReachedByATurnInSeveralMoves) {
  // A dead-end street that bends left at b into a 15 m dead-end stub:
  // every way back is a turnaround 3.2 m across, where the car needs
  // 7.9 m (netconvert puts none at the bend). SUMO's route turns round at
  // the stub's end; the car stops short of it and turns round forwards
  // and in reverse within the two streets' lanes and the bend.
  WorldSetup setup;
  setup.world.map.net_path =
      TwoWayNet("dead_end_bend",
                R"(<node id="a" x="0" y="0"/><node id="b" x="200" y="0"/>
                   <node id="c" x="200" y="15"/>)",
                {{"a", "b"}, {"b", "c"}});
  setup.task.start = Location::Xy(20, -1.6);
  setup.task.goal = Location::Xy(150, 1.6);
  setup.cache_dir = CacheDir();
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  const std::vector<RouteTurnaround>& turns = (*world)->route_turnarounds();
  ASSERT_EQ(turns.size(), 2u);
  const RouteTurnaround& turn = turns[0];
  EXPECT_FALSE(turn.corner);
  EXPECT_GE(ManoeuvreMoves(turn.reference), 3);
  // The bend back west comes 5 m past where the turn ends, too soon for
  // the car, standing there, to follow the lanes round it within 1 m: a
  // corner driven as a manoeuvre of its own, in one move.
  EXPECT_TRUE(turns[1].corner);
  EXPECT_NEAR(turns[1].start_s_m, turn.end_s_m, 1e-6);
  EXPECT_EQ(ManoeuvreMoves(turns[1].reference), 1);
  // It ends on the lane back out of the stub, heading south.
  EXPECT_NEAR(turn.goal.x_m, 198.4, 1.0);
  EXPECT_NEAR(turn.goal.yaw_rad, -M_PI / 2, 0.05);
  // The ideal path takes the manoeuvre, not SUMO's U-turn.
  EXPECT_GT((*world)->ideal_path().length_m(),
            (*world)->road_path().length_m() - 20.0);
  const IdealDriveReport report = DriveToTheGoal(**world, 30.0, 200.0);
  EXPECT_EQ(report.collisions, 0);
  // Up to 3.4 m off the ideal path, all of it about the bend (the bench's
  // real nets measure this outside junctions).
  EXPECT_LT(report.max_lateral_error_m, 4.0);
  double reversed_m = 0.0;
  for (size_t i = 1; i < report.trajectory.size(); ++i) {
    const TrajectorySample& a = report.trajectory[i - 1];
    if (a.v_mps < 0) {
      reversed_m += std::hypot(report.trajectory[i].x_m - a.x_m,
                               report.trajectory[i].y_m - a.y_m);
    }
  }
  EXPECT_GT(reversed_m, 1.0);
  // The rear axle never leaves the two streets' lanes (3.2 m each side of
  // their middles) but in the bend.
  for (const TrajectorySample& t : report.trajectory) {
    const bool bend = std::abs(t.x_m - 200.0) < 7 && std::abs(t.y_m) < 7;
    ASSERT_TRUE(std::abs(t.y_m) < 3.2 || std::abs(t.x_m - 200.0) < 3.2 || bend)
        << "at t " << t.t_s << ": (" << t.x_m << ", " << t.y_m << ")";
  }
}

// A dead-end street of two lanes, `lane_width_m` each, with no side
// street: only a U-turn leads to a goal on its far side.
WorldSetup DeadEndStreet(const std::string& name, double lane_width_m) {
  WorldSetup setup;
  setup.world.map.net_path = TwoWayNet(
      name, R"(<node id="a" x="0" y="0"/><node id="b" x="200" y="0"/>)",
      {{"a", "b"}}, lane_width_m);
  setup.task.start = Location::Xy(20, -0.5 * lane_width_m);
  setup.task.goal = Location::Xy(150, 0.5 * lane_width_m);
  setup.cache_dir = CacheDir();
  return setup;
}

TEST(WorldTest, AUTurnInAStreetNarrowerThanTheCarIsMadeOnItsShoulders) {
  // Two 2.2 m lanes: 4.4 m across, shorter than the 4.6 m car. With 1 m
  // of shoulder either side a turn in several moves fits.
  Result<std::unique_ptr<World>> world =
      World::Open(DeadEndStreet("narrow_dead_end", 2.2));
  ASSERT_TRUE(world.ok()) << world.status().message();
  const std::vector<RouteTurnaround>& turns = (*world)->route_turnarounds();
  ASSERT_EQ(turns.size(), 1u);
  EXPECT_FALSE(turns[0].corner);
  EXPECT_TRUE(turns[0].on_shoulders);
  EXPECT_GE(ManoeuvreMoves(turns[0].reference), 3);
  // Its moves keep to the street and its shoulders: 2.2 + 1 m either side
  // of the centre line, less the body's half width at most.
  for (const algorithms::GearedPose& p : turns[0].reference) {
    EXPECT_LT(std::abs(p.pose.y_m), 3.2) << "at x " << p.pose.x_m;
  }
}

TEST(WorldTest, AGoalOnlyAUTurnInAStreetTooNarrowForAnyTurnReachesIsRejected) {
  // Two 1.2 m lanes: 2.4 m across and 4.4 m with the shoulders, shorter
  // than the 4.6 m car.
  Result<std::unique_ptr<World>> world =
      World::Open(DeadEndStreet("narrowest_dead_end", 1.2));
  ASSERT_FALSE(world.ok());
  const std::string& message = world.status().message();
  EXPECT_EQ(message.rfind("task.goal: unreachable from task.start", 0), 0u)
      << message;
  EXPECT_NE(message.find("turns around from lane 'ab_0' to lane 'ba_0'"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("no turn in several moves fits"), std::string::npos)
      << message;
}

// Two aisles between four rows: rows of W<i>/E<i> nodes at i = 0 (south
// ring), 1, 2 (aisles) and 3 (north ring), every road two-way.
WorldSetup TwoAisleLot() {
  WorldSetup setup = SmallLot();
  setup.world.map.generator_params = {{"rows", 4}, {"slots_per_row", 8}};
  setup.task.goal = Location::OnEdge("E3_W3", 20.0);
  return setup;
}

TEST(WorldTest, ARouteThatChangesLaneSaysWhereAndByHowMuch) {
  // A two-lane road whose left turn leaves from its left lane only; the
  // car starts in the right lane.
  const std::string net = std::string(ADSE_SOURCE_DIR) +
                          "/tests/data/nets/two_lanes_left_turn.net.xml";
  WorldSetup setup;
  setup.world.map.net_path = net;
  setup.task.start = Location::Xy(20, -4.8);   // right lane, eastbound
  setup.task.goal = Location::Xy(401.6, 100);  // north, after the left turn
  setup.cache_dir = CacheDir();
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  const auto& changes = (*world)->route_lane_changes();
  ASSERT_EQ(changes.size(), 1u);
  const algorithms::LaneChangeSection& change = changes.front();
  EXPECT_NEAR(change.shift_m, 3.2, 1e-6);  // one lane to the left
  EXPECT_NEAR(change.lane_width_m, 3.2, 1e-6);
  // The middle half of what the route drives of the road: 20 to 400 m,
  // less the junction's corner.
  EXPECT_NEAR(change.start_s_m, 93.0, 3.0);
  EXPECT_NEAR(change.end_s_m, 280.0, 5.0);
  // The road part is in the right lane up to the section, in the left one
  // from its end, and half way across at its middle.
  const geometry::Path2& road = (*world)->road_path();
  EXPECT_NEAR(road.PointAt(change.start_s_m).y(), -4.8, 0.05);
  EXPECT_NEAR(road.PointAt(0.5 * (change.start_s_m + change.end_s_m)).y(), -3.2,
              0.05);
  EXPECT_NEAR(road.PointAt(change.end_s_m).y(), -1.6, 0.05);
}

TEST(WorldTest, WaypointsLeadTheRouteThroughTheAislesInOrder) {
  WorldSetup direct = TwoAisleLot();
  WorldSetup serpentine = TwoAisleLot();
  // West along the first aisle, then east along the second.
  serpentine.task.via = {Location::OnEdge("E1_W1", 5.0),
                         Location::OnEdge("W2_E2", 5.0)};
  double direct_length = 0.0;
  {
    Result<std::unique_ptr<World>> world = World::Open(direct);
    ASSERT_TRUE(world.ok()) << world.status().ToString();
    direct_length = (*world)->ideal_path().length_m();
  }
  // libsumo holds one simulation per process: the second world opens after
  // the first is gone.
  Result<std::unique_ptr<World>> world = World::Open(serpentine);
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  const World& w = **world;
  EXPECT_EQ(w.route_edges(),
            (std::vector<std::string>{"W0_E0", "E0_E1", "E1_W1", "W1_W2",
                                      "W2_E2", "E2_E3", "E3_W3"}));
  // Two more aisle lengths than the direct route (about 20 m each).
  EXPECT_GT(w.ideal_path().length_m(), direct_length + 30.0);
  EXPECT_LT(w.ideal_path().MaxGap(), 0.51);
  EXPECT_LT(w.ideal_path_max_join_gap_m(), 0.5);
}

TEST(WorldTest, AWaypointOffTheRoadIsRejectedByItsIndex) {
  WorldSetup setup = TwoAisleLot();
  setup.task.via = {Location::OnEdge("E1_W1", 5.0),
                    Location::Xy(15.0, 8.0)};  // in the parking rows
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_FALSE(world.ok());
  EXPECT_NE(world.status().message().find("task.via[1]"), std::string::npos)
      << world.status().message();
  EXPECT_NE(world.status().message().find("off the road"), std::string::npos)
      << world.status().message();
}

TEST(WorldTest, SecondOpenWorldInOneProcessIsRefused) {
  Result<std::unique_ptr<World>> first = World::Open(SmallLot());
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  Result<std::unique_ptr<World>> second = World::Open(SmallLot());
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(second.status().code(), Status::Code::kUnavailable);
}

// A valet task into slot 3 of row 0 (below the aisle: x in [17, 19.5],
// y in [5.5, 10.5]), nose in (heading south).
WorldSetup ValetLot() {
  WorldSetup setup = SmallLot();
  setup.task.kind = TaskKind::kValetParking;
  setup.task.goal = Location();
  setup.task.goal.slot = "slot_r0_s3";
  setup.task.goal.has_yaw = true;
  setup.task.goal.yaw_deg = -90;
  setup.task.goal_tolerance_m = 0.5;
  return setup;
}

TEST(WorldTest, ValetGoalIsTheParkedPoseInTheNamedSlot) {
  const WorldSetup setup = ValetLot();
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  const World& w = **world;
  ASSERT_TRUE(w.parking_task());
  EXPECT_EQ(w.goal_slot().name, "slot_r0_s3");
  EXPECT_FALSE(w.goal_slot().occupied);
  // The body's centre (half a wheelbase ahead of the rear axle) is the
  // slot's centre, heading into the slot.
  const geometry::Pose2& goal = w.parking_goal();
  EXPECT_NEAR(goal.x_m, 18.25, 1e-9);
  EXPECT_NEAR(goal.y_m, 8.0 + 0.5 * setup.ego.wheelbase_m, 1e-9);
  EXPECT_NEAR(goal.yaw_rad, -M_PI / 2, 1e-9);
  // The road part ends on the aisle beside the slot; the ideal path goes
  // on with the reference manoeuvre to the parked pose.
  const geometry::Path2& road = w.road_path();
  EXPECT_NEAR(road.points.back().x(), 18.25, 0.3);
  EXPECT_GT(road.points.back().y(), 10.5);
  const Eigen::Vector2d end = w.ideal_path().points.back();
  EXPECT_NEAR(end.x(), goal.x_m, 1e-6);
  EXPECT_NEAR(end.y(), goal.y_m, 1e-6);
  EXPECT_GT(w.ideal_path().length_m(), road.length_m() + 4.0);
  EXPECT_FALSE(w.goal_reached());  // not parked at the start
}

TEST(WorldTest, PerfectDriverParksAlongTheReferenceManoeuvre) {
  Result<std::unique_ptr<World>> world = World::Open(ValetLot());
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  World& w = **world;
  ASSERT_FALSE(w.reference_manoeuvre().empty());
  IdealDriverOptions options;
  options.scan = false;
  options.timeout_s = 120;
  Result<IdealDriveReport> report = DriveIdealPath(w, nullptr, options);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_TRUE(report->reached_goal);
  EXPECT_TRUE(w.goal_reached());
  EXPECT_EQ(report->collisions, 0);
  EXPECT_LT(report->max_lateral_error_m, 0.5);
  // It drove in reverse at some point only if the manoeuvre asks for it.
  bool plan_reverses = false, drove_back = false;
  for (const algorithms::GearedPose& p : w.reference_manoeuvre())
    plan_reverses = plan_reverses || p.reverse;
  for (const TrajectorySample& t : report->trajectory)
    drove_back = drove_back || t.v_mps < -0.1;
  EXPECT_EQ(drove_back, plan_reverses);
}

TEST(WorldTest, ValetGoalNeedsTheParkedHeadingAlongTheSlot) {
  WorldSetup setup = ValetLot();
  setup.task.goal.has_yaw = false;
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_FALSE(world.ok());
  EXPECT_EQ(world.status().message().rfind("task.goal.yaw_deg:", 0), 0u)
      << world.status().message();
}

TEST(WorldTest, ValetGoalAcrossTheSlotIsRefused) {
  WorldSetup setup = ValetLot();
  setup.task.goal.yaw_deg = 0;
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_FALSE(world.ok());
  EXPECT_EQ(world.status().message().rfind("task.goal.yaw_deg: 0 is across", 0),
            0u)
      << world.status().message();
}

TEST(WorldTest, ValetGoalInAnUnknownSlotIsRefused) {
  WorldSetup setup = ValetLot();
  setup.task.goal.slot = "slot_r9_s3";
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_FALSE(world.ok());
  EXPECT_EQ(world.status().message().rfind("task.goal.slot:", 0), 0u)
      << world.status().message();
}

TEST(WorldTest, OccupiedTargetSlotIsRefused) {
  WorldSetup setup = ValetLot();
  setup.world.traffic.parked_slots = {"slot_r0_s2", "slot_r0_s3"};
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_FALSE(world.ok());
  EXPECT_EQ(world.status().code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(world.status().message().rfind(
                "task.goal.slot: slot 'slot_r0_s3' is occupied", 0),
            0u)
      << world.status().message();
}

TEST(WorldTest, ParkedSlotsListedAreExactlyTheOccupiedOnes) {
  WorldSetup setup = ValetLot();
  setup.world.traffic.parked_slots = {"slot_r0_s2", "slot_r0_s4", "slot_r1_s0"};
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  int occupied = 0;
  for (const ParkingSlot& slot : (*world)->scene().parking_slots()) {
    const bool listed = slot.name == "slot_r0_s2" ||
                        slot.name == "slot_r0_s4" || slot.name == "slot_r1_s0";
    EXPECT_EQ(slot.occupied, listed) << slot.name;
    occupied += slot.occupied;
  }
  EXPECT_EQ(occupied, 3);
  setup.world.traffic.parked_slots = {"slot_r0_s2", "nowhere"};
  world.value().reset();
  Result<std::unique_ptr<World>> again = World::Open(setup);
  ASSERT_FALSE(again.ok());
  EXPECT_EQ(again.status().message().rfind("world.traffic.parked_slots[1]:", 0),
            0u)
      << again.status().message();
}

}  // namespace
}  // namespace adse::world
