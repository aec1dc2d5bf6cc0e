#include "stack/algorithms/parking_control.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace adse::algorithms {

ParkingFollower::ParkingFollower(const ParkingFollowerParams& params)
    : params_(params), pid_(params.pid) {}

double DistanceFromPath(const std::vector<GearedPose>& poses,
                        const Eigen::Vector2d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < poses.size(); ++i) {
    const Eigen::Vector2d a(poses[i].pose.x_m, poses[i].pose.y_m);
    const Eigen::Vector2d b =
        i + 1 < poses.size()
            ? Eigen::Vector2d(poses[i + 1].pose.x_m, poses[i + 1].pose.y_m)
            : a;
    best = std::min(best, geometry::DistanceToSegment(p, a, b));
  }
  return best;
}

void ParkingFollower::SetPath(const std::vector<GearedPose>& poses) {
  path_ = poses;
  segments_.clear();
  current_ = 0;
  finished_ = false;
  last_index_ = 0;
  settling_ = true;
  pid_.Reset();
  for (size_t i = 0; i < poses.size(); ++i) {
    const Eigen::Vector2d p(poses[i].pose.x_m, poses[i].pose.y_m);
    // A pose whose gear differs from the one before starts a new segment,
    // which begins at the cusp (the previous pose).
    if (segments_.empty() || poses[i].reverse != segments_.back().reverse) {
      Segment seg;
      seg.reverse = poses[i].reverse;
      if (i > 0) {
        seg.points.emplace_back(poses[i - 1].pose.x_m, poses[i - 1].pose.y_m);
      }
      segments_.push_back(std::move(seg));
    }
    Segment& seg = segments_.back();
    if (seg.points.empty() || (p - seg.points.back()).norm() > 1e-6) {
      seg.points.push_back(p);
    }
  }
  for (Segment& seg : segments_) {
    seg.s_m.assign(1, 0.0);
    for (size_t i = 1; i < seg.points.size(); ++i) {
      seg.s_m.push_back(seg.s_m.back() +
                        (seg.points[i] - seg.points[i - 1]).norm());
    }
    if (seg.points.size() >= 2) {
      seg.end_direction =
          (seg.points.back() - seg.points[seg.points.size() - 2]).normalized();
    }
  }
  // A segment of a single point (a path of one pose) has nothing to drive.
  segments_.erase(
      std::remove_if(segments_.begin(), segments_.end(),
                     [](const Segment& s) { return s.points.size() < 2; }),
      segments_.end());
}

double ParkingFollower::Project(const Segment& seg, const Eigen::Vector2d& p,
                                double* lateral_m) {
  double best_d = std::numeric_limits<double>::infinity();
  double best_s = 0.0;
  size_t best_i = last_index_;
  for (size_t i = last_index_; i + 1 < seg.points.size(); ++i) {
    const Eigen::Vector2d a = seg.points[i];
    const Eigen::Vector2d ab = seg.points[i + 1] - a;
    const double len2 = ab.squaredNorm();
    const double t =
        len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    const double d = (a + t * ab - p).norm();
    if (d < best_d) {
      best_d = d;
      best_i = i;
      best_s = seg.s_m[i] + t * std::sqrt(len2);
      const double cross = ab.x() * (p - a).y() - ab.y() * (p - a).x();
      *lateral_m = std::sqrt(len2) > 0 ? cross / std::sqrt(len2) : 0.0;
    }
    // The nearest stretch is behind us once distances grow well past it.
    if (d > best_d + 2.0 * params_.lookahead_m) break;
  }
  last_index_ = best_i;
  return best_s;
}

Eigen::Vector2d ParkingFollower::PointAt(const Segment& seg, double s) const {
  if (s >= seg.s_m.back()) {
    return seg.points.back() + seg.end_direction * (s - seg.s_m.back());
  }
  const size_t i =
      std::upper_bound(seg.s_m.begin(), seg.s_m.end(), s) - seg.s_m.begin();
  const size_t k = std::clamp<size_t>(i, 1, seg.points.size() - 1);
  const double len = seg.s_m[k] - seg.s_m[k - 1];
  const double t = len > 0 ? (s - seg.s_m[k - 1]) / len : 0.0;
  return seg.points[k - 1] + t * (seg.points[k] - seg.points[k - 1]);
}

