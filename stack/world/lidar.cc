#include "stack/world/lidar.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace adse::world {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
// Beams steeper than this (within ~1e-12 rad of vertical) cross no face.
constexpr double kMinCos = 1e-12;

double WrapPi(double a) {
  a = std::remainder(a, 2.0 * M_PI);
  return a;
}

// Distance along the ray to where it enters the box (slab test in the box
// frame); +inf when it misses or starts inside (a box around the sensor is
// the sensor's own car and is not seen).
inline double SlabEntry(double ox, double oy, double oz, double dx, double dy,
                        double dz, double hx, double hy, double hz) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double t_near = -kInf, t_far = kInf;
  const double o[3] = {ox, oy, oz};
  const double d[3] = {dx, dy, dz};
  const double lo[3] = {-hx, -hy, 0.0};
  const double hi[3] = {hx, hy, hz};
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0.0) {
      if (o[k] < lo[k] || o[k] > hi[k]) return kInf;
      continue;
    }
    const double inv = 1.0 / d[k];
    double ta = (lo[k] - o[k]) * inv;
    double tb = (hi[k] - o[k]) * inv;
    if (ta > tb) std::swap(ta, tb);
    t_near = std::max(t_near, ta);
    t_far = std::min(t_far, tb);
    if (t_near > t_far) return kInf;
  }
  return t_near >= 0.0 ? t_near : kInf;
}

}  // namespace

WeatherEffects EffectsOf(Weather weather) {
  // Coarse figures following the trends of LiDAR-in-weather studies (e.g.
  // Rasshofer et al. 2011, Kutila et al. 2018), not a calibrated model:
  // droplets scatter and absorb the near-infrared pulse, so the usable range
  // shrinks, some pulses come back too weak to register (dropout), and
  // partial echoes off droplets jitter the range. Fog's dense small droplets
  // scatter far more than rain's sparse large ones, hence harsher values.
  switch (weather) {
    case Weather::kClear:
      return {1.0, 0.0, 0.0};
    case Weather::kRain:
      return {0.8, 0.03, 0.05};
    case Weather::kFog:
      return {0.5, 0.05, 0.15};
  }
  return {};
}

LidarSimulator::LidarSimulator(const Scene* scene, const LidarParams& params,
                               Weather weather, uint64_t seed)
    : scene_(scene),
      params_(params),
      effects_(EffectsOf(weather)),
      random_(seed) {
  const int beams = std::max(1, params_.beams);
  elevations_rad_.resize(beams);
  for (int i = 0; i < beams; ++i) {
    const double deg = beams == 1 ? 0.0
                                  : params_.vertical_fov_down_deg +
                                        (params_.vertical_fov_up_deg -
                                         params_.vertical_fov_down_deg) *
                                            i / (beams - 1);
    elevations_rad_[i] = deg * kDegToRad;
    elevation_cos_.push_back(std::cos(elevations_rad_[i]));
    elevation_sin_.push_back(std::sin(elevations_rad_[i]));
    elevation_tan_.push_back(std::tan(elevations_rad_[i]));
  }
  const double res_deg = params_.horizontal_resolution_deg > 0.0
                             ? params_.horizontal_resolution_deg
                             : 360.0;
  // Azimuths 0, res, 2 res, ... below 360 (the tolerance keeps 360/0.4 at
  // 900 despite rounding).
  const int columns =
      std::max(1, static_cast<int>(std::ceil(360.0 / res_deg - 1e-9)));
  azimuth_step_rad_ = res_deg * kDegToRad;
  azimuth_cos_.resize(columns);
  azimuth_sin_.resize(columns);
  for (int j = 0; j < columns; ++j) {
    azimuth_cos_[j] = std::cos(j * azimuth_step_rad_);
    azimuth_sin_[j] = std::sin(j * azimuth_step_rad_);
  }
}

int LidarSimulator::rays_per_scan() const {
  return static_cast<int>(elevations_rad_.size() * azimuth_cos_.size());
}

