// How a SUMO driver yields to the ego: SUMO's own car-following does not
// see the ego everywhere (it is placed by moveToXY), so the world asks
// each driver near it whether the ego lies in the lanes it drives next
// and caps its speed to stop short of it. libsumo-free: the world hands it
// the driver's path.
#ifndef ADSE_STACK_WORLD_TRAFFIC_YIELD_H_
#define ADSE_STACK_WORLD_TRAFFIC_YIELD_H_

#include <Eigen/Core>
#include <vector>

#include "stack/geometry/geometry.h"

namespace adse::world {

struct YieldParams {
  // The driver's corridor: its half width and this much more, m.
  double corridor_margin_m = 0.3;
  // How far short of the ego the driver means to stand, m.
  double standstill_gap_m = 2.0;
  // The driver looks this long ahead beyond its stopping distance, s.
  double reaction_s = 1.0;
  // ... and at least this far, m.
  double min_lookahead_m = 10.0;
};

// How far ahead a driver at `speed_mps` that brakes at `decel_mps2` looks.
double YieldLookaheadM(double speed_mps, double decel_mps2,
                       const YieldParams& params = {});

// The highest speed at which a driver of width `width_m` following `path`
// (from its front bumper) still stops `standstill_gap_m` short of the ego
// braking at `decel_mps2`, the ego keeping its speed along the path
// (Krauss' safe speed with the ego as leader); a negative value when the
// ego is not in its corridor.
double YieldSpeedMps(const std::vector<Eigen::Vector2d>& path, double width_m,
                     double decel_mps2, const geometry::OrientedBox& ego_body,
                     const Eigen::Vector2d& ego_velocity_mps,
                     const YieldParams& params = {});

}  // namespace adse::world

#endif  // ADSE_STACK_WORLD_TRAFFIC_YIELD_H_
