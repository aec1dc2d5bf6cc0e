// The SUMO world end to end on generated maps: routing, the ideal path,
// traffic determinism, the ego, LiDAR seeing SUMO vehicles, lane changes,
// waypoints, valet parking, and the errors for bad maps and bad
// start/goal. Real nets, turns in several moves and the contact rule have
// files of their own. Each TEST runs in its own process
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
#include "stack/world/map_builder.h"
#include "stack/world/map_cloud.h"
#include "tests/stack/world/testing/real_nets.h"
#include "tests/testing/temp_files.h"

namespace adse::world {
namespace {

using testing::CacheDir;
using testing::DriveToTheGoal;

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
      (adse::testing::TestScratch() / "adse_corrupt.net.xml").string();
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

// `setup` on a net and polygons file of its own instead of its generator.
WorldSetup OnFiles(WorldSetup setup, const std::string& net,
                   const std::string& polygons) {
  setup.world.map.generator.clear();
  setup.world.map.generator_params.clear();
  setup.world.map.net_path = net;
  setup.world.map.polygons_path = polygons;
  return setup;
}

TEST(WorldTest, APolygonWhoseHeightIsNoNumberIsRejectedByName) {
  // The small lot's own net and polygons, its first wall's height mistyped.
  const WorldSetup lot = SmallLot();
  Result<MapArtifacts> map = PrepareMap(lot.world.map, lot.cache_dir);
  ASSERT_TRUE(map.ok()) << map.status().ToString();
  std::ifstream in(map->polygons_path);
  std::string polygons((std::istreambuf_iterator<char>(in)),
                       std::istreambuf_iterator<char>());
  const std::string height = "<param key=\"height_m\" value=\"2.50\"/>";
  const size_t at = polygons.find(height);
  ASSERT_NE(at, std::string::npos);
  polygons.replace(at, height.size(),
                   "<param key=\"height_m\" value=\"2,5\"/>");
  const std::string mistyped =
      (adse::testing::TestScratch() / "adse_mistyped.poly.xml").string();
  std::ofstream(mistyped) << polygons;
  WorldSetup setup = OnFiles(lot, map->net_path, mistyped);
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_FALSE(world.ok());
  EXPECT_EQ(world.status().message(),
            "world.map.polygons: " + mistyped +
                ": polygon 'wall_0' (type 'adse.wall'): expected height_m as "
                "a number of metres >= 0, found '2,5'");
}

TEST(WorldTest, APolygonsFileSumoCannotLoadIsNamedAsThePolygons) {
  // The small lot's own net, its polygons file holding one id twice.
  const WorldSetup lot = SmallLot();
  Result<MapArtifacts> map = PrepareMap(lot.world.map, lot.cache_dir);
  ASSERT_TRUE(map.ok()) << map.status().ToString();
  const std::string twice =
      (adse::testing::TestScratch() / "adse_twice.poly.xml").string();
  std::ofstream(twice)
      << "<additional>\n"
         "  <poly id=\"p\" type=\"adse.wall\" shape=\"0,0 1,0 1,1\"/>\n"
         "  <poly id=\"p\" type=\"adse.wall\" shape=\"2,0 3,0 3,1\"/>\n"
         "</additional>\n";
  WorldSetup setup = OnFiles(lot, map->net_path, twice);
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_FALSE(world.ok());
  EXPECT_NE(world.status().message().find("world.map.polygons: SUMO cannot "
                                          "load '" +
                                          twice + "'"),
            std::string::npos)
      << world.status().message();
  EXPECT_EQ(world.status().message().find("world.map.net"), std::string::npos)
      << world.status().message();
  // The network alone still loads: the next world opens.
  setup.world.map.polygons_path = map->polygons_path;
  EXPECT_TRUE(World::Open(setup).ok());
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
  const auto dir = adse::testing::TestScratch() / "adse_islands";
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
