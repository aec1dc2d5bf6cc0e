#include "stack/algorithms/occupancy_grid.h"

#include <algorithm>
#include <cmath>

namespace adse::algorithms {

geometry::OrientedBox FootprintBox(const geometry::Pose2& pose,
                                   const VehicleFootprint& footprint,
                                   double grown_m) {
  geometry::OrientedBox body;
  body.yaw_rad = pose.yaw_rad;
  body.length_m = footprint.front_m + footprint.rear_m + 2 * grown_m;
  body.width_m = footprint.width_m + 2 * grown_m;
  body.center =
      Eigen::Vector2d(pose.x_m, pose.y_m) +
      0.5 * (footprint.front_m - footprint.rear_m) *
          Eigen::Vector2d(std::cos(pose.yaw_rad), std::sin(pose.yaw_rad));
  return body;
}
namespace {

constexpr double kFar = 1e20;

// Squared distance transform of one line (Felzenszwalb and Huttenlocher):
// d[q] = min over p of (q - p)^2 + f[p], by the lower envelope of parabolas.
void DistanceTransform1d(const std::vector<double>& f, std::vector<double>* d,
                         std::vector<int>* v, std::vector<double>* z) {
  const int n = static_cast<int>(f.size());
  int k = 0;
  (*v)[0] = 0;
  (*z)[0] = -kFar;
  (*z)[1] = kFar;
  auto cross = [&](int q, int p) {
    return ((f[q] + double(q) * q) - (f[p] + double(p) * p)) / (2.0 * (q - p));
  };
  for (int q = 1; q < n; ++q) {
    double s = cross(q, (*v)[k]);
    while (s <= (*z)[k]) {
      --k;
      s = cross(q, (*v)[k]);
    }
    ++k;
    (*v)[k] = q;
    (*z)[k] = s;
    (*z)[k + 1] = kFar;
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while ((*z)[k + 1] < q) ++k;
    const double dq = q - (*v)[k];
    (*d)[q] = dq * dq + f[(*v)[k]];
  }
}

}  // namespace

OccupancyGrid::OccupancyGrid(const Eigen::Vector2d& min_corner,
                             const Eigen::Vector2d& max_corner,
                             double resolution_m)
    : min_(min_corner),
      resolution_m_(std::max(resolution_m, 1e-3)),
      inverse_resolution_(1.0 / resolution_m_) {
  nx_ = std::max(1, static_cast<int>(std::ceil((max_corner.x() - min_.x()) /
                                               resolution_m_)));
  ny_ = std::max(1, static_cast<int>(std::ceil((max_corner.y() - min_.y()) /
                                               resolution_m_)));
  cells_.assign(static_cast<size_t>(nx_) * ny_, 0);
}

Eigen::Vector2d OccupancyGrid::CellCentre(int ix, int iy) const {
  return min_ + resolution_m_ * Eigen::Vector2d(ix + 0.5, iy + 0.5);
}

void OccupancyGrid::Mark(const Eigen::Vector2d& p) {
  int ix, iy;
  CellOf(p, &ix, &iy);
  if (InBounds(ix, iy)) cells_[iy * nx_ + ix] = 1;
}

void OccupancyGrid::AddObstacle(const std::vector<Eigen::Vector2d>& outline) {
  if (outline.empty()) return;
  // The outline's edges, sampled at a quarter cell so that no cell an edge
  // crosses more than a sliver of is missed.
  const size_t edges = outline.size() == 2 ? 1 : outline.size();
  const double step = 0.25 * resolution_m_;
  for (size_t i = 0; i < edges; ++i) {
    const Eigen::Vector2d& a = outline[i];
    const Eigen::Vector2d& b = outline[(i + 1) % outline.size()];
    const int n =
        std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    for (int k = 0; k <= n; ++k) Mark(a + (b - a) * (double(k) / n));
  }
  if (outline.size() == 1) Mark(outline.front());
  if (outline.size() < 3) return;
  FillPolygon(outline, &cells_);
}

void OccupancyGrid::FillPolygon(const std::vector<Eigen::Vector2d>& polygon,
                                std::vector<uint8_t>* cells) const {
  // The inside: cells whose centre the polygon holds.
  Eigen::Vector2d lo = polygon.front(), hi = polygon.front();
  for (const Eigen::Vector2d& p : polygon) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  int x0, y0, x1, y1;
  CellOf(lo, &x0, &y0);
  CellOf(hi, &x1, &y1);
  for (int iy = std::max(y0, 0); iy <= std::min(y1, ny_ - 1); ++iy) {
    for (int ix = std::max(x0, 0); ix <= std::min(x1, nx_ - 1); ++ix) {
      if (geometry::InsidePolygon(polygon, CellCentre(ix, iy))) {
        (*cells)[iy * nx_ + ix] = 1;
      }
    }
  }
}

void OccupancyGrid::KeepInside(
    const std::vector<std::vector<Eigen::Vector2d>>& areas) {
  if (areas.empty()) return;
  std::vector<uint8_t> inside(cells_.size(), 0);
  for (const std::vector<Eigen::Vector2d>& area : areas) {
    if (area.size() >= 3) FillPolygon(area, &inside);
  }
  for (size_t i = 0; i < cells_.size(); ++i) {
    if (!inside[i]) cells_[i] = 1;
  }
}

void OccupancyGrid::ComputeDistances() {
  // Two passes of the 1D transform: columns, then rows of the result.
  std::vector<double> sq(cells_.size());
  for (size_t i = 0; i < cells_.size(); ++i) sq[i] = cells_[i] ? 0.0 : kFar;
  const int longest = std::max(nx_, ny_);
  std::vector<double> f, d(longest);
  std::vector<int> v(longest);
  std::vector<double> z(longest + 1);
  for (int ix = 0; ix < nx_; ++ix) {
    f.resize(ny_);
    d.resize(ny_);
    for (int iy = 0; iy < ny_; ++iy) f[iy] = sq[iy * nx_ + ix];
    DistanceTransform1d(f, &d, &v, &z);
    for (int iy = 0; iy < ny_; ++iy) sq[iy * nx_ + ix] = d[iy];
  }
  distance_cells_.resize(cells_.size());
  for (int iy = 0; iy < ny_; ++iy) {
    f.assign(sq.begin() + iy * nx_, sq.begin() + (iy + 1) * nx_);
    d.resize(nx_);
    DistanceTransform1d(f, &d, &v, &z);
    for (int ix = 0; ix < nx_; ++ix) {
      distance_cells_[iy * nx_ + ix] = static_cast<float>(std::sqrt(d[ix]));
    }
  }
}

double OccupancyGrid::ClearanceLowerBound(const Eigen::Vector2d& p) const {
  int ix, iy;
  CellOf(p, &ix, &iy);
  if (distance_cells_.empty() || !InBounds(ix, iy)) return 0.0;
  // Cell centres are exact; `p` and the obstacle may each be anywhere in
  // their cells, half a diagonal from the centre.
  return std::max(
      0.0, (distance_cells_[iy * nx_ + ix] - std::sqrt(2.0)) * resolution_m_);
}

bool OccupancyGrid::FootprintCollides(const geometry::Pose2& pose,
                                      const VehicleFootprint& footprint,
                                      double margin_m,
                                      int64_t* work_units) const {
  const double x0 = -footprint.rear_m - margin_m;
  const double x1 = footprint.front_m + margin_m;
  const double hw = 0.5 * footprint.width_m + margin_m;
  const double c = std::cos(pose.yaw_rad);
  const double s = std::sin(pose.yaw_rad);
  // Quick accept: three discs along the axis cover the footprint.
  if (!distance_cells_.empty()) {
    const double third = (x1 - x0) / 3.0;
    const double radius = std::hypot(0.5 * third, hw);
    bool clear = true;
    for (int k = 0; k < 3 && clear; ++k) {
      const double lx = x0 + third * (k + 0.5);
      clear = ClearanceLowerBound(Eigen::Vector2d(pose.x_m + c * lx,
                                                  pose.y_m + s * lx)) > radius;
    }
    if (work_units) *work_units += 3;
    if (clear) return false;
  }
  int64_t tested = 0;
  auto hit = [&](double lx, double ly) {
    ++tested;
    return OccupiedAt(Eigen::Vector2d(pose.x_m + c * lx - s * ly,
                                      pose.y_m + s * lx + c * ly));
  };
  bool collides = false;
  // Outline first (where contact begins), every cell: occupied cells hold
  // any obstacle that touches them, so a sample step of one cell misses at
  // most a corner sliver, well inside the planner's margin.
  const double edge_step = resolution_m_;
  const int nl =
      std::max(1, static_cast<int>(std::ceil((x1 - x0) / edge_step)));
  const int nw = std::max(1, static_cast<int>(std::ceil(2 * hw / edge_step)));
  for (int i = 0; i <= nl && !collides; ++i) {
    const double lx = x0 + (x1 - x0) * i / nl;
    collides = hit(lx, -hw) || hit(lx, hw);
  }
  for (int j = 1; j < nw && !collides; ++j) {
    const double ly = -hw + 2 * hw * j / nw;
    collides = hit(x0, ly) || hit(x1, ly);
  }
  // Inside, on a lattice of about half a metre.
  const int il = std::max(1, static_cast<int>(std::ceil((x1 - x0) / 0.5)));
  const int iw = std::max(1, static_cast<int>(std::ceil(2 * hw / 0.5)));
  for (int i = 1; i < il && !collides; ++i) {
    for (int j = 1; j < iw && !collides; ++j) {
      collides = hit(x0 + (x1 - x0) * i / il, -hw + 2 * hw * j / iw);
    }
  }
  if (work_units) *work_units += tested;
  return collides;
}

}  // namespace adse::algorithms
