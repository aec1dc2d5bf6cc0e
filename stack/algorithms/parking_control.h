// The controller's low-speed parking mode: follows a freespace path with
// gear changes, one segment (a stretch in one gear) at a time, stopping at
// each cusp before shifting. Pure pursuit steers (on the mirrored heading
// in reverse), a PID holds the parking speed. Eigen and std types only.
#ifndef ADSE_STACK_ALGORITHMS_PARKING_CONTROL_H_
#define ADSE_STACK_ALGORITHMS_PARKING_CONTROL_H_

#include <cmath>
#include <vector>

#include "stack/algorithms/control.h"
#include "stack/algorithms/reeds_shepp.h"
#include "stack/geometry/geometry.h"

namespace adse::algorithms {

struct ParkingFollowerParams {
  double wheelbase_m = 2.7;        // rear axle to front axle
  double max_steer_rad = 0.6;      // front wheel angle limit
  double forward_speed_mps = 1.5;  // cruise speed forwards
  double reverse_speed_mps = 1.0;  // cruise speed in reverse
  double lookahead_m = 2.0;        // pure pursuit, fixed at these speeds
  // Braking towards a cusp or the end (positive number): braking starts
  // when stopping at the end needs this much, and then asks for exactly
  // what stopping there needs, up to max_brake_mps2.
  double stop_decel_mps2 = 0.6;
  double max_brake_mps2 = 3.0;
  // A segment's end counts as reached this close to it (along the path).
  double arrive_tolerance_m = 0.1;
  // Farther than this from the path (DistanceFromPath), the car is off its
  // course: it brakes and holds until a new path comes (the freespace
  // planner re-plans from where it stands, as Autoware's does past its
  // th_course_out_distance_m). 0: never.
  double course_out_m = 0.0;
  // Slower than this counts as standing: the gear may change.
  double standstill_mps = 0.05;
  // How fast the wheels turn, rad/s: standing at a segment's start, the
  // car waits until they have turned to its first steering command (as
  // Autoware keeps a car stopped until its steering converges), or a short
  // move between cusps, steered on the way, turns the car far less than
  // planned. 0: no wait.
  double steer_rate_rad_per_s = 0.0;
  // The wheels count as turned within this of the command.
  double steer_settled_rad = 0.02;
  PidParams pid;  // speed loop
};

struct ParkingCommand {
  double accel_mps2 = 0.0;  // along the gear; negative brakes
  double steer_rad = 0.0;
  bool reverse = false;  // gear of the segment being driven
  // At the end of the last segment, standing: from then on it holds (a
  // parked car does not creep when its pose estimate moves).
  bool finished = false;
  // Off the path by more than course_out_m: braking to hold where it is.
  bool course_out = false;
  int segment = 0;  // index of the segment being driven
  double target_speed_mps = 0.0;
  double lateral_error_m = 0.0;  // from the segment, left positive
  double remaining_m = 0.0;      // to the segment's end (negative: past it)
};

// From `p` to the nearest point of the polyline through `poses`
// (infinity for an empty path): the one measure of being off course that
// the controller (it holds) and the freespace planner (it re-plans) share.
double DistanceFromPath(const std::vector<GearedPose>& poses,
                        const Eigen::Vector2d& p);

class ParkingFollower {
 public:
  explicit ParkingFollower(const ParkingFollowerParams& params = {});

  // A new path (as FreespacePlanner returns it); progress restarts at its
  // first segment.
  void SetPath(const std::vector<GearedPose>& poses);
  bool has_path() const { return !segments_.empty(); }
  int segments() const { return static_cast<int>(segments_.size()); }

  // One control step: the rear axle's pose, the signed speed (negative in
  // reverse) and the time since the previous step. `speed_cap_mps` lowers
  // the cruise speeds (the stack's degraded mode when fixes are old).
  ParkingCommand Update(const geometry::Pose2& pose, double v_mps, double dt_s,
                        double speed_cap_mps = INFINITY);
  const ParkingFollowerParams& params() const { return params_; }

 private:
  struct Segment {
    std::vector<Eigen::Vector2d> points;
    std::vector<double> s_m;  // arc length at each point
    bool reverse = false;
    // Direction of travel at the end, for targets past it.
    Eigen::Vector2d end_direction = Eigen::Vector2d::UnitX();
  };
  // Arc length of `p`'s projection on segment `seg`, searched forward from
  // the last projection; sets the signed lateral offset.
  double Project(const Segment& seg, const Eigen::Vector2d& p,
                 double* lateral_m);
  Eigen::Vector2d PointAt(const Segment& seg, double s) const;

  ParkingFollowerParams params_;
  Pid pid_;
  std::vector<GearedPose> path_;  // as given, for the course-out check
  std::vector<Segment> segments_;
  int current_ = 0;
  bool finished_ = false;
  size_t last_index_ = 0;  // projection's segment start, never decreasing
  // The wheel angle as the commands so far have turned it (at
  // steer_rate_rad_per_s), and whether the car is still to move off on
  // the current segment.
  double steer_estimate_rad_ = 0.0;
  bool settling_ = true;
};

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_PARKING_CONTROL_H_
