#include "stack/world/traffic_yield.h"

#include <algorithm>
#include <cmath>

namespace adse::world {

double YieldLookaheadM(double speed_mps, double decel_mps2,
                       const YieldParams& params) {
  return std::max(params.min_lookahead_m,
                  speed_mps * speed_mps / (2 * std::max(decel_mps2, 0.1)) +
                      speed_mps * params.reaction_s + params.standstill_gap_m);
}

double YieldSpeedMps(const std::vector<Eigen::Vector2d>& path, double width_m,
                     double decel_mps2, const geometry::OrientedBox& ego_body,
                     const Eigen::Vector2d& ego_velocity_mps,
                     const YieldParams& params) {
  const double d = geometry::DistanceAlongPathToBox(
      path, width_m / 2 + params.corridor_margin_m, ego_body);
  if (d < 0) return -1.0;
  geometry::Path2 ahead;
  ahead.points = path;
  ahead.UpdateArcLength();
  const double heading = ahead.HeadingAt(d);
  // Only the ego's motion away along the path helps; coming towards the
  // driver or across, it is an obstacle standing where it is.
  const double along =
      std::max(0.0, ego_velocity_mps.dot(
                        Eigen::Vector2d(std::cos(heading), std::sin(heading))));
  return std::sqrt(along * along +
                   2 * decel_mps2 * std::max(0.0, d - params.standstill_gap_m));
}

}  // namespace adse::world
