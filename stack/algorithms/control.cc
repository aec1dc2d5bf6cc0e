#include "stack/algorithms/control.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace adse::algorithms {
namespace {

// Length of trajectory searched for the point nearest to the ego.
constexpr double kNearestSearchM = 30.0;

Eigen::Vector2d Xy(const PlannedPoint& p) { return {p.x_m, p.y_m}; }

// Larger root u of |a + u d - p|^2 = r^2 (the exit from the circle), or
// NaN when the line misses the circle.
double ExitParameter(const Eigen::Vector2d& a, const Eigen::Vector2d& d,
                     const Eigen::Vector2d& p, double r) {
  const double qa = d.squaredNorm();
  if (qa <= 0.0) return std::numeric_limits<double>::quiet_NaN();
  const Eigen::Vector2d f = a - p;
  const double qb = 2.0 * f.dot(d);
  const double qc = f.squaredNorm() - r * r;
  const double disc = qb * qb - 4.0 * qa * qc;
  if (disc < 0.0) return std::numeric_limits<double>::quiet_NaN();
  return (-qb + std::sqrt(disc)) / (2.0 * qa);
}

// Speed profile by arc length along the trajectory (clamped to its ends).
double SpeedAt(const std::vector<PlannedPoint>& traj, double s) {
  if (s <= traj.front().s_m) return traj.front().v_mps;
  if (s >= traj.back().s_m) return traj.back().v_mps;
  const auto it = std::upper_bound(
      traj.begin(), traj.end(), s,
      [](double value, const PlannedPoint& p) { return value < p.s_m; });
  const PlannedPoint& b = *it;
  const PlannedPoint& a = *(it - 1);
  const double ds = b.s_m - a.s_m;
  if (ds <= 0.0) return b.v_mps;
  return a.v_mps + (s - a.s_m) / ds * (b.v_mps - a.v_mps);
}

}  // namespace

PurePursuitOutput PurePursuit::Compute(
    const geometry::Pose2& pose, double v_mps,
    const std::vector<PlannedPoint>& traj) const {
  PurePursuitOutput out;
  if (traj.empty()) return out;
  out.valid = true;
  const Eigen::Vector2d p(pose.x_m, pose.y_m);

  // Nearest segment (the trajectory is short: a linear scan is cheapest).
  // Only its first part is searched: trajectories start at the ego, and
  // one that turns back (a U-turn between aisles) may pass closer later.
  Eigen::Vector2d nearest = Xy(traj.front());
  Eigen::Vector2d dir(std::cos(traj.front().yaw_rad),
                      std::sin(traj.front().yaw_rad));
  double raw_t_last = 0.0;
  if (traj.size() >= 2) {
    double best = std::numeric_limits<double>::infinity();
    double searched_m = 0.0;
    for (size_t i = 0; i + 1 < traj.size(); ++i) {
      if (searched_m > kNearestSearchM) break;
      const Eigen::Vector2d a = Xy(traj[i]);
      const Eigen::Vector2d ab = Xy(traj[i + 1]) - a;
      const double ab2 = ab.squaredNorm();
      searched_m += std::sqrt(ab2);
      const double raw_t = ab2 > 0.0 ? (p - a).dot(ab) / ab2 : 0.0;
      const double t = std::clamp(raw_t, 0.0, 1.0);
      const double d2 = (p - (a + t * ab)).squaredNorm();
      if (d2 < best) {
        best = d2;
        out.nearest_index = i;
        out.nearest_t = t;
        nearest = a + t * ab;
        if (ab2 > 0.0) dir = ab / std::sqrt(ab2);
        raw_t_last = raw_t;
      }
    }
    out.past_end = out.nearest_index + 2 == traj.size() && raw_t_last > 1.0;
  } else {
    out.past_end = (p - nearest).dot(dir) > 0.0;
  }
  const Eigen::Vector2d r = p - nearest;
  out.lateral_error_m = dir.x() * r.y() - dir.y() * r.x();

  double ld = std::clamp(params_.lookahead_gain_s * std::max(v_mps, 0.0),
                         params_.min_lookahead_m, params_.max_lookahead_m);
  // Far off the trajectory the lookahead circle would miss it: widen it.
  ld = std::max(ld, std::abs(out.lateral_error_m) + 1.0);
  out.lookahead_m = ld;

  // First exit of the lookahead circle along the trajectory ahead of the
  // nearest point; beyond its end, along the last direction (so steering
  // stays calm while stopping at the end).
  bool found = false;
  for (size_t i = out.nearest_index; i + 1 < traj.size() && !found; ++i) {
    const Eigen::Vector2d a = Xy(traj[i]);
    const Eigen::Vector2d d = Xy(traj[i + 1]) - a;
    const double u = ExitParameter(a, d, p, ld);
    const double u_min = i == out.nearest_index ? out.nearest_t : 0.0;
    if (std::isfinite(u) && u >= u_min && u <= 1.0) {
      out.target = a + u * d;
      found = true;
    }
  }
  if (!found) {
    Eigen::Vector2d end_dir(std::cos(traj.back().yaw_rad),
                            std::sin(traj.back().yaw_rad));
    if (traj.size() >= 2) {
      const Eigen::Vector2d d = Xy(traj.back()) - Xy(traj[traj.size() - 2]);
      if (d.squaredNorm() > 1e-12) end_dir = d.normalized();
    }
    const double u = ExitParameter(Xy(traj.back()), end_dir, p, ld);
    out.target =
        Xy(traj.back()) + std::max(0.0, std::isfinite(u) ? u : 0.0) * end_dir;
  }

  // Target in the vehicle frame; the arc through it tangent to the heading
  // has curvature 2 y / d^2.
  const Eigen::Vector2d delta = out.target - p;
  const double c = std::cos(pose.yaw_rad), s = std::sin(pose.yaw_rad);
  const double x_v = c * delta.x() + s * delta.y();
  const double y_v = -s * delta.x() + c * delta.y();
  const double d2 = x_v * x_v + y_v * y_v;
  out.curvature_1pm = d2 > 1e-6 ? 2.0 * y_v / d2 : 0.0;
  out.steer_rad = std::clamp(std::atan(params_.wheelbase_m * out.curvature_1pm),
                             -params_.max_steer_rad, params_.max_steer_rad);
  return out;
}

