#include "stack/world/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace adse::world {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// A ray whose horizontal component is below this is treated as vertical: it
// runs along no face (faces are vertical), so it hits nothing.
constexpr double kMinHorizontal = 1e-12;
// Grids larger than this get coarser cells so huge OSM maps stay in memory.
constexpr double kMaxCells = 4.0e6;

double Cross(double ax, double ay, double bx, double by) {
  return ax * by - ay * bx;
}

// Liang-Barsky: does segment a->b touch the box [lo, hi]?
bool SegmentTouchesBox(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                       const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  double u0 = 0.0, u1 = 1.0;
  const Eigen::Vector2d d = b - a;
  for (int k = 0; k < 2; ++k) {
    if (d[k] == 0.0) {
      if (a[k] < lo[k] || a[k] > hi[k]) return false;
      continue;
    }
    double ua = (lo[k] - a[k]) / d[k];
    double ub = (hi[k] - a[k]) / d[k];
    if (ua > ub) std::swap(ua, ub);
    u0 = std::max(u0, ua);
    u1 = std::min(u1, ub);
    if (u0 > u1) return false;
  }
  return true;
}

}  // namespace

std::vector<std::array<Eigen::Vector2d, 2>> ObstacleEdges(
    const Obstacle& obstacle) {
  std::vector<std::array<Eigen::Vector2d, 2>> edges;
  const auto& fp = obstacle.footprint;
  const size_t n = fp.size();
  if (n < 2) return edges;
  const size_t count = n == 2 ? 1 : n;
  edges.reserve(count);
  for (size_t i = 0; i < count; ++i) {
    const Eigen::Vector2d& a = fp[i];
    const Eigen::Vector2d& b = fp[(i + 1) % n];
    if ((b - a).squaredNorm() > 0.0) edges.push_back({a, b});
  }
  return edges;
}

void Scene::AddObstacle(Obstacle obstacle) {
  if (obstacle.z_min_m > obstacle.z_max_m) {
    std::swap(obstacle.z_min_m, obstacle.z_max_m);
  }
  for (const auto& p : obstacle.footprint) {
    min_ = has_bounds_ ? min_.cwiseMin(p) : p;
    max_ = has_bounds_ ? max_.cwiseMax(p) : p;
    has_bounds_ = true;
  }
  for (const auto& e : ObstacleEdges(obstacle)) {
    z_lo_m_ = segments_.empty() ? obstacle.z_min_m
                                : std::min(z_lo_m_, obstacle.z_min_m);
    z_hi_m_ = segments_.empty() ? obstacle.z_max_m
                                : std::max(z_hi_m_, obstacle.z_max_m);
    segments_.push_back({e[0], e[1], obstacle.z_min_m, obstacle.z_max_m});
  }
  obstacles_.push_back(std::move(obstacle));
}

void Scene::AddParkingSlot(ParkingSlot slot) { slots_.push_back(slot); }

void Scene::Finalize(double cell_size_m) {
  cell_ = cell_size_m > 0.0 ? cell_size_m : 4.0;
  grid_origin_ = min_;
  const Eigen::Vector2d extent = max_ - min_;
  if (extent.x() / cell_ * (extent.y() / cell_) > kMaxCells) {
    cell_ = std::sqrt(extent.x() * extent.y() / kMaxCells) * 1.01;
  }
  // floor()+1 keeps points on the max edge inside the last cell.
  nx_ = static_cast<int>(std::floor(extent.x() / cell_)) + 1;
  ny_ = static_cast<int>(std::floor(extent.y() / cell_)) + 1;

  cells_.assign(static_cast<size_t>(nx_) * ny_, {});
  // Segments are registered in every cell they touch, with a margin so that
  // rounding in the ray walk near cell borders cannot miss a face.
  const double eps = 1e-9 * cell_ + 1e-9;
  for (size_t i = 0; i < segments_.size(); ++i) {
    const Segment& s = segments_[i];
    const Eigen::Vector2d lo = s.a.cwiseMin(s.b) - grid_origin_;
    const Eigen::Vector2d hi = s.a.cwiseMax(s.b) - grid_origin_;
    const int ix0 = std::clamp(static_cast<int>(std::floor((lo.x() - eps) / cell_)), 0, nx_ - 1);
    const int ix1 = std::clamp(static_cast<int>(std::floor((hi.x() + eps) / cell_)), 0, nx_ - 1);
    const int iy0 = std::clamp(static_cast<int>(std::floor((lo.y() - eps) / cell_)), 0, ny_ - 1);
    const int iy1 = std::clamp(static_cast<int>(std::floor((hi.y() + eps) / cell_)), 0, ny_ - 1);
    for (int iy = iy0; iy <= iy1; ++iy) {
      for (int ix = ix0; ix <= ix1; ++ix) {
        const Eigen::Vector2d c_lo =
            grid_origin_ + Eigen::Vector2d(ix * cell_, iy * cell_);
        const Eigen::Vector2d c_hi = c_lo + Eigen::Vector2d(cell_, cell_);
        const Eigen::Vector2d margin(eps, eps);
        if (SegmentTouchesBox(s.a, s.b, c_lo - margin, c_hi + margin)) {
          cells_[static_cast<size_t>(iy) * nx_ + ix].push_back(
              static_cast<int>(i));
        }
      }
    }
  }
  cell_begin_.assign(cells_.size() + 1, 0);
  size_t total = 0;
  for (size_t c = 0; c < cells_.size(); ++c) {
    cell_begin_[c] = static_cast<uint32_t>(total);
    total += cells_[c].size();
  }
  cell_begin_[cells_.size()] = static_cast<uint32_t>(total);
  cell_items_.clear();
  cell_items_.reserve(total);
  for (const auto& cell : cells_) {
    cell_items_.insert(cell_items_.end(), cell.begin(), cell.end());
  }
  cells_.clear();
  cells_.shrink_to_fit();
  indexed_segments_ = segments_.size();
}

