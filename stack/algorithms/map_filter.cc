#include "stack/algorithms/map_filter.h"

#include <algorithm>
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
  for (const Eigen::Vector3f& p : map_points) {
    if (p.z() > params_.ground_height_m)
      occupied.insert(Key(p.x(), p.y(), p.z()));
  }
  voxels_.reserve(occupied.size() * 8);
  const double v = params_.voxel_m;
  for (const Eigen::Vector3f& p : map_points) {
    // Ground, or a voxel done.
    if (occupied.erase(Key(p.x(), p.y(), p.z())) == 0) continue;
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

int64_t StructureGrid::Cell(double v) const {
  return static_cast<int64_t>(std::floor(v / params_.cell_m));
}

int64_t StructureGrid::Key(int64_t ix, int64_t iy) const {
  // 31 bits per axis: far beyond any map.
  return ((ix + (int64_t{1} << 30)) << 31) | (iy + (int64_t{1} << 30));
}

void StructureGrid::SetMap(const std::vector<Eigen::Vector3f>& map_points) {
  cells_.clear();
  for (const Eigen::Vector3f& p : map_points) {
    if (p.z() < params_.min_height_m) continue;
    cells_.insert(Key(Cell(p.x()), Cell(p.y())));
  }
}

double StructureGrid::StructureFraction(const Eigen::Vector2d& center,
                                        double length_m, double width_m,
                                        double yaw_rad) const {
  const double step = params_.cell_m;
  const int nx = std::max(1, static_cast<int>(std::ceil(length_m / step)));
  const int ny = std::max(1, static_cast<int>(std::ceil(width_m / step)));
  const int reach = static_cast<int>(std::ceil(params_.reach_m / step));
  const Eigen::Vector2d along(std::cos(yaw_rad), std::sin(yaw_rad));
  const Eigen::Vector2d across(-along.y(), along.x());
  int near = 0;
  // Cell centres of an nx x ny grid over the footprint.
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      const Eigen::Vector2d p = center +
                                ((i + 0.5) / nx - 0.5) * length_m * along +
                                ((j + 0.5) / ny - 0.5) * width_m * across;
      const int64_t cx = Cell(p.x()), cy = Cell(p.y());
      bool found = false;
      for (int dx = -reach; dx <= reach && !found; ++dx) {
        for (int dy = -reach; dy <= reach && !found; ++dy) {
          found = cells_.count(Key(cx + dx, cy + dy)) > 0;
        }
      }
      near += found ? 1 : 0;
    }
  }
  return static_cast<double>(near) / (nx * ny);
}

}  // namespace adse::algorithms
