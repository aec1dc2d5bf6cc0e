// The world reads a SUMO net as SUMO means it: a position along a lane is
// in the lane's own length, scaled onto its shape. On nets Debian's
// sumo-tools ships. Each TEST runs in its own process
// (gtest_discover_tests), which libsumo needs.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "stack/world/ideal_driver.h"
#include "stack/world/world.h"

namespace adse::world {
namespace {

constexpr char kGrid6Net[] = "/usr/share/sumo/tools/game/grid6/grid6.net.xml";

std::string CacheDir() {
  const char* dir = std::getenv("ADSE_CACHE_DIR");
  return dir ? dir
             : (std::filesystem::temp_directory_path() / "adse-test-cache")
                   .string();
}

TEST(SumoNetTest, AGoalOnALaneLongerThanItsLengthIsWhereSumoPutsIt) {
  ASSERT_TRUE(std::filesystem::exists(kGrid6Net))
      << "sumo-tools is not installed";
  // grid6's gneE17 is 80 m long on a 93.9 m shape: SUMO puts 40 m at the
  // shape's middle, (106.45, 269.14). The path ended at 40 m along the
  // shape, 6.9 m short, where the car stood for ever (the real-nets
  // bench's grid6-0).
  WorldSetup setup;
  setup.world.map.net_path = kGrid6Net;
  setup.task.start = Location::OnEdge("gneE27", 10.0, 0);
  setup.task.goal = Location::OnEdge("gneE17", 40.0, 0);
  setup.task.speed_limit_kmh = 40.0;
  setup.cache_dir = CacheDir();
  Result<std::unique_ptr<World>> world = World::Open(setup);
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  const Eigen::Vector2d end = (*world)->ideal_path().points.back();
  EXPECT_NEAR(end.x(), 106.45, 0.1);
  EXPECT_NEAR(end.y(), 269.14, 0.1);
  IdealDriverOptions options;
  options.scan = false;
  options.speed_limit_mps = 40.0 / 3.6;
  options.timeout_s = 300.0;
  Result<IdealDriveReport> report = DriveIdealPath(**world, nullptr, options);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_TRUE(report->reached_goal);
}

}  // namespace
}  // namespace adse::world
