#include "stack/world/ideal_driver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

#include "stack/algorithms/traffic_light.h"
#include "stack/world/manoeuvre_tracker.h"
#include "stack/world/predictive_steering.h"
#include "stack/world/traffic_signal_detector.h"

namespace adse::world {
namespace {

using Clock = std::chrono::steady_clock;
double Seconds(Clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

}  // namespace

Result<IdealDriveReport> DriveIdealPath(World& world, LidarSimulator* lidar,
                                        const IdealDriverOptions& options,
                                        const ScanCallback& on_scan) {
  IdealDriveReport report;
  // The road part (all of the ideal path but a valet task's manoeuvre) by
  // predictive steering; then the manoeuvre, gears and all, move by move
  // on the true pose (ManoeuvreTracker). A three-point turn on the way is
  // driven the same way from where the car stops for it.
  const geometry::Path2& path = world.road_path();
  // The speed limit, curves ahead (the stops come on top).
  const SpeedProfile speed = CurveSpeedProfile(path, options.speed_limit_mps,
                                               options.max_lateral_accel_mps2,
                                               options.comfort_decel_mps2);
  const std::vector<RouteTurnaround>& turns = world.route_turnarounds();
  size_t next_turn = 0;       // the first turn not yet driven
  geometry::Path2 turn_path;  // the turn being driven, for its error
  std::optional<ManoeuvreTracker> manoeuvre;  // while driving one
  const double dt = world.step_s();
  const VehicleLimits& limits = world.ego_limits();
  const double scan_period = lidar ? 1.0 / lidar->params().rate_hz : 0.0;
  double next_scan_t = 0.0;
  double point_sum = 0.0;
  algorithms::TrafficLightParams signal_params;
  signal_params.max_red_wait_s = options.max_red_wait_s;
  algorithms::TrafficLightPlanner signals(signal_params);
  const std::vector<RouteSignal>& route_signals = world.route_signals();
  while (world.time_s() < options.timeout_s) {
    const VehicleState& ego = world.ego();
    const Eigen::Vector2d pos(ego.x_m, ego.y_m);
    report.trajectory.push_back({world.time_s(), ego.x_m, ego.y_m, ego.yaw_rad,
                                 ego.v_mps, ego.steer_rad, ego.accel_mps2});
    const double s_progress = world.road_progress_m();
    const double off_road = world.road_offset_m();
    // Lane driving: the ideal path is the road part, already measured;
    // in a three-point turn, the turn's path.
    report.max_lateral_error_m =
        std::max(report.max_lateral_error_m,
                 world.parking_task() ? world.ideal_path().DistanceTo(pos)
                 : !turn_path.points.empty() ? turn_path.DistanceTo(pos)
                                             : off_road);
    if (world.goal_reached() && std::abs(ego.v_mps) < 0.5) {
      report.reached_goal = true;
      break;
    }
    if (lidar && options.scan && world.time_s() + 1e-9 >= next_scan_t) {
      const auto t0 = Clock::now();
      std::vector<geometry::OrientedBox> boxes;
      for (const OtherVehicle& v : world.others()) boxes.push_back(v.box);
      const geometry::Pose2 pose{ego.x_m, ego.y_m, ego.yaw_rad};
      PointCloud cloud = lidar->Scan(pose, world.time_s(), boxes);
      report.lidar_wall_s += Seconds(Clock::now() - t0);
      point_sum += static_cast<double>(cloud.points.size());
      ++report.scans;
      if (on_scan) on_scan(cloud, pose);
      next_scan_t += scan_period;
    }
    if (!manoeuvre && !world.reference_manoeuvre().empty() &&
        s_progress >= path.length_m() - 0.05 && std::abs(ego.v_mps) < 0.05) {
      manoeuvre.emplace(world.reference_manoeuvre(), limits);
    }
    // Where the car must stand: the goal, the start of a turn in several
    // moves, or a signal's stop line before it (at a turn's start, a
    // signal of the turn's junction holds the car there). Signals: a
    // perfect detector (the true state, no latency) and the stack's own
    // rule for when to stop.
    const bool to_turn = next_turn < turns.size();
    const double stop_s =
        to_turn ? turns[next_turn].start_s_m : path.length_m();
    std::optional<double> signal_stop_s;
    if (!manoeuvre && options.obey_signals && !route_signals.empty()) {
      algorithms::SignalObservation seen;
      seen.stamp_s = world.time_s();
      const int i = NextSignalAhead(route_signals, s_progress);
      if (i >= 0) {
        const std::string letters = world.RouteSignalStates();
        seen.state = SignalStateOfLetter(
            i < static_cast<int>(letters.size()) ? letters[i] : 'o');
        seen.stop_line_distance_m = route_signals[i].stop_line_s_m - s_progress;
        seen.tls_id = route_signals[i].tls_id;
      }
      signals.Observe(seen);
      // The planner needs only the path's extent: from here to the stop.
      std::vector<algorithms::PlannedPoint> ahead(2);
      ahead[0].s_m = s_progress;
      ahead[1].s_m = stop_s;
      const algorithms::SignalStop stop = signals.Apply(
          world.time_s(), world.time_s(), ego.v_mps, &ahead, to_turn);
      if (stop.stop) {
        signal_stop_s = stop.stop_s_m;
        if (std::abs(ego.v_mps) < 0.1) report.red_light_wait_s += dt;
      }
    }
    if (!manoeuvre && to_turn && !signal_stop_s &&
        s_progress >= turns[next_turn].start_s_m - 0.5 &&
        std::abs(ego.v_mps) < 0.05) {
      turn_path = geometry::Path2();
      for (const algorithms::GearedPose& p : turns[next_turn].reference) {
        turn_path.points.emplace_back(p.pose.x_m, p.pose.y_m);
      }
      turn_path.UpdateArcLength();
      manoeuvre.emplace(turns[next_turn].reference, limits);
    }
    if (manoeuvre) {
      const ControlCommand c = manoeuvre->Update(ego);
      if (manoeuvre->finished() && !turn_path.points.empty()) {
        // Turned: on along the road part.
        manoeuvre.reset();
        turn_path = geometry::Path2();
        ++next_turn;
      }
      const auto t0 = Clock::now();
      ADSE_RETURN_IF_ERROR(world.Step(c));
      report.world_wall_s += Seconds(Clock::now() - t0);
      continue;
    }
    // Steering that looks ahead through the car's own model.
    ControlCommand command;
    command.steer_rad =
        PredictiveSteer(path, speed, s_progress, ego, limits, options.steering);
    // Speed: limit, curves ahead, and a stop at the goal.
    double v_target = speed.At(s_progress);
    double remaining = std::max(0.0, stop_s - s_progress);
    if (signal_stop_s) {
      remaining = std::clamp(*signal_stop_s - s_progress, 0.0, remaining);
    }
    v_target = std::min(v_target,
                        std::sqrt(2 * options.comfort_decel_mps2 * remaining));
    command.accel_mps2 =
        options.steering.speed_gain_per_s * (v_target - ego.v_mps);
    // Near the stop, brake exactly as much as stopping on it needs; a
    // proportional controller alone lags and overshoots.
    if (remaining > 0.05) {
      const double stop_decel = ego.v_mps * ego.v_mps / (2 * remaining);
      if (stop_decel > 0.8 * options.comfort_decel_mps2) {
        command.accel_mps2 = std::min(command.accel_mps2, -stop_decel);
      }
    } else {
      command.accel_mps2 = -limits.max_decel_mps2;
    }
    command.accel_mps2 = std::clamp(command.accel_mps2, -limits.max_decel_mps2,
                                    limits.max_accel_mps2);
    const auto t0 = Clock::now();
    ADSE_RETURN_IF_ERROR(world.Step(command));
    report.world_wall_s += Seconds(Clock::now() - t0);
  }
  report.time_s = world.time_s();
  report.collisions = world.collisions();
  report.mean_points_per_scan = report.scans ? point_sum / report.scans : 0.0;
  return report;
}

}  // namespace adse::world
