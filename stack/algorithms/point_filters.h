// Point cloud filters in the vehicle frame (x forward, y left, z up; origin
// on the ground under the rear axle). Eigen and std types only.
#ifndef ADSE_STACK_ALGORITHMS_POINT_FILTERS_H_
#define ADSE_STACK_ALGORITHMS_POINT_FILTERS_H_

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace adse::algorithms {

using Points = std::vector<Eigen::Vector3f>;

struct CropParams {
  double min_range_m = 1.0;   // horizontal range below which points go
  double max_range_m = 60.0;  // horizontal range above which points go
  double z_min_m = -1.0;      // points lower than this go (below ground)
  double z_max_m = 4.0;       // points higher than this go (trees, roofs)
  // The ego body in the vehicle frame: returns off our own car (mirrors,
  // roof rack) are removed. x from rear overhang to front bumper.
  bool remove_ego = true;         // false keeps points inside the ego box
  double ego_x_min_m = -1.0;      // rear bumper behind the rear axle
  double ego_x_max_m = 3.8;       // front bumper ahead of the rear axle
  double ego_half_width_m = 1.0;  // half the body width plus a margin
};

// Keeps points inside the range annulus and the z band, outside the ego box.
// Non-finite points are dropped. Work units: points in.
Points CropPoints(const Points& points, const CropParams& params);

struct GroundParams {
  // A point higher than this above the ground plane is an obstacle. The
  // ground is z = 0 in the vehicle frame unless a plane is fitted.
  double height_threshold_m = 0.25;
  // Fit a plane by RANSAC to low points (tilted or bumpy ground, sensor
  // pitch); falls back to z = 0 when the fit is implausible.
  bool fit_plane = false;
  int ransac_iterations = 40;              // plane hypotheses tried
  double ransac_inlier_distance_m = 0.08;  // |distance| counting as inlier
  double ransac_candidate_band_m = 0.4;    // only |z| below this may be ground
  double max_plane_tilt_rad = 0.15;        // steeper fits are rejected
  double max_plane_offset_m = 0.3;         // |height at the origin| allowed
  double min_inlier_fraction = 0.2;        // of the candidates, to accept
  uint64_t seed = 1;                       // RANSAC draws (deterministic)
};

struct GroundResult {
  Points obstacles;  // points above the ground by more than the threshold
  Points ground;     // the rest
  // Ground plane n·p + d = 0 with unit normal n (z up): (nx, ny, nz, d).
  Eigen::Vector4d plane = Eigen::Vector4d(0, 0, 1, 0);
  bool plane_fitted = false;  // true: RANSAC plane used, false: z = 0
  int64_t work_units = 0;     // points in (+ points x hypotheses if fitted)
};

// Splits points into ground and obstacles.
GroundResult RemoveGround(const Points& points, const GroundParams& params);

// Voxel-grid downsampling (pcl::VoxelGrid): one centroid per occupied cube
// of edge leaf_m. leaf_m <= 0 (or a grid too fine for PCL's index range)
// returns the input unchanged. Work units: points in.
Points VoxelDownsample(const Points& points, double leaf_m);

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_POINT_FILTERS_H_
