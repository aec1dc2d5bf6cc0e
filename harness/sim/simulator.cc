#include "harness/sim/simulator.h"

#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <ctime>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <thread>

#include "analysis/metrics/run_metrics.h"
#include "analysis/metrics/standing.h"
#include "harness/profile/profile.h"
#include "harness/sim/calibration.h"
#include "harness/sim/early_stop.h"
#include "harness/sim/host_placement.h"
#include "harness/sim/realtime_platform.h"
#include "harness/sim/run_key.h"
#include "harness/sim/stack_process.h"
#include "harness/spec/spec_parser.h"
#include "harness/spec/types.h"
#include "stack/algorithms/command_gate.h"
#include "stack/base/clock.h"
#include "stack/base/hash.h"
#include "stack/base/random.h"
#include "stack/nodes/ad_stack.h"
#include "stack/runtime/executor.h"
#include "stack/runtime/realtime_executor.h"
#include "stack/world/lidar.h"
#include "stack/world/map_cloud.h"
#include "stack/world/parking_goal.h"
#include "stack/world/traffic_signal_detector.h"

namespace adse::sim {
namespace {

using Clock = std::chrono::steady_clock;
double Seconds(Clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

std::string HostDescription() {
  char name[256] = {0};
  ::gethostname(name, sizeof(name) - 1);
  std::string cpu;
  std::ifstream info("/proc/cpuinfo");
  for (std::string line; std::getline(info, line);) {
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  }
  return fmt::format("{}; {}; {} cores", name, cpu,
                     std::thread::hardware_concurrency());
}

// The valet task's goal and lot, for the parking metrics and picture.
void RecordParking(const world::World& w, const world::TaskOptions& task,
                   runfile::ParkingRecord* out) {
  out->present = true;
  out->slot = w.goal_slot().name;
  out->goal_x_m = w.parking_goal().x_m;
  out->goal_y_m = w.parking_goal().y_m;
  out->goal_yaw_rad = w.parking_goal().yaw_rad;
  out->tolerance_m = task.goal_tolerance_m;
  out->yaw_tolerance_rad = task.goal_yaw_tolerance_deg * M_PI / 180.0;
  out->wheelbase_m = w.ego_limits().wheelbase_m;
  out->length_m = w.ego_limits().length_m;
  out->width_m = w.ego_limits().width_m;
  for (const world::ParkingSlot& s : w.scene().parking_slots()) {
    out->slots.push_back({s.box.center.x(), s.box.center.y(), s.box.yaw_rad,
                          s.box.length_m, s.box.width_m, s.occupied ? 1 : 0,
                          s.name == w.goal_slot().name ? 1 : 0});
  }
  const std::vector<std::vector<Eigen::Vector2d>> outlines =
      world::ObstacleOutlines(w.scene());
  for (size_t i = 0; i < outlines.size(); ++i) {
    for (const Eigen::Vector2d& p : outlines[i]) {
      out->obstacles.push_back({static_cast<int32_t>(i), p.x(), p.y()});
    }
  }
}

}  // namespace

world::WorldSetup WorldSetupFromSpec(const spec::Spec& spec) {
  world::WorldSetup setup;
  setup.world = spec.world;
  setup.task = spec.task;
  setup.cache_dir = spec.harness.cache_dir;
  return setup;
}

Status CheckCostModelFile(const spec::Spec& spec) {
  const spec::PlatformOptions& platform = spec.platform;
  if (platform.cost_model != spec::CostModel::kCounted) return Status::Ok();
  if (!platform.profile.empty()) {
    return profile::ReadProfile(platform.profile)
        .status()
        .WithContext("platform.profile");
  }
  // No file named is the run's to refuse, saying what to make.
  if (platform.calibration.empty()) return Status::Ok();
  return LoadCalibration(platform.calibration)
      .status()
      .WithContext("platform.calibration");
}

namespace {

Status CheckRealTimeProfile(const spec::PlatformOptions& platform) {
  if (platform.cost_model == spec::CostModel::kCounted &&
      !platform.profile.empty()) {
    return Status::Ok();
  }
  return Status::InvalidArgument(
      "platform.kind: cgroup pads every callback to its cost profile: "
      "set platform.cost_model: counted and platform.profile");
}

}  // namespace

Status CheckRealTimePlatform(const spec::PlatformOptions& platform) {
  ADSE_RETURN_IF_ERROR(CheckRealTimeProfile(platform));
  return PlaceOnHost(platform.cores).status();
}

Result<runfile::RunData> SimulatePoint(const spec::Spec& spec,
                                       const spec::DesignPoint& point,
                                       const SimulateOptions& options,
                                       SimulationStats* stats_out) {
  const auto t_begin = Clock::now();
  SimulationStats stats;
  if (!spec.cases.empty()) {
    // A run drives one task; a caller picks the case (spec::ForCase).
    return Status::InvalidArgument(fmt::format(
        "task.cases: the scenario has {} cases; a run drives one of them",
        spec.cases.size()));
  }
  Result<spec::PointConfig> config = spec::ApplyPoint(spec, point);
  if (!config.ok()) return config.status();
  // A point the cost expression cannot price is refused before it runs.
  Result<double> cost = spec::EvaluateCost(spec, point);
  if (!cost.ok()) return cost.status();
  const spec::PlatformOptions& platform = config->platform;
  const StackConfig& stack_config = config->stack;

  world::WorldSetup setup = WorldSetupFromSpec(spec);
  if (options.seed) setup.world.traffic.seed = *options.seed;
  const uint64_t seed = setup.world.traffic.seed;
  Result<std::unique_ptr<world::World>> opened = world::World::Open(setup);
  if (!opened.ok()) return opened.status();
  world::World& w = **opened;

  Result<std::string> cloud_path = w.MapCloudPath();
  if (!cloud_path.ok())
    return cloud_path.status().WithContext("localization map");
  Result<std::vector<Eigen::Vector3f>> map_cloud = world::ReadPcd(*cloud_path);
  if (!map_cloud.ok())
    return map_cloud.status().WithContext("localization map");

  stack::StackInputs inputs;
  // The road part: the whole ideal path for lane driving; for valet parking
  // it ends on the aisle, where the stack's freespace planner takes over.
  inputs.route = w.road_path();
  inputs.lane_width_m = w.lane_width_m();
  inputs.map_cloud = std::move(map_cloud).value();
  inputs.initial_pose = {w.ego().x_m, w.ego().y_m, w.ego().yaw_rad};
  inputs.speed_limit_mps = spec.task.speed_limit_kmh / 3.6;
  inputs.goal_tolerance_m = spec.task.goal_tolerance_m;
  inputs.goal_yaw_tolerance_rad =
      spec.task.goal_yaw_tolerance_deg * M_PI / 180.0;
  inputs.wheelbase_m = w.ego_limits().wheelbase_m;
  inputs.max_steer_rate_rad_per_s = w.ego_limits().max_steer_rate_rad_per_s;
  inputs.vehicle_length_m = w.ego_limits().length_m;
  inputs.vehicle_width_m = w.ego_limits().width_m;
  // Signals on the route: the stack's map holds them, and the world's
  // detector reports them (runs without keep the graph they always had).
  inputs.traffic_signals = !w.route_signals().empty();
  inputs.lane_changes = w.route_lane_changes();
  inputs.turnarounds.assign(w.route_turnarounds().begin(),
                            w.route_turnarounds().end());
  if (w.parking_task()) {
    inputs.parking = true;
    inputs.parking_goal = w.parking_goal();
    // The lot's map as the car carries it: walls, poles and the parked
    // cars of the map's occupancy.
    inputs.parking_obstacles = world::ObstacleOutlines(w.scene());
  }

  stack::Graph graph;
  Result<std::unique_ptr<stack::AdStack>> ad_stack =
      stack::AdStack::Build(stack_config, inputs, &graph);
  if (!ad_stack.ok())
    return ad_stack.status().WithContext("building the stack");
  const stack::StackTopics topics = (*ad_stack)->topics();

  runfile::RunData run;
  // The vehicle side: the safety gate between the computer and the actuators.
  algorithms::CommandGateParams gate_params;
  gate_params.stale_after_s = stack_config.Get("control.stale_after_s");
  gate_params.emergency_decel_mps2 =
      stack_config.Get("control.emergency_decel_mps2");
  algorithms::CommandGate gate(gate_params);
  graph.AddSink<stack::ControlMsg>(
      topics.control, [&](const stack::ControlMsg& m, double t_s) {
        gate.OnCommand(t_s, m.accel_mps2, m.steer_rad, m.reverse);
        run.controls.push_back({t_s, m.header.stamp_s, m.accel_mps2,
                                m.steer_rad, m.header.perception_stamp_s});
      });
  // valet_parking: the stack's manoeuvre, or its word that there is none
  // (which ends the run: waiting longer changes nothing).
  bool no_path = false;
  if (topics.parking_path >= 0) {
    graph.AddSink<stack::ParkingPathMsg>(
        topics.parking_path, [&](const stack::ParkingPathMsg& m, double t_s) {
          no_path = !m.found;
          if (no_path) run.termination_detail = m.failure;
          // A hold (a road user in the way) is no plan.
          if (m.hold) return;
          // A three-point turn's plan is no parking manoeuvre.
          if (!w.parking_task()) return;
          if (run.parking.first_planned_at_s < 0) {
            run.parking.first_planned_at_s = t_s;
          } else if (m.found) {
            ++run.parking.replans;
          }
          run.parking.planned_at_s = t_s;
          run.parking.path_found = m.found ? 1 : 0;
          // The plan this one replaces is kept, numbered in order.
          if (!run.parking.planned_path.empty()) {
            std::vector<runfile::EarlierPlanRow>& earlier =
                run.parking.earlier_plans;
            const int32_t plan = earlier.empty() ? 0 : earlier.back().plan + 1;
            for (const runfile::ParkingPathRow& r : run.parking.planned_path) {
              earlier.push_back({plan, r.x_m, r.y_m, r.yaw_rad, r.reverse});
            }
          }
          run.parking.planned_path.clear();
          for (const stack::ParkingPathPoint& p : m.poses) {
            run.parking.planned_path.push_back(
                {p.x_m, p.y_m, p.yaw_rad, p.reverse ? 1 : 0});
          }
        });
  }
  // ... and the planner's word that the car is parked (its is_completed):
  // the manoeuvre is over and needs no correction, as far as the stack can
  // tell. Outside the tolerances nothing more will happen.
  double parking_completed_at_s = -1.0;
  if (topics.parking_completed >= 0) {
    graph.AddSink<stack::ParkingDoneMsg>(
        topics.parking_completed,
        [&](const stack::ParkingDoneMsg&, double t_s) {
          if (parking_completed_at_s < 0) parking_completed_at_s = t_s;
        });
  }
  graph.AddSink<stack::StopReasonMsg>(
      topics.stop_reason, [&](const stack::StopReasonMsg& m, double t_s) {
        run.stop_reasons.push_back(
            {t_s, m.header.stamp_s, m.reason, m.stop_distance_m, m.track_id,
             m.obstacle_gap_m, m.static_structure ? 1 : 0});
      });
  graph.AddSink<stack::ObjectsMsg>(
      topics.objects, [&](const stack::ObjectsMsg& m, double t_s) {
        for (const stack::TrackedObject& o : m.objects) {
          run.objects.push_back({t_s, m.header.stamp_s, o.id, o.position.x(),
                                 o.position.y(), o.velocity.x(), o.velocity.y(),
                                 o.length_m, o.width_m, o.yaw_rad, o.age});
        }
      });
  graph.AddSink<stack::PoseMsg>(topics.pose,
                                [&](const stack::PoseMsg& m, double t_s) {
                                  gate.OnLocalization(t_s, m.valid);
                                });

  // The executor takes the graph as it is now: sinks must be added first.
  stack::VirtualPlatformOptions vp;
  vp.cores = platform.cores;
  vp.freq_ghz = platform.freq_ghz;
  vp.reference_ghz = platform.reference_ghz;
  vp.cost_scale = platform.cost_scale;
  vp.dispatch = platform.dispatch == spec::Dispatch::kProcessorSharing
                    ? stack::DispatchKind::kProcessorSharing
                    : stack::DispatchKind::kRunToCompletion;
  std::string profile_name;
  if (platform.cost_model == spec::CostModel::kCounted &&
      !platform.profile.empty()) {
    vp.cost_model = stack::CostModelKind::kCounted;
    Result<profile::Profile> loaded = profile::ReadProfile(platform.profile);
    if (!loaded.ok()) return loaded.status().WithContext("platform.profile");
    profile_name = loaded->name;
    // The graph has the signal subscription only where the route has
    // signals, and the freespace planner only where it turns in several
    // moves; say which profile covers them rather than just what
    // is missing.
    struct RouteCallback {
      bool in_graph;
      const char* callback;
      const char* why;
    };
    for (const RouteCallback& c :
         {RouteCallback{topics.traffic_signal >= 0,
                        "behavior_velocity_planner/traffic_signal",
                        "the route has traffic signals, so the stack "
                        "subscribes to its signal detector"},
          RouteCallback{!inputs.turnarounds.empty(),
                        "behavior_path_planner/turnaround_done",
                        "the route turns in several moves (at a U-turn or "
                        "a corner sharper than the car), so the stack runs "
                        "its freespace planner"}}) {
      if (c.in_graph && loaded->costs.callbacks.count(c.callback) == 0) {
        return Status::InvalidArgument(fmt::format(
            "platform.profile: {} ({}), which profile '{}' lacks; name a "
            "profile that has it, such as "
            "profiles/autoware-2022.12-i9-12900kf-signals.yaml",
            c.why, c.callback, profile_name));
      }
    }
    vp.profile =
        std::make_shared<const stack::CostProfile>(std::move(loaded->costs));
    vp.profile_seed = Random::DeriveSeed(seed, "cost");
  } else if (platform.cost_model == spec::CostModel::kCounted) {
    vp.cost_model = stack::CostModelKind::kCounted;
    Result<std::map<std::string, stack::CountedCost>> calibration =
        LoadCalibration(platform.calibration);
    if (!calibration.ok())
      return calibration.status().WithContext("platform.calibration");
    // A callback the file does not cost would be charged the executor's
    // default: refuse, as for a profile.
    std::vector<std::string> missing;
    for (const stack::CallbackSpec& callback : graph.callbacks()) {
      if (calibration->count(callback.name) == 0) {
        missing.push_back(callback.name);
      }
    }
    if (!missing.empty()) {
      return Status::InvalidArgument(fmt::format(
          "platform.calibration: {}: expected a cost for every callback the "
          "stack runs, found none for {} ({} of {}); fit one for this stack "
          "with `adse calibrate`",
          platform.calibration, fmt::join(missing, ", "), missing.size(),
          graph.callbacks().size()));
    }
    vp.counted = std::move(calibration).value();
  }
  std::map<std::string, std::string> platform_notes;
  // Declared before the executor: its threads end before the group goes.
  std::unique_ptr<RealTimePlatform> realtime;
  StackProcess* stack_process = nullptr;  // the executor, in real time
  Result<std::unique_ptr<stack::Executor>> made =
      Status::Internal("no executor made");
  if (platform.kind == spec::PlatformKind::kCgroup) {
    // (The host's CPUs are the real-time platform's to place.)
    ADSE_RETURN_IF_ERROR(CheckRealTimeProfile(platform));
    stack::RealTimeOptions rt;
    rt.cores = platform.cores;
    rt.freq_ghz = platform.freq_ghz;
    rt.profile = vp.profile;
    rt.profile_seed = vp.profile_seed;
    rt.cost_scale = platform.cost_scale;
    rt.time_dilation = platform.time_dilation;
    Result<std::unique_ptr<RealTimePlatform>> prepared =
        RealTimePlatform::Prepare(platform, &rt);
    if (!prepared.ok()) return prepared.status();
    realtime = std::move(prepared).value();
    platform_notes = realtime->notes();
    // The stack runs in a process of its own, which joins the stack's group
    // before its executor starts; the world stays here.
    Result<std::unique_ptr<StackProcess>> started = StackProcess::Start(
        &graph,
        [rt](
            const stack::Graph* g) -> Result<std::unique_ptr<stack::Executor>> {
          if (rt.enter_thread) ADSE_RETURN_IF_ERROR(rt.enter_thread());
          if (!rt.host_cpus.empty())
            ADSE_RETURN_IF_ERROR(SetThreadCpus(rt.host_cpus));
          return stack::CreateRealTimeExecutor(g, rt);
        });
    if (started.ok()) {
      stack_process = started->get();
      made = std::unique_ptr<stack::Executor>(std::move(started).value());
    } else {
      made = started.status();
    }
  } else {
    made = stack::CreateVirtualExecutor(&graph, vp);
  }
  if (!made.ok()) return made.status().WithContext("platform");
  stack::Executor& executor = **made;
  // Real time: how far the world fell behind the stack's clock.
  const auto wall_start = Clock::now();
  double world_lag_max_s = 0.0;

  const world::LidarParams lidar_params = stack_config.Lidar();
  world::LidarSimulator lidar(&w.scene(), lidar_params, setup.world.weather,
                              Random::DeriveSeed(seed, "lidar"));
  Random odometry_noise(Random::DeriveSeed(seed, "odometry"));
  std::optional<world::TrafficSignalDetector> signal_detector;
  if (topics.traffic_signal >= 0) {
    signal_detector.emplace(w.road_path(), w.route_signals(),
                            stack_config.SignalDetector());
  }
  const double lidar_period = 1.0 / lidar_params.rate_hz;
  const double odometry_period = 1.0 / stack_config.Get("odometry.rate_hz");
  double next_lidar = 0.0, next_odometry = 0.0, next_vehicles = 0.0,
         next_progress = 0.0;
  stats.setup_s = Seconds(Clock::now() - t_begin);

  Result<EarlyStop> early_stop =
      EarlyStop::Create(spec, point, stack_config.Get("control.rate_hz"));
  if (!early_stop.ok()) return early_stop.status();
  analysis::StallWatch stall(spec.task.stall_timeout_s,
                             spec.task.traffic_stall_timeout_s);

  const double dt = w.step_s();
  const double timeout = spec.task.timeout_s;
  std::string status = runfile::kRunComplete;
  std::string reason = "timeout";
  auto record_ego = [&] {
    const world::VehicleState& s = w.ego();
    run.ego.push_back({w.time_s(), s.x_m, s.y_m, s.yaw_rad, s.v_mps,
                       s.steer_rad, s.accel_mps2});
  };
  record_ego();
  while (w.time_s() < timeout - 1e-9) {
    const double t = w.time_s();
    const world::VehicleState& ego = w.ego();
    // Sensors sample the world as it is at this step.
    while (next_lidar < t + dt - 1e-9) {
      const auto t0 = Clock::now();
      std::vector<geometry::OrientedBox> boxes;
      boxes.reserve(w.others().size());
      for (const world::OtherVehicle& v : w.others()) boxes.push_back(v.box);
      // The car moves during the sweep, so the scan comes distorted; the
      // stack's distortion corrector undoes it from odometry.
      const geometry::Twist2 motion{
          ego.v_mps,
          ego.v_mps * std::tan(ego.steer_rad) / w.ego_limits().wheelbase_m};
      world::PointCloud scan = lidar.Scan({ego.x_m, ego.y_m, ego.yaw_rad},
                                          next_lidar, boxes, motion);
      stack::PointCloudMsg msg;
      msg.header.stamp_s = next_lidar;
      msg.points = std::move(scan.points);
      // Sensor frame to vehicle frame: the sensor sits above the rear axle.
      for (Eigen::Vector3f& p : msg.points)
        p.z() += static_cast<float>(lidar_params.mount_height_m);
      stats.lidar_s += Seconds(Clock::now() - t0);
      executor.PublishExternal(
          topics.lidar_raw,
          std::make_shared<const stack::PointCloudMsg>(std::move(msg)),
          next_lidar, std::max(next_lidar, t));
      next_lidar += lidar_period;
    }
    while (next_odometry < t + dt - 1e-9) {
      stack::OdometryMsg msg;
      msg.header.stamp_s = next_odometry;
      msg.v_mps = ego.v_mps * (1.0 + odometry_noise.Normal(0.0, 0.005));
      msg.yaw_rate_rps =
          ego.v_mps * std::tan(ego.steer_rad) / w.ego_limits().wheelbase_m +
          odometry_noise.Normal(0.0, 0.002);
      executor.PublishExternal(topics.odometry,
                               std::make_shared<const stack::OdometryMsg>(msg),
                               next_odometry, std::max(next_odometry, t));
      next_odometry += odometry_period;
    }
    if (signal_detector) {
      // The detector looks at the signals as they are at this step; each
      // report comes latency_s after its look.
      while (signal_detector->next_look_s() < t + dt - 1e-9) {
        signal_detector->Look({ego.x_m, ego.y_m}, w.RouteSignalStates());
      }
      for (world::SignalReport& r : signal_detector->TakeDue(t + dt)) {
        const double publish_s = std::max(r.publish_s, t);
        run.signals.push_back(
            {publish_s, r.stamp_s, r.state, r.stop_line_distance_m, r.tls_id});
        stack::TrafficSignalMsg msg;
        msg.header.stamp_s = r.stamp_s;
        msg.state = r.state;
        msg.stop_line_distance_m = r.stop_line_distance_m;
        msg.tls_id = std::move(r.tls_id);
        executor.PublishExternal(
            topics.traffic_signal,
            std::make_shared<const stack::TrafficSignalMsg>(std::move(msg)),
            r.stamp_s, publish_s);
      }
    }
    const auto t_exec = Clock::now();
    // Where this process handles Ctrl-C and SIGTERM (it ran a real-time
    // run, e.g. `adse fidelity` between its runs), a virtual run ends on
    // them too: else the stop would wait for the next real-time run.
    if (const int sig = RealTimePlatform::Interrupted()) {
      return Status::Unavailable(
          fmt::format("interrupted by {} at t={:.2f} s; nothing was recorded",
                      sig == SIGINT ? "SIGINT (Ctrl-C)" : "SIGTERM", t));
    }
    if (realtime != nullptr) {
      world_lag_max_s =
          std::max(world_lag_max_s,
                   Seconds(t_exec - wall_start) / platform.time_dilation - t);
    }
    Status advanced = executor.AdvanceTo(t + dt);
    stats.executor_s += Seconds(Clock::now() - t_exec);
    if (!advanced.ok())
      return advanced.WithContext(fmt::format("stack at t={:.2f} s", t));

    const algorithms::GateOutput command = gate.Output(t + dt);
    const auto t_world = Clock::now();
    Status stepped =
        w.Step({command.accel_mps2, command.steer_rad, command.reverse});
    stats.world_s += Seconds(Clock::now() - t_world);
    if (!stepped.ok()) return stepped;
    record_ego();
    for (const world::Contact& c : w.new_contacts())
      run.collisions.push_back({w.time_s(), c.id, c.ego_caused ? 1 : 0});
    if (w.time_s() + 1e-9 >= next_vehicles) {
      for (const world::OtherVehicle& v : w.others()) {
        run.vehicles.push_back({w.time_s(), v.id, v.box.center.x(),
                                v.box.center.y(), v.box.yaw_rad, v.speed_mps,
                                v.box.length_m, v.box.width_m});
      }
      next_vehicles += options.vehicle_record_period_s;
    }
    if (options.progress && w.time_s() >= next_progress) {
      options.progress(w.time_s(), timeout);
      next_progress += 1.0;
    }
    // A parking car is parked once the stack says so (the planner, when the
    // manoeuvre is over and needs no correction): standing within the
    // tolerances at a cusp, before a last short leg, it is not yet.
    if (w.goal_reached() &&
        (!w.parking_task() || parking_completed_at_s >= 0)) {
      reason = "goal_reached";
      break;
    }
    if (no_path) {
      reason = "no_path";
      break;
    }
    // Once the car truly stands (the stack's speed estimate lags), and a
    // second after the stack's word at the earliest.
    if (parking_completed_at_s >= 0 &&
        w.time_s() > parking_completed_at_s + 1.0 &&
        std::abs(w.ego().v_mps) < 0.01) {
      reason = "parked_out_of_tolerance";
      break;
    }
    if (!early_stop->empty()) {
      const RunProgress progress{w.time_s(),
                                 static_cast<int64_t>(run.controls.size()),
                                 static_cast<int64_t>(run.collisions.size())};
      if (std::optional<std::string> violated =
              early_stop->Violated(progress)) {
        status = runfile::kRunInfeasible;
        reason = runfile::kConstraintViolatedPrefix + *violated;
        break;
      }
    }
    if (stall.Observe(w.time_s(), w.ego().v_mps, run.stop_reasons)) {
      status = runfile::kRunStalled;
      reason = runfile::kStalledPrefix +
               std::string(StopReasonToString(stall.reason()));
      break;
    }
  }

  // Provenance and the stack's description.
  run.status = status;
  run.termination_reason = reason;
  run.scenario_name = spec.name;
  run.scenario_text = spec.source_text;
  run.scenario_hash = Sha256Hex(spec.source_text);
  run.task_case = spec.task_case;
  run.adse_version = ADSE_VERSION;
  run.host = HostDescription();
  run.created_utc = UtcTimestamp();
  run.seed = seed;
  run.design_point = point;
  if (Result<std::string> key = RunKey(spec, point, seed); key.ok())
    run.content_key = *key;
  run.platform = {{"kind", spec::PlatformKindToString(platform.kind)},
                  {"cores", std::to_string(platform.cores)},
                  {"freq_ghz", fmt::format("{}", platform.freq_ghz)},
                  {"reference_ghz", fmt::format("{}", platform.reference_ghz)},
                  {"cost_model", spec::CostModelToString(platform.cost_model)},
                  {"cost_scale", fmt::format("{}", platform.cost_scale)}};
  if (!profile_name.empty()) run.platform["profile"] = profile_name;
  if (platform.kind == spec::PlatformKind::kVirtual) {
    run.platform["dispatch"] = spec::DispatchToString(platform.dispatch);
  }
  for (const auto& [key, value] : platform_notes) run.platform[key] = value;
  if (platform.kind == spec::PlatformKind::kCgroup) {
    run.platform["world_lag_max_s"] = fmt::format("{:.4f}", world_lag_max_s);
  }
  for (size_t i = 0; i < w.ideal_path().points.size(); ++i) {
    run.ideal_path.push_back({w.ideal_path().s_m[i],
                              w.ideal_path().points[i].x(),
                              w.ideal_path().points[i].y()});
  }
  run.lane_width_m = w.lane_width_m();
  if (w.parking_task()) RecordParking(w, spec.task, &run.parking);
  const std::vector<std::vector<Eigen::Vector2d>> lanes = w.LaneShapes();
  for (size_t i = 0; i < lanes.size(); ++i) {
    for (const Eigen::Vector2d& p : lanes[i]) {
      run.lanes.push_back({static_cast<int32_t>(i), p.x(), p.y()});
    }
  }
  for (const stack::NodeSpec& n : graph.nodes())
    run.node_names.push_back(n.name);
  for (const stack::TopicSpec& t : graph.topics())
    run.topic_names.push_back(t.name);
  for (const stack::CallbackSpec& c : graph.callbacks()) {
    run.callback_info.push_back({c.name, c.node,
                                 c.kind == stack::CallbackSpec::Kind::kTimer
                                     ? runfile::CallbackKind::kTimer
                                     : runfile::CallbackKind::kSubscription,
                                 c.topic, c.period_s});
  }
  executor.Stop();
  if (stack_process != nullptr) {
    if (!stack_process->stop_status().ok())
      return stack_process->stop_status().WithContext("stopping the stack");
    run.platform["stack_process"] = stack_process->Describe();
  }
  run.trace = executor.trace();
  // executor_s so far is the wall time inside AdvanceTo: the callbacks plus
  // the executor's own bookkeeping. Only the measured model records the
  // callbacks' host CPU time, so only then can the two be told apart.
  stats.stack_and_executor_s = stats.executor_s;
  if (vp.cost_model == stack::CostModelKind::kMeasured) {
    for (const stack::CallbackRecord& r : run.trace.callbacks)
      stats.stack_cpu_s += r.host_cpu_s;
    stats.executor_s = std::max(0.0, stats.executor_s - stats.stack_cpu_s);
  } else {
    stats.stack_cpu_s = std::nan("");
    stats.executor_s = std::nan("");
  }
  run.metrics = analysis::ComputeRunMetrics(run);
  run.metrics["hardware_cost"] = *cost;
  stats.simulated_s = w.time_s();
  stats.wall_s = Seconds(Clock::now() - t_begin);
  if (stats_out) *stats_out = stats;
  return run;
}

}  // namespace adse::sim
