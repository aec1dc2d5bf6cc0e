// Messages exchanged on the stack's topics. Plain data; Eigen only. A
// message is published once and shared read-only by every subscriber.
#ifndef ADSE_STACK_RUNTIME_MESSAGES_H_
#define ADSE_STACK_RUNTIME_MESSAGES_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "stack/algorithms/signal_state.h"
#include "stack/algorithms/stop_reason.h"
#include "stack/geometry/geometry.h"

namespace adse::stack {

// Publish times and sequence numbers are recorded by the runtime in the
// trace, not in the message.
struct Header {
  // Time of the sensor sample this message derives from (for end-to-end
  // latency); for timer-born messages, the stamp of the input they used.
  double stamp_s = 0.0;
  // Stamp of the scan whose tracked objects this message's decisions rest
  // on, carried from the obstacle stop planner to the command: the
  // sensing-to-control chain through perception, the path CARET's e2e
  // latency follows. -1 when no objects were used.
  double perception_stamp_s = -1.0;
};

// A LiDAR scan or a filtered cloud, points in the vehicle frame (x forward,
// y left, z up; origin on the ground under the rear axle).
struct PointCloudMsg {
  Header header;
  std::vector<Eigen::Vector3f> points;
};

// Wheel odometry: what the vehicle reports about its own motion.
struct OdometryMsg {
  Header header;
  double v_mps = 0.0;
  double yaw_rate_rps = 0.0;
};

// A pose estimate in the map frame with its covariance (x, y, yaw).
struct PoseMsg {
  Header header;
  // The time the pose describes. header.stamp_s is the scan it last rests
  // on (for latency); the EKF's pose is of the moment it is published.
  double time_s = 0.0;
  geometry::Pose2 pose;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  double v_mps = 0.0;    // filtered speed (EKF output)
  double fitness = 0.0;  // scan matcher fitness (NDT), lower is better
  bool valid = true;     // false: localization lost
};

struct TrackedObject {
  int id = 0;
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // map frame
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();
  double length_m = 0.0;  // along yaw_rad
  double width_m = 0.0;
  // Heading of the box's length (map frame, modulo a half turn). Planning
  // needs it: a car standing across the map's axes is not an axis-aligned
  // box (taken as one, a car waiting in the crossing lane of a turn reached
  // into the ego's corridor).
  double yaw_rad = 0.0;
  int age = 0;  // updates seen
};

struct ObjectsMsg {
  Header header;
  std::vector<TrackedObject> objects;
};

// The traffic signal controlling the ego's next link on its route, as the
// car's detector sees it (/perception/traffic_signal; only in graphs whose
// map has signals on the route).
struct TrafficSignalMsg {
  Header header;  // when the detector saw it
  SignalState state = SignalState::kUnknown;
  // Along the route from the rear axle to the signal's stop line; -1 when
  // no signal is within the detector's range.
  double stop_line_distance_m = -1;
  std::string tls_id;  // the signal's id; empty when none is in range
};

// The route as a reference path in the map frame.
struct PathMsg {
  Header header;
  geometry::Path2 path;
};

struct TrajectoryPoint {
  double x_m = 0.0, y_m = 0.0, yaw_rad = 0.0;
  double s_m = 0.0;            // arc length along the reference path
  double v_mps = 0.0;          // target speed at this point
  double curvature_1pm = 0.0;  // signed path curvature (left positive)
};

// Why the planned trajectory stops (/planning/stop_reason), published with
// every trajectory by the stage that decides it (obstacle_stop_planner).
struct StopReasonMsg {
  Header header;  // the pose the trajectory was planned from
  StopReason reason = StopReason::kNone;
  // From the ego's rear axle to where the speed becomes 0, along the path;
  // 0 when there or behind; -1 without a stop.
  double stop_distance_m = -1;
  // kObstacle: the track id, the gap from the ego's front bumper to the
  // object's near edge, and whether the map has static structure there.
  int track_id = -1;
  double obstacle_gap_m = -1;
  bool static_structure = false;
};

struct TrajectoryMsg {
  Header header;
  std::vector<TrajectoryPoint> points;
  bool ends_at_goal = false;       // the path's last point is the goal
  bool localization_lost = false;  // planned from a pose marked invalid
  double ego_v_mps = 0.0;          // speed of the pose it was planned from
  geometry::Pose2 ego_pose;        // that pose (rear axle, map frame)
  // A traffic signal set the speed to 0 from signal_stop_s_m on (rear
  // axle, route s; set by behavior_velocity_planner).
  bool signal_stop = false;
  double signal_stop_s_m = 0.0;
  StopReasonMsg stop;  // set by obstacle_stop_planner
  // The part of the route it lies on: 0 up to the first three-point turn,
  // k after the k-th. Its end is that turn's start when ends_at_goal is
  // set and the route has more turns than this.
  int route_leg = 0;
};

// The freespace planner's parking manoeuvre (or why there is none).
struct ParkingPathPoint {
  double x_m = 0.0;  // rear axle, map frame
  double y_m = 0.0;
  double yaw_rad = 0.0;
  bool reverse = false;  // gear this pose is driven in
};
struct ParkingPathMsg {
  Header header;
  bool found = false;
  // The move under way runs into a road user and no path leads round it
  // yet: stand where you are until the next path (found, no poses).
  bool hold = false;
  std::vector<ParkingPathPoint> poses;  // start to goal, when found
  std::string failure;                  // why not, when not found
  int64_t expansions = 0;               // search effort
};

// The controller's parking mode reached the manoeuvre's end and holds.
struct ParkingDoneMsg {
  Header header;
  int turnaround = -1;  // the three-point turn completed; -1: the parking
  // The turn (a corner's) is left to the lanes: no manoeuvre led on from
  // where the car stood, and the path goes on from the turn's start.
  bool on_lanes = false;
};

struct ControlMsg {
  Header header;
  double accel_mps2 = 0.0;  // along the gear; negative brakes
  double steer_rad = 0.0;
  bool reverse = false;  // gear
};

}  // namespace adse::stack

#endif  // ADSE_STACK_RUNTIME_MESSAGES_H_
