// Reeds–Shepp curves: the shortest paths of a car that turns no tighter than
// a radius and drives forwards and backwards (Reeds and Shepp, 1990), as
// the freespace planner's analytic expansion and heuristic. Eigen and std
// types only.
#ifndef ADSE_STACK_ALGORITHMS_REEDS_SHEPP_H_
#define ADSE_STACK_ALGORITHMS_REEDS_SHEPP_H_

#include <optional>
#include <vector>

#include "stack/geometry/geometry.h"

namespace adse::algorithms {

enum class SteerKind { kLeft, kStraight, kRight };

// One piece of a path: an arc at the minimum radius or a straight line.
// A negative length drives it in reverse.
struct RsSegment {
  SteerKind steer = SteerKind::kStraight;
  double length_m = 0.0;
};

struct ReedsSheppPath {
  std::vector<RsSegment> segments;
  double length_m() const;   // sum of |segment lengths|
  int gear_changes() const;  // direction reversals between segments
};

// The candidate Reeds–Shepp paths from `from` to `to` (every word of the
// CSC, CCC, CCCC, CCSC and CCSCC families that has a solution), shortest
// first. Each candidate ends at `to`; zero-length segments are dropped.
std::vector<ReedsSheppPath> ReedsSheppCandidates(const geometry::Pose2& from,
                                                 const geometry::Pose2& to,
                                                 double turning_radius_m);

// Length of the shortest candidate; the obstacle-free lower bound the
// planner's heuristic uses.
double ReedsSheppDistance(const geometry::Pose2& from,
                          const geometry::Pose2& to, double turning_radius_m);

// Where `from` ends after driving `length_m` (signed: negative reverses)
// on a circle of signed curvature (left positive; 0 is straight).
geometry::Pose2 AdvanceArc(const geometry::Pose2& from, double curvature_1pm,
                           double length_m);

// A pose along a path and the gear it is driven in (true: reverse).
struct GearedPose {
  geometry::Pose2 pose;
  bool reverse = false;
};

// Poses along `path` from `from`, no farther apart than `step_m`, the first
// being `from` and each segment's end included (so a gear change appears
// as a pose with the old gear followed by poses with the new one).
std::vector<GearedPose> SampleReedsShepp(const geometry::Pose2& from,
                                         const ReedsSheppPath& path,
                                         double turning_radius_m,
                                         double step_m);

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_REEDS_SHEPP_H_
