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

TEST(RemoveInsideBoxes, RemovesExactlyThePointsInAnyBox) {
  const Points points = {{0.5f, 0.0f, 1.0f},   // in box a
                         {3.0f, 1.2f, 1.1f},   // in box b
                         {3.0f, 1.2f, 2.0f},   // above box b
                         {10.0f, 0.0f, 0.5f},  // in neither
                         {1.0f, 1.0f, 1.0f}};  // on box a's corner: inside
  const std::vector<CropBox> boxes = {{-1.0, 1.0, -1.0, 1.0, 0.0, 2.0},
                                      {2.5, 3.5, 1.0, 1.5, 0.8, 1.4}};
  const Points kept = RemoveInsideBoxes(points, boxes);
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept[0], points[2]);
  EXPECT_EQ(kept[1], points[3]);
  EXPECT_EQ(RemoveInsideBoxes(points, {}).size(), points.size());
}

TEST(CorrectDistortion, UndoesASweepTakenWhileTurning) {
  // Points on a circle of radius 15 m around the start, at 0.4 deg steps,
  // as a sensor sweeping counter-clockwise in 0.1 s reports them while it
  // drives at 8 m/s and turns at 0.5 rad/s: each in the frame of its own
  // moment. Correction must give the start-frame points back.
  const geometry::Twist2 twist{8.0, 0.5};
  DistortionParams params;
  params.sweep_s = 0.1;
  Points truth, distorted;
  for (int j = 0; j < 900; ++j) {
    const double a = j * 0.4 * M_PI / 180.0;
    const Eigen::Vector3f p(15.0f * std::cos(a), 15.0f * std::sin(a), 0.7f);
    truth.push_back(p);
    const geometry::Pose2 m =
        geometry::MotionAfter(twist, params.sweep_s * j / 900.0);
    const double c = std::cos(m.yaw_rad), s = std::sin(m.yaw_rad);
    const double dx = p.x() - m.x_m, dy = p.y() - m.y_m;
    distorted.emplace_back(c * dx + s * dy, -s * dx + c * dy, p.z());
  }
  const Points corrected = CorrectDistortion(distorted, twist, params);
  ASSERT_EQ(corrected.size(), truth.size());
  double worst_before = 0.0, worst_after = 0.0;
  for (size_t i = 0; i < truth.size(); ++i) {
    worst_before =
        std::max<double>(worst_before, (distorted[i] - truth[i]).norm());
    worst_after =
        std::max<double>(worst_after, (corrected[i] - truth[i]).norm());
  }
  EXPECT_GT(worst_before, 0.5);
  // The moment comes from the distorted point's azimuth, which is off by
  // the motion's own angle: centimetres, not the decimetres undone.
  EXPECT_LT(worst_after, 0.05);
  // Standing still leaves the scan as it is.
  EXPECT_EQ(CorrectDistortion(distorted, {}, params), distorted);
}

TEST(TwistHistory, GivesTheSampleNearestTheSweepsMiddleAndForgetsTheOldest) {
  TwistHistory history(3);
  EXPECT_EQ(history.Nearest(1.0).v_mps, 0.0);  // none yet: standing
  history.Add(0.00, {1.0, 0.0});
  history.Add(0.02, {2.0, 0.1});
  history.Add(0.04, {3.0, 0.2});
  EXPECT_EQ(history.Nearest(0.021).v_mps, 2.0);
  EXPECT_EQ(history.Nearest(0.021).yaw_rate_rps, 0.1);
  EXPECT_EQ(history.Nearest(0.03).v_mps, 2.0);  // equally near: the older
  EXPECT_EQ(history.Nearest(-5.0).v_mps, 1.0);
  history.Add(0.06, {4.0, 0.3});
  EXPECT_EQ(history.size(), 3u);
  EXPECT_EQ(history.Nearest(-5.0).v_mps, 2.0);  // 0.00 was dropped
  EXPECT_EQ(history.Nearest(9.0).v_mps, 4.0);
}

TEST(RemoveRingOutliers, DropsIsolatedReturnsAndKeepsSurfaces) {
  RingOutlierParams params;  // 16 rings, -15..15 deg, sensor at 1.9 m
  Points points;
  // Ring 7 (-1 deg) on a wall 10 m ahead: a surface, 50 columns long.
  const double e7 = -1.0 * M_PI / 180.0;
  for (int j = -25; j < 25; ++j) {
    const double a = j * 0.4 * M_PI / 180.0;
    const double r = 10.0 / std::cos(a);
    points.emplace_back(r * std::cos(a), r * std::sin(a),
                        1.9 + std::tan(e7) * 10.0);
  }
  // Ring 7 again, a lone return at 25 m to the left (rain, a stray).
  const double r = 25.0;
  points.emplace_back(0.0f, r, 1.9 + std::tan(e7) * r);
  // Ring 3 (-9 deg): two neighbours 3 cm apart at 12 m, shorter than
  // min_length_m and fewer than min_points.
  const double e3 = -9.0 * M_PI / 180.0;
  for (int j = 0; j < 2; ++j) {
    const double a = M_PI + j * 0.0025;
    points.emplace_back(12.0 * std::cos(a), 12.0 * std::sin(a),
                        1.9 + std::tan(e3) * 12.0);
  }
  const Points kept = RemoveRingOutliers(points, params);
  ASSERT_EQ(kept.size(), 50u);
  for (size_t i = 0; i < kept.size(); ++i) EXPECT_EQ(kept[i], points[i]);
  // A jump in range breaks a run: the wall's two halves at 10 m and 30 m
  // are separate runs, each long enough to stay.
  Points split;
  for (int j = 0; j < 20; ++j) {
    const double d = j < 10 ? 10.0 : 30.0;
    const double a = j * 0.4 * M_PI / 180.0;
    split.emplace_back(d * std::cos(a), d * std::sin(a),
                       1.9 + std::tan(e7) * d);
  }
  EXPECT_EQ(RemoveRingOutliers(split, params).size(), 20u);
  params.min_points = 11;
  params.min_length_m = 100.0;
  EXPECT_EQ(RemoveRingOutliers(split, params).size(), 0u);
}

}  // namespace
}  // namespace adse::algorithms
