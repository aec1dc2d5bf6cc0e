// Lane changes along the route. Autoware's lane change module starts one
// only when its safety check finds no object in the target lane nearer
// than an RSS distance over the manoeuvre. adse's mission planner fixes
// where the route changes lane (the route blends into the next lane over
// a section, as the world builds it); LaneChangeGuard holds the car before
// a section until the target lane has that gap. Without it the car steered
// into a lane where a car was overtaking it. Eigen and std types only.
#ifndef ADSE_STACK_ALGORITHMS_LANE_CHANGE_H_
#define ADSE_STACK_ALGORITHMS_LANE_CHANGE_H_

#include <vector>

#include "stack/algorithms/planning.h"
#include "stack/geometry/geometry.h"

namespace adse::algorithms {

// A part of the route where it moves over from one lane into another of
// the same road (the route knows, as a lanelet route does).
struct LaneChangeSection {
  double start_s_m = 0.0;  // route s where the route starts leaving its lane
  double end_s_m = 0.0;    // route s from where it is in the target lane
  // Offset of the target lane's centre from the lane left, left positive:
  // the lanes crossed times lane_width_m.
  double shift_m = 0.0;
  double lane_width_m = 3.2;

  // How far (0..1) the route has moved over at route s: a smoothstep from
  // start_s_m to end_s_m. The world blends the two lanes' shapes by it.
  double Weight(double s_m) const;
};

struct LaneChangeParams {
  // The RSS distance of Autoware's safety check, with its defaults: a car
  // behind reacts after rear_reaction_time_s and brakes at
  // rear_decel_mps2; the car ahead brakes at front_decel_mps2; a further
  // rear_safety_margin_s at the rear car's speed, and never less than
  // min_gap_m.
  double front_decel_mps2 = 1.0;
  double rear_decel_mps2 = 1.0;
  double rear_reaction_time_s = 2.0;
  double rear_safety_margin_s = 1.0;
  double min_gap_m = 3.0;
  // The manoeuvre is predicted this far ahead (Autoware's horizon for
  // objects behind), every step_s.
  double horizon_s = 10.0;
  double step_s = 0.5;
  // The ego speeds up at max_accel_mps2 to the plan's top speed, and a
  // section it cannot stop before at max_decel_mps2 it drives through
  // (committed, as a pass judge line).
  double max_accel_mps2 = 1.5;
  double max_decel_mps2 = 2.5;
  // Objects ahead slower than this are left to the obstacle stop (a
  // parked or queued car is in the route's corridor once it matters).
  double min_front_object_speed_mps = 1.0;
  double ego_front_m = 3.8;  // rear axle to front bumper
  double ego_rear_m = 1.0;   // rear axle to rear bumper
  // Once holding, the car goes again only after this long with a gap
  // (the hysteresis of Autoware's modules' state transit margin).
  double transit_margin_s = 1.0;
};

// An object's gap to the ego and the gap the RSS distance asks for; the
// ego is the rear car when the object is ahead and the front car when it
// is behind. Alongside, the gap is negative.
struct LaneChangeGap {
  double gap_m = 0.0;
  double required_m = 0.0;
};
LaneChangeGap RssGap(double ego_s_m, double ego_v_mps, double object_s_m,
                     double object_v_mps, double object_length_m,
                     const LaneChangeParams& params);

class LaneChangeGuard {
 public:
  LaneChangeGuard(const geometry::Path2& route,
                  std::vector<LaneChangeSection> sections,
                  const LaneChangeParams& params = {});

  // Stops `points` (the path from the ego on, route s) at the start of the
  // next lane change when an object in its target lane would come nearer
  // than the RSS distance while the ego changes lane, unless the ego is
  // committed. The stop names the object; gap_m is its gap now (negative
  // alongside). reason is StopReason::kLaneChange.
  ObstacleStop Plan(std::vector<PlannedPoint>* points,
                    const std::vector<PlannerObstacle>& obstacles,
                    double ego_v_mps, double now_s);

 private:
  // The first section not yet left behind at route s, or -1.
  int Next(double ego_s_m) const;

  geometry::Path2 route_;
  std::vector<LaneChangeSection> sections_;  // by start
  LaneChangeParams params_;
  int held_ = -1;               // the section the car is held before
  double last_unsafe_s_ = 0.0;  // when it last had no gap
  int last_id_ = -1;            // the object that had none, and its gap
  double last_gap_m_ = 0.0;
};

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_LANE_CHANGE_H_
