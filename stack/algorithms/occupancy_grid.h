// A 2D occupancy grid rasterised from obstacle outlines (parked cars,
// walls, poles) and the collision check of a car's rectangular footprint
// against it: what the freespace planner searches in. Eigen and std only.
#ifndef ADSE_STACK_ALGORITHMS_OCCUPANCY_GRID_H_
#define ADSE_STACK_ALGORITHMS_OCCUPANCY_GRID_H_

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "stack/geometry/geometry.h"

namespace adse::algorithms {

// The car's outline around its rear axle centre (the pose's origin).
struct VehicleFootprint {
  double front_m = 3.65;  // rear axle to front bumper
  double rear_m = 0.95;   // rear axle to rear bumper
  double width_m = 1.9;   // body width
};

// The footprint of a body `length_m` long and `width_m` wide whose centre
// lies half a wheelbase ahead of the rear axle, as the world's vehicles'
// bodies do.
inline VehicleFootprint FootprintOfBody(double length_m, double wheelbase_m,
                                        double width_m) {
  VehicleFootprint f;
  f.front_m = 0.5 * (wheelbase_m + length_m);
  f.rear_m = 0.5 * (length_m - wheelbase_m);
  f.width_m = width_m;
  return f;
}

// The body of a car whose rear axle stands at `pose`, grown by `grown_m`
// on every side.
geometry::OrientedBox FootprintBox(const geometry::Pose2& pose,
                                   const VehicleFootprint& footprint,
                                   double grown_m = 0.0);

class OccupancyGrid {
 public:
  // A grid over the rectangle [min_corner, max_corner] with square cells of
  // `resolution_m`, all free.
  OccupancyGrid(const Eigen::Vector2d& min_corner,
                const Eigen::Vector2d& max_corner, double resolution_m);

  // Marks every cell the outline touches: two points are a thin segment (a
  // wall), three or more a filled polygon closed back to its first point.
  void AddObstacle(const std::vector<Eigen::Vector2d>& outline);
  // Marks every cell whose centre lies in none of `areas` (polygons): the
  // car keeps to them, e.g. a road's lanes and junctions. Empty: no effect.
  void KeepInside(const std::vector<std::vector<Eigen::Vector2d>>& areas);

  int width_cells() const { return nx_; }
  int height_cells() const { return ny_; }
  double resolution_m() const { return resolution_m_; }
  const Eigen::Vector2d& min_corner() const { return min_; }
  bool InBounds(int ix, int iy) const {
    return ix >= 0 && iy >= 0 && ix < nx_ && iy < ny_;
  }
  bool Occupied(int ix, int iy) const {
    return !InBounds(ix, iy) || cells_[iy * nx_ + ix] != 0;
  }
  // The cell holding `p` (may be out of bounds). Inline: the planner's
  // innermost call.
  void CellOf(const Eigen::Vector2d& p, int* ix, int* iy) const {
    const double fx = (p.x() - min_.x()) * inverse_resolution_;
    const double fy = (p.y() - min_.y()) * inverse_resolution_;
    *ix = static_cast<int>(fx) - (fx < 0.0 && fx != static_cast<int>(fx));
    *iy = static_cast<int>(fy) - (fy < 0.0 && fy != static_cast<int>(fy));
  }
  Eigen::Vector2d CellCentre(int ix, int iy) const;
  // Outside the grid counts as occupied: the planner never leaves it.
  bool OccupiedAt(const Eigen::Vector2d& p) const {
    int ix, iy;
    CellOf(p, &ix, &iy);
    return Occupied(ix, iy);
  }

  // Computes every cell's distance to the nearest occupied cell (exact
  // Euclidean distance transform). Call after the last AddObstacle();
  // FootprintCollides() then accepts poses far from obstacles at once.
  void ComputeDistances();
  // A lower bound of the distance from `p` to the nearest obstacle, 0 when
  // distances are not computed or `p` is outside the grid.
  double ClearanceLowerBound(const Eigen::Vector2d& p) const;

  // True when the footprint at `pose`, grown by `margin_m` on every side,
  // touches an occupied cell. Its outline is sampled every cell and its
  // inside on a coarser lattice (an obstacle wholly inside a car can only
  // be there when the car started on it). Near no obstacle (three discs
  // covering the footprint are clear) it answers without sampling. Adds the
  // points looked up to *work_units when given.
  bool FootprintCollides(const geometry::Pose2& pose,
                         const VehicleFootprint& footprint, double margin_m,
                         int64_t* work_units = nullptr) const;

 private:
  void Mark(const Eigen::Vector2d& p);
  // Sets to 1 the cells of `cells` (one per grid cell) whose centre
  // `polygon` (3 or more points) holds.
  void FillPolygon(const std::vector<Eigen::Vector2d>& polygon,
                   std::vector<uint8_t>* cells) const;
  Eigen::Vector2d min_;
  double resolution_m_;
  double inverse_resolution_;
  int nx_ = 0, ny_ = 0;
  std::vector<uint8_t> cells_;
  std::vector<float> distance_cells_;  // empty until ComputeDistances()
};

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_OCCUPANCY_GRID_H_
