#include "stack/config/stack_config.h"

#include <fmt/format.h>

#include <cmath>

namespace adse {

const std::vector<KnobInfo>& StackKnobs() {
  static const std::vector<KnobInfo> kKnobs = [] {
    const world::LidarParams d;
    return std::vector<KnobInfo>{
        {"lidar.rate_hz", false, 0.5, 100.0, d.rate_hz,
         "LiDAR scans per second, Hz", KnobInfo::Load::kSensorRate},
        {"lidar.beams", true, 1, 128, static_cast<double>(d.beams),
         "vertical channels"},
        {"lidar.horizontal_resolution_deg", false, 0.05, 10.0,
         d.horizontal_resolution_deg, "azimuth step, degrees",
         KnobInfo::Load::kDownsample},
        {"lidar.range_m", false, 1.0, 300.0, d.range_m,
         "maximum range in clear weather, m"},
        {"lidar.vertical_fov_up_deg", false, -30.0, 45.0, d.vertical_fov_up_deg,
         "elevation of the top beam, degrees"},
        {"lidar.vertical_fov_down_deg", false, -45.0, 30.0,
         d.vertical_fov_down_deg, "elevation of the bottom beam, degrees"},
        {"lidar.mount_height_m", false, 0.3, 5.0, d.mount_height_m,
         "sensor height above the ground, m"},
        {"lidar.range_noise_stddev_m", false, 0.0, 1.0, d.range_noise_stddev_m,
         "range noise in clear weather, m"},
        // Wheel odometry from the vehicle.
        {"odometry.rate_hz", false, 1.0, 200.0, 50.0,
         "wheel odometry messages per second, Hz", KnobInfo::Load::kSensorRate},
        // Localization.
        {"localization.voxel_leaf_m", false, 0.1, 5.0, 1.0,
         "voxel size of the scan given to NDT, m", KnobInfo::Load::kDownsample},
        {"localization.ndt_resolution_m", false, 0.5, 10.0, 2.0,
         "NDT cell size, m"},
        {"localization.ndt_max_iterations", true, 1, 200, 30,
         "NDT iteration limit"},
        {"localization.ndt_max_fitness", false, 0.01, 100.0, 0.5,
         "NDT fitness score (mean squared match distance, m^2) above which a "
         "match is rejected"},
        {"localization.ndt_threads", true, 1, 256, 8,
         "cores the data-parallel NDT can use"},
        {"localization.ekf_rate_hz", false, 1.0, 500.0, 50.0,
         "EKF output rate, Hz"},
        {"localization.lost_after_s", false, 0.1, 60.0, 3.0,
         "time without an accepted NDT match after which localization is lost, "
         "s"},
        // Perception.
        {"perception.ground_height_m", false, 0.0, 2.0, 0.25,
         "points below this height are ground, m"},
        {"perception.max_range_m", false, 1.0, 300.0, 40.0,
         "obstacle points beyond this range are ignored, m"},
        {"perception.cluster_tolerance_m", false, 0.05, 5.0, 0.7,
         "Euclidean clustering distance, m"},
        {"perception.min_cluster_points", true, 1, 10000, 5,
         "smallest cluster kept"},
        {"perception.threads", true, 1, 256, 4,
         "cores the data-parallel clustering can use"},
        {"perception.max_object_size_m", false, 1.0, 100.0, 12.0,
         "clusters longer than this are static structure, not objects, m"},
        {"perception.tracker_rate_hz", false, 1.0, 100.0, 10.0,
         "rate at which the tracker publishes its tracks, predicted to the "
         "time of publishing (Autoware's publish_rate), Hz"},
        // Planning.
        {"planning.rate_hz", false, 0.5, 100.0, 10.0,
         "behaviour/velocity planner rate, Hz"},
        {"planning.horizon_m", false, 5.0, 500.0, 50.0,
         "trajectory length ahead, m"},
        {"planning.corridor_half_width_m", false, 0.5, 5.0, 1.5,
         "obstacles closer than this to the path stop the car, m"},
        {"planning.stop_margin_m", false, 0.5, 30.0, 5.0,
         "distance kept to an obstacle in the path, m"},
        {"planning.max_lateral_accel_mps2", false, 0.1, 10.0, 2.0,
         "lateral acceleration limit in curves, m/s^2"},
        {"planning.max_accel_mps2", false, 0.1, 10.0, 1.5,
         "acceleration limit, m/s^2"},
        {"planning.max_decel_mps2", false, 0.1, 10.0, 2.5,
         "comfortable deceleration, m/s^2"},
        {"planning.yield_horizon_s", false, 0.0, 30.0, 3.0,
         "a moving road user predicted to cross the path within this time, "
         "while the car would be there, is yielded to (0: never; README, "
         "\"Crossing traffic\"), s"},
        // Control.
        {"control.rate_hz", false, 1.0, 500.0, 30.0,
         "trajectory follower rate (control-command topic), Hz"},
        {"control.max_travel_per_fix_m", false, 0.1, 100.0, 2.0,
         "speed cap: distance the car may cover per localization fix age, m"},
        {"control.stale_after_s", false, 0.05, 10.0, 0.5,
         "the command gate brakes when the newest command is older, s"},
        {"control.emergency_decel_mps2", false, 0.5, 10.0, 3.0,
         "the command gate's braking, m/s^2"},
        // Traffic signals (maps with signals on the route only): the
        // world's detector and the velocity planner's signal stage.
        {"traffic_light.detector_rate_hz", false, 0.5, 100.0, 10.0,
         "signal detector observations per second, Hz",
         KnobInfo::Load::kSensorRate},
        {"traffic_light.detector_range_m", false, 5.0, 500.0, 100.0,
         "farthest stop line (along the route) whose signal the detector "
         "reads, m"},
        {"traffic_light.detector_latency_s", false, 0.0, 5.0, 0.1,
         "from the detector's look to its message, s"},
        {"traffic_light.state_timeout_s", false, 0.05, 60.0, 1.0,
         "a signal observation older than this counts as unknown, s"},
        {"traffic_light.unknown_wait_s", false, 0.0, 600.0, 5.0,
         "standing this long at the line of a signal it cannot read, the car "
         "goes on, s"},
        {"traffic_light.max_red_wait_s", false, 1.0, 3600.0, 300.0,
         "standing this long at a red line, the signal is taken as broken and "
         "the car goes on, s"},
        {"traffic_light.stop_margin_m", false, 0.0, 10.0, 1.0,
         "front bumper to the stop line when stopped for a signal, m"},
        // Parking (valet_parking only): the freespace planner and the
        // controller's parking mode.
        {"parking.rate_hz", false, 0.2, 50.0, 2.0,
         "freespace planner's timer (plans once the car stands at the end "
         "of its road route), Hz"},
        {"parking.turning_radius_m", false, 4.0, 20.0, 5.0,
         "tightest turn the parking path asks for, m"},
        {"parking.max_expansions", true, 100, 1000000, 50000,
         "freespace search budget (node expansions) before no_path"},
        {"parking.collision_margin_m", false, 0.0, 2.0, 0.25,
         "clearance the parking path keeps around the car's body (from a "
         "start already closer than this, the clearance the car has, at "
         "least 0.05), m"},
        {"parking.forward_speed_mps", false, 0.2, 5.0, 1.5,
         "parking speed forwards, m/s"},
        {"parking.reverse_speed_mps", false, 0.2, 3.0, 1.0,
         "parking speed in reverse, m/s"},
        {"parking.course_out_m", false, 0.0, 10.0, 1.0,
         "farther than this from the parking path the car stops and the "
         "planner plans again from there (0: never), m"},
        {"parking.max_replans", true, 0, 100, 3,
         "plans after the first one (for leaving the course or for ending "
         "the manoeuvre outside the goal's tolerances); past them an "
         "off-course car ends the run with no_path and one off the goal "
         "stays where it stands"},
    };
  }();
  return kKnobs;
}

const KnobInfo* FindStackKnob(const std::string& path) {
  for (const KnobInfo& knob : StackKnobs()) {
    if (knob.path == path) return &knob;
  }
  return nullptr;
}

Status StackConfig::Set(const std::string& path, double value) {
  const KnobInfo* knob = FindStackKnob(path);
  if (knob == nullptr) {
    return Status::InvalidArgument("stack." + path +
                                   " is not a stack parameter");
  }
  if (!std::isfinite(value) || value < knob->min_value ||
      value > knob->max_value) {
    return Status::InvalidArgument(
        fmt::format("stack.{} must be in [{}, {}] ({}), found {}", path,
                    knob->min_value, knob->max_value, knob->doc, value));
  }
  if (knob->integer && value != std::floor(value)) {
    return Status::InvalidArgument(
        fmt::format("stack.{} must be a whole number, found {}", path, value));
  }
  values_[path] = value;
  return Status::Ok();
}

double StackConfig::Get(const std::string& path) const {
  if (auto it = values_.find(path); it != values_.end()) return it->second;
  const KnobInfo* knob = FindStackKnob(path);
  return knob ? knob->default_value : 0.0;
}

world::TrafficSignalDetectorParams StackConfig::SignalDetector() const {
  world::TrafficSignalDetectorParams p;
  p.rate_hz = Get("traffic_light.detector_rate_hz");
  p.range_m = Get("traffic_light.detector_range_m");
  p.latency_s = Get("traffic_light.detector_latency_s");
  return p;
}

world::LidarParams StackConfig::Lidar() const {
  world::LidarParams p;
  p.rate_hz = Get("lidar.rate_hz");
  p.beams = static_cast<int>(Get("lidar.beams"));
  p.horizontal_resolution_deg = Get("lidar.horizontal_resolution_deg");
  p.range_m = Get("lidar.range_m");
  p.vertical_fov_up_deg = Get("lidar.vertical_fov_up_deg");
  p.vertical_fov_down_deg = Get("lidar.vertical_fov_down_deg");
  p.mount_height_m = Get("lidar.mount_height_m");
  p.range_noise_stddev_m = Get("lidar.range_noise_stddev_m");
  return p;
}

}  // namespace adse
