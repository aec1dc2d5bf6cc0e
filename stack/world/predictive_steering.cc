#include "stack/world/predictive_steering.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "stack/algorithms/planning.h"

namespace adse::world {
namespace {

// A squared distance that grows with its fourth power past `bound_m`, so
// a rollout spreads a corner's unavoidable error to both sides of the
// path rather than cutting the corner by all of it.
double Penalty(double d, double bound_m) {
  const double d2 = d * d;
  return d2 + d2 * d2 / (bound_m * bound_m);
}

// Curvature of the path around arc length s, from the heading change over
// 4 m (robust to polylines whose vertices carry all the turning).
double SignedCurvatureAt(const geometry::Path2& path, double s) {
  const double ds = 2.0;
  const double dh = path.HeadingAt(std::min(s + ds, path.length_m())) -
                    path.HeadingAt(std::max(s - ds, 0.0));
  return std::atan2(std::sin(dh), std::cos(dh)) / (2 * ds);
}
double CurvatureAt(const geometry::Path2& path, double s) {
  return std::abs(SignedCurvatureAt(path, s));
}

struct Rollout {
  double first_target_rad;   // held for the first third
  double second_target_rad;  // held after
};

// How far a rollout strays from the path: its worst distance (squared,
// weighted), the mean penalised distance over its steps, and the
// penalised distance and heading error's chord at its end; plus the cost
// of moving the target from the wheels' angle.
double Cost(const geometry::Path2& path, const SpeedProfile& speed, double s0,
            const VehicleState& ego, const VehicleLimits& limits,
            const PredictiveSteeringOptions& options, double dt_s,
            const Rollout& r) {
  double x = ego.x_m, y = ego.y_m, yaw = ego.yaw_rad, steer = ego.steer_rad;
  double v_mps = std::max(std::abs(ego.v_mps), options.min_speed_mps);
  double s = s0;
  double sum = 0.0, d = 0.0, worst = 0.0;
  int n = 0;
  const double max_step = limits.max_steer_rate_rad_per_s * dt_s;
  const int switch_step = options.steps / 3;
  for (int k = 0; k < options.steps; ++k) {
    const double v_next =
        v_mps +
        dt_s * std::clamp(options.speed_gain_per_s * (speed.At(s) - v_mps),
                          -limits.max_decel_mps2, limits.max_accel_mps2);
    const double v_mid =
        std::max(0.5 * (v_mps + v_next), options.min_speed_mps);
    v_mps = v_next;
    const double target =
        k < switch_step ? r.first_target_rad : r.second_target_rad;
    steer += std::clamp(target - steer, -max_step, max_step);
    const double yaw_rate = v_mid * std::tan(steer) / limits.wheelbase_m;
    const double yaw_mid = yaw + 0.5 * dt_s * yaw_rate;
    x += dt_s * v_mid * std::cos(yaw_mid);
    y += dt_s * v_mid * std::sin(yaw_mid);
    yaw += dt_s * yaw_rate;
    // Near the last projection: the rollout stays on its own pass.
    d = path.DistanceTo(Eigen::Vector2d(x, y), s - 0.5, s + v_mid * dt_s + 1.0,
                        &s);
    sum += Penalty(d, options.soft_bound_m);
    worst = std::max(worst, d);
    ++n;
    // Past the path's end the car stops; what it would do there is moot.
    if (s >= path.length_m() - 1e-6) break;
  }
  const double heading_error =
      std::remainder(yaw - path.HeadingAt(s), 2.0 * M_PI);
  // The chord of the heading error: grows up to a car facing backwards
  // (sin would be 0 there, and a rollout looping the wrong way round
  // looked as good as one along the path).
  const double lever =
      2.0 * options.heading_lever_m * std::sin(0.5 * heading_error);
  const double change = r.first_target_rad - ego.steer_rad;
  return options.worst_weight * worst * worst + sum / n +
         Penalty(d, options.soft_bound_m) + lever * lever +
         options.steer_change_weight_m2 * change * change;
}

}  // namespace

double SpeedProfile::At(double s_m) const {
  if (v_mps.empty()) return 0.0;
  const double i =
      std::clamp(s_m / spacing_m, 0.0, static_cast<double>(v_mps.size() - 1));
  return v_mps[static_cast<size_t>(i)];
}

SpeedProfile CurveSpeedProfile(const geometry::Path2& path,
                               double speed_limit_mps,
                               double max_lateral_accel_mps2,
                               double comfort_decel_mps2) {
  SpeedProfile profile;
  const size_t n =
      static_cast<size_t>(std::ceil(path.length_m() / profile.spacing_m)) + 1;
  profile.v_mps.resize(n, speed_limit_mps);
  for (size_t i = 0; i < n; ++i) {
    const double k = CurvatureAt(path, i * profile.spacing_m);
    if (k > 1e-4) {
      profile.v_mps[i] =
          std::min(speed_limit_mps, std::sqrt(max_lateral_accel_mps2 / k));
    }
  }
  // Slow down in time for what comes: a backward pass.
  for (size_t i = n - 1; i-- > 0;) {
    profile.v_mps[i] =
        std::min(profile.v_mps[i],
                 std::sqrt(profile.v_mps[i + 1] * profile.v_mps[i + 1] +
                           2.0 * comfort_decel_mps2 * profile.spacing_m));
  }
  return profile;
}

double PredictiveSteer(const geometry::Path2& path, const SpeedProfile& speed,
                       double s_progress_m, const VehicleState& ego,
                       const VehicleLimits& limits,
                       const PredictiveSteeringOptions& options) {
  if (path.points.size() < 2 || options.steps < 1) return 0.0;
  const double v = std::max(std::abs(ego.v_mps), options.min_speed_mps);
  const double horizon_s =
      std::max(options.horizon_time_s, options.horizon_m / v);
  const double dt = horizon_s / options.steps;
  const double max_steer = limits.max_steer_rad;
  const int n = std::max(options.steer_values, 2);
  std::vector<double> targets;
  for (int i = 0; i < n; ++i)
    targets.push_back(-max_steer + 2.0 * max_steer * i / (n - 1));
  targets.push_back(std::clamp(ego.steer_rad, -max_steer, max_steer));

  Rollout best{ego.steer_rad, ego.steer_rad};
  double best_cost = std::numeric_limits<double>::infinity();
  auto consider = [&](const Rollout& r) {
    const double c =
        Cost(path, speed, s_progress_m, ego, limits, options, dt, r);
    if (c < best_cost) {
      best_cost = c;
      best = r;
    }
  };
  for (double first : targets)
    for (double second : targets) consider({first, second});
  // The grid is coarse (0.1 rad, a lateral acceleration of 4 m/s^2 at
  // 10 m/s); each target is refined about the best by golden-section
  // search, the one commanded now last.
  const double spacing = 2.0 * max_steer / (n - 1);
  auto refine = [&](double Rollout::*target) {
    const double kInvPhi = 0.5 * (std::sqrt(5.0) - 1.0);
    double lo = std::max(best.*target - spacing, -max_steer);
    double hi = std::min(best.*target + spacing, max_steer);
    auto cost_at = [&](double value) {
      Rollout r = best;
      r.*target = value;
      return Cost(path, speed, s_progress_m, ego, limits, options, dt, r);
    };
    double a = hi - kInvPhi * (hi - lo), b = lo + kInvPhi * (hi - lo);
    double fa = cost_at(a), fb = cost_at(b);
    for (int i = 0; i < 12; ++i) {
      if (fa < fb) {
        hi = b, b = a, fb = fa;
        a = hi - kInvPhi * (hi - lo), fa = cost_at(a);
      } else {
        lo = a, a = b, fa = fb;
        b = lo + kInvPhi * (hi - lo), fb = cost_at(b);
      }
    }
    Rollout r = best;
    r.*target = fa < fb ? a : b;
    consider(r);
  };
  refine(&Rollout::second_target_rad);
  refine(&Rollout::first_target_rad);
  return best.first_target_rad;
}

std::vector<RehearsalSample> RehearseFollowing(
    const geometry::Path2& path, const SpeedProfile& speed, double s0_m,
    double s1_m, double start_v_mps, const VehicleLimits& limits,
    const PredictiveSteeringOptions& options, double dt_s) {
  std::vector<RehearsalSample> samples;
  if (path.points.size() < 2 || dt_s <= 0.0) return samples;
  s0_m = std::clamp(s0_m, 0.0, path.length_m());
  s1_m = std::clamp(s1_m, s0_m, path.length_m());
  BicycleModel car(limits);
  VehicleState start;
  const Eigen::Vector2d p0 = path.PointAt(s0_m);
  start.x_m = p0.x();
  start.y_m = p0.y();
  start.yaw_rad = path.HeadingAt(s0_m);
  start.v_mps = start_v_mps;
  start.steer_rad =
      std::clamp(std::atan(limits.wheelbase_m * SignedCurvatureAt(path, s0_m)),
                 -limits.max_steer_rad, limits.max_steer_rad);
  car.Reset(start);
  // Progress as the world measures it (World::road_progress_m).
  const algorithms::PathPlannerParams window;
  double s = s0_m;
  // A car that falls behind a crawl (it never should) ends the rehearsal.
  const int max_steps = static_cast<int>(std::ceil(
                            (s1_m - s0_m) / (options.min_speed_mps * dt_s))) +
                        static_cast<int>(std::ceil(10.0 / dt_s));
  for (int k = 0; k < max_steps && s < s1_m; ++k) {
    const VehicleState& ego = car.state();
    ControlCommand command;
    command.steer_rad = PredictiveSteer(path, speed, s, ego, limits, options);
    command.accel_mps2 =
        std::clamp(options.speed_gain_per_s * (speed.At(s) - ego.v_mps),
                   -limits.max_decel_mps2, limits.max_accel_mps2);
    car.Step(command, dt_s);
    double lateral = 0.0, d = 0.0;
    s = std::max(s, algorithms::ProjectOnPath(
                        path, Eigen::Vector2d(car.state().x_m, car.state().y_m),
                        s - window.projection_back_m,
                        s + window.projection_ahead_m, s, &lateral, &d));
    samples.push_back({s, d});
  }
  return samples;
}

}  // namespace adse::world
