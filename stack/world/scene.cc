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

// Nearest hit of the ray with the face over segment a-b at a distance in
// [0, *t_best); updates *t_best when found. Rejects with multiplications
// first and divides only for a hit: most faces tested are missed.
inline void IntersectFace(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                          double z_min, double z_max,
                          const Eigen::Vector3d& origin,
                          const Eigen::Vector3d& dir, double* t_best) {
  // Solve origin.xy + t*dir.xy = a + u*(b - a); t is the 3D distance since
  // dir is a unit vector.
  const double ex = b.x() - a.x();
  const double ey = b.y() - a.y();
  double denom = Cross(dir.x(), dir.y(), ex, ey);
  const double wx = a.x() - origin.x();
  const double wy = a.y() - origin.y();
  double t_num = Cross(wx, wy, ex, ey);
  double u_num = Cross(wx, wy, dir.x(), dir.y());
  // Parallel (incl. along the face): grazing, not a return.
  if (denom == 0.0) return;
  if (denom < 0.0) {
    denom = -denom;
    t_num = -t_num;
    u_num = -u_num;
  }
  // Now t = t_num / denom and u = u_num / denom with denom > 0.
  if (t_num < 0.0 || u_num < 0.0 || u_num > denom) return;
  const double t = t_num / denom;
  if (!(t < *t_best)) return;
  const double z = origin.z() + t * dir.z();
  if (z < z_min || z > z_max) return;
  *t_best = t;
}

}  // namespace

