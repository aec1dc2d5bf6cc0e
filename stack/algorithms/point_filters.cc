#include "stack/algorithms/point_filters.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "stack/base/random.h"

namespace adse::algorithms {

Points CropPoints(const Points& points, const CropParams& params) {
  Points out;
  out.reserve(points.size());
  const double min_r2 = params.min_range_m * params.min_range_m;
  const double max_r2 = params.max_range_m * params.max_range_m;
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;
    const double r2 = double(p.x()) * p.x() + double(p.y()) * p.y();
    if (r2 < min_r2 || r2 > max_r2) continue;
    if (p.z() < params.z_min_m || p.z() > params.z_max_m) continue;
    if (params.remove_ego && p.x() >= params.ego_x_min_m &&
        p.x() <= params.ego_x_max_m &&
        std::abs(p.y()) <= params.ego_half_width_m) {
      continue;
    }
    out.push_back(p);
  }
  return out;
}

Points RemoveInsideBoxes(const Points& points,
                         const std::vector<CropBox>& boxes) {
  Points out;
  out.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    const bool inside =
        std::any_of(boxes.begin(), boxes.end(), [&p](const CropBox& b) {
          return p.x() >= b.x_min_m && p.x() <= b.x_max_m &&
                 p.y() >= b.y_min_m && p.y() <= b.y_max_m &&
                 p.z() >= b.z_min_m && p.z() <= b.z_max_m;
        });
    if (!inside) out.push_back(p);
  }
  return out;
}

void TwistHistory::Add(double stamp_s, const geometry::Twist2& twist) {
  samples_.emplace_back(stamp_s, twist);
  if (samples_.size() > capacity_) samples_.pop_front();
}

geometry::Twist2 TwistHistory::Nearest(double stamp_s) const {
  geometry::Twist2 twist;
  double best_s = std::numeric_limits<double>::infinity();
  for (const auto& [sample_s, sample] : samples_) {
    const double gap_s = std::abs(sample_s - stamp_s);
    if (gap_s < best_s) {
      best_s = gap_s;
      twist = sample;
    }
  }
  return twist;
}

Points CorrectDistortion(const Points& points, const geometry::Twist2& twist,
                         const DistortionParams& params) {
  if (twist.v_mps == 0.0 && twist.yaw_rate_rps == 0.0) return points;
  constexpr double kTwoPi = 2.0 * M_PI;
  Points out;
  out.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    double azimuth = std::atan2(double(p.y()), double(p.x()));
    if (azimuth < 0.0) azimuth += kTwoPi;
    const geometry::Pose2 moved =
        geometry::MotionAfter(twist, params.sweep_s * azimuth / kTwoPi);
    const double c = std::cos(moved.yaw_rad), s = std::sin(moved.yaw_rad);
    out.emplace_back(static_cast<float>(c * p.x() - s * p.y() + moved.x_m),
                     static_cast<float>(s * p.x() + c * p.y() + moved.y_m),
                     p.z());
  }
  return out;
}

Points RemoveRingOutliers(const Points& points,
                          const RingOutlierParams& params) {
  constexpr double kRadToDeg = 180.0 / M_PI;
  const int beams = std::max(1, params.beams);
  const double span_deg = params.fov_up_deg - params.fov_down_deg;
  // Points by ring; each ring stays in the driver's (azimuth) order.
  std::vector<std::vector<int>> rings(beams);
  std::vector<double> range(points.size()), azimuth(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    const double horizontal = std::hypot(double(p.x()), double(p.y()));
    const double elevation_deg =
        std::atan2(p.z() - params.sensor_height_m, horizontal) * kRadToDeg;
    const int ring = beams == 1 ? 0
                                : static_cast<int>(std::lround(
                                      (elevation_deg - params.fov_down_deg) /
                                      span_deg * (beams - 1)));
    range[i] = std::hypot(horizontal, p.z() - params.sensor_height_m);
    azimuth[i] = std::atan2(double(p.y()), double(p.x())) * kRadToDeg;
    rings[std::clamp(ring, 0, beams - 1)].push_back(static_cast<int>(i));
  }
  std::vector<char> keep(points.size(), 0);
  for (const std::vector<int>& ring : rings) {
    size_t begin = 0;
    while (begin < ring.size()) {
      size_t end = begin + 1;  // the run is [begin, end)
      while (end < ring.size()) {
        const int a = ring[end - 1], b = ring[end];
        const double lo = std::min(range[a], range[b]);
        const double hi = std::max(range[a], range[b]);
        const double gap = std::abs(azimuth[b] - azimuth[a]);
        if (lo <= 0.0 || hi / lo > params.distance_ratio ||
            std::min(gap, 360.0 - gap) > params.max_azimuth_gap_deg) {
          break;
        }
        ++end;
      }
      const double length =
          (points[ring[end - 1]] - points[ring[begin]]).norm();
      if (static_cast<int>(end - begin) >= params.min_points ||
          length >= params.min_length_m) {
        for (size_t k = begin; k < end; ++k) keep[ring[k]] = 1;
      }
      begin = end;
    }
  }
  Points out;
  out.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    if (keep[i]) out.push_back(points[i]);
  }
  return out;
}

