// Behaviour/velocity planning along the reference path, and the velocity
// smoother. Eigen and std types only.
#ifndef ADSE_STACK_ALGORITHMS_PLANNING_H_
#define ADSE_STACK_ALGORITHMS_PLANNING_H_

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "stack/geometry/geometry.h"

namespace adse::algorithms {

// One trajectory point: where the rear axle should pass and how fast.
struct PlannedPoint {
  double x_m = 0.0;
  double y_m = 0.0;
  double yaw_rad = 0.0;
  double s_m = 0.0;            // arc length along the reference path
  double v_mps = 0.0;          // target speed here
  double curvature_1pm = 0.0;  // signed path curvature (left positive)
};

// An object in the map frame (a confirmed track, say).
struct PlannerObstacle {
  int id = 0;
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  // unused for now
  double length_m = 0.0;
  double width_m = 0.0;
  double yaw_rad = 0.0;
};

struct PlannerParams {
  double horizon_m = 50.0;              // trajectory length ahead of the ego
  double spacing_m = 1.0;               // distance between trajectory points
  double speed_limit_mps = 8.33;        // 30 km/h
  double max_lateral_accel_mps2 = 1.5;  // v <= sqrt(a_lat / |curvature|)
  double min_curve_speed_mps = 1.0;     // curvature never asks for less
  // Curvature of the circle through the path points at s - w/2, s and
  // s + w/2: smooths polylines whose vertices carry all the turning.
  double curvature_window_m = 4.0;
  // Half width of the swept corridor: an obstacle whose box comes closer
  // than this to the path blocks it.
  double corridor_half_width_m = 1.4;
  double stop_margin_m = 3.0;  // gap left between ego front and obstacle
  double ego_front_m = 3.8;    // rear axle to front bumper
  // Projection of the ego on the path searches this window around the
  // last projection (paths may loop or pass close to themselves).
  double projection_back_m = 2.0;
  double projection_ahead_m = 20.0;
  // Nearest point in the window farther than this: search the whole path.
  double reacquire_distance_m = 5.0;
};

struct PlannedTrajectory {
  std::vector<PlannedPoint> points;  // from the ego's projection onwards
  bool stop_for_goal = false;        // the goal is within the horizon
  bool stop_for_obstacle = false;    // an obstacle blocks within it
  int obstacle_id = -1;              // the blocking obstacle, if any
  double stop_s_m = -1.0;            // where v becomes 0 (-1: nowhere)
  double ego_s_m = 0.0;              // ego projection on the path
  double lateral_offset_m = 0.0;     // ego from path, left positive
  int64_t work_units = 0;            // points + obstacle projections
};

class BehaviorVelocityPlanner {
 public:
  explicit BehaviorVelocityPlanner(const PlannerParams& params = {})
      : params_(params) {}

  // A new reference path; progress restarts. The goal is projected on the
  // path (default: its end) and the ego stops there.
  void SetPath(const geometry::Path2& path,
               std::optional<Eigen::Vector2d> goal = std::nullopt);
  bool has_path() const { return path_.points.size() >= 2; }
  double goal_s_m() const { return goal_s_m_; }

  // Trajectory ahead of `pose` (rear axle, map frame) with raw target
  // speeds (steps to 0 at stops; SmoothVelocity makes them drivable).
  // Empty without a path.
  PlannedTrajectory Plan(const geometry::Pose2& pose,
                         const std::vector<PlannerObstacle>& obstacles);

  // Progress along the path (never decreases until SetPath).
  double progress_s_m() const { return last_s_m_; }
  const PlannerParams& params() const { return params_; }

 private:
  // Nearest path point to p over arc lengths [s_lo, s_hi]; returns its s
  // and the signed lateral offset (left positive) and distance. Passes of
  // the path about as near as the nearest are resolved towards s_ref.
  double Project(const Eigen::Vector2d& p, double s_lo, double s_hi,
                 double s_ref, double* lateral_m, double* distance_m) const;
  double CurvatureAt(double s) const;

  PlannerParams params_;
  geometry::Path2 path_;
  double goal_s_m_ = 0.0;
  double last_s_m_ = 0.0;
  bool has_progress_ = false;
};

struct SmootherParams {
  double max_accel_mps2 = 1.0;  // forward pass: speed-up limit
  double max_decel_mps2 = 1.5;  // backward pass: slow-down limit (positive)
  // Lowest speed the forward pass starts from, so a standing vehicle gets
  // a target above zero (unless the raw profile says stop).
  double start_speed_mps = 1.0;
};

// Limits acceleration (forward from the current speed) and deceleration
// (backward from every lower speed ahead, stops included) along the
// trajectory; never raises a speed. Work units: points.
void SmoothVelocity(std::vector<PlannedPoint>* points, double current_v_mps,
                    const SmootherParams& params);

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_PLANNING_H_
