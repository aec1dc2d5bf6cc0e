// Point cloud filters in the vehicle frame (x forward, y left, z up; origin
// on the ground under the rear axle). Eigen and std types only.
#ifndef ADSE_STACK_ALGORITHMS_POINT_FILTERS_H_
#define ADSE_STACK_ALGORITHMS_POINT_FILTERS_H_

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <utility>
#include <vector>

#include "stack/geometry/geometry.h"

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

// An axis-aligned box in the vehicle frame.
struct CropBox {
  double x_min_m = 0.0, x_max_m = 0.0;
  double y_min_m = 0.0, y_max_m = 0.0;
  double z_min_m = 0.0, z_max_m = 0.0;
};

// Removes the points inside any of `boxes` (Autoware's crop_box_filter with
// `negative: true`, as its self and mirror crops run). Work units: points
// in.
Points RemoveInsideBoxes(const Points& points,
                         const std::vector<CropBox>& boxes);

struct DistortionParams {
  double sweep_s = 0.1;  // one revolution, 1 / LiDAR rate
  // Odometry samples the corrector keeps (2 s at 50 Hz): like Autoware's it
  // queues the twists, deeper, so a busy node still takes every one.
  size_t twist_history = 100;
};

// The corrector's recent odometry: the newest `capacity` twists by stamp.
class TwistHistory {
 public:
  explicit TwistHistory(size_t capacity) : capacity_(capacity) {}

  // Keeps `twist`, dropping the oldest sample past the capacity.
  void Add(double stamp_s, const geometry::Twist2& twist);
  // The twist of the sample stamped nearest `stamp_s` (the older of two
  // equally near); standing still when none is kept.
  geometry::Twist2 Nearest(double stamp_s) const;
  size_t size() const { return samples_.size(); }

 private:
  size_t capacity_;
  std::deque<std::pair<double, geometry::Twist2>> samples_;
};

// Undoes a spinning LiDAR's motion distortion: each point is moved from the
// sensor frame at the moment its column was sensed to the frame at the
// sweep's start (the scan's stamp), by the twist the car had. The sensor
// turns counter-clockwise from azimuth 0 at the start, so a point's moment
// comes from its azimuth (the simulated sensor gives no per-point time).
// In a right turn the last few columns' points can appear past azimuth 360
// and are then taken for the first ones (at 0.5 rad/s and 10 Hz, 3 deg of
// 360). The sensor sits above the origin of the vehicle frame. Work units:
// points in.
Points CorrectDistortion(const Points& points, const geometry::Twist2& twist,
                         const DistortionParams& params);

// Autoware's ring_outlier_filter: along each beam's ring, in azimuth order,
// neighbours whose ranges differ by at most `distance_ratio` and whose
// azimuths by at most `max_azimuth_gap_deg` form a run; a run with fewer
// than `min_points` points that is also shorter than `min_length_m` is
// noise (rain, dust, a stray return) and goes.
struct RingOutlierParams {
  int beams = 16;                    // the sensor's rings
  double fov_down_deg = -15.0;       // elevation of the bottom ring
  double fov_up_deg = 15.0;          // elevation of the top ring
  double sensor_height_m = 1.9;      // above the vehicle frame's origin
  double distance_ratio = 1.03;      // max/min range of neighbours in a run
  double max_azimuth_gap_deg = 1.0;  // neighbours farther apart break a run
  int min_points = 4;                // a run this long stays ...
  double min_length_m = 0.1;         // ... and so does one this wide
};

// Removes isolated returns; keeps the input's order. Work units: points in.
Points RemoveRingOutliers(const Points& points,
                          const RingOutlierParams& params);

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
