// Why the planner holds the car: the one vocabulary the planner publishes
// (/planning/stop_reason), the run file stores and the run report counts.
// Readers compare these values, never the text.
#ifndef ADSE_STACK_ALGORITHMS_STOP_REASON_H_
#define ADSE_STACK_ALGORITHMS_STOP_REASON_H_

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace adse {

// Stored as int8 codes in run files (an HDF5 enum): never renumber a value;
// add new ones at the end. The names are in stop_reason.cc's table.
enum class StopReason : int8_t {
  kNone = 0,              // "none": the trajectory does not stop
  kGoal = 1,              // "goal": it ends at the goal
  kObstacle = 2,          // "obstacle": a tracked object in the corridor
  kLocalizationLost = 3,  // "localization_lost": no valid pose to drive by
  kNoTrajectory = 4,      // "no_trajectory": nothing to plan from (no
                          // route or pose), or no fresh plan at all
  kRedLight = 5,          // "red_light": a traffic signal's stop line (red,
                          // a yellow it can stop for, or a state it cannot
                          // read until it has waited that out)
  kLaneChange = 6,        // "lane_change": before a lane change, for a gap
                          // in the target lane
  kTurnaround = 7,        // "turnaround": where the route turns round
                          // tighter than the car can, for a turn in
                          // several moves
};

const char* StopReasonToString(StopReason reason);
// False when `name` is no stop reason; `reason` is then unchanged.
bool StringToStopReason(std::string_view name, StopReason* reason);
// Every reason's name, in code order.
std::vector<std::string> StopReasonNames();
// The stops for a tracked object (kObstacle, kLaneChange): they name the
// track and its gap.
bool StopReasonNamesTrack(StopReason reason);

}  // namespace adse

#endif  // ADSE_STACK_ALGORITHMS_STOP_REASON_H_
