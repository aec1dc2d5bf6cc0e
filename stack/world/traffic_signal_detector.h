// A simulated traffic-signal detector (a camera and its recognition, as a
// sensor of the world): every 1/rate_hz it looks along the route for the
// signal controlling the ego's next link and, latency_s later, reports its
// state, the distance to its stop line and its id, when that line lies
// within range_m. libsumo-free: the world hands it the signals' states.
#ifndef ADSE_STACK_WORLD_TRAFFIC_SIGNAL_DETECTOR_H_
#define ADSE_STACK_WORLD_TRAFFIC_SIGNAL_DETECTOR_H_

#include <Eigen/Core>
#include <deque>
#include <string>
#include <vector>

#include "stack/algorithms/signal_state.h"
#include "stack/geometry/geometry.h"

namespace adse::world {

struct RouteSignal;

struct TrafficSignalDetectorParams {
  double rate_hz = 10.0;   // looks per second, Hz
  double range_m = 100.0;  // farthest stop line it reads, along the route, m
  double latency_s = 0.1;  // from a look to its report, s
};

// One report: what the detector saw at stamp_s, published at publish_s.
struct SignalReport {
  double stamp_s = 0.0;
  double publish_s = 0.0;
  SignalState state = SignalState::kUnknown;
  // Along the route from the rear axle to the stop line; -1 when no signal
  // is in range.
  double stop_line_distance_m = -1.0;
  std::string tls_id;  // empty when no signal is in range
};

// SUMO's state letter of a link as the detector reads it: G/g green, y/Y
// yellow, r/R and u (red-yellow, not yet green) red; o/O (off, blinking)
// and s (stop, then go) unknown.
SignalState SignalStateOfLetter(char letter);

// The next signal along the route whose stop line the rear axle, at route
// s = `rear_axle_s_m`, has not passed (a car stopped with its nose over
// the line still sees it): its index in `signals` (in route order, each
// with a stop_line_s_m), or -1 when none is left.
template <typename Signal>
int NextSignalAhead(const std::vector<Signal>& signals, double rear_axle_s_m) {
  for (size_t i = 0; i < signals.size(); ++i) {
    if (signals[i].stop_line_s_m > rear_axle_s_m) return static_cast<int>(i);
  }
  return -1;
}

class TrafficSignalDetector {
 public:
  // `route`: the road path the signals' stop lines lie on (World's
  // road_path() and route_signals()).
  TrafficSignalDetector(const geometry::Path2& route,
                        const std::vector<RouteSignal>& signals,
                        const TrafficSignalDetectorParams& params);

  // When the next look is due.
  double next_look_s() const { return next_look_s_; }
  // Looks now (at next_look_s()) with the ego's rear axle at `rear_axle`
  // and the signals' state letters (World::RouteSignalStates()); the
  // report waits latency_s.
  void Look(const Eigen::Vector2d& rear_axle, const std::string& letters);
  // The reports due for publication before t_s, oldest first.
  std::vector<SignalReport> TakeDue(double t_s);

 private:
  struct Signal {
    std::string tls_id;
    double stop_line_s_m = 0.0;
  };
  geometry::Path2 route_;
  std::vector<Signal> signals_;
  TrafficSignalDetectorParams params_;
  double next_look_s_ = 0.0;
  long long looks_ = 0;   // looks so far: next_look_s_ = looks_ / rate_hz
  double ego_s_m_ = 0.0;  // the ego's progress along the route
  bool has_progress_ = false;
  std::deque<SignalReport> pending_;
};

}  // namespace adse::world

#endif  // ADSE_STACK_WORLD_TRAFFIC_SIGNAL_DETECTOR_H_
