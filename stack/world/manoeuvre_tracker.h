// The ground-truth driver's way through a manoeuvre in several moves (a
// three-point turn, a valet task's parking): each move in its gear, the
// path's own curvature fed forward with feedback on the true pose's
// lateral and heading error, the wheels turned while standing at each
// cusp, and the speed kept low enough for the steering's rate limit to
// follow the path's changes of curvature. The stack's parking controller
// (pure pursuit, 2 m lookahead) strayed 1-2.5 m from such turns on real
// nets, whose moves are often shorter than its lookahead.
#ifndef ADSE_STACK_WORLD_MANOEUVRE_TRACKER_H_
#define ADSE_STACK_WORLD_MANOEUVRE_TRACKER_H_

#include <vector>

#include "stack/algorithms/reeds_shepp.h"
#include "stack/world/vehicle_model.h"

namespace adse::world {

struct ManoeuvreTrackerOptions {
  double forward_speed_mps = 1.5;  // cruise speed forwards
  double reverse_speed_mps = 1.0;  // cruise speed in reverse
  // Never slower than this while a move is not done: the speed that
  // lets the wheels catch up with a change of curvature just ahead.
  double crawl_speed_mps = 0.15;
  // Braking towards a move's end (a cusp or the manoeuvre's end).
  double stop_decel_mps2 = 0.6;
  double speed_gain_per_s = 1.5;
  // Feedback on the error from the path, in the direction of travel:
  // curvature = path's - lateral_gain x offset - heading_gain x heading
  // error (a critically damped response over about 1.5 m of travel).
  double lateral_gain_1pm2 = 0.45;
  double heading_gain_1pm = 1.3;
  // The curvature fed forward is the path's this long ahead at the
  // current speed: the wheels start to turn before a change, not at it.
  double preview_s = 0.4;
  // How far ahead changes of curvature are looked for, to slow for them.
  double lookahead_m = 3.0;
  // A move's end counts as reached this close to it (along the path).
  double arrive_tolerance_m = 0.05;
  // At a cusp the car stands until the wheels are this close to the
  // next move's first steering angle.
  double steer_settle_rad = 0.05;
  // Slower than this counts as standing.
  double standstill_mps = 0.05;
};

class ManoeuvreTracker {
 public:
  // `path` as the freespace planner returns it: poses of the rear axle,
  // a gear change being a pose in the old gear followed by poses in the
  // new one. An empty path is finished at once.
  ManoeuvreTracker(const std::vector<algorithms::GearedPose>& path,
                   const VehicleLimits& limits,
                   const ManoeuvreTrackerOptions& options = {});

  // One control step from the true state.
  ControlCommand Update(const VehicleState& ego);

  // Standing at the end of the last move.
  bool finished() const { return finished_; }
  int moves() const { return static_cast<int>(moves_.size()); }

 private:
  struct Move {
    bool reverse = false;
    std::vector<Eigen::Vector2d> points;
    std::vector<double> d_m;          // distance along the move
    std::vector<double> heading_rad;  // direction of travel, unwrapped
    // Curvature of the direction of travel (left positive) over the
    // interval from point i to i + 1.
    std::vector<double> curvature_1pm;
  };
  double CurvatureAt(const Move& move, double d_m) const;
  // The steering angle that drives `move` at `curvature_1pm` (in its
  // direction of travel), within the wheels' limits.
  double SteerFor(const Move& move, double curvature_1pm) const;

  VehicleLimits limits_;
  ManoeuvreTrackerOptions options_;
  std::vector<Move> moves_;
  size_t current_ = 0;
  size_t index_ = 0;  // the projection's interval, never decreasing
  bool finished_ = false;
};

}  // namespace adse::world

#endif  // ADSE_STACK_WORLD_MANOEUVRE_TRACKER_H_
