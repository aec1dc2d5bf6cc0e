// The planning, parking and control nodes of the stack's graph.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "stack/nodes/internal/stack_graph.h"
#include "stack/nodes/objects.h"

namespace adse::stack::internal {
namespace {

// Braking asked for while there is no valid pose to steer by.
constexpr double kNoPoseDecelMps2 = 3.0;
// A three-point turn has ended within this of its goal on the lane (the
// path takes the car on from there).
constexpr double kTurnToleranceM = 1.0;
constexpr double kTurnYawToleranceRad = 0.35;
// ... or on its lane up to this far past it.
constexpr double kTurnAheadM = 5.0;
// The freespace planner minds the road users this close to the car.
constexpr double kManoeuvreObjectRangeM = 30.0;
// A move counts as blocked when a road user comes within this share of
// the margin a plan keeps: a tracked box that wobbles by a few centimetres
// does not make the planner plan again and again.
constexpr double kBlockedMarginShare = 0.5;
// How far on along its path (in poses) the car is looked for each time.
constexpr size_t kProgressWindowPoses = 8;
// Slower than this the car stands (the planner hands a turn over to the
// freespace planner only then).
constexpr double kStandingMps = 0.1;

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

}  // namespace

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
                          EndRouteLeg();
                        });
  if (!inputs_.turnarounds.empty()) {
    // A route with three-point turns: the freespace planner says when the
    // car has turned, and the path goes on from there.
    turn_done_ = g->AddTopic<ParkingDoneMsg>("/planning/turnaround/completed");
    g->Subscribe<ParkingDoneMsg>(
        path_node, turn_done_, "turnaround_done", 1,
        [this](const ParkingDoneMsg& in, CallbackContext&) {
          if (in.turnaround != route_leg_) return;
          const algo::TurnaroundSection& turn = inputs_.turnarounds[route_leg_];
          path_planner_->ResumeAt(in.on_lanes ? turn.start_s_m : turn.end_s_m);
          ++route_leg_;
          EndRouteLeg();
        });
  }
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
          out.route_leg = route_leg_;
          out.localization_lost = !path_pose_->valid;
          out.ego_v_mps = path_pose_->v_mps;
          out.ego_pose = path_pose_->pose;
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
          // A leg that ends at a turn in several moves ends short of the
          // junction the turn goes through.
          const bool ends_for_turn =
              in.ends_at_goal &&
              in.route_leg < static_cast<int>(inputs_.turnarounds.size());
          const algo::SignalStop stop =
              traffic_light_->Apply(ctx.now_s(), in.header.stamp_s,
                                    in.ego_v_mps, &points, ends_for_turn);
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
  stop_params.ego_half_width_m = inputs_.vehicle_width_m / 2;
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
  // The way the controller would drive off from where the car stands.
  const algo::PurePursuit pursuit(FollowerParams().pure_pursuit);
  g->Subscribe<TrajectoryMsg>(
      stop_node, path_limited_, "trajectory", 1,
      [this, stop_params, pursuit](const TrajectoryMsg& in,
                                   CallbackContext& ctx) {
        std::vector<algo::PlannerObstacle> obstacles;
        if (stop_objects_) {
          for (const TrackedObject& o : stop_objects_->objects) {
            obstacles.push_back(ObstacleFromObject(o));
          }
        }
        std::vector<algo::PlannedPoint> points = ToPlanned(in.points);
        const algo::ObstacleStop in_path = algo::InsertObstacleStop(
            &points, obstacles,
            [&] {
              return pursuit.Rollout(in.ego_pose, points,
                                     stop_params.drive_off_m,
                                     stop_params.footprint_step_m);
            },
            stop_params);
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
        algo::StopDecision decision = algo::DecideStop(
            &points, in.ends_at_goal, in.localization_lost, stop,
            in.signal_stop ? std::optional<double>(in.signal_stop_s_m)
                           : std::nullopt);
        // The path of a leg that ends at a three-point turn ends there.
        if (decision.reason == StopReason::kGoal &&
            in.route_leg < static_cast<int>(inputs_.turnarounds.size())) {
          decision.reason = StopReason::kTurnaround;
        }
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

void Stack::EndRouteLeg() {
  if (route_leg_ < static_cast<int>(inputs_.turnarounds.size())) {
    path_planner_->EndAt(inputs_.turnarounds[route_leg_].start_s_m);
  }
}

void Stack::BuildManoeuvres(Graph* g) {
  // Autoware's parking scenario: once the car stands at the end of its
  // road route (on the aisle beside the slot), the freespace planner plans
  // the manoeuvre into the slot from the localization pose; again from
  // where it stands whenever the car has left that path's course, or has
  // driven it to its end outside the goal's tolerances. It says when the
  // car is parked (Autoware's is_completed). A three-point turn on the
  // route is planned and driven the same way, from where the route's leg
  // ends to the turn's goal within the road's lanes and junctions; it
  // says when the car has turned.
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
  g->Subscribe<ObjectsMsg>(node, topics_.objects, "objects", 1,
                           [this](const ObjectsMsg& in, CallbackContext&) {
                             freespace_objects_ = in;
                           });
  const double course_out_m = config_.Get("parking.course_out_m");
  const int max_replans = static_cast<int>(config_.Get("parking.max_replans"));
  g->AddTimer(node, "plan", 1.0 / config_.Get("parking.rate_hz"),
              [this, course_out_m, max_replans](CallbackContext& ctx) {
                PlanManoeuvre(ctx, course_out_m, max_replans);
              });
}

void Stack::PlanManoeuvre(CallbackContext& ctx, double course_out_m,
                          int max_replans) {
  if (parking_completed_ || !freespace_pose_ || !freespace_pose_->valid) return;
  const int turns = static_cast<int>(inputs_.turnarounds.size());
  if (manoeuvre_ == turns && !inputs_.parking) return;  // all turns made
  // The manoeuvre now: the next three-point turn, then the parking.
  const bool turning = manoeuvre_ < turns;
  const algo::TurnaroundSection* turn =
      turning ? &inputs_.turnarounds[manoeuvre_] : nullptr;
  const geometry::Pose2& goal = turning ? turn->goal : inputs_.parking_goal;
  const geometry::Pose2& pose = freespace_pose_->pose;
  const Eigen::Vector2d at(pose.x_m, pose.y_m);
  const bool standing = std::abs(freespace_pose_->v_mps) < kStandingMps;
  const double stamp_s = freespace_pose_->header.stamp_s;
  // The road users about the car, as its own outlines: the map's
  // structure is among the manoeuvre's obstacles already.
  std::vector<geometry::OrientedBox> others;
  const std::vector<std::vector<Eigen::Vector2d>>& map_obstacles =
      turning ? turn->obstacles : inputs_.parking_obstacles;
  if (freespace_objects_) {
    for (const TrackedObject& o : freespace_objects_->objects) {
      if ((o.position - at).norm() > kManoeuvreObjectRangeM ||
          structure_grid_.IsStructure(o.position, o.length_m, o.width_m,
                                      o.yaw_rad)) {
        continue;
      }
      geometry::OrientedBox box;
      box.center = o.position;
      box.yaw_rad = o.yaw_rad;
      box.length_m = o.length_m;
      box.width_m = o.width_m;
      others.push_back(box);
    }
  }
  auto complete = [&](bool on_lanes = false) {
    ParkingDoneMsg done;
    done.header.stamp_s = stamp_s;
    done.on_lanes = on_lanes;
    if (!turning) {
      parking_completed_ = true;
      ctx.Publish(topics_.parking_completed, std::move(done));
      return;
    }
    // Turned: the path goes on, and the next manoeuvre starts afresh.
    done.turnaround = manoeuvre_++;
    parking_planned_ = false;
    path_driven_ = false;
    freespace_replans_ = 0;
    freespace_path_.clear();
    freespace_holding_ = false;
    ctx.Publish(turn_done_, std::move(done));
  };
  ParkingPathMsg out;
  out.header.stamp_s = stamp_s;
  bool correcting = false;
  bool round_road_user = false;  // planning round a road user in the way
  const bool first_plan = !parking_planned_;
  const bool on_departing_lane =
      turning &&
      geometry::WithinToleranceOrAhead(pose, goal, kTurnToleranceM, kTurnAheadM,
                                       kTurnYawToleranceRad);
  if (!parking_planned_) {
    // Handed over when standing within reach of where the route's leg
    // ends (the route's end, or the turn's start).
    const Eigen::Vector2d end = turning ? inputs_.route.PointAt(turn->start_s_m)
                                        : inputs_.route.points.back();
    if (!standing ||
        (at - end).norm() > std::max(3.0, inputs_.goal_tolerance_m))
      return;
    parking_planned_ = true;
  } else if (turning && standing && on_departing_lane) {
    // Standing on the lane it turns onto, at the path's end or before it
    // (at a cusp, or held by a road user), it has turned. Moving on
    // instead, it backed towards the cars that had queued on that lane
    // behind its goal and stood held by them until the stall timeout (the
    // bench's A10KW-0 of its third seed, 3.1 m past its goal, 0.9 m off
    // its line).
    complete();
    return;
  } else if (path_driven_) {
    // At the path's end: parked (turned) if the stack's pose is within the
    // goal's tolerances, or if no re-plan is left; otherwise a new path
    // from here corrects it.
    path_driven_ = false;
    const bool there = turning ? on_departing_lane
                               : geometry::WithinTolerance(
                                     pose, goal, inputs_.goal_tolerance_m,
                                     inputs_.goal_yaw_tolerance_rad);
    if (there || freespace_replans_ == max_replans) {
      complete();
      return;
    }
    ++freespace_replans_;
    correcting = true;
  } else {
    // A road user in the way of the move under way: a path round it from
    // here, or, while there is none, the car holds where it is (not
    // counted against parking.max_replans).
    if (!freespace_holding_ && !freespace_path_.empty()) {
      const size_t end = std::min(freespace_path_.size(),
                                  freespace_progress_ + kProgressWindowPoses);
      double nearest_m = INFINITY;
      for (size_t i = freespace_progress_; i < end; ++i) {
        const geometry::Pose2& p = freespace_path_[i].pose;
        const double d_m = (Eigen::Vector2d(p.x_m, p.y_m) - at).norm();
        if (d_m < nearest_m) {
          nearest_m = d_m;
          freespace_progress_ = i;
        }
      }
    }
    round_road_user = freespace_holding_ ||
                      (!freespace_path_.empty() &&
                       algo::FirstBlockedPose(
                           freespace_path_, freespace_progress_, others,
                           freespace_->footprint(),
                           kBlockedMarginShare *
                               freespace_->params().collision_margin_m) >= 0);
    // Standing off the course of its path (where the controller holds
    // it), the car gets a new path from there.
    if (!round_road_user) {
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
  }
  auto plan = [&](const std::vector<std::vector<Eigen::Vector2d>>& among) {
    Result<algo::FreespacePath> found =
        turning ? freespace_->Plan(pose, goal, among, turn->drivable)
                : freespace_->Plan(pose, goal, among);
    ctx.ReportWork(
        {static_cast<double>(freespace_->last_stats().work_units), 0.0, 1});
    return found;
  };
  // Copied only when a plan is made, not at every tick.
  std::vector<std::vector<Eigen::Vector2d>> obstacles = map_obstacles;
  for (const geometry::OrientedBox& box : others) {
    obstacles.push_back(geometry::BoxCorners(box));
  }
  const Result<algo::FreespacePath> path = plan(obstacles);
  out.expansions = freespace_->last_stats().expansions;
  freespace_progress_ = 0;
  if (!path.ok() && !round_road_user && !others.empty()) {
    // Only road users in the way (a way leads on without them): they
    // hold the car rather than end its run.
    round_road_user = plan(map_obstacles).ok();
  }
  if (!path.ok() && round_road_user) {
    // No way round yet: the car holds (told once) and the planner tries
    // again at its next tick.
    freespace_path_.clear();
    if (freespace_holding_) return;
    freespace_holding_ = true;
    out.found = true;
    out.hold = true;
    ctx.Publish(topics_.parking_path, std::move(out));
    return;
  }
  freespace_holding_ = false;
  if (!path.ok() && turning && turn->corner && first_plan) {
    // No manoeuvre round the corner from where the car stands (a little
    // off the pose the world planned from; on pasubio's narrow streets
    // that left it boxed in by the map's poles): on along the lanes, as
    // before corners were turned, rather than end the run.
    complete(/*on_lanes=*/true);
    return;
  }
  if (!path.ok() && correcting) {
    // No way to the goal from where it stands: parked (turned) there, off
    // the goal (the planner's failure would end the run as no_path).
    complete();
    return;
  }
  out.found = path.ok();
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
  algo::ParkingCommand c = parking_follower_->Update(
      follower_pose_->pose, follower_pose_->v_mps, dt_s, speed_cap_mps);
  // A turn in several moves starts only once its signal lets the car into
  // the junction: until the car first moves, the planner's signal stop at
  // the leg's end holds it (once in, it turns on whatever the signal
  // shows, as a car in a junction clears it).
  const bool turning =
      follower_leg_ < static_cast<int>(inputs_.turnarounds.size());
  if (std::abs(follower_pose_->v_mps) >= kStandingMps) turn_entered_ = true;
  const bool signal_holds = turning && !turn_entered_ && follower_trajectory_ &&
                            follower_trajectory_->route_leg == follower_leg_ &&
                            follower_trajectory_->signal_stop;
  if (parking_hold_ || signal_holds) {
    // A road user in the way, or the signal: brake to a stand in the gear
    // it drives.
    c.accel_mps2 = -parking_follower_->params().max_brake_mps2;
    c.finished = false;
  }
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

algo::FollowerParams Stack::FollowerParams() const {
  algo::FollowerParams params;
  params.pure_pursuit.wheelbase_m = inputs_.wheelbase_m;
  return params;
}

void Stack::BuildControl(Graph* g) {
  follower_ = std::make_unique<algo::TrajectoryFollower>(FollowerParams());
  const int node = g->AddNode("trajectory_follower");
  g->Subscribe<PoseMsg>(
      node, topics_.pose, "pose", 1,
      [this](const PoseMsg& in, CallbackContext&) { follower_pose_ = in; });
  g->Subscribe<TrajectoryMsg>(
      node, topics_.trajectory, "trajectory", 1,
      [this](const TrajectoryMsg& in, CallbackContext&) {
        follower_trajectory_ = in;
      });
  if (inputs_.parking || !inputs_.turnarounds.empty()) {
    algo::ParkingFollowerParams parking;
    parking.wheelbase_m = inputs_.wheelbase_m;
    parking.forward_speed_mps = config_.Get("parking.forward_speed_mps");
    parking.reverse_speed_mps = config_.Get("parking.reverse_speed_mps");
    parking.course_out_m = config_.Get("parking.course_out_m");
    parking.steer_rate_rad_per_s = inputs_.max_steer_rate_rad_per_s;
    parking_follower_ = std::make_unique<algo::ParkingFollower>(parking);
    g->Subscribe<ParkingPathMsg>(
        node, topics_.parking_path, "parking_path", 1,
        [this](const ParkingPathMsg& in, CallbackContext&) {
          if (!in.found) return;
          parking_hold_ = in.hold;
          if (in.hold) return;
          std::vector<algo::GearedPose> poses;
          for (const ParkingPathPoint& p : in.poses)
            poses.push_back({{p.x_m, p.y_m, p.yaw_rad}, p.reverse});
          parking_follower_->SetPath(poses);
          parking_mode_ = true;
          path_end_reported_ = false;
        });
  }
  if (!inputs_.turnarounds.empty()) {
    // Turned: back to the path, once the planner's path of the next leg
    // has come (an older one ends behind the car).
    g->Subscribe<ParkingDoneMsg>(
        node, turn_done_, "turnaround_done", 1,
        [this](const ParkingDoneMsg& in, CallbackContext&) {
          parking_mode_ = false;
          parking_hold_ = false;
          turn_entered_ = false;
          follower_leg_ = in.turnaround + 1;
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
                      follower_trajectory_ &&
                              follower_trajectory_->route_leg == follower_leg_
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

}  // namespace adse::stack::internal
