// Static geometry the LiDAR sees and the localization map is built from:
// walls, poles, parked cars, building footprints. Eigen only.
#ifndef ADSE_STACK_WORLD_SCENE_H_
#define ADSE_STACK_WORLD_SCENE_H_

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "stack/geometry/geometry.h"

namespace adse::world {

enum class ObstacleKind { kWall, kPole, kParkedCar, kBuilding };

// "wall", "pole", "parked car", "building".
const char* ObstacleKindToString(ObstacleKind kind);

// A vertical prism: a closed footprint polygon extruded from z_min to z_max.
// A wall is a thin footprint; a pole a small polygon around its centre.
struct Obstacle {
  ObstacleKind kind = ObstacleKind::kWall;
  std::vector<Eigen::Vector2d> footprint;  // closed implicitly, >= 2 points
  double z_min_m = 0.0;
  double z_max_m = 2.0;
};

// The vertical faces of an obstacle as footprint edges: a 2-point footprint
// is one edge (a thin wall), a longer one is closed back to its first point.
// Zero-length edges (repeated points, an explicitly closed ring) are dropped.
std::vector<std::array<Eigen::Vector2d, 2>> ObstacleEdges(
    const Obstacle& obstacle);

// Where a horizontal 2D ray crosses an obstacle face: at horizontal
// distance s_m, a face spanning z_min_m..z_max_m.
struct FaceCrossing {
  double s_m;
  double z_min_m;
  double z_max_m;
};

// A parking slot (for parked cars and valet goals).
struct ParkingSlot {
  std::string name;           // the map's polygon id
  geometry::OrientedBox box;  // slot rectangle; length along the slot's depth
  bool occupied = false;
};

// The static scene with a 2D uniform grid over obstacle edges so that ray
// casts touch only the cells a ray crosses.
class Scene {
 public:
  Scene() = default;

  // Obstacles with a non-finite coordinate are ignored; z_min > z_max are
  // swapped.
  void AddObstacle(Obstacle obstacle);
  void AddParkingSlot(ParkingSlot slot);
  // Builds the acceleration grid; call after the last Add*(). Until then
  // (or after a later Add*()) CastRay() is correct but tests every face.
  void Finalize(double cell_size_m = 4.0);

  const std::vector<Obstacle>& obstacles() const { return obstacles_; }
  const std::vector<ParkingSlot>& parking_slots() const { return slots_; }

  // Distance along a 3D ray (origin, unit direction) to the first obstacle
  // face it hits within max_range_m; negative when none. Ground excluded.
  double CastRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                 double max_range_m) const;

  // Every face crossed by the 2D ray (origin, unit dir) within max_s_m,
  // nearest first. All rays of a spinning LiDAR's azimuth column share
  // these: a ray at elevation e from height h hits the first crossing with
  // h + s tan(e) within the face's z span, at distance s / cos(e) (the
  // same answer CastRay gives), so the grid is walked once per column.
  void CrossingsAlong(const Eigen::Vector2d& origin, const Eigen::Vector2d& dir,
                      double max_s_m,
                      std::vector<FaceCrossing>* crossings) const;

  // Axis-aligned bounds of all obstacles: min and max corners.
  Eigen::Vector2d min_corner() const { return min_; }
  Eigen::Vector2d max_corner() const { return max_; }
  // Grid cell edge actually used (Finalize may enlarge it on huge maps).
  double cell_size_m() const { return cell_; }

 private:
  struct Segment {
    Eigen::Vector2d a, b;
    double z_min_m, z_max_m;
  };
  // Calls visit(cell, t_enter, t_exit) for each grid cell the 2D ray
  // origin + t * (dx, dy), t in [t0, t1], passes through, in order, until
  // visit returns true. Defined (and only used) in scene.cc.
  template <typename Visit>
  void WalkGrid(double ox, double oy, double dx, double dy, double t0,
                double t1, Visit&& visit) const;
  std::vector<Obstacle> obstacles_;
  std::vector<ParkingSlot> slots_;
  std::vector<Segment> segments_;
  // Grid: cells_[iy * nx_ + ix] lists segment indices. Used while building
  // only: Finalize() flattens it into cell_begin_/cell_items_ (one block of
  // memory, cache friendly) and clears it.
  std::vector<std::vector<int>> cells_;
  Eigen::Vector2d min_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d max_ = Eigen::Vector2d::Zero();
  bool has_bounds_ = false;
  double cell_ = 4.0;
  int nx_ = 0, ny_ = 0;
  // Segments of cell c are cell_items_[cell_begin_[c] .. cell_begin_[c+1]).
  std::vector<uint32_t> cell_begin_;
  std::vector<uint32_t> cell_items_;
  // Height span of each cell's faces: a ray passing over (or under) every
  // face of a cell skips it, e.g. above a row of parked cars.
  std::vector<float> cell_z_lo_m_, cell_z_hi_m_;
  Eigen::Vector2d grid_origin_ = Eigen::Vector2d::Zero();
  // Number of segments the grid indexes; fewer than segments_ = stale grid.
  size_t indexed_segments_ = 0;
  // Height span of all faces: a ray outside it can hit nothing.
  double z_lo_m_ = 0.0;
  double z_hi_m_ = 0.0;
};

}  // namespace adse::world

#endif  // ADSE_STACK_WORLD_SCENE_H_
