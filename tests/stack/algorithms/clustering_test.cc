#include "stack/algorithms/clustering.h"

#include "stack/algorithms/point_filters.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace adse::algorithms {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Points on the faces of an oriented box (what clusters of a car look like
// from all around), every `step` metres, z from 0.3 to h.
void AddBox(const Eigen::Vector2d& c, double l, double w, double yaw, double h,
            double step, std::vector<Eigen::Vector3f>* out) {
  const Eigen::Vector2d ax(std::cos(yaw), std::sin(yaw));
  const Eigen::Vector2d ay(-ax.y(), ax.x());
  for (double z = 0.3; z <= h + 1e-9; z += 0.4) {
    for (double u = -l / 2; u <= l / 2 + 1e-9; u += step) {
      for (double side : {-1.0, 1.0}) {
        const Eigen::Vector2d p = c + u * ax + side * w / 2 * ay;
        out->emplace_back(p.x(), p.y(), z);
      }
    }
    for (double v = -w / 2 + step; v < w / 2 - 1e-9; v += step) {
      for (double side : {-1.0, 1.0}) {
        const Eigen::Vector2d p = c + side * l / 2 * ax + v * ay;
        out->emplace_back(p.x(), p.y(), z);
      }
    }
  }
}

double AngleDiffHalfTurn(double a, double b) {
  double d = std::fmod(a - b, kPi);
  if (d > kPi / 2) d -= kPi;
  if (d < -kPi / 2) d += kPi;
  return d;
}

TEST(DetectObjects, FindsThreeKnownBoxes) {
  struct Truth {
    Eigen::Vector2d c;
    double l, w, yaw;
  };
  const Truth truth[] = {{{10, 2}, 4.5, 1.8, 0.0},
                         {{-6, -5}, 4.0, 1.7, 0.6},
                         {{3, 12}, 2.0, 2.0, 0.0}};
  std::vector<Eigen::Vector3f> points;
  for (const Truth& t : truth) AddBox(t.c, t.l, t.w, t.yaw, 1.5, 0.1, &points);
  const DetectionResult result = DetectObjects(points, ClusteringParams());
  // Work units: the points clustered, after the default voxel grid.
  EXPECT_EQ(result.work_units,
            static_cast<int64_t>(
                VoxelDownsample(points, ClusteringParams().downsample_leaf_m)
                    .size()));
  ASSERT_EQ(result.detections.size(), 3u);
  int matched = 0;
  for (const Truth& t : truth) {
    for (const Detection& d : result.detections) {
      if ((d.center - t.c).norm() > 1.0) continue;
      ++matched;
      EXPECT_NEAR(d.center.x(), t.c.x(), 0.2);
      EXPECT_NEAR(d.center.y(), t.c.y(), 0.2);
      EXPECT_NEAR(d.length_m, t.l, 0.2);
      EXPECT_NEAR(d.width_m, t.w, 0.2);
      if (t.l > t.w + 0.5) {
        EXPECT_NEAR(AngleDiffHalfTurn(d.yaw_rad, t.yaw), 0.0, 0.05);
      }
      EXPECT_NEAR(d.z_min_m, 0.3, 1e-5);
      EXPECT_GT(d.point_count, 50);
    }
  }
  EXPECT_EQ(matched, 3);
}

TEST(DetectObjects, AxisAlignedBoxesWhenAsked) {
  std::vector<Eigen::Vector3f> points;
  AddBox({0, 0}, 4.0, 2.0, kPi / 4, 1.0, 0.1, &points);
  ClusteringParams params;
  params.oriented_boxes = false;
  const DetectionResult result = DetectObjects(points, params);
  ASSERT_EQ(result.detections.size(), 1u);
  const Detection& d = result.detections[0];
  // Rotated 45 degrees: the axis-aligned box is (4 + 2) / sqrt(2) square.
  const double side = 6.0 / std::sqrt(2.0);
  EXPECT_NEAR(d.length_m, side, 0.1);
  EXPECT_NEAR(d.width_m, side, 0.1);
  EXPECT_EQ(d.yaw_rad, 0.0);
  EXPECT_NEAR(d.center.norm(), 0.0, 0.1);
}

TEST(DetectObjects, DropsNoiseAndIgnoresEmptyInput) {
  std::vector<Eigen::Vector3f> points = {{0, 0, 1}, {5, 5, 1}, {10, 0, 1}};
  EXPECT_TRUE(DetectObjects(points, ClusteringParams()).detections.empty());
  EXPECT_TRUE(DetectObjects({}, ClusteringParams()).detections.empty());
}

