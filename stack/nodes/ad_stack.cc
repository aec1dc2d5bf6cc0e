#include "stack/nodes/ad_stack.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>
#include <optional>

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
#include "stack/nodes/objects.h"
#include "stack/nodes/pose_listener.h"

namespace adse::stack {
namespace {

namespace algo = adse::algorithms;

// Amdahl fractions of the data-parallel nodes: the share of their work that
// more threads speed up (ndt_omp-style scan matching; per-cluster work).
// PCL 1.13's NDT and clustering run serially on the host; their parallel
// speed-up on the virtual platform is this model, not a measurement.
constexpr double kNdtParallelFraction = 0.85;
constexpr double kClusteringParallelFraction = 0.6;
// Odometry samples the distortion corrector keeps (2 s at 50 Hz).
constexpr size_t kTwistHistory = 100;
// Queue of a tf listener's pose subscription (tf2_ros's /tf QoS depth).
constexpr int kTfListenerDepth = 100;
// Braking asked for while there is no valid pose to steer by.
constexpr double kNoPoseDecelMps2 = 3.0;

// Trajectory points as the planning and control algorithms take them; the
// speed can be capped on the way.
std::vector<algo::PlannedPoint> ToPlanned(
    const std::vector<TrajectoryPoint>& points, double max_v_mps = INFINITY) {
  std::vector<algo::PlannedPoint> out;
  out.reserve(points.size());
  for (const TrajectoryPoint& p : points) {
    algo::PlannedPoint q;
    q.x_m = p.x_m;
    q.y_m = p.y_m;
    q.yaw_rad = p.yaw_rad;
    q.s_m = p.s_m;
    q.v_mps = std::min(p.v_mps, max_v_mps);
    q.curvature_1pm = p.curvature_1pm;
    out.push_back(q);
  }
  return out;
}

std::vector<TrajectoryPoint> ToMessage(
    const std::vector<algo::PlannedPoint>& points) {
  std::vector<TrajectoryPoint> out;
  out.reserve(points.size());
  for (const algo::PlannedPoint& p : points) {
    out.push_back({p.x_m, p.y_m, p.yaw_rad, p.s_m, p.v_mps, p.curvature_1pm});
  }
  return out;
}

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
  void BuildParking(Graph* g);
  void PlanParking(CallbackContext& ctx, double course_out_m, int max_replans);
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
  std::deque<OdometryMsg> corrector_twists_;  // newest odometry samples
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
  int freespace_replans_ = 0;
  bool parking_planned_ = false;    // the planner has answered (path or not)
  bool path_driven_ = false;        // the controller says: driven to its end
  bool parking_completed_ = false;  // the planner has said: parked
  int parking_done_ = -1;  // topic: the controller drove its path's end
  std::unique_ptr<algo::ParkingFollower> parking_follower_;
  bool parking_mode_ = false;       // the follower drives the parking path
  bool path_end_reported_ = false;  // ... and has reported reaching its end
};

Status Stack::Build(Graph* g) {
  topics_.lidar_raw = g->AddTopic<PointCloudMsg>("/sensing/lidar/points_raw");
  topics_.odometry = g->AddTopic<OdometryMsg>("/sensing/odometry");
  points_ = g->AddTopic<PointCloudMsg>("/sensing/lidar/points");
  downsampled_ = g->AddTopic<PointCloudMsg>("/localization/points_downsampled");
  ndt_pose_ = g->AddTopic<PoseMsg>("/localization/ndt_pose");
  topics_.pose = g->AddTopic<PoseMsg>("/localization/pose");
  obstacle_points_ = g->AddTopic<PointCloudMsg>("/perception/obstacle_points");
  detections_ = g->AddTopic<ObjectsMsg>("/perception/detections");
  topics_.objects = g->AddTopic<ObjectsMsg>("/perception/objects");
  route_ = g->AddTopic<PathMsg>("/planning/route");
  path_ = g->AddTopic<TrajectoryMsg>("/planning/path");
  path_limited_ = g->AddTopic<TrajectoryMsg>("/planning/path_with_velocity");
  trajectory_raw_ = g->AddTopic<TrajectoryMsg>("/planning/trajectory_raw");
  topics_.trajectory = g->AddTopic<TrajectoryMsg>("/planning/trajectory");
  topics_.stop_reason = g->AddTopic<StopReasonMsg>("/planning/stop_reason");
  topics_.control = g->AddTopic<ControlMsg>("/control/command");
  BuildSensing(g);
  ADSE_RETURN_IF_ERROR(BuildLocalization(g));
  BuildPerception(g);
  BuildPlanning(g);
  if (inputs_.parking) BuildParking(g);
  BuildControl(g);
  return Status::Ok();
}

void Stack::BuildSensing(Graph* g) {
  // Autoware's top-LiDAR chain, one node per stage so the stages pipeline
  // across scans: driver (range crop) -> self crop -> mirror crop ->
  // distortion corrector -> ring outlier filter -> /sensing/lidar/points.
  const int raw = g->AddTopic<PointCloudMsg>("/sensing/lidar/pointcloud_raw");
  const int self_cropped =
      g->AddTopic<PointCloudMsg>("/sensing/lidar/self_cropped");
  const int mirror_cropped =
      g->AddTopic<PointCloudMsg>("/sensing/lidar/mirror_cropped");
  const int rectified = g->AddTopic<PointCloudMsg>("/sensing/lidar/rectified");

  // A stage that maps one cloud to another, reporting points in as work.
  auto add_stage = [g](const std::string& node_name,
                       const std::string& callback_name, int in_topic,
                       int out_topic,
                       std::function<algo::Points(const PointCloudMsg&)> run) {
    const int node = g->AddNode(node_name);
    g->Subscribe<PointCloudMsg>(
        node, in_topic, callback_name, 1,
        [run = std::move(run), out_topic](const PointCloudMsg& in,
                                          CallbackContext& ctx) {
          PointCloudMsg out;
          out.header = in.header;
          out.points = run(in);
          ctx.ReportWork({static_cast<double>(in.points.size()), 0.0, 1});
          ctx.Publish(out_topic, std::move(out));
        });
    return node;
  };

  // The driver: the sensor's range window and the z band; the ego body is
  // the self crop's job.
  const world::LidarParams lidar = config_.Lidar();
  algo::CropParams window;
  window.max_range_m = lidar.range_m;
  window.remove_ego = false;
  add_stage("lidar_driver", "points_raw", topics_.lidar_raw, raw,
            [window](const PointCloudMsg& in) {
              return algo::CropPoints(in.points, window);
            });

  // Returns off our own body, from rear to front bumper with a margin.
  const double rear_m =
      inputs_.wheelbase_m / 2 - inputs_.vehicle_length_m / 2 - 0.2;
  const double front_m =
      inputs_.wheelbase_m / 2 + inputs_.vehicle_length_m / 2 + 0.2;
  const double half_width_m = inputs_.vehicle_width_m / 2 + 0.2;
  const std::vector<algo::CropBox> self_box = {
      {rear_m, front_m, -half_width_m, half_width_m, -0.5, 2.5}};
  add_stage("crop_box_filter_self", "points", raw, self_cropped,
            [self_box](const PointCloudMsg& in) {
              return algo::RemoveInsideBoxes(in.points, self_box);
            });
  // The side mirrors, beside the A-pillars, just outside the body.
  const double mirror_x_m = inputs_.wheelbase_m * 0.55;
  const std::vector<algo::CropBox> mirror_boxes = {
      {mirror_x_m - 0.3, mirror_x_m + 0.3, half_width_m, half_width_m + 0.3,
       0.8, 1.4},
      {mirror_x_m - 0.3, mirror_x_m + 0.3, -half_width_m - 0.3, -half_width_m,
       0.8, 1.4}};
  add_stage("crop_box_filter_mirror", "points", self_cropped, mirror_cropped,
            [mirror_boxes](const PointCloudMsg& in) {
              return algo::RemoveInsideBoxes(in.points, mirror_boxes);
            });

  // Distortion corrector: the sweep's motion from the odometry sample
  // nearest the sweep's middle. Like Autoware's, it queues the twists (a
  // deeper queue, so a busy node still takes every sample in turn).
  algo::DistortionParams distortion;
  distortion.sweep_s = 1.0 / lidar.rate_hz;
  const int corrector = add_stage(
      "distortion_corrector", "points", mirror_cropped, rectified,
      [this, distortion](const PointCloudMsg& in) {
        const double middle_s = in.header.stamp_s + distortion.sweep_s / 2;
        geometry::Twist2 twist;
        double best_s = INFINITY;
        for (const OdometryMsg& o : corrector_twists_) {
          const double gap_s = std::abs(o.header.stamp_s - middle_s);
          if (gap_s < best_s) {
            best_s = gap_s;
            twist = {o.v_mps, o.yaw_rate_rps};
          }
        }
        return algo::CorrectDistortion(in.points, twist, distortion);
      });
  g->Subscribe<OdometryMsg>(corrector, topics_.odometry, "twist", 10,
                            [this](const OdometryMsg& in, CallbackContext&) {
                              corrector_twists_.push_back(in);
                              if (corrector_twists_.size() > kTwistHistory)
                                corrector_twists_.pop_front();
                            });

  algo::RingOutlierParams ring;
  ring.beams = lidar.beams;
  ring.fov_down_deg = lidar.vertical_fov_down_deg;
  ring.fov_up_deg = lidar.vertical_fov_up_deg;
  ring.sensor_height_m = lidar.mount_height_m;
  add_stage("ring_outlier_filter", "points", rectified, points_,
            [ring](const PointCloudMsg& in) {
              return algo::RemoveRingOutliers(in.points, ring);
            });
}

Status Stack::BuildLocalization(Graph* g) {
  // Voxel filter feeding the scan matcher.
  const double leaf = config_.Get("localization.voxel_leaf_m");
  const int voxel = g->AddNode("voxel_filter");
  g->Subscribe<PointCloudMsg>(
      voxel, points_, "points", 1,
      [this, leaf](const PointCloudMsg& in, CallbackContext& ctx) {
        PointCloudMsg out;
        out.header = in.header;
        out.points = algo::VoxelDownsample(in.points, leaf);
        ctx.ReportWork({static_cast<double>(in.points.size()), 0.0, 1});
        ctx.Publish(downsampled_, std::move(out));
      });

  // NDT scan matching against the map cloud, guessed from the EKF.
  algo::NdtParams ndt_params;
  ndt_params.resolution_m = config_.Get("localization.ndt_resolution_m");
  ndt_params.max_iterations =
      static_cast<int>(config_.Get("localization.ndt_max_iterations"));
  ndt_params.max_fitness_m2 = config_.Get("localization.ndt_max_fitness");
  ndt_ = std::make_unique<algo::NdtMatcher>(ndt_params);
  ADSE_RETURN_IF_ERROR(ndt_->SetMap(inputs_.map_cloud));
  const int threads = static_cast<int>(config_.Get("localization.ndt_threads"));
  const int ndt_node = g->AddNode("ndt_scan_matcher");
  // The initial-pose buffer runs in its own callback group (a node of its
  // own here), as in Autoware: a long alignment must not starve it, or the
  // next alignment starts from a stale guess.
  const int ndt_buffer = g->AddNode("ndt_scan_matcher_pose_buffer");
  g->Subscribe<PoseMsg>(
      ndt_buffer, topics_.pose, "ekf_pose", 1,
      [this](const PoseMsg& in, CallbackContext&) { ndt_poses_.Add(in); });
  g->Subscribe<PointCloudMsg>(
      ndt_node, downsampled_, "points", 1,
      [this, threads](const PointCloudMsg& in, CallbackContext& ctx) {
        // The EKF's poses interpolated to the scan's time (Autoware's
        // SmartPoseBuffer), moved on along the motion past the newest.
        const geometry::Pose2 guess =
            ndt_poses_.At(in.header.stamp_s).value_or(inputs_.initial_pose);
        Result<algo::NdtResult> r = ndt_->Align(in.points, guess);
        PoseMsg out;
        out.header = in.header;
        out.time_s = in.header.stamp_s;
        out.valid = r.ok() && r->accepted;
        if (r.ok()) {
          out.pose = r->pose;
          out.fitness = r->fitness_score_m2;
          ctx.ReportWork({static_cast<double>(r->work_units),
                          kNdtParallelFraction, threads});
        }
        out.covariance = ndt_->MatchCovariance();
        ctx.Publish(ndt_pose_, std::move(out));
      });

  // EKF: odometry prediction, NDT correction with delay compensation.
  algo::EkfParams ekf_params;
  ekf_params.lost_after_s = config_.Get("localization.lost_after_s");
  ekf_ = algo::Ekf(ekf_params);
  ekf_.Initialize(inputs_.initial_pose, 0.0, 0.0);
  const int ekf_node = g->AddNode("ekf_localizer");
  g->Subscribe<OdometryMsg>(
      ekf_node, topics_.odometry, "odometry", 10,
      [this](const OdometryMsg& in, CallbackContext& ctx) {
        ekf_.Predict(std::max(0.0, ctx.now_s() - ekf_last_t_));
        ekf_last_t_ = ctx.now_s();
        ekf_.UpdateOdometry(in.v_mps, in.yaw_rate_rps);
      });
  g->Subscribe<PoseMsg>(
      ekf_node, ndt_pose_, "ndt_pose", 1,
      [this](const PoseMsg& in, CallbackContext& ctx) {
        if (!in.valid) return;
        ekf_.Predict(std::max(0.0, ctx.now_s() - ekf_last_t_));
        ekf_last_t_ = ctx.now_s();
        // The match describes the scan's time, not now.
        if (ekf_.UpdateDelayedPose(in.pose, in.covariance, in.header.stamp_s))
          ekf_stamp_ = in.header.stamp_s;
      });
  g->AddTimer(ekf_node, "publish",
              1.0 / config_.Get("localization.ekf_rate_hz"),
              [this](CallbackContext& ctx) {
                ekf_.Predict(std::max(0.0, ctx.now_s() - ekf_last_t_));
                ekf_last_t_ = ctx.now_s();
                ekf_.RememberPose(ctx.now_s());
                PoseMsg out;
                out.header.stamp_s = ekf_stamp_;
                out.time_s = ctx.now_s();
                out.pose = ekf_.pose();
                out.v_mps = ekf_.v_mps();
                out.covariance = ekf_.PoseCovariance();
                out.valid = !ekf_.Lost();
                ctx.Publish(topics_.pose, std::move(out));
              });
  return Status::Ok();
}

void Stack::BuildPerception(Graph* g) {
  algo::GroundParams ground;
  ground.height_threshold_m = config_.Get("perception.ground_height_m");
  const double max_range = config_.Get("perception.max_range_m");
  algo::MapFilterParams map_params;
  map_params.ground_height_m = ground.height_threshold_m;
  map_filter_ = algo::MapFilter(map_params);
  map_filter_.SetMap(inputs_.map_cloud);
  const int ground_node = g->AddNode("ground_filter");
  // Autoware's filters look the pose up in tf, whose listener has its own
  // thread: in the scans' node a saturated filter starved it, and scans
  // were placed by poses a second old. tf2's subscription keeps 100.
  g->Subscribe<PoseMsg>(
      g->AddNode("ground_filter_tf_listener"), topics_.pose, "pose",
      kTfListenerDepth,
      [this](const PoseMsg& in, CallbackContext&) { ground_poses_.Add(in); });
  g->Subscribe<PointCloudMsg>(
      ground_node, points_, "points", 1,
      [this, ground, max_range](const PointCloudMsg& in, CallbackContext& ctx) {
        algo::GroundResult r = algo::RemoveGround(in.points, ground);
        std::vector<Eigen::Vector3f> near;
        const double r2 = max_range * max_range;
        for (const Eigen::Vector3f& p : r.obstacles) {
          if (p.x() * p.x() + p.y() * p.y() <= r2) near.push_back(p);
        }
        // What the static map explains (walls, poles, parked cars) is not
        // an object to stop for.
        PointCloudMsg out;
        out.header = in.header;
        out.points = map_filter_.Filter(
            near,
            ground_poses_.At(in.header.stamp_s).value_or(inputs_.initial_pose));
        ctx.ReportWork(
            {static_cast<double>(r.work_units + near.size()), 0.0, 1});
        ctx.Publish(obstacle_points_, std::move(out));
      });

  algo::ClusteringParams clustering;
  clustering.tolerance_m = config_.Get("perception.cluster_tolerance_m");
  clustering.min_points =
      static_cast<int>(config_.Get("perception.min_cluster_points"));
  const int threads = static_cast<int>(config_.Get("perception.threads"));
  const double max_object_m = config_.Get("perception.max_object_size_m");
  const int cluster_node = g->AddNode("euclidean_cluster");
  g->Subscribe<PoseMsg>(
      g->AddNode("euclidean_cluster_tf_listener"), topics_.pose, "pose",
      kTfListenerDepth,
      [this](const PoseMsg& in, CallbackContext&) { cluster_poses_.Add(in); });
  g->Subscribe<PointCloudMsg>(
      cluster_node, obstacle_points_, "points", 1,
      [this, clustering, threads, max_object_m](const PointCloudMsg& in,
                                                CallbackContext& ctx) {
        algo::DetectionResult r = algo::DetectObjects(in.points, clustering);
        ObjectsMsg out;
        out.header = in.header;
        const geometry::Pose2 pose =
            cluster_poses_.At(in.header.stamp_s).value_or(inputs_.initial_pose);
        for (const algo::Detection& d : r.detections) {
          // Clusters larger than any vehicle are static structure (a wall's
          // corner fits a box spanning the road); the map, not the object
          // list, describes them.
          if (std::max(d.length_m, d.width_m) > max_object_m) continue;
          out.objects.push_back(ObjectFromDetection(algo::ToMapFrame(d, pose)));
        }
        ctx.ReportWork({static_cast<double>(r.work_units),
                        kClusteringParallelFraction, threads});
        ctx.Publish(detections_, std::move(out));
      });

  // Autoware 2022.12's multi_object_tracker: its detections callback
  // associates and updates; its own timer predicts the tracks to the time
  // of publishing and publishes them (delay compensation), so objects reach
  // planning at the tracker's rate whatever the scan rate.
  tracker_ = std::make_unique<algo::Tracker>();
  const int tracker_node = g->AddNode("multi_object_tracker");
  g->Subscribe<ObjectsMsg>(
      tracker_node, detections_, "detections", 1,
      [this](const ObjectsMsg& in, CallbackContext& ctx) {
        std::vector<algo::Detection> detections;
        for (const TrackedObject& o : in.objects) {
          detections.push_back(DetectionFromObject(o));
        }
        tracker_->Update(in.header.stamp_s, detections);
        ctx.ReportWork(
            {static_cast<double>(tracker_->last_work_units()), 0.0, 1});
      });
  g->AddTimer(
      tracker_node, "publish", 1.0 / config_.Get("perception.tracker_rate_hz"),
      [this](CallbackContext& ctx) {
        // Nothing to report before the first scan's detections.
        if (!tracker_->has_time()) return;
        ObjectsMsg out;
        out.header.stamp_s = tracker_->last_update_s();
        for (const algo::Track& t : tracker_->ConfirmedTracksAt(ctx.now_s())) {
          out.objects.push_back(ObjectFromTrack(t));
        }
        ctx.ReportWork({static_cast<double>(out.objects.size()), 0.0, 1});
        ctx.Publish(topics_.objects, std::move(out));
      });
}

void Stack::BuildPlanning(Graph* g) {
  // Mission planner: the route from the map and the goal, published once.
  const int mission = g->AddNode("mission_planner");
  g->AddTimer(mission, "route", 1e6, [this](CallbackContext& ctx) {
    PathMsg out;
    out.header.stamp_s = -1.0;
    out.path = inputs_.route;
    ctx.ReportWork({static_cast<double>(inputs_.route.points.size()), 0.0, 1});
    ctx.Publish(route_, std::move(out));
  });

  // behavior_path_planner: the route ahead of the ego at the lane's limit.
  algo::PathPlannerParams path_params;
  path_params.horizon_m = config_.Get("planning.horizon_m");
  path_params.speed_limit_mps = inputs_.speed_limit_mps;
  path_planner_ = std::make_unique<algo::PathPlanner>(path_params);
  const int path_node = g->AddNode("behavior_path_planner");
  g->Subscribe<PathMsg>(path_node, route_, "route", 1,
                        [this](const PathMsg& in, CallbackContext&) {
                          path_planner_->SetRoute(in.path,
                                                  in.path.points.back());
                        });
  g->Subscribe<PoseMsg>(
      path_node, topics_.pose, "pose", 1,
      [this](const PoseMsg& in, CallbackContext&) { path_pose_ = in; });
  g->AddTimer(
      path_node, "plan", 1.0 / config_.Get("planning.rate_hz"),
      [this](CallbackContext& ctx) {
        TrajectoryMsg out;
        out.header.stamp_s = -1.0;
        // Without a route or a pose there is nothing to plan: an
        // empty path, so the stages downstream say so.
        if (path_planner_->has_route() && path_pose_) {
          const algo::PlannedPath path = path_planner_->Plan(path_pose_->pose);
          out.header.stamp_s = path_pose_->header.stamp_s;
          out.ends_at_goal = path.ends_at_goal;
          out.localization_lost = !path_pose_->valid;
          out.ego_v_mps = path_pose_->v_mps;
          out.points = ToMessage(path.points);
          ctx.ReportWork({static_cast<double>(path.work_units), 0.0, 1});
        }
        ctx.Publish(path_, std::move(out));
      });

  // behavior_velocity_planner: speed limits along the path, 0 at the goal.
  algo::VelocityLimitParams limits;
  limits.max_lateral_accel_mps2 =
      config_.Get("planning.max_lateral_accel_mps2");
  const int velocity_node = g->AddNode("behavior_velocity_planner");
  g->Subscribe<TrajectoryMsg>(
      velocity_node, path_, "path", 1,
      [this, limits](const TrajectoryMsg& in, CallbackContext& ctx) {
        std::vector<algo::PlannedPoint> points = ToPlanned(in.points);
        int64_t work = algo::LimitVelocity(&points, in.ends_at_goal, limits);
        TrajectoryMsg out = in;
        if (traffic_light_) {
          const algo::SignalStop stop = traffic_light_->Apply(
              ctx.now_s(), in.header.stamp_s, in.ego_v_mps, &points);
          out.signal_stop = stop.stop;
          out.signal_stop_s_m = stop.stop_s_m;
          work += stop.work_units;
        }
        out.points = ToMessage(points);
        ctx.ReportWork({static_cast<double>(work), 0.0, 1});
        ctx.Publish(path_limited_, std::move(out));
      });
  if (inputs_.traffic_signals) {
    // Autoware's traffic-light module: the detector's signal ahead, a stop
    // at its line (the detector is the world's sensor, never SUMO here).
    topics_.traffic_signal =
        g->AddTopic<TrafficSignalMsg>("/perception/traffic_signal");
    algo::TrafficLightParams signal_params;
    signal_params.state_timeout_s =
        config_.Get("traffic_light.state_timeout_s");
    signal_params.unknown_wait_s = config_.Get("traffic_light.unknown_wait_s");
    signal_params.max_red_wait_s = config_.Get("traffic_light.max_red_wait_s");
    signal_params.stop_margin_m = config_.Get("traffic_light.stop_margin_m");
    signal_params.ego_front_m =
        inputs_.wheelbase_m / 2 + inputs_.vehicle_length_m / 2;
    signal_params.max_decel_mps2 = config_.Get("planning.max_decel_mps2");
    traffic_light_ = std::make_unique<algo::TrafficLightPlanner>(signal_params);
    g->Subscribe<TrafficSignalMsg>(
        velocity_node, topics_.traffic_signal, "traffic_signal", 1,
        [this](const TrafficSignalMsg& in, CallbackContext&) {
          traffic_light_->Observe({in.header.stamp_s, in.state,
                                   in.stop_line_distance_m, in.tls_id});
        });
  }

  // obstacle_stop_planner: a stop before the nearest object in the path's
  // corridor.
  algo::ObstacleStopParams stop_params;
  stop_params.corridor_half_width_m =
      config_.Get("planning.corridor_half_width_m");
  stop_params.stop_margin_m = config_.Get("planning.stop_margin_m");
  stop_params.ego_front_m =
      inputs_.wheelbase_m / 2 + inputs_.vehicle_length_m / 2;
  algo::CrossingYieldParams yield_params;
  yield_params.horizon_s = config_.Get("planning.yield_horizon_s");
  yield_params.max_decel_mps2 = config_.Get("planning.max_decel_mps2");
  yield_params.max_accel_mps2 = config_.Get("planning.max_accel_mps2");
  crossing_yield_ = std::make_unique<algo::CrossingYielder>(yield_params);
  // Autoware's lane change is a behavior_path_planner module; here it sits
  // beside the crossing yield, which has the objects.
  algo::LaneChangeParams lane_change_params;
  lane_change_params.ego_front_m = stop_params.ego_front_m;
  lane_change_params.ego_rear_m =
      inputs_.vehicle_length_m / 2 - inputs_.wheelbase_m / 2;
  lane_change_params.max_accel_mps2 = config_.Get("planning.max_accel_mps2");
  lane_change_params.max_decel_mps2 = config_.Get("planning.max_decel_mps2");
  lane_change_ = std::make_unique<algo::LaneChangeGuard>(
      inputs_.route, inputs_.lane_changes, lane_change_params);
  structure_grid_.SetMap(inputs_.map_cloud);
  const int stop_node = g->AddNode("obstacle_stop_planner");
  g->Subscribe<ObjectsMsg>(
      stop_node, topics_.objects, "objects", 1,
      [this](const ObjectsMsg& in, CallbackContext&) { stop_objects_ = in; });
  g->Subscribe<TrajectoryMsg>(
      stop_node, path_limited_, "trajectory", 1,
      [this, stop_params](const TrajectoryMsg& in, CallbackContext& ctx) {
        std::vector<algo::PlannerObstacle> obstacles;
        if (stop_objects_) {
          for (const TrackedObject& o : stop_objects_->objects) {
            obstacles.push_back(ObstacleFromObject(o));
          }
        }
        std::vector<algo::PlannedPoint> points = ToPlanned(in.points);
        const algo::ObstacleStop in_path =
            algo::InsertObstacleStop(&points, obstacles, stop_params);
        const algo::ObstacleStop crossing = crossing_yield_->Plan(
            &points, obstacles, in.ego_v_mps, ctx.now_s(), stop_params);
        const algo::ObstacleStop lane_change =
            lane_change_->Plan(&points, obstacles, in.ego_v_mps, ctx.now_s());
        algo::ObstacleStop stop =
            algo::NearerStop(algo::NearerStop(in_path, crossing), lane_change);
        // Whether the map has structure there matters only for the object
        // stopped for.
        if (stop.obstacle_id >= 0) {
          for (const algo::PlannerObstacle& ob : obstacles) {
            if (ob.id != stop.obstacle_id) continue;
            stop.static_structure = structure_grid_.IsStructure(
                ob.position, ob.length_m, ob.width_m, ob.yaw_rad);
            break;
          }
        }
        const algo::StopDecision decision = algo::DecideStop(
            &points, in.ends_at_goal, in.localization_lost, stop,
            in.signal_stop ? std::optional<double>(in.signal_stop_s_m)
                           : std::nullopt);
        TrajectoryMsg out = in;
        out.points = ToMessage(points);
        out.header.perception_stamp_s =
            stop_objects_ ? stop_objects_->header.stamp_s : -1.0;
        out.stop.header = in.header;
        out.stop.reason = decision.reason;
        out.stop.stop_distance_m = decision.distance_m;
        out.stop.track_id = decision.obstacle_id;
        out.stop.obstacle_gap_m = decision.obstacle_gap_m;
        out.stop.static_structure = decision.static_structure;
        ctx.ReportWork(
            {static_cast<double>(in_path.work_units + crossing.work_units +
                                 lane_change.work_units),
             0.0, 1});
        ctx.Publish(topics_.stop_reason, out.stop);
        ctx.Publish(trajectory_raw_, std::move(out));
      });

  algo::SmootherParams smoother;
  smoother.max_accel_mps2 = config_.Get("planning.max_accel_mps2");
  smoother.max_decel_mps2 = config_.Get("planning.max_decel_mps2");
  const int smoother_node = g->AddNode("velocity_smoother");
  g->Subscribe<PoseMsg>(
      smoother_node, topics_.pose, "pose", 1,
      [this](const PoseMsg& in, CallbackContext&) { smoother_pose_ = in; });
  g->Subscribe<TrajectoryMsg>(
      smoother_node, trajectory_raw_, "trajectory", 1,
      [this, smoother](const TrajectoryMsg& in, CallbackContext& ctx) {
        std::vector<algo::PlannedPoint> points = ToPlanned(in.points);
        algo::SmoothVelocity(
            &points, smoother_pose_ ? smoother_pose_->v_mps : 0.0, smoother);
        TrajectoryMsg out = in;
        for (size_t i = 0; i < points.size(); ++i)
          out.points[i].v_mps = points[i].v_mps;
        ctx.ReportWork({static_cast<double>(points.size()), 0.0, 1});
        ctx.Publish(topics_.trajectory, std::move(out));
      });
}

void Stack::BuildParking(Graph* g) {
  // Autoware's parking scenario: once the car stands at the end of its
  // road route (on the aisle beside the slot), the freespace planner plans
  // the manoeuvre into the slot from the localization pose; again from
  // where it stands whenever the car has left that path's course, or has
  // driven it to its end outside the goal's tolerances. It says when the
  // car is parked (Autoware's is_completed).
  topics_.parking_path =
      g->AddTopic<ParkingPathMsg>("/planning/scenario_planning/parking/path");
  topics_.parking_completed = g->AddTopic<ParkingDoneMsg>(
      "/planning/scenario_planning/parking/is_completed");
  parking_done_ = g->AddTopic<ParkingDoneMsg>("/control/parking_done");
  algo::FreespacePlannerParams params;
  params.turning_radius_m = config_.Get("parking.turning_radius_m");
  params.max_expansions =
      static_cast<int>(config_.Get("parking.max_expansions"));
  params.collision_margin_m = config_.Get("parking.collision_margin_m");
  freespace_ = std::make_unique<algo::FreespacePlanner>(
      params,
      algo::FootprintOfBody(inputs_.vehicle_length_m, inputs_.wheelbase_m,
                            inputs_.vehicle_width_m));
  const int node = g->AddNode("freespace_planner");
  g->Subscribe<PoseMsg>(
      node, topics_.pose, "pose", 1,
      [this](const PoseMsg& in, CallbackContext&) { freespace_pose_ = in; });
  g->Subscribe<ParkingDoneMsg>(
      node, parking_done_, "parking_done", 1,
      [this](const ParkingDoneMsg&, CallbackContext&) { path_driven_ = true; });
  const double course_out_m = config_.Get("parking.course_out_m");
  const int max_replans = static_cast<int>(config_.Get("parking.max_replans"));
  g->AddTimer(node, "plan", 1.0 / config_.Get("parking.rate_hz"),
              [this, course_out_m, max_replans](CallbackContext& ctx) {
                PlanParking(ctx, course_out_m, max_replans);
              });
}

void Stack::PlanParking(CallbackContext& ctx, double course_out_m,
                        int max_replans) {
  if (parking_completed_ || !freespace_pose_ || !freespace_pose_->valid) return;
  const geometry::Pose2& pose = freespace_pose_->pose;
  const Eigen::Vector2d at(pose.x_m, pose.y_m);
  const bool standing = std::abs(freespace_pose_->v_mps) < 0.1;
  const double stamp_s = freespace_pose_->header.stamp_s;
  auto complete = [&] {
    parking_completed_ = true;
    ParkingDoneMsg done;
    done.header.stamp_s = stamp_s;
    ctx.Publish(topics_.parking_completed, std::move(done));
  };
  ParkingPathMsg out;
  out.header.stamp_s = stamp_s;
  bool correcting = false;
  if (!parking_planned_) {
    // Handed over when standing within reach of the route's end.
    const Eigen::Vector2d end = inputs_.route.points.back();
    if (!standing ||
        (at - end).norm() > std::max(3.0, inputs_.goal_tolerance_m))
      return;
    parking_planned_ = true;
  } else if (path_driven_) {
    // At the path's end: parked if the stack's pose is within the goal's
    // tolerances, or if no re-plan is left; otherwise a new path from
    // here corrects it.
    path_driven_ = false;
    if (geometry::WithinTolerance(pose, inputs_.parking_goal,
                                  inputs_.goal_tolerance_m,
                                  inputs_.goal_yaw_tolerance_rad) ||
        freespace_replans_ == max_replans) {
      complete();
      return;
    }
    ++freespace_replans_;
    correcting = true;
  } else {
    // Standing off the course of its path (where the controller holds
    // it), the car gets a new path from there.
    if (freespace_path_.empty() || course_out_m <= 0 || !standing) return;
    const double off_m = algo::DistanceFromPath(freespace_path_, at);
    if (off_m <= course_out_m) return;
    if (freespace_replans_ == max_replans) {
      out.found = false;
      out.failure = fmt::format(
          "off the course of its path ({:.2f} m > parking.course_out_m) "
          "after {} re-plans (parking.max_replans)",
          off_m, max_replans);
      freespace_path_.clear();
      ctx.Publish(topics_.parking_path, std::move(out));
      return;
    }
    ++freespace_replans_;
  }
  const Result<algo::FreespacePath> path =
      freespace_->Plan(pose, inputs_.parking_goal, inputs_.parking_obstacles);
  ctx.ReportWork(
      {static_cast<double>(freespace_->last_stats().work_units), 0.0, 1});
  if (!path.ok() && correcting) {
    // No way to the goal from where it stands: parked there, off the goal
    // (the planner's failure would end the run as no_path).
    complete();
    return;
  }
  out.found = path.ok();
  out.expansions = freespace_->last_stats().expansions;
  if (path.ok()) {
    freespace_path_ = path->poses;
    for (const algo::GearedPose& p : path->poses) {
      out.poses.push_back({p.pose.x_m, p.pose.y_m, p.pose.yaw_rad, p.reverse});
    }
  } else {
    freespace_path_.clear();
    out.failure = path.status().message();
  }
  ctx.Publish(topics_.parking_path, std::move(out));
}

void Stack::Park(CallbackContext& ctx, double dt_s, double speed_cap_mps,
                 ControlMsg* out) {
  const algo::ParkingCommand c = parking_follower_->Update(
      follower_pose_->pose, follower_pose_->v_mps, dt_s, speed_cap_mps);
  out->accel_mps2 = c.accel_mps2;
  out->steer_rad = c.steer_rad;
  out->reverse = c.reverse;
  ctx.ReportWork({1.0, 0.0, 1});
  if (c.finished && !path_end_reported_) {
    // Once per path: the car stands at its end (the planner decides
    // whether that is parked).
    path_end_reported_ = true;
    ParkingDoneMsg done;
    done.header.stamp_s = out->header.stamp_s;
    ctx.Publish(parking_done_, std::move(done));
  }
  ctx.Publish(topics_.control, std::move(*out));
}

void Stack::BuildControl(Graph* g) {
  algo::FollowerParams params;
  params.pure_pursuit.wheelbase_m = inputs_.wheelbase_m;
  follower_ = std::make_unique<algo::TrajectoryFollower>(params);
  const int node = g->AddNode("trajectory_follower");
  g->Subscribe<PoseMsg>(
      node, topics_.pose, "pose", 1,
      [this](const PoseMsg& in, CallbackContext&) { follower_pose_ = in; });
  g->Subscribe<TrajectoryMsg>(
      node, topics_.trajectory, "trajectory", 1,
      [this](const TrajectoryMsg& in, CallbackContext&) {
        follower_trajectory_ = in;
      });
  if (inputs_.parking) {
    algo::ParkingFollowerParams parking;
    parking.wheelbase_m = inputs_.wheelbase_m;
    parking.forward_speed_mps = config_.Get("parking.forward_speed_mps");
    parking.reverse_speed_mps = config_.Get("parking.reverse_speed_mps");
    parking.course_out_m = config_.Get("parking.course_out_m");
    parking_follower_ = std::make_unique<algo::ParkingFollower>(parking);
    g->Subscribe<ParkingPathMsg>(
        node, topics_.parking_path, "parking_path", 1,
        [this](const ParkingPathMsg& in, CallbackContext&) {
          if (!in.found) return;
          std::vector<algo::GearedPose> poses;
          for (const ParkingPathPoint& p : in.poses)
            poses.push_back({{p.x_m, p.y_m, p.yaw_rad}, p.reverse});
          parking_follower_->SetPath(poses);
          parking_mode_ = true;
          path_end_reported_ = false;
        });
  }
  const double max_travel_per_fix_m =
      config_.Get("control.max_travel_per_fix_m");
  g->AddTimer(node, "control", 1.0 / config_.Get("control.rate_hz"),
              [this, max_travel_per_fix_m](CallbackContext& ctx) {
                ControlMsg out;
                out.header.stamp_s =
                    follower_pose_ ? follower_pose_->header.stamp_s : -1.0;
                const double dt =
                    follower_last_t_ < 0 ? 0.0 : ctx.now_s() - follower_last_t_;
                follower_last_t_ = ctx.now_s();
                if (!follower_pose_ || !follower_pose_->valid) {
                  // Nothing to steer by: ask for a stop.
                  out.accel_mps2 = -kNoPoseDecelMps2;
                } else {
                  // Degraded mode: drive no faster than lets the car cover
                  // max_travel_per_fix_m between localization fixes, so a slow
                  // scan matcher still gets a close initial guess (the stack
                  // slows down rather than losing itself).
                  const double fix_age =
                      ctx.now_s() - follower_pose_->header.stamp_s;
                  const double speed_cap =
                      follower_pose_->header.stamp_s < 0
                          ? 0.0
                          : max_travel_per_fix_m / std::max(fix_age, 1e-3);
                  if (parking_mode_) return Park(ctx, dt, speed_cap, &out);
                  const std::vector<algo::PlannedPoint> points =
                      follower_trajectory_
                          ? ToPlanned(follower_trajectory_->points, speed_cap)
                          : std::vector<algo::PlannedPoint>{};
                  const algo::FollowerCommand c = follower_->Update(
                      follower_pose_->pose, follower_pose_->v_mps, points, dt);
                  if (follower_trajectory_) {
                    out.header.perception_stamp_s =
                        follower_trajectory_->header.perception_stamp_s;
                  }
                  out.accel_mps2 = c.accel_mps2;
                  out.steer_rad = c.steer_rad;
                  ctx.ReportWork({static_cast<double>(points.size()), 0.0, 1});
                }
                ctx.Publish(topics_.control, std::move(out));
              });
}

}  // namespace

Result<std::unique_ptr<AdStack>> AdStack::Build(const StackConfig& config,
                                                const StackInputs& inputs,
                                                Graph* graph) {
  if (inputs.route.points.size() < 2) {
    return Status::InvalidArgument(
        "the stack needs a route of at least two points");
  }
  if (inputs.map_cloud.empty()) {
    return Status::InvalidArgument("the stack needs a localization map cloud");
  }
  auto stack = std::make_unique<Stack>(config, inputs);
  ADSE_RETURN_IF_ERROR(stack->Build(graph));
  return std::unique_ptr<AdStack>(std::move(stack));
}

}  // namespace adse::stack
