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

TEST(MapFilterTest, MappedGroundExplainsNothingAndCostsNoVoxels) {
  // A 40 m square of ground (1 m grid, as the localization map has it).
  std::vector<Eigen::Vector3f> ground;
  for (float x = -20; x <= 20; x += 1.0f) {
    for (float y = -20; y <= 20; y += 1.0f) ground.emplace_back(x, y, 0.0f);
  }
  MapFilter filter;
  filter.SetMap(ground);
  EXPECT_EQ(filter.voxels(), 0u);
  // With a wall along x = 10 added, a low return off the wall is still
  // explained; a car's door at 0.6 m on the open (mapped) ground is not.
  std::vector<Eigen::Vector3f> map = ground;
  for (float y = -5; y <= 5; y += 0.2f) {
    for (float z = 0; z <= 2; z += 0.2f) map.emplace_back(10.0f, y, z);
  }
  filter.SetMap(map);
  EXPECT_GT(filter.voxels(), 0u);
  const geometry::Pose2 origin{0.0, 0.0, 0.0};
  const std::vector<Eigen::Vector3f> kept = filter.Filter(
      {Eigen::Vector3f(10.1f, 1.0f, 0.35f), Eigen::Vector3f(4.0f, -3.0f, 0.6f),
       Eigen::Vector3f(4.0f, -3.0f, 0.3f)},
      origin);
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_FLOAT_EQ(kept[0].z(), 0.6f);
  EXPECT_FLOAT_EQ(kept[1].z(), 0.3f);
}

TEST(StructureGridTest, TellsMapStructureFromFreeRoad) {
  // A wall along x = 10, y in [-5, 5], on a ground grid that covers
  // everything (ground is not structure).
  std::vector<Eigen::Vector3f> map;
  for (float y = -5; y <= 5; y += 0.2f) {
    for (float z = 0; z <= 2; z += 0.2f) map.emplace_back(10.0f, y, z);
  }
  for (float x = -20; x <= 20; x += 1.0f) {
    for (float y = -20; y <= 20; y += 1.0f) map.emplace_back(x, y, 0.0f);
  }
  StructureGrid grid;
  grid.SetMap(map);
  EXPECT_GT(grid.cells(), 0u);
  // A box fitted to a stretch of the wall (a cluster of its points).
  EXPECT_DOUBLE_EQ(grid.StructureFraction({10.2, 0}, 3.0, 0.4, M_PI / 2), 1.0);
  EXPECT_TRUE(grid.IsStructure({10.2, 0}, 3.0, 0.4, M_PI / 2));
  // The same wall seen 0.8 m off (a localization error): still structure.
  EXPECT_TRUE(grid.IsStructure({9.2, 0}, 3.0, 0.4, M_PI / 2));
  // A car on the open road, over ground points only.
  EXPECT_DOUBLE_EQ(grid.StructureFraction({0, 0}, 4.5, 1.8, 0.0), 0.0);
  EXPECT_FALSE(grid.IsStructure({0, 0}, 4.5, 1.8, 0.0));
  // A car parked 0.6 m from the wall: only its side next to it is near
  // structure, less than half of its footprint.
  const double along_wall =
      grid.StructureFraction({8.5, 0}, 4.5, 1.8, M_PI / 2);
  EXPECT_GT(along_wall, 0.0);
  EXPECT_LT(along_wall, 0.5);
  EXPECT_FALSE(grid.IsStructure({8.5, 0}, 4.5, 1.8, M_PI / 2));
  // Past the wall's end.
  EXPECT_FALSE(grid.IsStructure({10.2, 9}, 3.0, 0.4, M_PI / 2));
}

}  // namespace
}  // namespace adse::algorithms