// The voxel grid is part of the algorithm: the same boxes as thinning by
// hand first, and fewer points clustered than given.
TEST(DetectObjects, DownsamplesToItsVoxelGridFirst) {
  std::vector<Eigen::Vector3f> points;
  AddBox({5.0, 2.0}, 4.5, 1.8, 0.3, 1.5, 0.05, &points);
  ClusteringParams params;
  ASSERT_EQ(params.downsample_leaf_m, 0.2);
  const DetectionResult inside = DetectObjects(points, params);
  ClusteringParams dense = params;
  dense.downsample_leaf_m = 0.0;
  const DetectionResult by_hand =
      DetectObjects(VoxelDownsample(points, 0.2), dense);
  ASSERT_EQ(inside.detections.size(), 1u);
  ASSERT_EQ(by_hand.detections.size(), 1u);
  EXPECT_EQ(inside.work_units, by_hand.work_units);
  EXPECT_LT(inside.work_units, static_cast<int64_t>(points.size()));
  EXPECT_EQ(inside.detections[0].center, by_hand.detections[0].center);
  EXPECT_EQ(inside.detections[0].length_m, by_hand.detections[0].length_m);
}

TEST(FitBox, LShapeGivesTheRightOrientation) {
  // Two visible sides of a car rotated by 0.3 rad.
  const double yaw = 0.3;
  const Eigen::Vector2d ax(std::cos(yaw), std::sin(yaw));
  const Eigen::Vector2d ay(-ax.y(), ax.x());
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i <= 45; ++i) {
    const Eigen::Vector2d p = 0.1 * i * ax;
    points.emplace_back(p.x(), p.y(), 1.0f);
  }
  for (int i = 1; i <= 18; ++i) {
    const Eigen::Vector2d p = 0.1 * i * ay;
    points.emplace_back(p.x(), p.y(), 1.0f);
  }
  const Detection d = FitBox(points, {}, true, 0.2);
  EXPECT_NEAR(AngleDiffHalfTurn(d.yaw_rad, yaw), 0.0, 0.02);
  EXPECT_NEAR(d.length_m, 4.5, 0.05);
  EXPECT_NEAR(d.width_m, 1.8, 0.05);
  const Eigen::Vector2d centre = 2.25 * ax + 0.9 * ay;
  EXPECT_NEAR((d.center - centre).norm(), 0.0, 0.05);
}

TEST(FitBox, DegenerateInputs) {
  const Detection none = FitBox({}, {}, true, 0.2);
  EXPECT_EQ(none.point_count, 0);
  const Detection one = FitBox({{1, 2, 0.5f}}, {}, true, 0.2);
  EXPECT_NEAR(one.center.x(), 1.0, 1e-6);
  EXPECT_NEAR(one.center.y(), 2.0, 1e-6);
  EXPECT_DOUBLE_EQ(one.length_m, 0.2);
  // A straight line of points (a wall seen edge on).
  std::vector<Eigen::Vector3f> line;
  for (int i = 0; i <= 30; ++i) line.emplace_back(0.1f * i, 0.1f * i, 1.0f);
  const Detection wall = FitBox(line, {}, true, 0.2);
  EXPECT_NEAR(wall.length_m, 3.0 * std::sqrt(2.0), 0.02);
  EXPECT_NEAR(wall.width_m, 0.2, 1e-9);
  EXPECT_NEAR(AngleDiffHalfTurn(wall.yaw_rad, kPi / 4), 0.0, 1e-6);
}

TEST(ToMapFrame, RotatesAndTranslates) {
  Detection d;
  d.center = {2.0, 1.0};
  d.yaw_rad = 0.1;
  const Detection m = ToMapFrame(d, geometry::Pose2{10.0, 5.0, kPi / 2});
  EXPECT_NEAR(m.center.x(), 9.0, 1e-9);
  EXPECT_NEAR(m.center.y(), 7.0, 1e-9);
  EXPECT_NEAR(AngleDiffHalfTurn(m.yaw_rad, 0.1 + kPi / 2), 0.0, 1e-9);
  EXPECT_GT(m.yaw_rad, -kPi / 2);
  EXPECT_LE(m.yaw_rad, kPi / 2);
}

}  // namespace
}  // namespace adse::algorithms
