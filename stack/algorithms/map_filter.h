// Removes points that the static map already explains (walls, poles, parked
// cars), as Autoware's compare-map segmentation does, so that only things
// the map does not know (traffic) reach clustering and the planner.
#ifndef ADSE_STACK_ALGORITHMS_MAP_FILTER_H_
#define ADSE_STACK_ALGORITHMS_MAP_FILTER_H_

#include <Eigen/Core>
#include <cstdint>
#include <unordered_set>
#include <vector>

#include "stack/geometry/geometry.h"

namespace adse::algorithms {

struct MapFilterParams {
  double voxel_m = 0.5;  // map voxel size; a point within about one voxel of
                         // a map point counts as explained by the map
  // Map points this low are ground. The ground filter removes scan points
  // this low before the map filter sees them, so ground needs no voxels,
  // and with them its neighbours would explain every point below
  // voxel_m * 2 anywhere on the map (a car's whole lower body), at the
  // cost of a voxel set over the map's whole area (GBs for a city).
  double ground_height_m = 0.25;
};

class MapFilter {
 public:
  explicit MapFilter(const MapFilterParams& params = {}) : params_(params) {}

  // Indexes the map (map frame). Each occupied voxel also marks its 26
  // neighbours, so a query is a single lookup.
  void SetMap(const std::vector<Eigen::Vector3f>& map_points);

  // Points (vehicle frame) the map does not explain, given the vehicle pose.
  std::vector<Eigen::Vector3f> Filter(
      const std::vector<Eigen::Vector3f>& points,
      const geometry::Pose2& pose) const;

  size_t voxels() const { return voxels_.size(); }

 private:
  int64_t Key(double x, double y, double z) const;
  MapFilterParams params_;
  std::unordered_set<int64_t> voxels_;
};

// Where the map has static structure (walls, poles, buildings, parked
// cars), seen from above: the planner's test of whether an object it stops
// for is map structure taken for an obstacle (a localization error, or
// something the map filter could not explain), rather than traffic.
struct StructureGridParams {
  double cell_m = 0.5;        // grid cell size
  double min_height_m = 0.3;  // map points lower than this are ground
  double reach_m = 1.0;       // structure this near a footprint point counts
  double min_fraction = 0.5;  // share of the footprint near structure
};

class StructureGrid {
 public:
  explicit StructureGrid(const StructureGridParams& params = {})
      : params_(params) {}

  // Indexes the map's points above the ground (map frame).
  void SetMap(const std::vector<Eigen::Vector3f>& map_points);

  // Share of the box's footprint (sampled every cell_m) within reach_m of
  // map structure (to within a cell), in [0, 1].
  double StructureFraction(const Eigen::Vector2d& center, double length_m,
                           double width_m, double yaw_rad) const;
  bool IsStructure(const Eigen::Vector2d& center, double length_m,
                   double width_m, double yaw_rad) const {
    return StructureFraction(center, length_m, width_m, yaw_rad) >=
           params_.min_fraction;
  }
  size_t cells() const { return cells_.size(); }

 private:
  int64_t Key(int64_t ix, int64_t iy) const;
  int64_t Cell(double v) const;
  StructureGridParams params_;
  std::unordered_set<int64_t> cells_;
};

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_MAP_FILTER_H_