PointCloud LidarSimulator::Scan(
    const geometry::Pose2& sensor_pose, double stamp_s,
    const std::vector<geometry::OrientedBox>& vehicles,
    const geometry::Twist2& motion) {
  PointCloud cloud;
  cloud.stamp_s = stamp_s;
  cloud.points.reserve(rays_per_scan());

  const double limit = max_range_m();
  const double h = params_.mount_height_m;
  const double sigma = params_.range_noise_stddev_m + effects_.extra_noise_m;
  const double dropout = effects_.dropout_probability;
  const double cy = std::cos(sensor_pose.yaw_rad);
  const double sy = std::sin(sensor_pose.yaw_rad);
  const int columns = azimuths();
  const int beams = static_cast<int>(elevations_rad_.size());
  const Eigen::Vector2d origin(sensor_pose.x_m, sensor_pose.y_m);
  beam_best_m_.resize(beams);
  beam_hit_.resize(beams);

  // Vehicles that can be reached, with the azimuth columns they can cover,
  // so each ray tests only the one or two boxes in its direction.
  in_view_.clear();
  for (const geometry::OrientedBox& box : vehicles) {
    const Eigen::Vector2d rel =
        box.center - Eigen::Vector2d(sensor_pose.x_m, sensor_pose.y_m);
    // Every point of the footprint is within half a diagonal of its centre,
    // so a farther centre means the whole box is out of range.
    const double half_diag = 0.5 * std::hypot(box.length_m, box.width_m);
    if (rel.norm() > limit + half_diag) continue;
    VehicleInView v;
    const double cb = std::cos(box.yaw_rad), sb = std::sin(box.yaw_rad);
    v.ox = -(cb * rel.x() + sb * rel.y());
    v.oy = -(-sb * rel.x() + cb * rel.y());
    v.cr = std::cos(sensor_pose.yaw_rad - box.yaw_rad);
    v.sr = std::sin(sensor_pose.yaw_rad - box.yaw_rad);
    v.half_length = 0.5 * box.length_m;
    v.half_width = 0.5 * box.width_m;
    v.height = box.height_m;
    if (std::abs(v.ox) <= v.half_length && std::abs(v.oy) <= v.half_width) {
      v.first_azimuth = 0;  // sensor above/inside the footprint: all around
      v.azimuth_count = columns;
    } else {
      // From outside, a convex footprint spans less than pi, around the
      // direction of its centre; its corners bound the span.
      const double center_az =
          std::atan2(rel.y(), rel.x()) - sensor_pose.yaw_rad;
      const double center_abs = std::atan2(rel.y(), rel.x());
      double lo = 0.0, hi = 0.0;
      for (const Eigen::Vector2d& c : geometry::BoxCorners(box)) {
        const Eigen::Vector2d r =
            c - Eigen::Vector2d(sensor_pose.x_m, sensor_pose.y_m);
        const double d = WrapPi(std::atan2(r.y(), r.x()) - center_abs);
        lo = std::min(lo, d);
        hi = std::max(hi, d);
      }
      // One column of margin each side absorbs rounding.
      const long j_lo =
          static_cast<long>(std::floor((center_az + lo) / azimuth_step_rad_)) -
          1;
      const long j_hi =
          static_cast<long>(std::ceil((center_az + hi) / azimuth_step_rad_)) +
          1;
      v.azimuth_count =
          static_cast<int>(std::min<long>(columns, j_hi - j_lo + 1));
      v.first_azimuth =
          static_cast<int>(((j_lo % columns) + columns) % columns);
    }
    in_view_.push_back(v);
  }

  const bool moving = motion.v_mps != 0.0 || motion.yaw_rate_rps != 0.0;
  const double sweep_s = params_.rate_hz > 0.0 ? 1.0 / params_.rate_hz : 0.0;
  for (int j = 0; j < columns; ++j) {
    const double ca = azimuth_cos_[j], sa = azimuth_sin_[j];
    // The sensor's pose when it senses this column, in the start frame.
    const geometry::Pose2 moved =
        moving ? geometry::MotionAfter(motion, sweep_s * j / columns)
               : geometry::Pose2{};
    const double mc = std::cos(moved.yaw_rad), ms = std::sin(moved.yaw_rad);
    // World-frame horizontal direction of this column.
    const double wx = cy * ca - sy * sa;
    const double wy = sy * ca + cy * sa;
    column_vehicles_.clear();
    for (size_t k = 0; k < in_view_.size(); ++k) {
      const VehicleInView& v = in_view_[k];
      const int offset = ((j - v.first_azimuth) % columns + columns) % columns;
      if (offset < v.azimuth_count) {
        column_vehicles_.push_back(static_cast<int>(k));
      }
    }
    // Nearest return per beam from the ground and the vehicles first; the
    // scene is then searched only up to it.
    double s_reach = 0.0;  // farthest horizontal distance any beam needs
    for (int i = 0; i < beams; ++i) {
      const double ce = elevation_cos_[i], se = elevation_sin_[i];
      double best = limit;
      bool hit = false;
      if (se < 0.0) {
        const double t_ground = h / -se;
        if (t_ground <= best) {
          best = t_ground;
          hit = true;
        }
      }
      for (const int k : column_vehicles_) {
        const VehicleInView& v = in_view_[k];
        // Ray direction in the box frame: rotate by (sensor yaw - box yaw).
        const double bx = ce * (v.cr * ca - v.sr * sa);
        const double by = ce * (v.sr * ca + v.cr * sa);
        const double t = SlabEntry(v.ox, v.oy, h, bx, by, se, v.half_length,
                                   v.half_width, v.height);
        if (t <= best) {
          best = t;
          hit = true;
        }
      }
      beam_best_m_[i] = best;
      beam_hit_[i] = hit;
      if (ce > kMinCos) s_reach = std::max(s_reach, best * ce);
    }
    if (scene_ != nullptr) {
      // All beams of a column share one vertical plane: the faces crossing
      // it are found with one grid walk, then each beam takes the first
      // face its height at that distance falls within.
      scene_->CrossingsAlong(origin, Eigen::Vector2d(wx, wy), s_reach,
                             &crossings_);
      for (int i = 0; i < beams && !crossings_.empty(); ++i) {
        const double ce = elevation_cos_[i];
        if (ce <= kMinCos) continue;  // vertical: runs along no face
        const double s_max = beam_best_m_[i] * ce;
        for (const FaceCrossing& c : crossings_) {
          if (c.s_m > s_max) break;
          const double z = h + c.s_m * elevation_tan_[i];
          if (z < c.z_min_m || z > c.z_max_m) continue;
          const double t = c.s_m / ce;
          if (t <= beam_best_m_[i]) {
            beam_best_m_[i] = t;
            beam_hit_[i] = true;
          }
          break;
        }
      }
    }
    for (int i = 0; i < beams; ++i) {
      if (!beam_hit_[i]) continue;
      if (dropout > 0.0 && random_.Bernoulli(dropout)) continue;
      const double best = beam_best_m_[i];
      const double r = sigma > 0.0 ? best + random_.Normal(0.0, sigma) : best;
      // A real sensor reports nothing beyond its range (or behind itself).
      if (r <= 0.0 || r > limit) continue;
      const double ce = elevation_cos_[i], se = elevation_sin_[i];
      // Start frame to the frame of this column's moment.
      const double px = r * ce * ca - moved.x_m, py = r * ce * sa - moved.y_m;
      cloud.points.emplace_back(static_cast<float>(mc * px + ms * py),
                                static_cast<float>(-ms * px + mc * py),
                                static_cast<float>(r * se));
    }
  }
  return cloud;
}

}  // namespace adse::world
