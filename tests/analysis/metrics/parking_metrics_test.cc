#include "analysis/metrics/parking_metrics.h"

#include <gtest/gtest.h>

#include <cmath>

#include "analysis/metrics/run_metrics.h"

namespace adse::analysis {
namespace {

using runfile::EgoSample;
using runfile::RunData;

// A car backing straight into a slot along -y: forwards 2 m along +x,
// a gear change, then 6 m in reverse down to the goal at (2, -6).
RunData BackingIn(double end_x_m, double end_yaw_rad) {
  RunData run;
  run.parking.present = true;
  run.parking.goal_x_m = 2.0;
  run.parking.goal_y_m = -6.0;
  run.parking.goal_yaw_rad = M_PI / 2;
  run.parking.tolerance_m = 0.3;
  run.parking.yaw_tolerance_rad = 0.1;
  run.parking.planned_at_s = 1.0;
  run.parking.path_found = 1;
  run.parking.planned_path = {{0, 0, 0, 0}, {2, 0, 0, 0}, {2, -6, M_PI / 2, 1}};
  // A wall beside the slot, 1.4 m from the parked body's side.
  run.parking.obstacles = {{0, 4.45, -10}, {0, 4.45, -2.5}};
  double t = 0.0;
  for (int i = 0; i <= 20; ++i) {  // forwards at 1 m/s
    run.ego.push_back({t, 0.1 * i, 0, 0, 1.0, 0, 0});
    t += 0.1;
  }
  run.ego.push_back({t, 2, 0, 0, 0.0, 0, 0});
  t += 0.1;
  for (int i = 1; i <= 60; ++i) {  // reverse along -y, heading +y
    const double u = i / 60.0;
    run.ego.push_back({t, 2 + u * (end_x_m - 2), -6 * u,
                       M_PI / 2 + u * (end_yaw_rad - M_PI / 2),
                       i == 60 ? 0.0 : -1.0, 0, 0});
    t += 0.1;
  }
  return run;
}

TEST(ParkingMetrics, ParkedWithinTolerances) {
  const RunData run = BackingIn(2.1, M_PI / 2 + 0.05);
  std::map<std::string, double> m;
  AddParkingMetrics(run, &m);
  EXPECT_EQ(m["parked"], 1.0);
  EXPECT_NEAR(m["parking_position_error_m"], 0.1, 1e-9);
  EXPECT_NEAR(m["parking_yaw_error_deg"], 0.05 * 180 / M_PI, 1e-9);
  EXPECT_EQ(m["gear_changes"], 1.0);
  EXPECT_EQ(m["obstacle_collisions"], 0.0);
  EXPECT_NEAR(m["parking_time_s"], run.ego.back().t_s - 1.0, 1e-9);
  // Closest at the end: the rear corner on the wall's side, with the body
  // (4.6 x 1.9, centre 1.35 m ahead of the axle) turned 0.05 rad past +y.
  const double yaw = M_PI / 2 + 0.05;
  const double corner_x =
      2.1 + (1.35 - 2.3) * std::cos(yaw) + 0.95 * std::sin(yaw);
  EXPECT_NEAR(m["min_clearance_m"], 4.45 - corner_x, 1e-9);
  // It drifted up to 0.1 m off the planned reverse leg.
  EXPECT_NEAR(m["parking_path_deviation_max_m"], 0.1, 1e-6);
  EXPECT_GT(m["parking_path_deviation_m"], 0.0);
  EXPECT_LT(m["parking_path_deviation_m"], 0.1);
}

TEST(ParkingMetrics, OutsideTheToleranceIsNotParked) {
  std::map<std::string, double> m;
  AddParkingMetrics(BackingIn(2.5, M_PI / 2), &m);
  EXPECT_EQ(m["parked"], 0.0);
  m.clear();
  AddParkingMetrics(BackingIn(2.0, M_PI / 2 + 0.2), &m);
  EXPECT_EQ(m["parked"], 0.0);
}

TEST(ParkingMetrics, TouchingAnObstacleCountsOnce) {
  RunData run = BackingIn(2.0, M_PI / 2);
  // A pole in the middle of the reverse leg.
  run.parking.obstacles.push_back({1, 2.0, -3.0});
  run.parking.obstacles.push_back({1, 2.2, -3.0});
  run.parking.obstacles.push_back({1, 2.2, -3.2});
  std::map<std::string, double> m;
  AddParkingMetrics(run, &m);
  EXPECT_EQ(m["obstacle_collisions"], 1.0);
  EXPECT_EQ(m["min_clearance_m"], 0.0);
  // Where: the car's tail reaches the pole's north edge (y = -3) first,
  // while reversing (its axle 0.95 m short of the body's rear, backing
  // along -y with the body's half-width 0.95 m either side of x = 2).
  const std::vector<ParkingContact> contacts = ParkingContacts(run);
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_LT(contacts[0].ego.v_mps, 0.0);
  EXPECT_NEAR(contacts[0].ego.y_m, -3.0 + 0.95, 0.1 + 1e-9);
  EXPECT_NEAR(contacts[0].y_m, -3.0, 0.1 + 1e-9);
  EXPECT_GE(contacts[0].x_m, 2.0 - 1e-9);
  EXPECT_LE(contacts[0].x_m, 2.2 + 1e-9);
  run.parking.present = false;
  EXPECT_TRUE(ParkingContacts(run).empty());
}

TEST(ParkingMetrics, OnlyValetRunsHaveThem) {
  RunData run = BackingIn(2.0, M_PI / 2);
  EXPECT_EQ(ComputeRunMetrics(run).count("parked"), 1u);
  run.parking.present = false;
  EXPECT_EQ(ComputeRunMetrics(run).count("parked"), 0u);
  // Without a plan: no deviation, no parking time.
  run = BackingIn(2.0, M_PI / 2);
  run.parking.planned_path.clear();
  run.parking.planned_at_s = -1;
  std::map<std::string, double> m;
  AddParkingMetrics(run, &m);
  EXPECT_TRUE(std::isnan(m["parking_path_deviation_m"]));
  EXPECT_TRUE(std::isnan(m["parking_time_s"]));
}

}  // namespace
}  // namespace adse::analysis
