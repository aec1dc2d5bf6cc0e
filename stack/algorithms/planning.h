// Planning along the route as Autoware splits it: the path ahead
// (behavior_path_planner), speed limits on it (behavior_velocity_planner), a
// stop before obstacles (obstacle_stop_planner) and the velocity smoother.
// Eigen and std types only.
#ifndef ADSE_STACK_ALGORITHMS_PLANNING_H_
#define ADSE_STACK_ALGORITHMS_PLANNING_H_

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "stack/algorithms/stop_reason.h"
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
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  // m/s, map frame
  double length_m = 0.0;
  double width_m = 0.0;
  double yaw_rad = 0.0;
  // The map has structure where it stands (StructureGrid): static
  // structure taken for an object, not traffic.
  bool static_structure = false;
  int age = 0;  // tracker updates seen (its velocity's history)
};

// Nearest point of `path` to p over arc lengths [s_lo, s_hi]: returns its
// s and sets the signed lateral offset (left positive) and the distance.
// Passes of the path about as near as the nearest (laps, a U-turn's two
// legs) are resolved towards s_ref, so near-ties do not flip between them.
double ProjectOnPath(const geometry::Path2& path, const Eigen::Vector2d& p,
                     double s_lo, double s_hi, double s_ref, double* lateral_m,
                     double* distance_m);

// --- behavior_path_planner: the reference path ahead of the ego ---------

struct PathPlannerParams {
  double horizon_m = 50.0;        // path length ahead of the ego
  double spacing_m = 1.0;         // distance between path points
  double speed_limit_mps = 8.33;  // the lane's limit (30 km/h)
  // Curvature of the circle through the path points at s - w/2, s and
  // s + w/2: smooths polylines whose vertices carry all the turning.
  double curvature_window_m = 4.0;
  // Projection of the ego on the path searches this window around the
  // last projection (paths may loop or pass close to themselves).
  double projection_back_m = 2.0;
  double projection_ahead_m = 20.0;
  // Nearest point in the window farther than this: search the whole path.
  double reacquire_distance_m = 5.0;
};

struct PlannedPath {
  std::vector<PlannedPoint> points;  // from the ego's projection onwards,
                                     // at the lane's speed limit
  bool ends_at_goal = false;         // the goal is within the horizon
  double ego_s_m = 0.0;              // ego projection on the route
  double lateral_offset_m = 0.0;     // ego from the route, left positive
  int64_t work_units = 0;            // points
};

class PathPlanner {
 public:
  explicit PathPlanner(const PathPlannerParams& params = {})
      : params_(params) {}

  // A new route; progress restarts. The goal is projected on the route
  // (default: its end) and the path ends there.
  void SetRoute(const geometry::Path2& route,
                std::optional<Eigen::Vector2d> goal = std::nullopt);
  bool has_route() const { return route_.points.size() >= 2; }
  double goal_s_m() const { return goal_s_m_; }
  // Where the route turns round tighter than the car can: the path ends
  // at `s_m` (as at a goal) and the progress stays short of it, whatever
  // the car does beyond (a turn in several moves), until ResumeAt().
  void EndAt(double s_m);
  // The car has turned round: progress goes on from `s_m`, and the path
  // ends at the route's goal again (or at the next EndAt()).
  void ResumeAt(double s_m);

  // The path ahead of `pose` (rear axle, map frame), sampled every
  // spacing_m with the curvature at each point. Empty without a route.
  PlannedPath Plan(const geometry::Pose2& pose);

  // Progress along the route (never decreases until SetRoute).
  double progress_s_m() const { return last_s_m_; }
  const PathPlannerParams& params() const { return params_; }

 private:
  double CurvatureAt(double s) const;

  PathPlannerParams params_;
  geometry::Path2 route_;
  double goal_s_m_ = 0.0;
  double route_goal_s_m_ = 0.0;  // the goal's, as SetRoute() projected it
  bool held_at_end_ = false;     // EndAt() holds the progress
  double last_s_m_ = 0.0;
  bool has_progress_ = false;
};

// --- behavior_velocity_planner: speed limits along the path -------------

struct VelocityLimitParams {
  double max_lateral_accel_mps2 = 1.5;  // v <= sqrt(a_lat / |curvature|)
  double min_curve_speed_mps = 1.0;     // curvature never asks for less
};

