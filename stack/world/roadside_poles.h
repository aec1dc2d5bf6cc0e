// Structure for a bare road network: lamp poles along its roads, so that
// the LiDAR and the localization map have something to see where the
// network brings no buildings or walls. Plain geometry, no SUMO.
#ifndef ADSE_STACK_WORLD_ROADSIDE_POLES_H_
#define ADSE_STACK_WORLD_ROADSIDE_POLES_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "stack/world/scene.h"

namespace adse::world {

// SUMO lane ids are "<edge>_<index>"; internal (junction) lanes start
// with ':'.
std::string EdgeOfLane(const std::string& lane_id);
int IndexOfLane(const std::string& lane_id);

// One lane of the network: its id, centre line and half width.
struct LaneGeometry {
  std::string id;
  std::vector<Eigen::Vector2d> points;
  double half_width_m = 0.0;
};

// Poles every 20 m, 1 m beyond the outer edge of each normal edge's
// rightmost lane (index 0) and leftmost lane (the far side of a one-way
// street), skipping any that would stand on a lane. `lanes` in a stable
// order (the caller sorts them by id), so the poles are reproducible.
std::vector<Obstacle> RoadsidePoles(const std::vector<LaneGeometry>& lanes);

}  // namespace adse::world

#endif  // ADSE_STACK_WORLD_ROADSIDE_POLES_H_