std::vector<geometry::Pose2> PurePursuit::Rollout(
    const geometry::Pose2& pose, const std::vector<PlannedPoint>& trajectory,
    double length_m, double step_m) const {
  std::vector<geometry::Pose2> out = {pose};
  if (trajectory.empty() || step_m <= 0.0) return out;
  geometry::Pose2 p = pose;
  for (double driven_m = 0.0; driven_m + step_m <= length_m + 1e-9;
       driven_m += step_m) {
    const PurePursuitOutput pp = Compute(p, 0.0, trajectory);
    if (pp.past_end) break;
    // One step along the arc the steering sets (midpoint heading).
    const double turn = step_m * std::tan(pp.steer_rad) / params_.wheelbase_m;
    const double mid = p.yaw_rad + 0.5 * turn;
    p.x_m += step_m * std::cos(mid);
    p.y_m += step_m * std::sin(mid);
    p.yaw_rad = std::remainder(p.yaw_rad + turn, 2 * std::numbers::pi);
    out.push_back(p);
  }
  return out;
}

double Pid::Update(double error, double dt_s, double feedforward) {
  const double old_integral = integral_;
  double derivative = 0.0;
  if (dt_s > 0.0) {
    integral_ = std::clamp(integral_ + error * dt_s, -params_.integral_limit_m,
                           params_.integral_limit_m);
    if (has_last_) derivative = (error - last_error_) / dt_s;
  }
  last_error_ = error;
  has_last_ = true;
  const double raw = feedforward + params_.kp * error + params_.ki * integral_ +
                     params_.kd * derivative;
  const double out =
      std::clamp(raw, -params_.max_decel_mps2, params_.max_accel_mps2);
  // Anti-windup: saturated and the error pushes further: do not integrate.
  if (out != raw && (raw > out) == (error > 0.0)) integral_ = old_integral;
  return out;
}

void Pid::Reset() {
  integral_ = 0.0;
  last_error_ = 0.0;
  has_last_ = false;
}

TrajectoryFollower::TrajectoryFollower(const FollowerParams& params)
    : params_(params), pure_pursuit_(params.pure_pursuit), pid_(params.pid) {}

void TrajectoryFollower::Reset() {
  pid_.Reset();
  last_steer_rad_ = 0.0;
}

FollowerCommand TrajectoryFollower::Update(
    const geometry::Pose2& pose, double v_mps,
    const std::vector<PlannedPoint>& trajectory, double dt_s) {
  FollowerCommand cmd;
  if (trajectory.empty()) {
    // Nothing to follow: brake, keep the wheels where they are.
    pid_.Reset();
    cmd.no_trajectory = true;
    cmd.stopping = true;
    cmd.accel_mps2 = -params_.no_trajectory_decel_mps2;
    cmd.steer_rad = last_steer_rad_;
    return cmd;
  }
  const PurePursuitOutput pp = pure_pursuit_.Compute(pose, v_mps, trajectory);
  cmd.steer_rad = pp.steer_rad;
  cmd.lateral_error_m = pp.lateral_error_m;
  cmd.lookahead_m = pp.lookahead_m;
  last_steer_rad_ = pp.steer_rad;

  // Speed target from the profile a little ahead of the projection.
  double s_near = trajectory.front().s_m;
  if (trajectory.size() >= 2) {
    const PlannedPoint& a = trajectory[pp.nearest_index];
    const PlannedPoint& b = trajectory[pp.nearest_index + 1];
    s_near = a.s_m + pp.nearest_t * (b.s_m - a.s_m);
  }
  const double preview =
      std::max(params_.speed_preview_min_m,
               params_.speed_preview_s * std::max(v_mps, 0.0));
  const double v_near = SpeedAt(trajectory, s_near);
  const double v_ahead = SpeedAt(trajectory, s_near + preview);
  cmd.target_speed_mps = v_ahead;

  // Stop when past the end, or when the profile says stop ahead and we
  // are there or already standing (e.g. a little short of the goal).
  cmd.stopping =
      pp.past_end ||
      (v_ahead <= params_.stop_speed_mps &&
       (v_near <= params_.stop_speed_mps || v_mps <= params_.stop_speed_mps));
  if (cmd.stopping) {
    // Brake at least stop_decel (holds a standing vehicle), harder when
    // still fast; no integral carried into the next start.
    pid_.Reset();
    const double p_brake = -params_.pid.kp * std::max(v_mps, 0.0);
    cmd.accel_mps2 = std::max(std::min(-params_.stop_decel_mps2, p_brake),
                              -params_.pid.max_decel_mps2);
    return cmd;
  }
  // The acceleration the profile itself asks for over the preview.
  const double feedforward = params_.feedforward_gain *
                             (v_ahead * v_ahead - v_near * v_near) /
                             (2.0 * preview);
  cmd.accel_mps2 = pid_.Update(v_ahead - v_mps, dt_s, feedforward);
  return cmd;
}

}  // namespace adse::algorithms