// Lowers each point's speed to what its curvature allows and, when the
// path ends at the goal, sets 0 at its last point. Returns work units
// (points).
int64_t LimitVelocity(std::vector<PlannedPoint>* points, bool ends_at_goal,
                      const VelocityLimitParams& params);

// --- obstacle_stop_planner: a stop before what blocks the path ----------

struct ObstacleStopParams {
  // Half width of the swept corridor: an obstacle whose box comes closer
  // than this to the path blocks it. The car's footprint ahead of its rear
  // axle, this wide, is also swept along the path: in a tight turn its
  // front corner swings out past a corridor around the rear axle's path.
  double corridor_half_width_m = 1.5;
  double stop_margin_m = 5.0;      // gap left between ego front and obstacle
  double ego_front_m = 3.8;        // rear axle to front bumper
  double ego_half_width_m = 0.95;  // half the body's width
  // What stands within the corridor where the car is already (a car
  // waiting beside it in a turn) holds it only when the body would come
  // nearer to it than this as the car drives off. A road user moving
  // alongside (cutting in) counts whenever it is in the corridor.
  double drive_off_clearance_m = 0.3;
  double standing_object_mps = 0.5;  // slower than this, a track stands
  // How far the car's own way back onto the path (its controller's, from
  // where it stands off the path) is checked for that, in place of the
  // path.
  double drive_off_m = 8.0;
  // The footprint is placed along the path at most this far apart.
  double footprint_step_m = 0.25;
  // Obstacles are looked for from the ego's front bumper back to the rear
  // axle (ego_front_m behind the path's start) up to this far past its end.
  double beyond_end_m = 10.0;
};

struct ObstacleStop {
  bool stop = false;              // an obstacle blocks the path
  int obstacle_id = -1;           // the nearest blocking obstacle
  bool static_structure = false;  // that obstacle is map structure
  double stop_s_m = -1;           // where v becomes 0 (rear axle), -1: nowhere
  // From the ego's front bumper to the obstacle's near edge, along the path.
  double gap_m = -1;
  // kObstacle (in the corridor, or crossing it) or kLaneChange (no gap in
  // the lane the route changes into).
  StopReason reason = StopReason::kObstacle;
  int64_t work_units = 0;  // obstacles x points
};

// Inserts a point at arc length stop_s (unless one is within 1 mm, or
// stop_s lies outside the points) and sets the speed 0 from there on, so v
// reaches 0 exactly at the stop line and not up to one spacing later.
void InsertStopAt(std::vector<PlannedPoint>* points, double stop_s);

// Finds the nearest obstacle whose box enters the corridor along `points`
// (a path from the ego onwards) ahead of the car, or which the car's
// footprint would touch, inserts a point exactly at the stop line
// stop_margin_m before it, and sets 0 from there on. `drive_off` gives
// the rear axle's poses as the car drives off from where it stands onto
// the path (PurePursuit::Rollout over drive_off_m), asked for only when
// something is within the corridor there already; may be empty.
using DriveOff = std::function<std::vector<geometry::Pose2>()>;
ObstacleStop InsertObstacleStop(std::vector<PlannedPoint>* points,
                                const std::vector<PlannerObstacle>& obstacles,
                                const DriveOff& drive_off,
                                const ObstacleStopParams& params);

// --- Crossing traffic: yield before a road user about to cross ----------
// Autoware's intersection module yields to what its map says will cross
// the ego's lane; adse's stack has no lanelet map, so it predicts each
// moving track straight along its velocity and yields where that box will
// cross the corridor while the ego would be there. Without it the ego
// turned into a junction in front of traffic and stood there, the other
// car waiting for it.

