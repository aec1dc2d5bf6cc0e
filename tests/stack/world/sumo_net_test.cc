// The world reads a SUMO net as SUMO means it: a position along a lane is
// in the lane's own length, scaled onto its shape; a game's signal is
// switched from program to program as its player would. On nets Debian's
// sumo-tools ships. Each TEST runs in its own process
// (gtest_discover_tests), which libsumo needs.
#include <gtest/gtest.h>

#include <memory>

#include "stack/world/world.h"
#include "tests/stack/world/testing/real_nets.h"

namespace adse::world {
namespace {

using testing::BenchRoute;
using testing::DriveToTheGoal;
using testing::kBs3dNet;
using testing::kGrid6Net;
using testing::OpenBenchRoute;
using testing::OpenOnSumoToolsNet;

TEST(SumoNetTest, AGoalOnALaneLongerThanItsLengthIsWhereSumoPutsIt) {
  // grid6's gneE17 is 80 m long on a 93.9 m shape: SUMO puts 40 m at the
  // shape's middle, (106.45, 269.14). The path ended at 40 m along the
  // shape, 6.9 m short, where the car stood for ever (the real-nets
  // bench's grid6-0).
  Result<std::unique_ptr<World>> world =
      OpenBenchRoute(kGrid6Net, Location::OnEdge("gneE27", 10.0, 0),
                     Location::OnEdge("gneE17", 40.0, 0));
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  const Eigen::Vector2d end = (*world)->ideal_path().points.back();
  EXPECT_NEAR(end.x(), 106.45, 0.1);
  EXPECT_NEAR(end.y(), 269.14, 0.1);
  DriveToTheGoal(**world, 40.0, 300.0);
}

// bs3d's signal at cluster_104171179_... runs program 3 (SUMO runs the
// last of a signal's programs), which holds the link from 166445407_0 to
// 23204862_0 red for ever (each of programs 0-3 is one direction's green
// of 1,000 s, until the game's player switches it); program 2 turns it
// green.
Result<IdealDriveReport> DriveThroughTheGameSignal(double switch_s) {
  WorldSetup setup =
      BenchRoute(kBs3dNet, Location::OnEdge("166445407", 20.0, 0),
                 Location::OnEdge("23204862", 60.0, 0));
  setup.world.traffic.signal_program_switch_s = switch_s;
  Result<std::unique_ptr<World>> world = OpenOnSumoToolsNet(setup);
  if (!world.ok()) return world.status();
  EXPECT_EQ((*world)->route_signals().size(), 1u);
  return DriveToTheGoal(**world, 40.0, 600.0);
}

TEST(SumoNetTest, AGameSignalWaitingForAPlayerIsSwitchedAsAPlayerWould) {
  // Switched every 30 s (to 0, 1, 2), program 2 runs from 90 s, green
  // after its 4 s of yellow and 2 s of red: the car, standing at the stop
  // line from about 16 s, waits about 80 s.
  Result<IdealDriveReport> report = DriveThroughTheGameSignal(30.0);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_NEAR(report->red_light_wait_s, 80.0, 8.0);
}

TEST(SumoNetTest, WithoutSwitchingAGameSignalIsPassedOnlyAfterTheLongestWait) {
  // The net's program as it is: red for ever, so the car waits
  // traffic_light.max_red_wait_s (300 s) and goes.
  Result<IdealDriveReport> report = DriveThroughTheGameSignal(0.0);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_NEAR(report->red_light_wait_s, 300.0, 2.0);
}

}  // namespace
}  // namespace adse::world