ParkingCommand ParkingFollower::Update(const geometry::Pose2& pose,
                                       double v_mps, double dt_s,
                                       double speed_cap_mps) {
  const ParkingFollowerParams& p = params_;
  ParkingCommand out;
  if (segments_.empty() || finished_) {
    out.accel_mps2 = -p.stop_decel_mps2;
    out.finished = true;
    if (!segments_.empty()) {
      out.segment = current_;
      out.reverse = segments_[current_].reverse;
    }
    return out;
  }
  const Eigen::Vector2d pos(pose.x_m, pose.y_m);
  if (p.course_out_m > 0 && DistanceFromPath(path_, pos) > p.course_out_m) {
    // Off course: stop where it is and wait for a path from here.
    out.course_out = true;
    out.segment = current_;
    out.reverse = segments_[current_].reverse;
    const bool standing = std::abs(v_mps) < p.standstill_mps;
    out.accel_mps2 = standing ? -p.stop_decel_mps2 : -p.max_brake_mps2;
    pid_.Reset();
    return out;
  }
  double s = 0.0, remaining = 0.0, lateral = 0.0;
  for (;;) {
    const Segment& seg = segments_[current_];
    s = Project(seg, pos, &lateral);
    remaining = seg.s_m.back() - s;
    // Past the end: how far, along the direction of travel there.
    const double beyond = (pos - seg.points.back()).dot(seg.end_direction);
    if (beyond > 0) remaining = -beyond;
    const bool at_end = remaining <= p.arrive_tolerance_m;
    const bool standing = std::abs(v_mps) < p.standstill_mps;
    if (at_end && standing && current_ + 1 < segments()) {
      // Shift at the cusp and drive the next segment.
      ++current_;
      last_index_ = 0;
      settling_ = true;
      pid_.Reset();
      continue;
    }
    out.finished = at_end && standing && current_ + 1 == segments();
    finished_ = out.finished;
    break;
  }
  const Segment& seg = segments_[current_];
  out.segment = current_;
  out.reverse = seg.reverse;
  out.remaining_m = remaining;
  out.lateral_error_m = lateral;

  // Speed: cruise, then brake to stop at the segment's end with the
  // deceleration that stopping there takes (the car's lag would overshoot
  // a speed profile tracked by the PID alone).
  const double cruise =
      std::min(seg.reverse ? p.reverse_speed_mps : p.forward_speed_mps,
               std::max(speed_cap_mps, 0.0));
  const double speed_along = seg.reverse ? -v_mps : v_mps;
  const double to_stop = std::max(0.0, remaining - 0.5 * p.arrive_tolerance_m);
  const double needed = speed_along > 0 ? speed_along * speed_along /
                                              (2.0 * std::max(to_stop, 0.01))
                                        : 0.0;
  if (remaining <= p.arrive_tolerance_m || speed_along < -p.standstill_mps) {
    // At the end, or still rolling the other way after a shift: brake.
    out.target_speed_mps = 0.0;
    out.accel_mps2 = -std::clamp(needed, p.stop_decel_mps2, p.max_brake_mps2);
    pid_.Reset();
  } else if (needed >= p.stop_decel_mps2) {
    out.target_speed_mps = std::sqrt(2.0 * p.stop_decel_mps2 * to_stop);
    out.accel_mps2 = -std::min(needed, p.max_brake_mps2);
    pid_.Reset();
  } else {
    out.target_speed_mps =
        std::min(cruise, std::sqrt(2.0 * p.stop_decel_mps2 * to_stop));
    out.accel_mps2 = pid_.Update(out.target_speed_mps - speed_along, dt_s);
  }

  // Steering: pure pursuit towards a point a lookahead ahead on the
  // segment; in reverse on the mirrored heading, with the angle negated
  // (backing up, a left wheel angle turns the heading clockwise).
  const Eigen::Vector2d target = PointAt(seg, s + p.lookahead_m);
  const double heading = pose.yaw_rad + (seg.reverse ? M_PI : 0.0);
  const Eigen::Vector2d d = target - pos;
  const double local_x = std::cos(heading) * d.x() + std::sin(heading) * d.y();
  const double local_y = -std::sin(heading) * d.x() + std::cos(heading) * d.y();
  const double dist2 = std::max(local_x * local_x + local_y * local_y, 1e-6);
  const double curvature = 2.0 * local_y / dist2;
  double steer = std::atan(p.wheelbase_m * curvature);
  if (seg.reverse) steer = -steer;
  out.steer_rad = std::clamp(steer, -p.max_steer_rad, p.max_steer_rad);

  const double turn_rad = out.steer_rad - steer_estimate_rad_;
  if (std::abs(v_mps) >= p.standstill_mps) settling_ = false;
  if (settling_ && p.steer_rate_rad_per_s > 0 &&
      std::abs(turn_rad) > p.steer_settled_rad) {
    // Standing at the segment's start: turn the wheels first.
    out.target_speed_mps = 0.0;
    out.accel_mps2 = -p.stop_decel_mps2;
    pid_.Reset();
  }
  const double step_rad = p.steer_rate_rad_per_s * dt_s;
  steer_estimate_rad_ += p.steer_rate_rad_per_s > 0
                             ? std::clamp(turn_rad, -step_rad, step_rad)
                             : turn_rad;
  return out;
}

}  // namespace adse::algorithms