const char* ObstacleKindToString(ObstacleKind kind) {
  switch (kind) {
    case ObstacleKind::kWall:
      return "wall";
    case ObstacleKind::kPole:
      return "pole";
    case ObstacleKind::kParkedCar:
      return "parked car";
    case ObstacleKind::kBuilding:
      return "building";
  }
  return "obstacle";
}

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
  // NaN or infinite coordinates would poison the bounds and the grid.
  bool finite =
      std::isfinite(obstacle.z_min_m) && std::isfinite(obstacle.z_max_m);
  for (const auto& p : obstacle.footprint) finite = finite && p.allFinite();
  if (!finite) return;
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
  while ((extent.x() / cell_ + 1.0) * (extent.y() / cell_ + 1.0) > kMaxCells) {
    cell_ *= 2.0;
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
    const int ix0 = std::clamp(
        static_cast<int>(std::floor((lo.x() - eps) / cell_)), 0, nx_ - 1);
    const int ix1 = std::clamp(
        static_cast<int>(std::floor((hi.x() + eps) / cell_)), 0, nx_ - 1);
    const int iy0 = std::clamp(
        static_cast<int>(std::floor((lo.y() - eps) / cell_)), 0, ny_ - 1);
    const int iy1 = std::clamp(
        static_cast<int>(std::floor((hi.y() + eps) / cell_)), 0, ny_ - 1);
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
  // Per-cell height spans, widened a little so a float bound never cuts off
  // a face that the double-precision test would hit.
  cell_z_lo_m_.assign(cells_.size(), std::numeric_limits<float>::infinity());
  cell_z_hi_m_.assign(cells_.size(), -std::numeric_limits<float>::infinity());
  for (size_t c = 0; c < cells_.size(); ++c) {
    double lo = kInf, hi = -kInf;
    for (const int i : cells_[c]) {
      lo = std::min(lo, segments_[i].z_min_m);
      hi = std::max(hi, segments_[i].z_max_m);
    }
    if (cells_[c].empty()) continue;
    const double pad = 1e-6 * (1.0 + std::max(std::abs(lo), std::abs(hi)));
    constexpr float kInfF = std::numeric_limits<float>::infinity();
    cell_z_lo_m_[c] = std::nextafter(static_cast<float>(lo - pad), -kInfF);
    cell_z_hi_m_[c] = std::nextafter(static_cast<float>(hi + pad), kInfF);
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

double Scene::CastRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                      double max_range_m) const {
  if (segments_.empty() || !(max_range_m > 0.0)) return -1.0;
  const double dx = dir.x(), dy = dir.y(), dz = dir.z();
  if (dx * dx + dy * dy < kMinHorizontal * kMinHorizontal) return -1.0;

  // Hits are accepted up to max_range_m inclusive.
  double best = std::nextafter(max_range_m, kInf);
  if (indexed_segments_ != segments_.size() || nx_ <= 0 || ny_ <= 0) {
    // Not (re)finalized: still right, just slow.
    for (const Segment& s : segments_) {
      IntersectFace(s.a, s.b, s.z_min_m, s.z_max_m, origin, dir, &best);
    }
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

  const Segment* segs = segments_.data();
  const uint32_t* items = cell_items_.data();
  const uint32_t* begin = cell_begin_.data();
  const float* cell_lo = cell_z_lo_m_.data();
  const float* cell_hi = cell_z_hi_m_.data();
  WalkGrid(
      origin.x(), origin.y(), dx, dy, t0, t1,
      [&](size_t c, double t_enter, double t_exit) {
        // Ray height span while in this cell (the float bounds are
        // rounded outwards when built).
        const double za = origin.z() + dz * t_enter;
        const double zb = origin.z() + dz * std::min(t_exit, t1);
        if (std::max(za, zb) >= cell_lo[c] && std::min(za, zb) <= cell_hi[c]) {
          for (uint32_t k = begin[c], end = begin[c + 1]; k < end; ++k) {
            const Segment& s = segs[items[k]];
            IntersectFace(s.a, s.b, s.z_min_m, s.z_max_m, origin, dir, &best);
          }
        }
        // A hit inside this cell beats anything in later cells.
        return best <= t_exit;
      });
  return best <= max_range_m ? best : -1.0;
}

void Scene::CrossingsAlong(const Eigen::Vector2d& origin,
                           const Eigen::Vector2d& dir, double max_s_m,
                           std::vector<FaceCrossing>* crossings) const {
  crossings->clear();
  if (segments_.empty() || !(max_s_m >= 0.0)) return;
  auto add = [&](const Segment& s) {
    const double ex = s.b.x() - s.a.x();
    const double ey = s.b.y() - s.a.y();
    double denom = Cross(dir.x(), dir.y(), ex, ey);
    if (denom == 0.0) return;  // parallel: grazing, not a return
    const double wx = s.a.x() - origin.x();
    const double wy = s.a.y() - origin.y();
    double s_num = Cross(wx, wy, ex, ey);
    double u_num = Cross(wx, wy, dir.x(), dir.y());
    if (denom < 0.0) {
      denom = -denom;
      s_num = -s_num;
      u_num = -u_num;
    }
    if (s_num < 0.0 || u_num < 0.0 || u_num > denom) return;
    const double dist = s_num / denom;
    if (dist > max_s_m) return;
    crossings->push_back({dist, s.z_min_m, s.z_max_m});
  };
  if (indexed_segments_ != segments_.size() || nx_ <= 0 || ny_ <= 0) {
    for (const Segment& s : segments_) add(s);
  } else {
    const Segment* segs = segments_.data();
    const uint32_t* items = cell_items_.data();
    const uint32_t* begin = cell_begin_.data();
    WalkGrid(origin.x(), origin.y(), dir.x(), dir.y(), 0.0, max_s_m,
             [&](size_t c, double, double) {
               for (uint32_t k = begin[c], end = begin[c + 1]; k < end; ++k) {
                 add(segs[items[k]]);
               }
               return false;
             });
  }
  // A face spanning several cells is found in each: identical inputs give
  // bitwise identical crossings, which sorting brings together.
  std::sort(crossings->begin(), crossings->end(),
            [](const FaceCrossing& a, const FaceCrossing& b) {
              if (a.s_m != b.s_m) return a.s_m < b.s_m;
              if (a.z_min_m != b.z_min_m) return a.z_min_m < b.z_min_m;
              return a.z_max_m < b.z_max_m;
            });
  crossings->erase(
      std::unique(crossings->begin(), crossings->end(),
                  [](const FaceCrossing& a, const FaceCrossing& b) {
                    return a.s_m == b.s_m && a.z_min_m == b.z_min_m &&
                           a.z_max_m == b.z_max_m;
                  }),
      crossings->end());
}

template <typename Visit>
void Scene::WalkGrid(double ox, double oy, double dx, double dy, double t0,
                     double t1, Visit&& visit) const {
  // Clip to the grid rectangle (slightly enlarged: faces on its border).
  const double margin = 1e-7 * cell_;
  const double d[2] = {dx, dy};
  const double o[2] = {ox, oy};
  const double lo[2] = {grid_origin_.x() - margin, grid_origin_.y() - margin};
  const double hi[2] = {grid_origin_.x() + nx_ * cell_ + margin,
                        grid_origin_.y() + ny_ * cell_ + margin};
  for (int k = 0; k < 2; ++k) {
    if (d[k] == 0.0) {
      if (o[k] < lo[k] || o[k] > hi[k]) return;
      continue;
    }
    double ta = (lo[k] - o[k]) / d[k];
    double tb = (hi[k] - o[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 > t1) return;

  // Amanatides-Woo walk over the cells the ray's 2D shadow crosses, from
  // the entry point at t0. Boundaries are kept as ray parameters.
  const double px = ox + t0 * dx - grid_origin_.x();
  const double py = oy + t0 * dy - grid_origin_.y();
  int ix = std::clamp(static_cast<int>(std::floor(px / cell_)), 0, nx_ - 1);
  int iy = std::clamp(static_cast<int>(std::floor(py / cell_)), 0, ny_ - 1);
  const int step_x = dx > 0.0 ? 1 : -1;
  const int step_y = dy > 0.0 ? 1 : -1;
  const double t_delta_x = dx != 0.0 ? cell_ / std::abs(dx) : kInf;
  const double t_delta_y = dy != 0.0 ? cell_ / std::abs(dy) : kInf;
  double t_max_x = kInf, t_max_y = kInf;
  if (dx != 0.0) {
    const double bx = grid_origin_.x() + (ix + (dx > 0.0 ? 1 : 0)) * cell_;
    t_max_x = (bx - ox) / dx;
  }
  if (dy != 0.0) {
    const double by = grid_origin_.y() + (iy + (dy > 0.0 ? 1 : 0)) * cell_;
    t_max_y = (by - oy) / dy;
  }
  double t_enter = t0;
  while (true) {
    const size_t c = static_cast<size_t>(iy) * nx_ + ix;
    const double t_exit = std::min(t_max_x, t_max_y);
    if (visit(c, t_enter, t_exit) || t_exit > t1) return;
    t_enter = t_exit;
    if (t_max_x < t_max_y) {
      ix += step_x;
      if (ix < 0 || ix >= nx_) return;
      t_max_x += t_delta_x;
    } else {
      iy += step_y;
      if (iy < 0 || iy >= ny_) return;
      t_max_y += t_delta_y;
    }
  }
}

}  // namespace adse::world
