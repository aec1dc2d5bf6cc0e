// Why the car stood: each stretch of time the ego stood still, attributed
// to the planner's stop reason that held it (/planning/stop_reasons), from
// the run file alone.
#ifndef ADSE_ANALYSIS_METRICS_STANDING_H_
#define ADSE_ANALYSIS_METRICS_STANDING_H_

#include <limits>
#include <map>
#include <utility>
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
  // StallWatch: a stand ends once the car has moved this far since it
  // began; creeping a few centimetres behind a standing car (a blip over
  // standing_speed_mps) does not start the count again.
  double stand_break_m = 1.0;
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

// One stretch of time the car stood without a break.
struct Stand {
  double start_s = 0.0;
  double standing_s = 0.0;
  double x_m = 0.0;  // where it stood (world)
  double y_m = 0.0;
  // False when the run file has no stop reasons: `cause` is then empty.
  bool known = false;
  // The reason that held the car longest in this stretch, with its share
  // of the stretch's time.
  StandingTime cause;
};

// Every stretch the ego stood at least min_standing_s, in time order, each
// attributed as SummarizeStanding attributes its samples.
std::vector<Stand> ListStands(const runfile::RunData& run,
                              double min_standing_s,
                              const StandingOptions& options = {});

// What holds a car standing at `t_s`, given the planner's newest stop
// sample published at or before then (nullptr: none yet), as
// SummarizeStanding attributes it.
StopReason HoldingReason(const runfile::StopSample* newest, double t_s,
                         const StandingOptions& options = {});

// Whether other traffic or a signal will let the car go by itself: a red
// light (whose wait the planner bounds with max_red_wait_s), a lane change
// waiting for a gap, or an obstacle where the map has no structure
// (another road user, which moves on).
bool TrafficWillRelease(StopReason reason, const runfile::StopSample* newest);

// Time stood, by the reason that held the car (and for the reasons that
// name a track, StopReasonNamesTrack, by track): the one attribution of
// SummarizeStanding, ListStands and StallWatch.
class ReasonTally {
 public:
  // `newest`: the stop sample behind `reason` (its track, for reasons that
  // name one).
  void Add(StopReason reason, const runfile::StopSample* newest, double dt);
  // Longest first, ties in code order; for reasons that name a track the
  // one that held the car longest (the lowest id on a tie).
  std::vector<StandingTime> ByReason() const;

 private:
  struct TrackTime {
    double standing_s = 0.0;
    // Gaps are negative for an object beside the car (its near edge
    // behind the front bumper), so no sentinel can stand for "none yet".
    double min_gap_m = std::numeric_limits<double>::infinity();
    bool static_structure = false;
  };
  std::map<StopReason, double> per_reason_;
  std::map<std::pair<StopReason, int>, TrackTime> per_track_;  // by track
};

// Watches a run as it is simulated for a car that stands and will not
// move again. It stalls when it has stood without a break for
// `stall_timeout_s`, counting only time held for reasons that traffic does
// not release (localization lost, no trajectory, static structure taken
// for an obstacle, the goal's stop short of the goal, a cause outside the
// planner such as stale commands); or, when `traffic_stall_timeout_s` > 0,
// once other road users have held it that long within one stand (one that
// never moves on: a broken-down car, a jam). Red lights pause both counts
// (the planner bounds their wait itself). Any movement starts them again.
class StallWatch {
 public:
  // A timeout <= 0: never stalls for that cause.
  explicit StallWatch(double stall_timeout_s,
                      double traffic_stall_timeout_s = 0.0,
                      StandingOptions options = {});

  // Takes the ego at `t_s` (samples in time order) with every stop sample
  // published so far; true once the car has stalled.
  bool Observe(double t_s, double v_mps,
               const std::vector<runfile::StopSample>& stops);

  // While stalled: the reason that held the car longest in the stand, and
  // for kObstacle the track.
  StopReason reason() const { return cause_.reason; }
  int track_id() const { return cause_.track_id; }
  // Whether it stalled behind other road users (traffic_stall_timeout_s).
  bool held_by_traffic() const { return held_by_traffic_; }
  // Counted time of the current stand: held by causes traffic does not
  // release, or by road users when it stalled behind them.
  double stood_s() const { return stood_s_; }

 private:
  double stall_timeout_s_;
  double traffic_stall_timeout_s_;
  StandingOptions options_;
  size_t next_ = 0;       // first stop sample after the last observation
  double last_t_s_ = -1;  // the last observation; < 0 before the first
  double stood_s_ = 0.0;
  double traffic_s_ = 0.0;  // held by road users in the current stand
  bool in_stand_ = false;
  double crept_m_ = 0.0;  // moved since the current stand began
  ReasonTally stand_;     // the counted time of the current stand
  ReasonTally traffic_;   // the time road users held it in this stand
  StandingTime cause_;
  bool held_by_traffic_ = false;
};

}  // namespace adse::analysis

#endif  // ADSE_ANALYSIS_METRICS_STANDING_H_
