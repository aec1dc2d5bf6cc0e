#include "stack/algorithms/pose_buffer.h"

#include <gtest/gtest.h>

#include <numbers>

namespace adse::algorithms {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(PoseBuffer, IsEmptyUntilAPoseIsAdded) {
  PoseBuffer buffer;
  EXPECT_FALSE(buffer.At(0.0).has_value());
  buffer.Add(1.0, {2.0, 3.0, 0.5}, 0.0);
  ASSERT_TRUE(buffer.At(0.0).has_value());
  EXPECT_DOUBLE_EQ(buffer.At(0.0)->x_m, 2.0);
}

TEST(PoseBuffer, InterpolatesBetweenThePosesAroundTheTime) {
  PoseBuffer buffer;
  buffer.Add(0.0, {0.0, 0.0, 0.0}, 10.0);
  buffer.Add(0.1, {1.0, 0.0, 0.1}, 10.0);
  buffer.Add(0.2, {2.0, 0.5, 0.2}, 10.0);
  const geometry::Pose2 p = *buffer.At(0.15);
  EXPECT_NEAR(p.x_m, 1.5, 1e-12);
  EXPECT_NEAR(p.y_m, 0.25, 1e-12);
  EXPECT_NEAR(p.yaw_rad, 0.15, 1e-12);
  EXPECT_NEAR(buffer.At(0.1)->x_m, 1.0, 1e-12) << "a kept time is exact";
}

TEST(PoseBuffer, TurnsTheShortWayAcrossPi) {
  PoseBuffer buffer;
  buffer.Add(0.0, {0.0, 0.0, kPi - 0.1}, 0.0);
  buffer.Add(1.0, {0.0, 0.0, -kPi + 0.1}, 0.0);
  EXPECT_NEAR(std::abs(buffer.At(0.5)->yaw_rad), kPi, 1e-9);
}

TEST(PoseBuffer, MovesTheNewestOnAlongItsHeadingAfterIt) {
  PoseBuffer buffer;
  buffer.Add(0.0, {0.0, 0.0, 0.0}, 4.0);
  buffer.Add(1.0, {4.0, 0.0, kPi / 2}, 4.0);
  const geometry::Pose2 p = *buffer.At(1.5);
  EXPECT_NEAR(p.x_m, 4.0, 1e-12);
  EXPECT_NEAR(p.y_m, 2.0, 1e-12);
  EXPECT_NEAR(buffer.At(-5.0)->x_m, 0.0, 1e-12) << "before: the oldest";
}

TEST(PoseBuffer, ForgetsPosesOlderThanItsWindowButKeepsTheNewest) {
  PoseBuffer buffer(1.0);
  for (int k = 0; k <= 30; ++k) buffer.Add(0.1 * k, {0.1 * k, 0, 0}, 1.0);
  EXPECT_EQ(buffer.size(), 11u);  // t = 2.0 .. 3.0
  EXPECT_NEAR(buffer.At(0.0)->x_m, 2.0, 1e-9) << "the oldest kept";
  PoseBuffer none(0.0);
  none.Add(0.0, {}, 0.0);
  none.Add(5.0, {}, 0.0);
  EXPECT_EQ(none.size(), 1u);
}

TEST(PoseBuffer, IgnoresAPoseOlderThanTheNewestAndReplacesAnEqualTime) {
  PoseBuffer buffer;
  buffer.Add(1.0, {1.0, 0, 0}, 0.0);
  buffer.Add(0.5, {9.0, 0, 0}, 0.0);
  EXPECT_EQ(buffer.size(), 1u);
  buffer.Add(1.0, {2.0, 0, 0}, 0.0);
  EXPECT_EQ(buffer.size(), 1u);
  EXPECT_DOUBLE_EQ(buffer.At(1.0)->x_m, 2.0);
}

TEST(PoseAhead, MovesAlongTheHeading) {
  const geometry::Pose2 p = PoseAhead({1.0, 2.0, kPi / 2}, 4.0, 0.5);
  EXPECT_NEAR(p.x_m, 1.0, 1e-12);
  EXPECT_NEAR(p.y_m, 4.0, 1e-12);
  EXPECT_EQ(p.yaw_rad, kPi / 2);
  const geometry::Pose2 back = PoseAhead({0.0, 0.0, 0.0}, 2.0, -1.0);
  EXPECT_NEAR(back.x_m, -2.0, 1e-12);
}

}  // namespace
}  // namespace adse::algorithms
