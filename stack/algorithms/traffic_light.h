// The traffic-light stage of behavior_velocity_planner: a stop at the stop
// line of the signal ahead, from what the car's detector reports
// (/perception/traffic_signal). The planner never reads the simulator: it
// knows a signal only by the detector's observations.
#ifndef ADSE_STACK_ALGORITHMS_TRAFFIC_LIGHT_H_
#define ADSE_STACK_ALGORITHMS_TRAFFIC_LIGHT_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "stack/algorithms/planning.h"
#include "stack/algorithms/signal_state.h"

namespace adse::algorithms {

// One detector observation: the signal controlling the ego's next link on
// its route, as seen at stamp_s.
struct SignalObservation {
  double stamp_s = 0.0;  // when the detector saw it
  SignalState state = SignalState::kUnknown;
  // Along the route from the ego's rear axle to the stop line at stamp_s;
  // -1 when no signal is in the detector's range.
  double stop_line_distance_m = -1.0;
  std::string tls_id;  // the signal's id; empty when none is in range
};

struct TrafficLightParams {
  double state_timeout_s = 1.0;  // an observation older than this: unknown
  // Standing at the line of a signal it cannot read for this long, the car
  // goes on (an unreadable signal never holds it forever).
  double unknown_wait_s = 5.0;
  // Standing at a red line for this long, the signal is taken as broken
  // and the car goes on: no signal blocks a run forever.
  double max_red_wait_s = 300.0;
  double stop_margin_m = 1.0;       // front bumper to stop line when stopped
  double ego_front_m = 3.8;         // rear axle to front bumper
  double max_decel_mps2 = 2.5;      // a yellow stops the car only within this
  double passed_line_m = 1.0;       // front bumper this far past: in the
                                    // junction, the signal no longer applies
  double standing_speed_mps = 0.1;  // slower than this: standing
  double at_line_m = 1.5;  // standing within this of the stop: at the line
  // A path that ends for a turn in several moves (which the car starts
  // standing) with a stop line at most this far past its end: the line is
  // the turn's own, and the car waits for it at the path's end.
  double turn_line_reach_m = 10.0;
};

struct SignalStop {
  bool stop = false;     // the signal stops the car within the path
  double stop_s_m = -1;  // where v becomes 0 (rear axle, route s)
  SignalState state = SignalState::kUnknown;  // as taken (old: unknown)
  std::string tls_id;
  int64_t work_units = 0;  // path points
};

class TrafficLightPlanner {
 public:
  explicit TrafficLightPlanner(const TrafficLightParams& params = {})
      : params_(params) {}

  // The detector's newest observation.
  void Observe(const SignalObservation& observation);

  // At now_s, for `points` (the path from the ego's rear axle on, route s,
  // planned from the pose stamped stamp_s with speed ego_v_mps): the stop
  // the signal ahead asks for, inserted into `points`. Red stops the car;
  // yellow when it can stop within max_decel_mps2 (else it commits to
  // pass, through the red that follows); unknown (an unreadable state or
  // an observation older than state_timeout_s) stops it at the line, then
  // lets it go after unknown_wait_s standing there; green, or no signal
  // in range, does not stop it. `ends_for_turn`: the path ends where the
  // car stops to turn in several moves through the junction ahead, short
  // of its line (see turn_line_reach_m).
  SignalStop Apply(double now_s, double stamp_s, double ego_v_mps,
                   std::vector<PlannedPoint>* points,
                   bool ends_for_turn = false);

 private:
  // Forgets what was decided for the previous signal.
  void NewSignal(const std::string& tls_id, double line_s_m);

  TrafficLightParams params_;
  std::optional<SignalObservation> latest_;
  bool pending_ = false;     // latest_ not yet placed on the route
  bool line_known_ = false;  // a signal ahead whose line is placed
  std::string tls_id_;
  double line_s_m_ = 0.0;         // its stop line, route s
  bool pass_yellow_ = false;      // committed to pass it on yellow
  bool stop_yellow_ = false;      // decided to stop for its yellow
  bool waited_out_ = false;       // waited out its unknown state
  bool red_waited_out_ = false;   // waited max_red_wait_s at its red
  double standing_since_s_ = -1;  // standing at its line since
};

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_TRAFFIC_LIGHT_H_
