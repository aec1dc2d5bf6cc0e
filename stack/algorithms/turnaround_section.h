// Where a route turns round tighter than the car can (a U-turn narrower
// than its turning circle), or takes a corner the car cannot follow on its
// lanes: what a lanelet route knows of such a turn, as the world finds it
// and the stack drives it. Eigen and std types only.
#ifndef ADSE_STACK_ALGORITHMS_TURNAROUND_SECTION_H_
#define ADSE_STACK_ALGORITHMS_TURNAROUND_SECTION_H_

#include <Eigen/Core>
#include <vector>

#include "stack/geometry/geometry.h"

namespace adse::algorithms {

// The car stops on the lane it arrives on and turns in several moves,
// forwards and in reverse, within the road's lanes and junctions, onto the
// lane it leaves on.
struct TurnaroundSection {
  double start_s_m = 0.0;  // along the route: where the car stops to turn
  double end_s_m = 0.0;    // along the route: where it drives on
  geometry::Pose2 goal;    // rear axle on the departing lane, at end_s_m
  // The lanes open to cars and the junctions about the turn, as polygons
  // (where the manoeuvre keeps to), and the structure standing there.
  std::vector<std::vector<Eigen::Vector2d>> drivable;
  std::vector<std::vector<Eigen::Vector2d>> obstacles;
  // A corner sharper than the car can follow closely on its lanes, rather
  // than a U-turn narrower than its turning circle: where no manoeuvre
  // leads on from where the car stands, it may take the lanes instead.
  bool corner = false;
};

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_TURNAROUND_SECTION_H_
