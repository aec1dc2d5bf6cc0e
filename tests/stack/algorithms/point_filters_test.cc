#include "stack/algorithms/point_filters.h"

#include <gtest/gtest.h>

#include <cmath>

#include "stack/base/random.h"

namespace adse::algorithms {
namespace {

TEST(CropPoints, RangeZAndEgoBox) {
  const float nan = std::nanf("");
  const Points points = {
      {10, 0, 1},     // kept
      {0.5, 0, 1},    // too close (and inside the ego box)
      {70, 0, 1},     // too far
      {10, 0, 5},     // too high
      {10, 0, -2},    // too low
      {2.5, 0.5, 1},  // on our own car
      {2.5, 1.5, 1},  // beside it: kept
      {-5, -5, 0},    // behind, on the ground: kept
      {nan, 0, 0},    // dropped
  };
  const Points kept = CropPoints(points, CropParams());
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_EQ(kept[0], points[0]);
  EXPECT_EQ(kept[1], points[6]);
  EXPECT_EQ(kept[2], points[7]);
  CropParams keep_ego;
  keep_ego.remove_ego = false;
  EXPECT_EQ(CropPoints(points, keep_ego).size(), 4u);
}

TEST(RemoveGround, FlatGroundAgainstZeroPlane) {
  Random random(5);
  Points points;
  for (int i = 0; i < 500; ++i) {
    points.emplace_back(random.Uniform(-20, 20), random.Uniform(-20, 20),
                        random.Normal(0.0, 0.03));
  }
  for (int i = 0; i < 100; ++i) {  // a car side, 0.4 .. 1.5 m
    points.emplace_back(8.0f, random.Uniform(-1, 1), random.Uniform(0.4, 1.5));
  }
  const GroundResult result = RemoveGround(points, GroundParams());
  EXPECT_FALSE(result.plane_fitted);
  EXPECT_EQ(result.obstacles.size(), 100u);
  EXPECT_EQ(result.ground.size(), 500u);
  EXPECT_EQ(result.work_units, 600);
  for (const Eigen::Vector3f& p : result.obstacles) EXPECT_GT(p.z(), 0.3f);
}

TEST(RemoveGround, RansacFollowsATiltedGround) {
  // Ground rising 4 % along x (a ramp, or the sensor pitched): at x = 15 m
  // it is 0.6 m high, which the flat z = 0 rule would call obstacle.
  Random random(9);
  Points points;
  for (int i = 0; i < 800; ++i) {
    const double x = random.Uniform(-15, 15), y = random.Uniform(-15, 15);
    points.emplace_back(x, y, 0.04 * x + random.Normal(0.0, 0.02));
  }
  for (int i = 0; i < 80; ++i) {  // a box standing on the ramp at x = 5
    const double z = 0.2 + random.Uniform(0.5, 1.5);
    points.emplace_back(5.0f, random.Uniform(-1, 1), z);
  }
  GroundParams flat;
  EXPECT_GT(RemoveGround(points, flat).obstacles.size(), 200u);
  GroundParams fit;
  fit.fit_plane = true;
  fit.ransac_candidate_band_m = 0.8;
  const GroundResult result = RemoveGround(points, fit);
  ASSERT_TRUE(result.plane_fitted);
  EXPECT_EQ(result.obstacles.size(), 80u);
  EXPECT_NEAR(result.plane(0) / result.plane(2), -0.04, 0.005);
  EXPECT_NEAR(result.plane(3), 0.0, 0.02);
  EXPECT_GT(result.work_units, static_cast<int64_t>(points.size()));
}

TEST(RemoveGround, ImplausiblePlaneFallsBackToFlat) {
  // Only a vertical wall in the ground band: every plane through three of
  // its points is vertical, so no ground plane is acceptable.
  Points points;
  for (int i = 0; i < 20; ++i) {
    for (int k = 0; k < 10; ++k)
      points.emplace_back(5.0f, 0.1f * i, 0.039f * k);
  }
  GroundParams params;
  params.fit_plane = true;
  const GroundResult result = RemoveGround(points, params);
  EXPECT_FALSE(result.plane_fitted);
  EXPECT_EQ(result.plane, Eigen::Vector4d(0, 0, 1, 0));
  EXPECT_EQ(result.obstacles.size(), 60u);  // z > 0.25: k = 7, 8, 9
}

}  // namespace
}  // namespace adse::algorithms
