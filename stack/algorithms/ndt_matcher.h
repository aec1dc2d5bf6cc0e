// NDT scan matching of a LiDAR scan against the localization map (PCL's
// NormalDistributionsTransform behind a pimpl: no PCL type in this header).
#ifndef ADSE_STACK_ALGORITHMS_NDT_MATCHER_H_
#define ADSE_STACK_ALGORITHMS_NDT_MATCHER_H_

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "stack/base/status.h"
#include "stack/geometry/geometry.h"

namespace adse::algorithms {

struct NdtParams {
  double resolution_m = 2.0;  // NDT voxel edge (the map's normal cells)
  double step_size_m = 0.1;   // More-Thuente line search: max step length
  double epsilon_m = 0.01;    // stop when a step moves the pose less than this
  int max_iterations = 30;    // Newton iterations per alignment
  // Acceptance: PCL reports "converged" at wrong poses (also whenever it
  // hits the iteration limit), so a result is accepted only when both
  // scores below look like a match. Measured on the world's map cloud and
  // simulated 16-beam scans (clear/rain/fog, 0-5 unmapped cars): right
  // poses gave fitness 0.01-0.20 m^2 and likelihood 2.2-3.2; poses ~10 m
  // off gave fitness 0.5-3.1 and likelihood 0.3-1.9, each failing a test,
  // except a 10 m shift along a repetitive row of parked cars (0.38,
  // 1.73): aliasing no score sees; the EKF's Mahalanobis gate catches it.
  // fitness_score_m2: mean squared distance from each aligned scan point to
  // the nearest map point, capped per point; must be below this.
  double max_fitness_m2 = 0.5;
  // Capping distance: a few unmapped objects cannot dominate the score.
  double fitness_max_distance_m = 3.0;
  // PCL's NDT score per point (transform likelihood); must be at least
  // this. Depends on resolution and outlier_ratio: retune with them.
  double min_transform_likelihood = 1.5;
  // That likelihood counts every scan point, and scores 0 for points the
  // map has no normal cell for: its ground grid (1 m, 1.5 m on city maps)
  // gives a 2 m cell too few points. Where structure is sparse (an OSM
  // town: roadside poles only) right poses score 0.1-0.3 and all were
  // refused. So a match is also accepted on the likelihood per structure
  // point (higher than ground_height_m at the pose) that has a cell, as
  // Autoware's nearest-voxel likelihood: measured 4.9-7.2 at right poses
  // (parking lot, a pole-lined road, the DRT town), 0-1.2 at poses 2.5-11
  // m off (where fitness alone, 0.33-0.40 at some, would not tell), given
  // enough such points (18-609 at right poses; a start on acosta, with two
  // poles in 20 m, had 18 at 6.5).
  double ground_height_m = 0.3;
  double min_structure_likelihood = 3.0;
  int min_structure_points = 10;
  double outlier_ratio = 0.55;  // NDT's mixture weight for outliers
  int threads = 1;              // hint only; PCL 1.13's NDT is serial
  // Uncertainty (1 sigma) the pose fusion gives a match: NDT's Hessian is
  // no calibrated covariance, so a fixed one at the map's accuracy is used.
  double match_position_std_m = 0.05;
  double match_yaw_std_rad = 0.01;
};

struct NdtResult {
  // Vehicle pose in the map frame (the scan-to-map transform), planar part.
  geometry::Pose2 pose;
  double z_m = 0.0;  // height of the transform (ground should give ~0)
  // Full scan-to-map transform, z and roll/pitch free.
  Eigen::Matrix4f transform = Eigen::Matrix4f::Identity();
  // The scores below are those of `pose` (z = 0, no roll or pitch), the
  // pose that is used, not of `transform`.
  double fitness_score_m2 = 0.0;      // see NdtParams::max_fitness_m2
  double transform_likelihood = 0.0;  // see min_transform_likelihood
  int iterations = 0;                 // Newton iterations used
  // PCL's flag; PCL also sets it when the iteration limit is hit.
  bool converged = false;
  bool hit_iteration_limit = false;  // iterations == max_iterations
  // converged, fitness below max, and either likelihood at least its min
  // or structure likelihood at least its min over enough points.
  bool accepted = false;
  int points_used = 0;  // scan points given to NDT
  // Structure points of the scan (higher than ground_height_m) with a
  // normal cell of the map within one resolution, and their likelihood
  // per point (see NdtParams::min_structure_likelihood).
  int structure_points = 0;
  double structure_likelihood = 0.0;
  int64_t work_units = 0;  // iterations x points (cost model)
};

class NdtMatcher {
 public:
  explicit NdtMatcher(const NdtParams& params = {});
  ~NdtMatcher();
  NdtMatcher(const NdtMatcher&) = delete;
  NdtMatcher& operator=(const NdtMatcher&) = delete;

  // Builds the NDT target (normal cells) and the fitness search tree once.
  // Costly for big maps; call once per map.
  Status SetMap(const std::vector<Eigen::Vector3f>& map_points);
  bool has_map() const;
  int map_size() const;

  // Aligns a scan given in the vehicle frame, starting from a planar guess
  // (z = 0, no roll/pitch). Errors: no map, an empty scan, a PCL failure.
  // A bad match is not an error: it comes back with accepted == false.
  Result<NdtResult> Align(const std::vector<Eigen::Vector3f>& scan,
                          const geometry::Pose2& initial_guess);

  const NdtParams& params() const { return params_; }
  // Covariance over (x, y, yaw) of a match (match_*_std of the params).
  Eigen::Matrix3d MatchCovariance() const;

 private:
  struct Impl;
  NdtParams params_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_NDT_MATCHER_H_
