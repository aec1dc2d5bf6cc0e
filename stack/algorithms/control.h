// Trajectory following: pure pursuit for steering, a PID on speed, and the
// follower combining them. Eigen and std types only.
#ifndef ADSE_STACK_ALGORITHMS_CONTROL_H_
#define ADSE_STACK_ALGORITHMS_CONTROL_H_

#include <vector>

#include "stack/algorithms/planning.h"
#include "stack/geometry/geometry.h"

namespace adse::algorithms {

struct PurePursuitParams {
  double wheelbase_m = 2.7;       // rear axle to front axle
  double lookahead_gain_s = 0.8;  // lookahead = gain x speed, clamped
  double min_lookahead_m = 4.0;   // at low speed
  double max_lookahead_m = 15.0;  // at high speed
  double max_steer_rad = 0.6;     // front wheel angle limit
};

struct PurePursuitOutput {
  bool valid = false;          // false: no trajectory to follow
  double steer_rad = 0.0;      // atan(wheelbase x curvature), limited
  double curvature_1pm = 0.0;  // of the arc to the lookahead point
  double lookahead_m = 0.0;
  Eigen::Vector2d target = Eigen::Vector2d::Zero();  // lookahead point
  size_t nearest_index = 0;      // segment start nearest to the rear axle
  double nearest_t = 0.0;        // position on that segment, 0..1
  double lateral_error_m = 0.0;  // from the trajectory, left positive
  bool past_end = false;         // the rear axle is beyond the last point
};

class PurePursuit {
 public:
  explicit PurePursuit(const PurePursuitParams& params = {})
      : params_(params) {}
  // `pose` is the rear axle in the trajectory's frame.
  PurePursuitOutput Compute(const geometry::Pose2& pose, double v_mps,
                            const std::vector<PlannedPoint>& trajectory) const;
  // The rear axle's poses, every step_m over length_m, as the car drives
  // off from `pose` at a crawl following `trajectory` (a kinematic bicycle
  // steered by Compute): its own way back onto a trajectory it stands
  // off. Starts with `pose`; ends early past the trajectory's end.
  std::vector<geometry::Pose2> Rollout(
      const geometry::Pose2& pose, const std::vector<PlannedPoint>& trajectory,
      double length_m, double step_m) const;
  const PurePursuitParams& params() const { return params_; }

 private:
  PurePursuitParams params_;
};

struct PidParams {
  double kp = 1.0;                // accel per m/s of speed error
  double ki = 0.2;                // accel per m of integrated error
  double kd = 0.0;                // accel per m/s^2 of error change
  double integral_limit_m = 2.0;  // |integral of error| clamp (anti-windup)
  double max_accel_mps2 = 2.0;    // output upper limit
  double max_decel_mps2 = 4.0;    // output lower limit (positive number)
};

class Pid {
 public:
  explicit Pid(const PidParams& params = {}) : params_(params) {}
  // Output for `error` after dt_s (dt_s <= 0: no integration/derivative).
  // `feedforward` is added before the output limits.
  double Update(double error, double dt_s, double feedforward = 0.0);
  void Reset();
  double integral() const { return integral_; }
  const PidParams& params() const { return params_; }

 private:
  PidParams params_;
  double integral_ = 0.0;
  double last_error_ = 0.0;
  bool has_last_ = false;
};

struct FollowerParams {
  PurePursuitParams pure_pursuit;
  PidParams pid;
  // Speed target taken this far ahead (time x current speed, at least
  // the minimum) so braking starts before the point that asks for it.
  double speed_preview_s = 0.6;
  double speed_preview_min_m = 1.0;
  double feedforward_gain = 1.0;  // x accel implied by the speed profile
  // Target speed below this counts as "stop here".
  double stop_speed_mps = 0.2;
  // Braking while stopping or standing still (positive number).
  double stop_decel_mps2 = 1.5;
  // Braking when there is no trajectory at all (positive number).
  double no_trajectory_decel_mps2 = 3.0;
};

struct FollowerCommand {
  double accel_mps2 = 0.0;  // negative brakes
  double steer_rad = 0.0;
  bool stopping = false;       // braking to/holding a stop
  bool no_trajectory = false;  // trajectory empty
  double target_speed_mps = 0.0;
  double lateral_error_m = 0.0;
  double lookahead_m = 0.0;
};

class TrajectoryFollower {
 public:
  explicit TrajectoryFollower(const FollowerParams& params = {});
  // One control step: pose (rear axle, map frame) and speed now, the
  // latest trajectory, and the time since the previous step.
  FollowerCommand Update(const geometry::Pose2& pose, double v_mps,
                         const std::vector<PlannedPoint>& trajectory,
                         double dt_s);
  void Reset();
  const FollowerParams& params() const { return params_; }

 private:
  FollowerParams params_;
  PurePursuit pure_pursuit_;
  Pid pid_;
  double last_steer_rad_ = 0.0;
};

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_CONTROL_H_