void Scene::Intersect(const Segment& s, const Eigen::Vector3d& origin,
                      const Eigen::Vector3d& dir, double t_lo,
                      double* t_best) {
  // Solve origin.xy + t*dir.xy = a + u*(b - a); t is the 3D distance since
  // dir is a unit vector.
  const double ex = s.b.x() - s.a.x();
  const double ey = s.b.y() - s.a.y();
  const double denom = Cross(dir.x(), dir.y(), ex, ey);
  // Parallel (incl. along the face): grazing, not a return.
  if (denom == 0.0) return;
  const double wx = s.a.x() - origin.x();
  const double wy = s.a.y() - origin.y();
  const double t = Cross(wx, wy, ex, ey) / denom;
  if (!(t >= t_lo && t < *t_best)) return;
  const double u = Cross(wx, wy, dir.x(), dir.y()) / denom;
  if (u < 0.0 || u > 1.0) return;
  const double z = origin.z() + t * dir.z();
  if (z < s.z_min_m || z > s.z_max_m) return;
  *t_best = t;
}

double Scene::CastRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                      double max_range_m) const {
  if (segments_.empty() || !(max_range_m > 0.0)) return -1.0;
  const double dx = dir.x(), dy = dir.y(), dz = dir.z();
  if (std::hypot(dx, dy) < kMinHorizontal) return -1.0;

  // Hits are accepted up to max_range_m inclusive.
  double best = std::nextafter(max_range_m, kInf);
  if (indexed_segments_ != segments_.size() || nx_ <= 0 || ny_ <= 0) {
    // Not (re)finalized: still right, just slow.
    for (const Segment& s : segments_) Intersect(s, origin, dir, 0.0, &best);
    return best <= max_range_m ? best : -1.0;
  }

  // Only the stretch of the ray inside the faces' height span can hit; the
  // slack keeps hits exactly on a face's top or bottom edge despite rounding.
  constexpr double kSlackM = 1e-9;
  double t0 = 0.0, t1 = max_range_m;
  if (dz != 0.0) {
    double ta = (z_lo_m_ - origin.z()) / dz;
    double tb = (z_hi_m_ - origin.z()) / dz;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta - kSlackM);
    t1 = std::min(t1, tb + kSlackM);
  } else if (origin.z() < z_lo_m_ || origin.z() > z_hi_m_) {
    return -1.0;
  }
  if (t0 > t1) return -1.0;

  // Clip to the grid rectangle (slightly enlarged: faces on its border).
  const double margin = 1e-7 * cell_;
  const double gx0 = grid_origin_.x() - margin;
  const double gy0 = grid_origin_.y() - margin;
  const double gx1 = grid_origin_.x() + nx_ * cell_ + margin;
  const double gy1 = grid_origin_.y() + ny_ * cell_ + margin;
  const double d[2] = {dx, dy};
  const double o[2] = {origin.x(), origin.y()};
  const double lo[2] = {gx0, gy0};
  const double hi[2] = {gx1, gy1};
  for (int k = 0; k < 2; ++k) {
    if (d[k] == 0.0) {
      if (o[k] < lo[k] || o[k] > hi[k]) return -1.0;
      continue;
    }
    double ta = (lo[k] - o[k]) / d[k];
    double tb = (hi[k] - o[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 > t1) return -1.0;

  // Amanatides-Woo walk over the cells the ray's 2D shadow crosses, from
  // the entry point at t0. Boundaries are kept as ray distances.
  const double px = o[0] + t0 * dx - grid_origin_.x();
  const double py = o[1] + t0 * dy - grid_origin_.y();
  int ix = std::clamp(static_cast<int>(std::floor(px / cell_)), 0, nx_ - 1);
  int iy = std::clamp(static_cast<int>(std::floor(py / cell_)), 0, ny_ - 1);
  const int step_x = dx > 0.0 ? 1 : -1;
  const int step_y = dy > 0.0 ? 1 : -1;
  const double t_delta_x = dx != 0.0 ? cell_ / std::abs(dx) : kInf;
  const double t_delta_y = dy != 0.0 ? cell_ / std::abs(dy) : kInf;
  double t_max_x = kInf, t_max_y = kInf;
  if (dx != 0.0) {
    const double bx = grid_origin_.x() + (ix + (dx > 0.0 ? 1 : 0)) * cell_;
    t_max_x = (bx - o[0]) / dx;
  }
  if (dy != 0.0) {
    const double by = grid_origin_.y() + (iy + (dy > 0.0 ? 1 : 0)) * cell_;
    t_max_y = (by - o[1]) / dy;
  }

  const Segment* segs = segments_.data();
  const uint32_t* items = cell_items_.data();
  const uint32_t* begin = cell_begin_.data();
  while (true) {
    const size_t c = static_cast<size_t>(iy) * nx_ + ix;
    for (uint32_t k = begin[c], end = begin[c + 1]; k < end; ++k) {
      Intersect(segs[items[k]], origin, dir, 0.0, &best);
    }
    const double t_exit = std::min(t_max_x, t_max_y);
    // A hit inside this cell beats anything in later cells.
    if (best <= t_exit || t_exit > t1) break;
    if (t_max_x < t_max_y) {
      ix += step_x;
      if (ix < 0 || ix >= nx_) break;
      t_max_x += t_delta_x;
    } else {
      iy += step_y;
      if (iy < 0 || iy >= ny_) break;
      t_max_y += t_delta_y;
    }
  }
  return best <= max_range_m ? best : -1.0;
}

}  // namespace adse::world
