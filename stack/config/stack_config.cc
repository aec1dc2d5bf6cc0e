#include "stack/config/stack_config.h"

#include <fmt/format.h>

#include <cmath>

namespace adse {

const std::vector<KnobInfo>& StackKnobs() {
  static const std::vector<KnobInfo> kKnobs = [] {
    const world::LidarParams d;
    return std::vector<KnobInfo>{
        {"lidar.rate_hz", false, 0.5, 100.0, d.rate_hz, "LiDAR scans per second, Hz"},
        {"lidar.beams", true, 1, 128, static_cast<double>(d.beams), "vertical channels"},
        {"lidar.horizontal_resolution_deg", false, 0.05, 10.0,
         d.horizontal_resolution_deg, "azimuth step, degrees"},
        {"lidar.range_m", false, 1.0, 300.0, d.range_m, "maximum range in clear weather, m"},
        {"lidar.vertical_fov_up_deg", false, -30.0, 45.0, d.vertical_fov_up_deg,
         "elevation of the top beam, degrees"},
        {"lidar.vertical_fov_down_deg", false, -45.0, 30.0, d.vertical_fov_down_deg,
         "elevation of the bottom beam, degrees"},
        {"lidar.mount_height_m", false, 0.3, 5.0, d.mount_height_m,
         "sensor height above the ground, m"},
        {"lidar.range_noise_stddev_m", false, 0.0, 1.0, d.range_noise_stddev_m,
         "range noise in clear weather, m"},
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
    return Status::InvalidArgument("stack." + path + " is not a stack parameter");
  }
  if (!std::isfinite(value) || value < knob->min_value ||
      value > knob->max_value) {
    return Status::InvalidArgument(fmt::format(
        "stack.{} must be in [{}, {}] ({}), found {}", path, knob->min_value,
        knob->max_value, knob->doc, value));
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
