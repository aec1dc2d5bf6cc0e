// The world reads a SUMO net as SUMO means it: a position along a lane is
// in the lane's own length, scaled onto its shape. On nets Debian's
// sumo-tools ships. Each TEST runs in its own process
// (gtest_discover_tests), which libsumo needs.
#include <gtest/gtest.h>

#include <memory>

#include "stack/world/world.h"
#include "tests/stack/world/testing/real_nets.h"

namespace adse::world {
namespace {

using testing::DriveToTheGoal;
using testing::kGrid6Net;
using testing::OpenBenchRoute;

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

}  // namespace
}  // namespace adse::world
