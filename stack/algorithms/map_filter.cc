#include "stack/algorithms/map_filter.h"

#include <cmath>

namespace adse::algorithms {

int64_t MapFilter::Key(double x, double y, double z) const {
  // 21 bits per axis: +-1M voxels, far beyond any map.
  const int64_t ix =
      static_cast<int64_t>(std::floor(x / params_.voxel_m)) + (1 << 20);
  const int64_t iy =
      static_cast<int64_t>(std::floor(y / params_.voxel_m)) + (1 << 20);
  const int64_t iz =
      static_cast<int64_t>(std::floor(z / params_.voxel_m)) + (1 << 20);
  return (ix << 42) | (iy << 21) | iz;
}

void MapFilter::SetMap(const std::vector<Eigen::Vector3f>& map_points) {
  voxels_.clear();
  std::unordered_set<int64_t> occupied;
  occupied.reserve(map_points.size());
  for (const Eigen::Vector3f& p : map_points)
    occupied.insert(Key(p.x(), p.y(), p.z()));
  voxels_.reserve(occupied.size() * 8);
  const double v = params_.voxel_m;
  for (const Eigen::Vector3f& p : map_points) {
    if (occupied.erase(Key(p.x(), p.y(), p.z())) == 0) continue;  // voxel done
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          voxels_.insert(Key(p.x() + dx * v, p.y() + dy * v, p.z() + dz * v));
        }
      }
    }
  }
}

std::vector<Eigen::Vector3f> MapFilter::Filter(
    const std::vector<Eigen::Vector3f>& points,
    const geometry::Pose2& pose) const {
  std::vector<Eigen::Vector3f> out;
  out.reserve(points.size());
  const double c = std::cos(pose.yaw_rad), s = std::sin(pose.yaw_rad);
  for (const Eigen::Vector3f& p : points) {
    const double x = pose.x_m + c * p.x() - s * p.y();
    const double y = pose.y_m + s * p.x() + c * p.y();
    if (!voxels_.count(Key(x, y, p.z()))) out.push_back(p);
  }
  return out;
}

}  // namespace adse::algorithms
