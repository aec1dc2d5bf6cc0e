// The three planning stages chained in one call, as the stack's nodes run
// them one after another (path -> speed limits -> obstacle stop), for
// tests that need a drivable trajectory rather than one stage.
#ifndef ADSE_TESTS_STACK_ALGORITHMS_TESTING_PLANNING_CHAIN_H_
#define ADSE_TESTS_STACK_ALGORITHMS_TESTING_PLANNING_CHAIN_H_

#include <vector>

#include "stack/algorithms/control.h"
#include "stack/algorithms/planning.h"

namespace adse::algorithms::testing {

struct ChainedPlan {
  PlannedPath path;       // the path planner's output (speeds: the limit)
  ObstacleStop obstacle;  // what the obstacle stop planner found
  std::vector<PlannedPoint> points;  // the final raw trajectory
};

inline ChainedPlan PlanChain(PathPlanner* planner, const geometry::Pose2& pose,
                             const std::vector<PlannerObstacle>& obstacles,
                             const VelocityLimitParams& velocity = {},
                             const ObstacleStopParams& stop = {}) {
  ChainedPlan out;
  out.path = planner->Plan(pose);
  out.points = out.path.points;
  LimitVelocity(&out.points, out.path.ends_at_goal, velocity);
  // The follower's way off from `pose`, as the stop planner's node gives it.
  const PurePursuit pursuit;
  out.obstacle = InsertObstacleStop(
      &out.points, obstacles,
      [&] {
        return pursuit.Rollout(pose, out.points, stop.drive_off_m,
                               stop.footprint_step_m);
      },
      stop);
  return out;
}

}  // namespace adse::algorithms::testing

#endif  // ADSE_TESTS_STACK_ALGORITHMS_TESTING_PLANNING_CHAIN_H_
