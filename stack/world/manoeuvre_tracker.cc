#include "stack/world/manoeuvre_tracker.h"

#include <algorithm>
#include <cmath>

namespace adse::world {
namespace {

double Wrap(double a) { return std::remainder(a, 2.0 * M_PI); }

// A change of steering smaller than this needs no slowing for.
constexpr double kNegligibleSteerRad = 0.02;
// The projection is searched this far past the last one, m.
constexpr double kSearchAheadM = 3.0;

}  // namespace

ManoeuvreTracker::ManoeuvreTracker(
    const std::vector<algorithms::GearedPose>& path,
    const VehicleLimits& limits, const ManoeuvreTrackerOptions& options)
    : limits_(limits), options_(options) {
  for (size_t i = 0; i < path.size(); ++i) {
    const algorithms::GearedPose& p = path[i];
    const Eigen::Vector2d xy(p.pose.x_m, p.pose.y_m);
    const double travel = p.pose.yaw_rad + (p.reverse ? M_PI : 0.0);
    if (moves_.empty() || moves_.back().reverse != p.reverse) {
      Move move;
      move.reverse = p.reverse;
      // A move starts where the last one ended (its cusp).
      if (!moves_.empty()) {
        move.points.push_back(moves_.back().points.back());
        move.d_m.push_back(0.0);
        move.heading_rad.push_back(travel);
      }
      moves_.push_back(std::move(move));
    }
    Move& move = moves_.back();
    if (!move.points.empty() && (xy - move.points.back()).norm() < 1e-6) {
      continue;
    }
    move.d_m.push_back(move.points.empty()
                           ? 0.0
                           : move.d_m.back() +
                                 (xy - move.points.back()).norm());
    move.heading_rad.push_back(
        move.heading_rad.empty()
            ? travel
            : move.heading_rad.back() + Wrap(travel - move.heading_rad.back()));
    move.points.push_back(xy);
  }
  // A move of one point (a gear change and no way in it) is no move.
  moves_.erase(
      std::remove_if(moves_.begin(), moves_.end(),
                     [](const Move& m) { return m.points.size() < 2; }),
      moves_.end());
  for (Move& move : moves_) {
    for (size_t i = 0; i + 1 < move.points.size(); ++i) {
      move.curvature_1pm.push_back(
          (move.heading_rad[i + 1] - move.heading_rad[i]) /
          (move.d_m[i + 1] - move.d_m[i]));
    }
  }
  finished_ = moves_.empty();
}

double ManoeuvreTracker::CurvatureAt(const Move& move, double d_m) const {
  const auto it = std::upper_bound(move.d_m.begin(), move.d_m.end(), d_m);
  const size_t i =
      std::clamp<size_t>(it == move.d_m.begin() ? 0 : it - move.d_m.begin() - 1,
                         0, move.curvature_1pm.size() - 1);
  return move.curvature_1pm[i];
}

double ManoeuvreTracker::SteerFor(const Move& move,
                                  double curvature_1pm) const {
  // The direction of travel turns by gear x tan(steer) / wheelbase per
  // metre driven.
  const double gear = move.reverse ? -1.0 : 1.0;
  return std::clamp(std::atan(gear * limits_.wheelbase_m * curvature_1pm),
                    -limits_.max_steer_rad, limits_.max_steer_rad);
}

ControlCommand ManoeuvreTracker::Update(const VehicleState& ego) {
  ControlCommand hold;
  hold.accel_mps2 = -limits_.max_decel_mps2;
  hold.steer_rad = ego.steer_rad;
  if (finished_) {
    hold.reverse = !moves_.empty() && moves_.back().reverse;
    return hold;
  }
  const Move& move = moves_[current_];
  hold.reverse = move.reverse;
  const double speed = std::abs(ego.v_mps);
  const bool standing = speed < options_.standstill_mps;
  const Eigen::Vector2d pos(ego.x_m, ego.y_m);

  // Where the car is along the move: the nearest interval from the last
  // one on; past the move's end the last interval extends.
  const size_t last = move.points.size() - 2;
  const size_t from = index_;
  double best = INFINITY, d = 0.0, lateral = 0.0, heading = 0.0;
  for (size_t i = from; i <= last; ++i) {
    if (move.d_m[i] > move.d_m[from] + kSearchAheadM) break;
    const Eigen::Vector2d a = move.points[i];
    const Eigen::Vector2d ab = move.points[i + 1] - a;
    const double len = ab.norm();
    double t = (pos - a).dot(ab) / (len * len);
    t = i == last ? std::max(0.0, t) : std::clamp(t, 0.0, 1.0);
    const Eigen::Vector2d closest = a + t * ab;
    const double dist = (pos - closest).norm();
    if (dist < best) {
      best = dist;
      index_ = i;
      d = move.d_m[i] + t * len;
      const Eigen::Vector2d u = ab / len;
      lateral = u.x() * (pos.y() - a.y()) - u.y() * (pos.x() - a.x());
      heading =
          move.heading_rad[i] +
          std::min(t, 1.0) * (move.heading_rad[i + 1] - move.heading_rad[i]);
    }
  }
  const double remaining = move.d_m.back() - d;

  // Arrived at the move's end: on to the next, or done.
  if (remaining <= options_.arrive_tolerance_m) {
    if (!standing) return hold;
    if (current_ + 1 == moves_.size()) {
      finished_ = true;
      return hold;
    }
    ++current_;
    index_ = 0;
    return Update(ego);
  }
  // Standing at a move's start: the wheels first.
  if (standing && d < options_.arrive_tolerance_m) {
    const double first = SteerFor(move, move.curvature_1pm.front());
    if (std::abs(ego.steer_rad - first) > options_.steer_settle_rad) {
      hold.steer_rad = first;
      return hold;
    }
  }

  ControlCommand command;
  command.reverse = move.reverse;
  const double travel = ego.yaw_rad + (move.reverse ? M_PI : 0.0);
  const double heading_error = Wrap(travel - heading);
  const double curvature = CurvatureAt(move, d + speed * options_.preview_s) -
                           options_.lateral_gain_1pm2 * lateral -
                           options_.heading_gain_1pm * heading_error;
  command.steer_rad = SteerFor(move, curvature);

  // Speed: the cruise speed, slow enough for the wheels to follow the
  // changes of curvature ahead, and a stop at the move's end.
  double v_target =
      move.reverse ? options_.reverse_speed_mps : options_.forward_speed_mps;
  for (size_t i = index_; i <= last; ++i) {
    const double ahead = move.d_m[i] - d;
    if (ahead > options_.lookahead_m) break;
    const double change =
        std::abs(SteerFor(move, move.curvature_1pm[i]) - ego.steer_rad);
    if (change > kNegligibleSteerRad) {
      v_target =
          std::min(v_target, std::max(options_.crawl_speed_mps,
                                      limits_.max_steer_rate_rad_per_s *
                                          std::max(0.0, ahead) / change));
    }
  }
  v_target =
      std::min(v_target, std::sqrt(2 * options_.stop_decel_mps2 * remaining));
  double accel = options_.speed_gain_per_s * (v_target - speed);
  // Near the end, brake exactly as much as stopping on it needs.
  const double stop_decel = speed * speed / (2 * remaining);
  if (stop_decel > 0.8 * options_.stop_decel_mps2) {
    accel = std::min(accel, -stop_decel);
  }
  command.accel_mps2 =
      std::clamp(accel, -limits_.max_decel_mps2, limits_.max_accel_mps2);
  return command;
}

}  // namespace adse::world
