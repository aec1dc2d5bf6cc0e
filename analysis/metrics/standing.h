// Why the car stood: each stretch of time the ego stood still, attributed
// to the planner's stop reason that held it (/planning/stop_reasons), from
// the run file alone.
#ifndef ADSE_ANALYSIS_METRICS_STANDING_H_
#define ADSE_ANALYSIS_METRICS_STANDING_H_

#include <vector>

#include "analysis/runfile/run_data.h"
#include "stack/algorithms/stop_reason.h"

namespace adse::analysis {

struct StandingOptions {
  double standing_speed_mps = 0.1;  // the ego stands below this speed
  // The planner's newest stop reason older than this: no fresh trajectory
  // holds the car (the planner is not publishing), whatever it last said.
  double stale_after_s = 1.0;
  // A stop farther ahead than this does not hold a car standing now: the
  // plan lets it move, so something outside the planner holds it.
  double hold_distance_m = 2.0;
};

// The time the car stood for one reason.
struct StandingTime {
  StopReason reason = StopReason::kNone;
  double standing_s = 0.0;
  // kObstacle: the track that held the car longest, its nearest gap (front
  // bumper to its near edge; negative when the object is beside the car)
  // and whether the map has structure there.
  int track_id = -1;
  double obstacle_gap_m = -1;
  bool static_structure = false;
};

struct StandingSummary {
  // False when the run file has no stop reasons (written before they were
  // recorded): the time stood is known, its reasons are not.
  bool has_reasons = false;
  double standing_s = 0.0;              // all the time the ego stood
  std::vector<StandingTime> by_reason;  // longest first; empty: never stood
};

// Attributes every ego sample below standing_speed_mps (each covering the
// time to the next sample) to the newest stop reason published at or
// before it: kNoTrajectory when there is none or it is stale, kNone when
// the plan does not stop within hold_distance_m (the car stood for a cause
// outside the planner: stale commands at the command gate, a speed cap).
StandingSummary SummarizeStanding(const runfile::RunData& run,
                                  const StandingOptions& options = {});

}  // namespace adse::analysis

#endif  // ADSE_ANALYSIS_METRICS_STANDING_H_
