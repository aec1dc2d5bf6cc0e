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

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_MAP_FILTER_H_
