// The world tests' shared setup: the map cache, the nets Debian's
// sumo-tools ships, a route of the real-nets bench and the ground-truth
// driver over it.
#ifndef ADSE_TESTS_STACK_WORLD_TESTING_REAL_NETS_H_
#define ADSE_TESTS_STACK_WORLD_TESTING_REAL_NETS_H_

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "stack/world/ideal_driver.h"
#include "stack/world/world.h"

namespace adse::world::testing {

inline constexpr char kDrtNet[] = "/usr/share/sumo/tools/game/DRT/osm.net.xml";
inline constexpr char kA10kwNet[] =
    "/usr/share/sumo/tools/game/A10KW/osm.net.xml";
inline constexpr char kBs3dNet[] = "/usr/share/sumo/tools/game/bs3d/bs.net.xml";
inline constexpr char kGrid6Net[] =
    "/usr/share/sumo/tools/game/grid6/grid6.net.xml";
inline constexpr char kAcostaNet[] =
    "/usr/share/sumo/tools/sumolib/scenario/scenarios/RealWorld/acosta/"
    "acosta_buslanes.net.xml";
inline constexpr char kSquareNet[] =
    "/usr/share/sumo/tools/game/square/square.net.xml";
inline constexpr char kPasubioNet[] =
    "/usr/share/sumo/tools/sumolib/scenario/scenarios/RealWorld/pasubio/"
    "pasubio_buslanes.net.xml";

// $ADSE_CACHE_DIR, else <tmp>/adse-test-cache: maps built once for all tests.
inline std::string CacheDir() {
  const char* dir = std::getenv("ADSE_CACHE_DIR");
  return dir ? dir
             : (std::filesystem::temp_directory_path() / "adse-test-cache")
                   .string();
}

// A route of the real-nets bench (tests/bench/real_nets_bench.sh) on
// `net`, driven at the bench's 40 km/h.
inline WorldSetup BenchRoute(const std::string& net, const Location& start,
                             const Location& goal) {
  WorldSetup setup;
  setup.world.map.net_path = net;
  setup.task.start = start;
  setup.task.goal = goal;
  setup.task.speed_limit_kmh = 40.0;
  setup.cache_dir = CacheDir();
  return setup;
}

// The world of `setup` on a sumo-tools net; NotFound when sumo-tools is not
// installed.
inline Result<std::unique_ptr<World>> OpenOnSumoToolsNet(
    const WorldSetup& setup) {
  const std::string& net = setup.world.map.net_path;
  if (!std::filesystem::exists(net)) {
    return Status::NotFound("sumo-tools is not installed: no " + net);
  }
  return World::Open(setup);
}

// The world of BenchRoute; NotFound when sumo-tools is not installed.
inline Result<std::unique_ptr<World>> OpenBenchRoute(const std::string& net,
                                                     const Location& start,
                                                     const Location& goal) {
  return OpenOnSumoToolsNet(BenchRoute(net, start, goal));
}

// The ground-truth driver over the whole route without the LiDAR; expects
// it to reach the goal.
inline IdealDriveReport DriveToTheGoal(World& world, double speed_limit_kmh,
                                       double timeout_s) {
  IdealDriverOptions options;
  options.scan = false;
  options.speed_limit_mps = speed_limit_kmh / 3.6;
  options.timeout_s = timeout_s;
  Result<IdealDriveReport> report = DriveIdealPath(world, nullptr, options);
  EXPECT_TRUE(report.ok()) << report.status().ToString();
  if (!report.ok()) return {};
  EXPECT_TRUE(report->reached_goal);
  return *report;
}

}  // namespace adse::world::testing

#endif  // ADSE_TESTS_STACK_WORLD_TESTING_REAL_NETS_H_
