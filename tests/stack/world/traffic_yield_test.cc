#include "stack/world/traffic_yield.h"

#include <gtest/gtest.h>

#include <cmath>

namespace adse::world {
namespace {

geometry::OrientedBox Ego(double x, double y, double yaw) {
  geometry::OrientedBox b;
  b.center = Eigen::Vector2d(x, y);
  b.yaw_rad = yaw;
  b.length_m = 4.5;
  b.width_m = 1.8;
  return b;
}

// A driver on a straight lane along +x from its front bumper at the origin.
const std::vector<Eigen::Vector2d> kLane = {{0, 0}, {40, 0}};

TEST(YieldSpeedTest, StopsShortOfTheEgoStandingAcrossItsLane) {
  // The ego's near side 20 m ahead: stop 2 m short braking at 4.5 m/s^2.
  const double v = YieldSpeedMps(kLane, 1.8, 4.5, Ego(20.9, 0.5, M_PI / 2),
                                 Eigen::Vector2d::Zero());
  EXPECT_NEAR(v, std::sqrt(2 * 4.5 * 18.0), 1e-9);
  // Driving across the lane does not help: it is where it is.
  EXPECT_NEAR(YieldSpeedMps(kLane, 1.8, 4.5, Ego(20.9, 0.5, M_PI / 2),
                            Eigen::Vector2d(0, 6)),
              v, 1e-9);
  // Within the standstill gap: stand.
  EXPECT_NEAR(YieldSpeedMps(kLane, 1.8, 4.5, Ego(2.5, 0, M_PI / 2),
                            Eigen::Vector2d::Zero()),
              0.0, 1e-9);
}

TEST(YieldSpeedTest, FollowsAnEgoDrivingAwayAndIgnoresOneBeside) {
  // Ahead in the lane at 10 m/s away: the speed that still stops behind it.
  EXPECT_NEAR(
      YieldSpeedMps(kLane, 1.8, 4.5, Ego(12.25, 0, 0), Eigen::Vector2d(10, 0)),
      std::sqrt(100 + 2 * 4.5 * 8.0), 1e-9);
  // Oncoming in its lane: only its position counts.
  EXPECT_NEAR(YieldSpeedMps(kLane, 1.8, 4.5, Ego(12.25, 0, M_PI),
                            Eigen::Vector2d(-10, 0)),
              std::sqrt(2 * 4.5 * 8.0), 1e-9);
  // In the next lane, 3.2 m over, or beyond the path: not in the way.
  EXPECT_LT(YieldSpeedMps(kLane, 1.8, 4.5, Ego(12.25, 3.2, 0),
                          Eigen::Vector2d::Zero()),
            0);
  EXPECT_LT(
      YieldSpeedMps(kLane, 1.8, 4.5, Ego(45, 0, 0), Eigen::Vector2d::Zero()),
      0);
}

TEST(YieldLookaheadTest, StoppingDistanceAndReactionOrTheMinimum) {
  // 13.89 m/s (50 km/h) at 4.5 m/s^2: 21.4 m braking + 13.9 m + 2 m.
  EXPECT_NEAR(YieldLookaheadM(13.89, 4.5), 13.89 * 13.89 / 9 + 13.89 + 2, 1e-9);
  EXPECT_NEAR(YieldLookaheadM(0.0, 4.5), 10.0, 1e-9);
}

}  // namespace
}  // namespace adse::world
