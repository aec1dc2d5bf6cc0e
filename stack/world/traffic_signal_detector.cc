#include "stack/world/traffic_signal_detector.h"

#include <algorithm>

#include "stack/algorithms/planning.h"
#include "stack/world/world.h"

namespace adse::world {
namespace {

// The ego's projection searches this window around its last one (routes
// may pass close to themselves), or the whole route when it is farther
// than kReacquireM from the window's nearest point.
constexpr double kBackM = 2.0;
constexpr double kAheadM = 20.0;
constexpr double kReacquireM = 5.0;
// Reports due within this of a deadline count as before it.
constexpr double kTimeEpsS = 1e-9;

}  // namespace

SignalState SignalStateOfLetter(char letter) {
  switch (letter) {
    case 'G':
    case 'g':
      return SignalState::kGreen;
    case 'y':
    case 'Y':
      return SignalState::kYellow;
    case 'r':
    case 'R':
    case 'u':
      return SignalState::kRed;
    default:
      return SignalState::kUnknown;
  }
}

TrafficSignalDetector::TrafficSignalDetector(
    const geometry::Path2& route, const std::vector<RouteSignal>& signals,
    const TrafficSignalDetectorParams& params)
    : route_(route), params_(params) {
  for (const RouteSignal& s : signals)
    signals_.push_back({s.tls_id, s.stop_line_s_m});
}

void TrafficSignalDetector::Look(const Eigen::Vector2d& rear_axle,
                                 const std::string& letters) {
  const double t = next_look_s_;
  ++looks_;
  next_look_s_ = static_cast<double>(looks_) / params_.rate_hz;
  double lateral = 0.0, distance = 0.0;
  if (route_.points.size() >= 2) {
    double s = has_progress_
                   ? algorithms::ProjectOnPath(
                         route_, rear_axle, ego_s_m_ - kBackM,
                         ego_s_m_ + kAheadM, ego_s_m_, &lateral, &distance)
                   : 0.0;
    if (!has_progress_ || distance > kReacquireM) {
      s = algorithms::ProjectOnPath(route_, rear_axle, 0.0, route_.length_m(),
                                    has_progress_ ? ego_s_m_ : 0.0, &lateral,
                                    &distance);
    }
    ego_s_m_ = s;
    has_progress_ = true;
  }
  SignalReport report;
  report.stamp_s = t;
  report.publish_s = t + params_.latency_s;
  const int i = NextSignalAhead(signals_, ego_s_m_);
  if (i >= 0) {
    const double ahead_m = signals_[i].stop_line_s_m - ego_s_m_;
    if (ahead_m <= params_.range_m) {
      report.state = SignalStateOfLetter(
          i < static_cast<int>(letters.size()) ? letters[i] : 'o');
      report.stop_line_distance_m = ahead_m;
      report.tls_id = signals_[i].tls_id;
    }
  }
  pending_.push_back(std::move(report));
}

std::vector<SignalReport> TrafficSignalDetector::TakeDue(double t_s) {
  std::vector<SignalReport> due;
  while (!pending_.empty() && pending_.front().publish_s < t_s - kTimeEpsS) {
    due.push_back(std::move(pending_.front()));
    pending_.pop_front();
  }
  return due;
}

}  // namespace adse::world
