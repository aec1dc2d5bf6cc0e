#include "stack/algorithms/clustering.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "stack/algorithms/point_filters.h"

namespace adse::algorithms {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Closeness score of the rectangle at heading yaw (Zhang et al., "Efficient
// L-Shape Fitting for Vehicle Detection Using Laser Scanners", 2017): each
// point counts 1 / (distance to the nearer of its two nearest box sides).
// Highest when the points hug the sides; works for full boxes and for the
// L-shapes a LiDAR sees, where the minimum-area rectangle is ambiguous.
double Closeness(const std::vector<Eigen::Vector2d>& pts, size_t stride,
                 double yaw) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  double u_lo = std::numeric_limits<double>::infinity(), u_hi = -u_lo;
  double v_lo = u_lo, v_hi = -u_lo;
  for (size_t i = 0; i < pts.size(); i += stride) {
    const double u = c * pts[i].x() + s * pts[i].y();
    const double v = -s * pts[i].x() + c * pts[i].y();
    u_lo = std::min(u_lo, u);
    u_hi = std::max(u_hi, u);
    v_lo = std::min(v_lo, v);
    v_hi = std::max(v_hi, v);
  }
  constexpr double kMinDistanceM = 0.01;  // caps one point's weight
  double score = 0.0;
  for (size_t i = 0; i < pts.size(); i += stride) {
    const double u = c * pts[i].x() + s * pts[i].y();
    const double v = -s * pts[i].x() + c * pts[i].y();
    const double du = std::min(u_hi - u, u - u_lo);
    const double dv = std::min(v_hi - v, v - v_lo);
    score += 1.0 / std::max(std::min(du, dv), kMinDistanceM);
  }
  return score;
}

// Extents of the points along the unit axis (c, s) and its normal.
void Extents(const std::vector<Eigen::Vector2d>& pts, double c, double s,
             double* u_lo, double* u_hi, double* v_lo, double* v_hi) {
  *u_lo = *v_lo = std::numeric_limits<double>::infinity();
  *u_hi = *v_hi = -std::numeric_limits<double>::infinity();
  for (const Eigen::Vector2d& p : pts) {
    const double u = c * p.x() + s * p.y();
    const double v = -s * p.x() + c * p.y();
    *u_lo = std::min(*u_lo, u);
    *u_hi = std::max(*u_hi, u);
    *v_lo = std::min(*v_lo, v);
    *v_hi = std::max(*v_hi, v);
  }
}

// Wraps a box heading into (-pi/2, pi/2]: a box looks the same both ways.
double WrapHalfTurn(double yaw) {
  while (yaw > kPi / 2) yaw -= kPi;
  while (yaw <= -kPi / 2) yaw += kPi;
  return yaw;
}

}  // namespace

Detection FitBox(const std::vector<Eigen::Vector3f>& points,
                 const std::vector<int>& indices, bool oriented,
                 double min_extent_m) {
  Detection det;
  std::vector<Eigen::Vector2d> pts;
  det.z_min_m = std::numeric_limits<double>::infinity();
  det.z_max_m = -std::numeric_limits<double>::infinity();
  auto add = [&](const Eigen::Vector3f& p) {
    if (!p.allFinite()) return;
    pts.emplace_back(p.x(), p.y());
    det.z_min_m = std::min<double>(det.z_min_m, p.z());
    det.z_max_m = std::max<double>(det.z_max_m, p.z());
  };
  if (indices.empty()) {
    for (const Eigen::Vector3f& p : points) add(p);
  } else {
    for (int i : indices) {
      if (i >= 0 && static_cast<size_t>(i) < points.size()) add(points[i]);
    }
  }
  det.point_count = static_cast<int>(pts.size());
  if (pts.empty()) {
    det.z_min_m = det.z_max_m = 0.0;
    det.length_m = det.width_m = min_extent_m;
    return det;
  }

  double best_yaw = 0.0;
  if (oriented && pts.size() >= 2) {
    // Coarse search over a quarter turn (a box repeats every 90 degrees),
    // then a fine one around the best; big clusters are subsampled for
    // the search only.
    const size_t stride = std::max<size_t>(1, pts.size() / 400);
    constexpr int kCoarseSteps = 90;
    const double coarse = (kPi / 2) / kCoarseSteps;
    double best_score = -1.0;
    for (int k = 0; k < kCoarseSteps; ++k) {
      const double score = Closeness(pts, stride, k * coarse);
      if (score > best_score + 1e-9) {
        best_score = score;
        best_yaw = k * coarse;
      }
    }
    const double center = best_yaw;
    for (int k = -10; k <= 10; ++k) {
      const double yaw = center + k * coarse / 10;
      const double score = Closeness(pts, stride, yaw);
      if (score > best_score + 1e-9) {
        best_score = score;
        best_yaw = yaw;
      }
    }
  }
  const double c = std::cos(best_yaw), s = std::sin(best_yaw);
  double u_lo, u_hi, v_lo, v_hi;
  Extents(pts, c, s, &u_lo, &u_hi, &v_lo, &v_hi);
  const double uc = 0.5 * (u_lo + u_hi), vc = 0.5 * (v_lo + v_hi);
  det.center = Eigen::Vector2d(c * uc - s * vc, s * uc + c * vc);
  double length = u_hi - u_lo, width = v_hi - v_lo;
  if (oriented && width > length) {
    std::swap(length, width);
    best_yaw += kPi / 2;
  }
  det.yaw_rad = oriented ? WrapHalfTurn(best_yaw) : 0.0;
  det.length_m = std::max(length, min_extent_m);
  det.width_m = std::max(width, min_extent_m);
  return det;
}

DetectionResult DetectObjects(const std::vector<Eigen::Vector3f>& points,
                              const ClusteringParams& params) {
  if (params.downsample_leaf_m > 0.0) {
    ClusteringParams dense = params;
    dense.downsample_leaf_m = 0.0;
    return DetectObjects(VoxelDownsample(points, params.downsample_leaf_m),
                         dense);
  }
  DetectionResult result;
  result.work_units = static_cast<int64_t>(points.size());
  std::vector<std::vector<int>> clusters;
  if (params.cluster_in_2d) {
    std::vector<Eigen::Vector3f> flat(points);
    for (Eigen::Vector3f& p : flat) p.z() = 0.0f;
    clusters = EuclideanClusters(flat, params.tolerance_m, params.min_points,
                                 params.max_points);
  } else {
    clusters = EuclideanClusters(points, params.tolerance_m, params.min_points,
                                 params.max_points);
  }
  result.detections.reserve(clusters.size());
  for (const std::vector<int>& cluster : clusters) {
    result.detections.push_back(
        FitBox(points, cluster, params.oriented_boxes, params.min_extent_m));
  }
  return result;
}

Detection ToMapFrame(const Detection& detection,
                     const geometry::Pose2& vehicle_pose) {
  Detection out = detection;
  const double c = std::cos(vehicle_pose.yaw_rad);
  const double s = std::sin(vehicle_pose.yaw_rad);
  const Eigen::Vector2d& p = detection.center;
  out.center = Eigen::Vector2d(vehicle_pose.x_m + c * p.x() - s * p.y(),
                               vehicle_pose.y_m + s * p.x() + c * p.y());
  out.yaw_rad = WrapHalfTurn(detection.yaw_rad + vehicle_pose.yaw_rad);
  return out;
}

}  // namespace adse::algorithms