struct CrossingYieldParams {
  // How far ahead a crossing is foreseen; 0 never yields.
  double horizon_s = 3.0;
  double step_s = 0.25;  // prediction step
  // Slower tracks are left to the obstacle stop: waiting cars, and parked
  // ones whose box centre wanders as the ego passes and more of them is
  // seen (at 1 m/s such tracks made the car brake along every aisle).
  double min_object_speed_mps = 2.5;
  // Tracks younger than this (updates) are not predicted: a new track's
  // speed is a guess.
  int min_track_age = 5;
  // The ego's speed counts as at least this when it judges how long it
  // would take to clear a crossing.
  double min_ego_speed_mps = 1.0;
  // A track moving within this angle of the path (following, oncoming)
  // does not cross it.
  double min_crossing_angle_rad = 0.5236;  // 30 degrees
  // Yield only when the ego's time in the crossing and the track's come
  // within this of each other.
  double time_margin_s = 1.0;
  // How fast the ego can speed up towards a crossing (the smoother's).
  double max_accel_mps2 = 1.5;
  // CrossingYielder goes again only after this long without a reason to
  // yield (Autoware: state_transit_margin_time).
  double transit_margin_s = 1.0;
  // A crossing the ego cannot stop before at this deceleration it drives
  // through (it is committed, as Autoware's pass judge line says).
  double max_decel_mps2 = 2.5;
};

// Stops `points` stop_margin_m before the first crossing a moving obstacle
// (not in the corridor now: that is InsertObstacleStop's) will make of the
// corridor within horizon_s, when the ego would be in that crossing within
// time_margin_s of the obstacle: from the earliest it could arrive
// (speeding up from ego_v_mps at max_accel_mps2 to the fastest `points`
// plan before it) to the latest it could leave (at ego_v_mps, at least
// min_ego_speed_mps). A crossing it can no longer stop before at
// max_decel_mps2 it drives through, unless `yielding` (the last plan
// yielded: braking for crossing traffic, it stays stopped). The returned
// stop names the obstacle; gap_m is to the crossing's near edge.
ObstacleStop InsertCrossingYield(std::vector<PlannedPoint>* points,
                                 const std::vector<PlannerObstacle>& obstacles,
                                 double ego_v_mps,
                                 const ObstacleStopParams& stop_params,
                                 const CrossingYieldParams& params,
                                 bool yielding = false);

// InsertCrossingYield with the hysteresis of Autoware's intersection
// module (its state transit margin): once stopped for crossing traffic it
// goes again only after transit_margin_s without a reason to yield, and
// keeps the nearer of its last stop line and a new one meanwhile. The
// tracks of a fast crossing car break up and are born again without their
// speed; without this the stop flickered and the car drove into the
// junction between two of them.
class CrossingYielder {
 public:
  explicit CrossingYielder(const CrossingYieldParams& params = {})
      : params_(params) {}
  ObstacleStop Plan(std::vector<PlannedPoint>* points,
                    const std::vector<PlannerObstacle>& obstacles,
                    double ego_v_mps, double now_s,
                    const ObstacleStopParams& stop_params);

 private:
  CrossingYieldParams params_;
  bool held_ = false;  // a yield is remembered
  ObstacleStop last_;  // the stop it made (route s)
  double last_t_s_ = 0.0;
};

// The stop of the two that comes first along the path (or the one there is).
const ObstacleStop& NearerStop(const ObstacleStop& a, const ObstacleStop& b);

// --- Why the trajectory stops ---------------------------------------------

struct StopDecision {
  StopReason reason = StopReason::kNone;
  // Along the path from the ego (rear axle) to where the speed becomes 0;
  // 0 when the stop is there or behind; -1 without a stop.
  double distance_m = -1;
  // kObstacle and kLaneChange only: the track, the gap from the ego's
  // front bumper to its near edge (kLaneChange: along the route, from the
  // nearer bumper; negative alongside), and whether the map has structure
  // there.
  int obstacle_id = -1;
  double obstacle_gap_m = -1;
  bool static_structure = false;
};

// The stop the trajectory `points` (from the ego onwards) makes, and why:
// no points, no trajectory; localization lost holds the car where it is
// (every speed set to 0: the planner does not drive by a pose it does not
// trust); otherwise the nearest of the goal's stop (ends_at_goal: its last
// point), the obstacle's (for its reason) and a traffic signal's
// (signal_stop_s_m: where the velocity planner set 0 for a signal, rear axle,
// route s), or none.
StopDecision DecideStop(std::vector<PlannedPoint>* points, bool ends_at_goal,
                        bool localization_lost, const ObstacleStop& obstacle,
                        std::optional<double> signal_stop_s_m = std::nullopt);

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
