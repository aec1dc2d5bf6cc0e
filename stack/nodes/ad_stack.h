// The autonomous-driving stack under test as a node graph: sensing,
// localization (voxel filter + NDT + EKF), perception (ground removal,
// clustering, tracking), planning (route, behaviour/velocity, smoother) and
// control (pure pursuit + PID). Nodes are thin wrappers around
// stack/algorithms. The vehicle-side command gate is not part of the graph:
// it runs on the vehicle's safety controller, not the computer being sized.
#ifndef ADSE_STACK_NODES_AD_STACK_H_
#define ADSE_STACK_NODES_AD_STACK_H_

#include <memory>
#include <vector>

#include "stack/algorithms/lane_change.h"
#include "stack/algorithms/turnaround_section.h"
#include "stack/base/status.h"
#include "stack/config/stack_config.h"
#include "stack/geometry/geometry.h"
#include "stack/runtime/graph.h"

namespace adse::stack {

// What the car's computer knows before it drives: its map, its mission and
// its own body. Never the ground truth of the run.
struct StackInputs {
  geometry::Path2 route;  // mission planner's route from map and goal
  double lane_width_m = 3.5;
  std::vector<Eigen::Vector3f> map_cloud;  // localization map (map frame)
  geometry::Pose2 initial_pose;  // given at start, as an operator does
  double speed_limit_mps = 30.0 / 3.6;
  double goal_tolerance_m = 2.0;
  double goal_yaw_tolerance_rad = M_PI;  // valet_parking's heading tolerance
  double wheelbase_m = 2.7;
  double max_steer_rate_rad_per_s = 0.8;  // how fast the wheels turn
  double vehicle_length_m = 4.6;
  double vehicle_width_m = 1.9;
  // valet_parking: the route ends on the aisle beside the slot; from there
  // the freespace planner takes the car to `parking_goal` (rear axle) among
  // the lot's walls, poles and parked cars as its map holds them.
  bool parking = false;
  geometry::Pose2 parking_goal;
  std::vector<std::vector<Eigen::Vector2d>> parking_obstacles;
  // The map has traffic signals on the route (a lanelet map holds them):
  // the stack then subscribes to the signal detector and its velocity
  // planner stops for them. Without, the graph has neither.
  bool traffic_signals = false;
  // Where the route changes lane (a lanelet route knows): the planner
  // changes lane only when the target lane has a gap.
  std::vector<algorithms::LaneChangeSection> lane_changes;
  // Where the route turns round tighter than the car can (a lanelet route
  // knows its turns), in route order: the path ends at each one's
  // start_s_m, the freespace planner takes the car round to its goal, and
  // the path goes on from end_s_m.
  std::vector<algorithms::TurnaroundSection> turnarounds;
};

// Topic indices the harness talks to.
struct StackTopics {
  int lidar_raw = -1;     // in: PointCloudMsg, vehicle frame
  int odometry = -1;      // in: OdometryMsg
  int pose = -1;          // out: PoseMsg (EKF)
  int control = -1;       // out: ControlMsg
  int trajectory = -1;    // out: TrajectoryMsg
  int stop_reason = -1;   // out: StopReasonMsg, why the trajectory stops
  int objects = -1;       // out: ObjectsMsg
  int parking_path = -1;  // out: ParkingPathMsg (valet_parking only)
  // out: ParkingDoneMsg (valet_parking only), the freespace planner's
  // is_completed: parked, as far as the stack can tell
  int parking_completed = -1;
  int traffic_signal = -1;  // in: TrafficSignalMsg (traffic_signals only)
};

class AdStack {
 public:
  // Adds the stack's nodes and topics to `graph`. The returned object owns
  // the nodes' state and must outlive the executor running the graph.
  static Result<std::unique_ptr<AdStack>> Build(const StackConfig& config,
                                                const StackInputs& inputs,
                                                Graph* graph);
  virtual ~AdStack() = default;
  virtual const StackTopics& topics() const = 0;
};

}  // namespace adse::stack

#endif  // ADSE_STACK_NODES_AD_STACK_H_
