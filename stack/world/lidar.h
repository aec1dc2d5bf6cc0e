// A spinning multi-beam LiDAR ray-cast against the ground plane, the static
// scene and the current vehicles (oriented boxes), with weather effects.
#ifndef ADSE_STACK_WORLD_LIDAR_H_
#define ADSE_STACK_WORLD_LIDAR_H_

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "stack/base/random.h"
#include "stack/geometry/geometry.h"
#include "stack/world/scene.h"
#include "stack/world/world_options.h"

namespace adse::world {

// Stack knobs `stack.lidar.*`.
struct LidarParams {
  double rate_hz = 10.0;                   // scans per second
  int beams = 16;                          // vertical channels
  double horizontal_resolution_deg = 0.4;  // azimuth step
  double range_m = 60.0;                   // maximum range in clear weather
  double vertical_fov_up_deg = 15.0;       // elevation of the top beam
  double vertical_fov_down_deg = -15.0;    // elevation of the bottom beam
  double mount_height_m = 1.9;             // sensor height above ground
  double range_noise_stddev_m = 0.02;      // in clear weather
};

// What the weather does to the sensor.
struct WeatherEffects {
  double range_factor = 1.0;         // multiplies range_m
  double extra_noise_m = 0.0;        // added to the range noise stddev
  double dropout_probability = 0.0;  // chance a return is lost
};
WeatherEffects EffectsOf(Weather weather);

// One scan, points in the sensor frame (x forward, y left, z up; origin at
// the sensor), float as real drivers publish them. Points come column by
// column (azimuth 0, 0+step, ... counter-clockwise), bottom beam first.
struct PointCloud {
  double stamp_s = 0.0;
  std::vector<Eigen::Vector3f> points;
};

class LidarSimulator {
 public:
  // `scene` may be null (ground and vehicles only); it must outlive this.
  LidarSimulator(const Scene* scene, const LidarParams& params, Weather weather,
                 uint64_t seed);

  // One full revolution from `sensor_pose` (at mount height) starting at
  // `stamp_s`, seeing the static scene, the ground and `vehicles`.
  // `vehicles` should not hold the ego: a box containing the sensor is
  // ignored, but one below it would show its roof.
  //
  // `motion` is the carrier's twist during the sweep. Column j is sensed
  // j / azimuths() of a revolution (1 / rate_hz) after the start, and its
  // points are given in the sensor frame of that moment, as a real
  // spinning sensor reports them: the scan is distorted by the motion.
  // The rays are cast from the start pose; at 30 km/h and 10 Hz the
  // sensor moves 0.8 m in a revolution, and the surface points this
  // shifts are a second-order effect the frame change does not model.
  PointCloud Scan(const geometry::Pose2& sensor_pose, double stamp_s,
                  const std::vector<geometry::OrientedBox>& vehicles,
                  const geometry::Twist2& motion = {});

  const LidarParams& params() const { return params_; }
  int rays_per_scan() const;
  // Azimuth columns per revolution; beams() * azimuths() = rays_per_scan().
  int azimuths() const { return static_cast<int>(azimuth_cos_.size()); }
  const std::vector<double>& elevations_rad() const { return elevations_rad_; }
  const WeatherEffects& effects() const { return effects_; }
  // Range limit in the current weather, m.
  double max_range_m() const { return params_.range_m * effects_.range_factor; }

 private:
  // A vehicle near enough to matter in this scan, prepared once per scan.
  struct VehicleInView {
    double ox, oy;  // sensor position in the box frame
    double cr, sr;  // cos/sin of (sensor yaw - box yaw)
    double half_length, half_width, height;
    int first_azimuth;  // azimuth columns it may cover, with wrap-around
    int azimuth_count;
  };

  const Scene* scene_;
  LidarParams params_;
  WeatherEffects effects_;
  Random random_;
  std::vector<double> elevations_rad_;
  // Per-beam and per-azimuth trigonometry, computed once.
  std::vector<double> elevation_cos_, elevation_sin_, elevation_tan_;
  std::vector<double> azimuth_cos_, azimuth_sin_;
  double azimuth_step_rad_ = 0.0;
  // Scratch reused across scans (no allocation per scan after the first).
  std::vector<VehicleInView> in_view_;
  std::vector<int> column_vehicles_;
  std::vector<FaceCrossing> crossings_;
  std::vector<double> beam_best_m_;  // nearest return so far, per beam
  std::vector<char> beam_hit_;
};

}  // namespace adse::world

#endif  // ADSE_STACK_WORLD_LIDAR_H_
