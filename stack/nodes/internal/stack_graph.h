// The AD stack's node graph: the Stack class that ad_stack.cc (sensing,
// localization, perception) and ad_stack_planning.cc (planning, parking,
// control) build together. Internal to stack/nodes.
#ifndef ADSE_STACK_NODES_INTERNAL_STACK_GRAPH_H_
#define ADSE_STACK_NODES_INTERNAL_STACK_GRAPH_H_

#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "stack/algorithms/clustering.h"
#include "stack/algorithms/control.h"
#include "stack/algorithms/ekf.h"
#include "stack/algorithms/freespace_planner.h"
#include "stack/algorithms/map_filter.h"
#include "stack/algorithms/ndt_matcher.h"
#include "stack/algorithms/parking_control.h"
#include "stack/algorithms/planning.h"
#include "stack/algorithms/point_filters.h"
#include "stack/algorithms/tracker.h"
#include "stack/algorithms/traffic_light.h"
#include "stack/nodes/ad_stack.h"
#include "stack/nodes/pose_listener.h"

namespace adse::stack::internal {

namespace algo = adse::algorithms;

class Stack final : public AdStack {
 public:
  Stack(const StackConfig& config, const StackInputs& inputs)
      : config_(config), inputs_(inputs) {}
  const StackTopics& topics() const override { return topics_; }
  Status Build(Graph* graph);

 private:
  void BuildSensing(Graph* g);
  Status BuildLocalization(Graph* g);
  void BuildPerception(Graph* g);
  void BuildPlanning(Graph* g);
  // The freespace planner's manoeuvres: the route's three-point turns and
  // valet parking's way into the slot.
  void BuildManoeuvres(Graph* g);
  // The path planner's path ends where the route's leg does: at the next
  // three-point turn, or the goal.
  void EndRouteLeg();
  void PlanManoeuvre(CallbackContext& ctx, double course_out_m,
                     int max_replans);
  // The trajectory follower's parameters (the obstacle stop predicts how
  // it drives off).
  algo::FollowerParams FollowerParams() const;
  void BuildControl(Graph* g);
  // The controller's parking mode: one command along the manoeuvre, gear
  // and all, published.
  void Park(CallbackContext& ctx, double dt_s, double speed_cap_mps,
            ControlMsg* out);

  StackConfig config_;
  StackInputs inputs_;
  StackTopics topics_;
  int points_ = -1, downsampled_ = -1, ndt_pose_ = -1, obstacle_points_ = -1,
      detections_ = -1, route_ = -1, path_ = -1, path_limited_ = -1,
      trajectory_raw_ = -1;

  // Node state. Callbacks of one node never overlap (the executor's
  // mutual exclusion), so none of this needs locking, but for the
  // PoseListeners, which a listener node fills for another.
  algo::TwistHistory corrector_twists_{0};  // newest odometry samples
  std::unique_ptr<algo::NdtMatcher> ndt_;
  PoseListener ndt_poses_;  // the EKF's, for the alignment's first guess
  algo::Ekf ekf_;
  double ekf_last_t_ = 0.0;
  double ekf_stamp_ = -1.0;  // stamp of the newest fused NDT pose
  algo::MapFilter map_filter_;
  algo::StructureGrid structure_grid_;  // obstacle_stop_planner's map view
  // Poses by time, so that a scan is placed where the car was when it was
  // taken, not where it is when processing reaches it.
  PoseListener ground_poses_;
  PoseListener cluster_poses_;
  std::unique_ptr<algo::Tracker> tracker_;
  std::unique_ptr<algo::PathPlanner> path_planner_;
  int route_leg_ = 0;  // three-point turns the path planner has seen made
  std::optional<PoseMsg> path_pose_;
  std::unique_ptr<algo::TrafficLightPlanner> traffic_light_;
  std::optional<ObjectsMsg> stop_objects_;
  std::unique_ptr<algo::CrossingYielder> crossing_yield_;
  std::unique_ptr<algo::LaneChangeGuard> lane_change_;
  std::optional<PoseMsg> smoother_pose_;
  std::unique_ptr<algo::TrajectoryFollower> follower_;
  std::optional<PoseMsg> follower_pose_;
  std::optional<TrajectoryMsg> follower_trajectory_;
  double follower_last_t_ = -1.0;
  std::unique_ptr<algo::FreespacePlanner> freespace_;
  std::optional<PoseMsg> freespace_pose_;
  std::vector<algo::GearedPose> freespace_path_;  // the last plan found
  // The road users the car sees, for the freespace planner.
  std::optional<ObjectsMsg> freespace_objects_;
  size_t freespace_progress_ = 0;   // the car's pose index on freespace_path_
  bool freespace_holding_ = false;  // told the controller to hold
  int freespace_replans_ = 0;
  bool parking_planned_ = false;    // the planner has answered (path or not)
  bool path_driven_ = false;        // the controller says: driven to its end
  bool parking_completed_ = false;  // the planner has said: parked
  int manoeuvre_ = 0;      // the freespace planner's: turns made so far
  int turn_done_ = -1;     // topic: a three-point turn is made
  int parking_done_ = -1;  // topic: the controller drove its path's end
  std::unique_ptr<algo::ParkingFollower> parking_follower_;
  bool parking_mode_ = false;       // the follower drives the parking path
  bool parking_hold_ = false;       // ... and the planner said: hold
  int follower_leg_ = 0;            // the route leg the controller follows
  bool turn_entered_ = false;       // moved in the turn it drives
  bool path_end_reported_ = false;  // ... and has reported reaching its end
};

}  // namespace adse::stack::internal

#endif  // ADSE_STACK_NODES_INTERNAL_STACK_GRAPH_H_
