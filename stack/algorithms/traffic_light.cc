#include "stack/algorithms/traffic_light.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace adse::algorithms {
namespace {

// Observations of one signal whose lines land farther apart than this are
// of another stop line (one controller may serve consecutive junctions).
constexpr double kSameLineM = 5.0;

}  // namespace

void TrafficLightPlanner::Observe(const SignalObservation& observation) {
  latest_ = observation;
  pending_ = true;
}

void TrafficLightPlanner::NewSignal(const std::string& tls_id,
                                    double line_s_m) {
  tls_id_ = tls_id;
  line_s_m_ = line_s_m;
  pass_yellow_ = false;
  stop_yellow_ = false;
  waited_out_ = false;
  red_waited_out_ = false;
  standing_since_s_ = -1.0;
}

SignalStop TrafficLightPlanner::Apply(double now_s, double stamp_s,
                                      double ego_v_mps,
                                      std::vector<PlannedPoint>* points,
                                      bool ends_for_turn) {
  SignalStop out;
  if (points == nullptr || points->empty()) return out;
  std::vector<PlannedPoint>& pts = *points;
  out.work_units = static_cast<int64_t>(pts.size());
  const double s0 = pts.front().s_m;
  if (pending_) {
    pending_ = false;
    if (latest_->tls_id.empty() || latest_->stop_line_distance_m < 0) {
      line_known_ = false;  // nothing in the detector's range
    } else {
      // The detector measured from where the car was at its stamp; the
      // car has moved on since at about its present speed.
      const double line_s = s0 - ego_v_mps * (stamp_s - latest_->stamp_s) +
                            latest_->stop_line_distance_m;
      if (!line_known_ || latest_->tls_id != tls_id_ ||
          std::abs(line_s - line_s_m_) > kSameLineM) {
        NewSignal(latest_->tls_id, line_s);
      } else {
        line_s_m_ = line_s;
      }
      line_known_ = true;
    }
  }
  if (!line_known_) return out;
  // Past the line: in the junction, the signal no longer applies.
  if (s0 + params_.ego_front_m > line_s_m_ + params_.passed_line_m) {
    return out;
  }
  const bool fresh = now_s - latest_->stamp_s <= params_.state_timeout_s;
  const SignalState state = fresh ? latest_->state : SignalState::kUnknown;
  out.state = state;
  out.tls_id = tls_id_;
  double stop_s = line_s_m_ - params_.stop_margin_m - params_.ego_front_m;
  if (ends_for_turn &&
      line_s_m_ - pts.back().s_m <= params_.turn_line_reach_m) {
    stop_s = std::min(stop_s, pts.back().s_m);
  }
  const double to_stop_m = stop_s - s0;
  const double v = std::abs(ego_v_mps);
  if (v < params_.standing_speed_mps && to_stop_m < params_.at_line_m) {
    if (standing_since_s_ < 0) standing_since_s_ = now_s;
  } else {
    standing_since_s_ = -1.0;
  }
  const double stood_s =
      standing_since_s_ < 0 ? 0.0 : now_s - standing_since_s_;
  bool stop = false;
  switch (state) {
    case SignalState::kGreen:
      stop_yellow_ = false;
      waited_out_ = false;
      break;
    case SignalState::kYellow:
      if (!pass_yellow_ && !stop_yellow_) {
        // Stop only where a comfortable deceleration suffices; else go on
        // and keep going when it turns red (stopping in the junction
        // would be worse).
        double need_mps2 = std::numeric_limits<double>::infinity();
        if (v < params_.standing_speed_mps) {
          need_mps2 = 0.0;
        } else if (to_stop_m > 0) {
          need_mps2 = v * v / (2.0 * to_stop_m);
        }
        if (need_mps2 <= params_.max_decel_mps2) {
          stop_yellow_ = true;
        } else {
          pass_yellow_ = true;
        }
      }
      stop = stop_yellow_;
      break;
    case SignalState::kRed:
      if (stood_s >= params_.max_red_wait_s) red_waited_out_ = true;
      stop = !pass_yellow_ && !red_waited_out_;
      break;
    case SignalState::kUnknown:
      if (stood_s >= params_.unknown_wait_s) waited_out_ = true;
      stop = !pass_yellow_ && !waited_out_;
      break;
  }
  if (!stop || stop_s > pts.back().s_m) return out;
  InsertStopAt(&pts, stop_s);
  out.stop = true;
  out.stop_s_m = stop_s;
  return out;
}

}  // namespace adse::algorithms
