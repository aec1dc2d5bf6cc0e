#include "stack/algorithms/map_filter.h"

#include <gtest/gtest.h>

#include <cmath>

namespace adse::algorithms {
namespace {

TEST(MapFilterTest, KeepsOnlyWhatTheMapDoesNotExplain) {
  // Map: a wall along x = 10 (map frame), y in [-5, 5], z in [0, 2].
  std::vector<Eigen::Vector3f> map;
  for (float y = -5; y <= 5; y += 0.2f) {
    for (float z = 0; z <= 2; z += 0.2f) map.emplace_back(10.0f, y, z);
  }
  MapFilter filter;
  filter.SetMap(map);
  // The vehicle stands at (2, 1) facing +y: map x = 2 - y_v, map y = 1 + x_v.
  const geometry::Pose2 pose{2.0, 1.0, M_PI / 2};
  std::vector<Eigen::Vector3f> scan;
  scan.emplace_back(0.0f, -8.0f, 1.0f);  // map (10, 1): on the wall
  scan.emplace_back(0.5f, -8.2f, 1.5f);  // map (10.2, 1.5): on the wall
  scan.emplace_back(0.0f, -4.0f, 1.0f);  // map (6, 1): a car in front of it
  scan.emplace_back(9.0f, -8.0f, 1.0f);  // map (10, 10): beyond the wall's end
  const std::vector<Eigen::Vector3f> kept = filter.Filter(scan, pose);
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_FLOAT_EQ(kept[0].y(), -4.0f);
  EXPECT_FLOAT_EQ(kept[1].x(), 9.0f);
}

}  // namespace
}  // namespace adse::algorithms
