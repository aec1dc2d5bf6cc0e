// The stack's node graph: its topics, the sensing, localization and
// perception nodes, and AdStack::Build (planning, parking and control are
// in ad_stack_planning.cc).
#include "stack/nodes/ad_stack.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "stack/nodes/internal/stack_graph.h"
#include "stack/nodes/objects.h"

namespace adse::stack {
namespace internal {
namespace {

// Amdahl fractions of the data-parallel nodes: the share of their work that
// more threads speed up (ndt_omp-style scan matching; per-cluster work).
// PCL 1.13's NDT and clustering run serially on the host; their parallel
// speed-up on the virtual platform is this model, not a measurement.
constexpr double kNdtParallelFraction = 0.85;
constexpr double kClusteringParallelFraction = 0.6;
// Queue of a tf listener's pose subscription (tf2_ros's /tf QoS depth).
constexpr int kTfListenerDepth = 100;

}  // namespace

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
  if (inputs_.parking || !inputs_.turnarounds.empty()) BuildManoeuvres(g);
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
  // nearest the sweep's middle.
  algo::DistortionParams distortion;
  distortion.sweep_s = 1.0 / lidar.rate_hz;
  corrector_twists_ = algo::TwistHistory(distortion.twist_history);
  const int corrector =
      add_stage("distortion_corrector", "points", mirror_cropped, rectified,
                [this, distortion](const PointCloudMsg& in) {
                  return algo::CorrectDistortion(
                      in.points,
                      corrector_twists_.Nearest(in.header.stamp_s +
                                                distortion.sweep_s / 2),
                      distortion);
                });
  g->Subscribe<OdometryMsg>(
      corrector, topics_.odometry, "twist", 10,
      [this](const OdometryMsg& in, CallbackContext&) {
        corrector_twists_.Add(in.header.stamp_s, {in.v_mps, in.yaw_rate_rps});
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

}  // namespace internal

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
  auto stack = std::make_unique<internal::Stack>(config, inputs);
  ADSE_RETURN_IF_ERROR(stack->Build(graph));
  return std::unique_ptr<AdStack>(std::move(stack));
}

}  // namespace adse::stack
