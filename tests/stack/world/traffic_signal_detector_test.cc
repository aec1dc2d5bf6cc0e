// The world's traffic-signal detector: what it reports (range, the next
// signal not yet passed, SUMO's letters read as states), when (its rate and
// latency), and the signals the world finds on a route of a real net. Each
// TEST runs in its own process (gtest_discover_tests), which libsumo needs.
#include "stack/world/traffic_signal_detector.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "stack/world/world.h"
#include "tests/stack/world/testing/real_nets.h"

namespace adse::world {
namespace {

constexpr char kRilsa[] =
    "/usr/share/sumo/tools/sumolib/scenario/scenarios/RiLSA1/rilsa1.net.xml";

geometry::Path2 StraightRoute(double length_m) {
  geometry::Path2 path;
  for (double x = 0.0; x <= length_m + 1e-9; x += 0.5)
    path.points.emplace_back(x, 0.0);
  path.UpdateArcLength();
  return path;
}

// Two signals on a 300 m straight route: J1's line at 150 m, J2's at 250 m.
std::vector<RouteSignal> TwoSignals() {
  return {{"J1", 3, 150.0}, {"J2", 0, 250.0}};
}

// One look with the rear axle at x and the reports it gives, latency 0.
SignalReport LookAt(TrafficSignalDetector* detector, double x,
                    const std::string& letters) {
  detector->Look({x, 0.4}, letters);
  std::vector<SignalReport> due = detector->TakeDue(1e9);
  EXPECT_EQ(due.size(), 1u);
  return due.empty() ? SignalReport() : due.front();
}

TEST(TrafficSignalDetector, ReportsTheNextSignalWithinItsRangeOnly) {
  TrafficSignalDetectorParams params;
  params.range_m = 100.0;
  params.latency_s = 0.0;
  TrafficSignalDetector detector(StraightRoute(300), TwoSignals(), params);
  // J1 is 130 m ahead: out of range, nothing reported.
  SignalReport r = LookAt(&detector, 20.0, "rG");
  EXPECT_TRUE(r.tls_id.empty());
  EXPECT_EQ(r.stop_line_distance_m, -1.0);
  EXPECT_EQ(r.state, SignalState::kUnknown);
  // 90 m ahead: in range, red (J1's letter comes first).
  r = LookAt(&detector, 60.0, "rG");
  EXPECT_EQ(r.tls_id, "J1");
  EXPECT_NEAR(r.stop_line_distance_m, 90.0, 1e-6);
  EXPECT_EQ(r.state, SignalState::kRed);
  // A car standing with its nose over the line still sees J1 ...
  r = LookAt(&detector, 148.0, "yG");
  EXPECT_EQ(r.tls_id, "J1");
  EXPECT_EQ(r.state, SignalState::kYellow);
  // ... until its rear axle passes it; then J2, 99 m on, is next.
  r = LookAt(&detector, 151.0, "rG");
  EXPECT_EQ(r.tls_id, "J2");
  EXPECT_NEAR(r.stop_line_distance_m, 99.0, 1e-6);
  EXPECT_EQ(r.state, SignalState::kGreen);
  // Past the last signal: nothing.
  EXPECT_TRUE(LookAt(&detector, 260.0, "rr").tls_id.empty());
}

TEST(TrafficSignalDetector, LooksAtItsRateAndReportsLatencyAfterEachLook) {
  TrafficSignalDetectorParams params;
  params.rate_hz = 10.0;
  params.latency_s = 0.25;
  TrafficSignalDetector detector(StraightRoute(300), TwoSignals(), params);
  for (int i = 0; i < 5; ++i) {
    EXPECT_NEAR(detector.next_look_s(), 0.1 * i, 1e-12);
    detector.Look({100.0 + i, 0.0}, "GG");
  }
  // Looks at 0, 0.1, ..., 0.4 are published at 0.25, 0.35, ...: before
  // 0.25 none, before 0.36 two, stamped with their looks.
  EXPECT_TRUE(detector.TakeDue(0.25).empty());
  std::vector<SignalReport> due = detector.TakeDue(0.36);
  ASSERT_EQ(due.size(), 2u);
  EXPECT_NEAR(due[0].stamp_s, 0.0, 1e-12);
  EXPECT_NEAR(due[0].publish_s, 0.25, 1e-12);
  EXPECT_NEAR(due[1].stamp_s, 0.1, 1e-12);
  EXPECT_NEAR(due[1].publish_s, 0.35, 1e-12);
  // What it saw then, not what is there when the report arrives.
  EXPECT_NEAR(due[1].stop_line_distance_m, 150.0 - 101.0, 1e-6);
  EXPECT_EQ(detector.TakeDue(10.0).size(), 3u);
  EXPECT_TRUE(detector.TakeDue(10.0).empty());
}

TEST(TrafficSignalDetector, ReadsSumosLettersAsACarWould) {
  EXPECT_EQ(SignalStateOfLetter('G'), SignalState::kGreen);
  EXPECT_EQ(SignalStateOfLetter('g'), SignalState::kGreen);
  EXPECT_EQ(SignalStateOfLetter('y'), SignalState::kYellow);
  EXPECT_EQ(SignalStateOfLetter('r'), SignalState::kRed);
  EXPECT_EQ(SignalStateOfLetter('u'), SignalState::kRed);      // red-yellow
  EXPECT_EQ(SignalStateOfLetter('o'), SignalState::kUnknown);  // off
  EXPECT_EQ(SignalStateOfLetter('s'), SignalState::kUnknown);  // stop, go
}

TEST(TrafficSignalDetector, TheWorldFindsTheSignalOnARilsaRoute) {
  ASSERT_TRUE(std::filesystem::exists(kRilsa)) << "sumo-tools is not installed";
  WorldSetup setup;
  setup.world.map.net_path = kRilsa;
  // North to south straight through the junction's signal ("0", link 1):
  // 77 m to the stop line at the end of nm_1.
  setup.task.start = Location::OnEdge("nm", 10.0, 1);
  setup.task.goal = Location::OnEdge("ms", 60.0, 1);
  setup.cache_dir = testing::CacheDir();
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  const std::vector<RouteSignal>& signals = (*world)->route_signals();
  ASSERT_EQ(signals.size(), 1u);
  EXPECT_EQ(signals[0].tls_id, "0");
  EXPECT_EQ(signals[0].link_index, 1);
  EXPECT_NEAR(signals[0].stop_line_s_m, 87.15 - 10.0, 0.5);
  // The program starts red for this link (its first phases serve east-west).
  EXPECT_EQ((*world)->RouteSignalStates(), "r");
  TrafficSignalDetector detector((*world)->road_path(), signals, {});
  detector.Look({(*world)->ego().x_m, (*world)->ego().y_m},
                (*world)->RouteSignalStates());
  const std::vector<SignalReport> due = detector.TakeDue(1.0);
  ASSERT_EQ(due.size(), 1u);
  EXPECT_EQ(due[0].state, SignalState::kRed);
  EXPECT_NEAR(due[0].stop_line_distance_m, 77.15, 0.5);
}

TEST(TrafficSignalDetector, AGeneratedLotHasNoSignals) {
  WorldSetup setup;
  setup.world.map.generator = "parking_lot";
  setup.world.map.generator_params = {{"rows", 2}, {"slots_per_row", 8}};
  setup.task.start = Location::Xy(8.0, -1.75);
  setup.task.goal = Location::Xy(10.0, 29.75);
  setup.cache_dir = testing::CacheDir();
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  EXPECT_TRUE((*world)->route_signals().empty());
  EXPECT_EQ((*world)->RouteSignalStates(), "");
}

}  // namespace
}  // namespace adse::world