namespace {

// RANSAC over the low points. Returns false when no plausible plane wins,
// so the caller keeps z = 0 (flat ground is the safe default: a bad fit
// would call a car's side "ground").
bool FitGroundPlane(const Points& points, const GroundParams& params,
                    Eigen::Vector4d* plane, int64_t* work) {
  std::vector<Eigen::Vector3d> low;
  low.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    if (p.allFinite() && std::abs(p.z()) < params.ransac_candidate_band_m) {
      low.push_back(p.cast<double>());
    }
  }
  if (low.size() < 3 || params.ransac_iterations <= 0) return false;
  Random random(params.seed);
  const double cos_max_tilt = std::cos(params.max_plane_tilt_rad);
  size_t best_inliers = 0;
  Eigen::Vector4d best(0, 0, 1, 0);
  for (int it = 0; it < params.ransac_iterations; ++it) {
    const Eigen::Vector3d& a = low[random.Below(low.size())];
    const Eigen::Vector3d& b = low[random.Below(low.size())];
    const Eigen::Vector3d& c = low[random.Below(low.size())];
    Eigen::Vector3d n = (b - a).cross(c - a);
    const double norm = n.norm();
    if (norm < 1e-6) continue;  // degenerate (collinear or repeated)
    n /= norm;
    if (n.z() < 0) n = -n;
    if (n.z() < cos_max_tilt) continue;
    const double d = -n.dot(a);
    // Height of the plane under the origin: z = -d / nz.
    if (std::abs(d / n.z()) > params.max_plane_offset_m) continue;
    size_t inliers = 0;
    for (const Eigen::Vector3d& p : low) {
      if (std::abs(n.dot(p) + d) < params.ransac_inlier_distance_m) ++inliers;
    }
    *work += static_cast<int64_t>(low.size());
    if (inliers > best_inliers) {
      best_inliers = inliers;
      best << n, d;
    }
  }
  if (best_inliers < 3 ||
      best_inliers < params.min_inlier_fraction * double(low.size())) {
    return false;
  }
  // Refine by least squares on the inliers (z = a x + b y + c) so the
  // plane does not hinge on three noisy samples.
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : low) {
    if (std::abs(best.head<3>().dot(p) + best(3)) <
        params.ransac_inlier_distance_m) {
      const Eigen::Vector3d row(p.x(), p.y(), 1.0);
      ata += row * row.transpose();
      atb += row * p.z();
    }
  }
  const Eigen::Vector3d abc = ata.ldlt().solve(atb);
  if (abc.allFinite()) {
    Eigen::Vector3d n(-abc(0), -abc(1), 1.0);
    const double norm = n.norm();
    n /= norm;
    const double d = -abc(2) / norm;
    if (n.z() >= cos_max_tilt &&
        std::abs(d / n.z()) <= params.max_plane_offset_m) {
      best << n, d;
    }
  }
  *plane = best;
  return true;
}

}  // namespace

GroundResult RemoveGround(const Points& points, const GroundParams& params) {
  GroundResult result;
  result.work_units = static_cast<int64_t>(points.size());
  if (params.fit_plane) {
    result.plane_fitted =
        FitGroundPlane(points, params, &result.plane, &result.work_units);
  }
  const Eigen::Vector3d n = result.plane.head<3>();
  const double d = result.plane(3);
  result.obstacles.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;
    const double height = n.dot(p.cast<double>()) + d;
    if (height > params.height_threshold_m) {
      result.obstacles.push_back(p);
    } else {
      result.ground.push_back(p);
    }
  }
  return result;
}

}  // namespace adse::algorithms
