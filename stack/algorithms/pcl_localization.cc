// Every PCL use of the stack lives here: PCL's NDT and filter headers cost
// ~15 s and ~1 GB per translation unit, so one file pays that once.

// GCC's flow analysis flags Eigen's JacobiSVD inside PCL's NDT as "maybe
// uninitialized" after inlining (a known false positive; -isystem does not
// silence middle-end warnings).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <pcl/common/transforms.h>
#include <pcl/console/print.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/ndt.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <exception>
#include <string>

#include "stack/algorithms/clustering.h"
#include "stack/algorithms/ndt_matcher.h"
#include "stack/algorithms/point_filters.h"

namespace adse::algorithms {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

Cloud::Ptr ToCloud(const std::vector<Eigen::Vector3f>& points) {
  auto cloud = std::make_shared<Cloud>();
  cloud->points.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    if (p.allFinite()) cloud->points.emplace_back(p.x(), p.y(), p.z());
  }
  cloud->width = static_cast<uint32_t>(cloud->points.size());
  cloud->height = 1;
  cloud->is_dense = true;
  return cloud;
}

// ---------------------------------------------------------------- NDT

// PCL's NDT with its normal cells open to the acceptance test.
class Ndt
    : public pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ> {
 public:
  // PCL's NDT score of `cloud` (map frame) as it stands: per point, the sum
  // over the normal cells within one resolution (Magnusson's eq. 6.9, as
  // computeDerivatives adds it up). Also the score and count of the points
  // higher than min_z_m (structure, not ground) that have a cell.
  double Score(const Cloud& cloud, double min_z_m, double* structure_score,
               int* structure_near) const {
    std::vector<TargetGridLeafConstPtr> cells;
    std::vector<float> distances;
    double score = 0.0;
    *structure_score = 0.0;
    *structure_near = 0;
    for (const pcl::PointXYZ& p : cloud.points) {
      target_cells_.radiusSearch(p, resolution_, cells, distances);
      double point_score = 0.0;
      for (const TargetGridLeafConstPtr& cell : cells) {
        const Eigen::Vector3d d =
            p.getVector3fMap().cast<double>() - cell->getMean();
        point_score +=
            -gauss_d1_ *
            std::exp(-gauss_d2_ * d.dot(cell->getInverseCov() * d) / 2);
      }
      score += point_score;
      if (!cells.empty() && p.z > min_z_m) {
        ++*structure_near;
        *structure_score += point_score;
      }
    }
    return score;
  }
};

}  // namespace

struct NdtMatcher::Impl {
  Ndt ndt;
  Cloud::Ptr map;
  // Nearest map point for the fitness score; shared with NDT so PCL does
  // not build a second tree on the first Align().
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree;
  Cloud aligned;  // scratch output of align(), reused
  Cloud planar;   // the scan at the planar pose, reused
};

NdtMatcher::NdtMatcher(const NdtParams& params)
    : params_(params), impl_(std::make_unique<Impl>()) {
  // Planar map cells (walls) make PCL warn about degenerate covariances on
  // every map build; they are handled, and the warnings drown real output.
  pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
  impl_->ndt.setResolution(static_cast<float>(params_.resolution_m));
  impl_->ndt.setStepSize(params_.step_size_m);
  // PCL 1.13 compares the *squared* translation of the last step with its
  // epsilon; with epsilon = 0.01 and 0.1 m steps it would stop after one
  // step. Our epsilon is a length, so PCL gets its square.
  impl_->ndt.setTransformationEpsilon(params_.epsilon_m * params_.epsilon_m);
  impl_->ndt.setMaximumIterations(params_.max_iterations);
  impl_->ndt.setOulierRatio(params_.outlier_ratio);
}

NdtMatcher::~NdtMatcher() = default;

bool NdtMatcher::has_map() const { return impl_->map != nullptr; }

Eigen::Matrix3d NdtMatcher::MatchCovariance() const {
  const double p = params_.match_position_std_m;
  const double y = params_.match_yaw_std_rad;
  return Eigen::Vector3d(p * p, p * p, y * y).asDiagonal();
}

int NdtMatcher::map_size() const {
  return impl_->map ? static_cast<int>(impl_->map->size()) : 0;
}

Status NdtMatcher::SetMap(const std::vector<Eigen::Vector3f>& map_points) {
  if (params_.resolution_m <= 0.0 || params_.step_size_m <= 0.0 ||
      params_.max_iterations <= 0) {
    return Status::InvalidArgument(
        "NDT needs resolution_m > 0, step_size_m > 0, max_iterations > 0");
  }
  Cloud::Ptr map = ToCloud(map_points);
  if (map->size() < 10) {
    return Status::InvalidArgument("NDT map has " +
                                   std::to_string(map->size()) +
                                   " finite points; need at least 10");
  }
  try {
    auto tree = std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>();
    tree->setInputCloud(map);
    impl_->ndt.setInputTarget(map);  // builds the normal cells
    // force_no_recompute: the tree is already built on this target.
    impl_->ndt.setSearchMethodTarget(tree, /*force_no_recompute=*/true);
    impl_->map = map;
    impl_->tree = tree;
  } catch (const std::exception& e) {
    impl_->map.reset();
    impl_->tree.reset();
    return Status::Internal(std::string("NDT map: ") + e.what());
  }
  return Status::Ok();
}

Result<NdtResult> NdtMatcher::Align(const std::vector<Eigen::Vector3f>& scan,
                                    const geometry::Pose2& initial_guess) {
  if (!has_map()) return Status::Unavailable("NDT has no map");
  Cloud::Ptr source = ToCloud(scan);
  if (source->empty()) {
    return Status::InvalidArgument("NDT scan has no finite points");
  }
  Eigen::Matrix4f guess = Eigen::Matrix4f::Identity();
  guess.topLeftCorner<3, 3>() =
      Eigen::AngleAxisf(static_cast<float>(initial_guess.yaw_rad),
                        Eigen::Vector3f::UnitZ())
          .toRotationMatrix();
  guess(0, 3) = static_cast<float>(initial_guess.x_m);
  guess(1, 3) = static_cast<float>(initial_guess.y_m);

  NdtResult result;
  try {
    impl_->ndt.setInputSource(source);
    impl_->ndt.align(impl_->aligned, guess);
    result.transform = impl_->ndt.getFinalTransformation();
    result.iterations = impl_->ndt.getFinalNumIteration();
    result.converged = impl_->ndt.hasConverged();
  } catch (const std::exception& e) {
    return Status::Internal(std::string("NDT align: ") + e.what());
  }
  if (!result.transform.allFinite()) {
    return Status::Internal("NDT produced a non-finite transform");
  }
  result.points_used = static_cast<int>(source->size());
  result.hit_iteration_limit = result.iterations >= params_.max_iterations;
  const Eigen::Matrix4f& t = result.transform;
  result.pose.x_m = t(0, 3);
  result.pose.y_m = t(1, 3);
  result.z_m = t(2, 3);
  // Yaw of the rotated x axis projected on the ground plane: stays right
  // with small roll/pitch left free.
  result.pose.yaw_rad = std::atan2(t(1, 0), t(0, 0));

  // Scores of the planar pose that is published, not of NDT's 6-DoF
  // result: where the map's ground has no cells (too sparse), nothing holds
  // NDT's z, which drifts up to 0.4 m and lifts the scan's ground off the
  // map's, failing right poses.
  const Eigen::Affine3f planar =
      Eigen::Translation3f(result.pose.x_m, result.pose.y_m, 0.0f) *
      Eigen::AngleAxisf(static_cast<float>(result.pose.yaw_rad),
                        Eigen::Vector3f::UnitZ());
  pcl::transformPointCloud(*source, impl_->planar, planar);
  // Fitness: mean capped squared distance of the scan to the map. PCL's
  // getFitnessScore ignores far points instead of capping them, which
  // scores a scan matched to nothing as perfect.
  const double cap2 =
      params_.fitness_max_distance_m * params_.fitness_max_distance_m;
  double sum = 0.0;
  std::vector<int> index(1);
  std::vector<float> dist2(1);
  for (const pcl::PointXYZ& p : impl_->planar.points) {
    if (impl_->tree->nearestKSearch(p, 1, index, dist2) > 0) {
      sum += std::min<double>(dist2[0], cap2);
    } else {
      sum += cap2;
    }
  }
  result.fitness_score_m2 = sum / result.points_used;
  double structure_score = 0.0;
  const double score =
      impl_->ndt.Score(impl_->planar, params_.ground_height_m, &structure_score,
                       &result.structure_points);
  result.transform_likelihood = score / result.points_used;
  result.structure_likelihood = result.structure_points > 0
                                    ? structure_score / result.structure_points
                                    : 0.0;
  const bool likely =
      result.transform_likelihood >= params_.min_transform_likelihood ||
      (result.structure_points >= params_.min_structure_points &&
       result.structure_likelihood >= params_.min_structure_likelihood);
  result.accepted = result.converged &&
                    result.fitness_score_m2 < params_.max_fitness_m2 && likely;
  // The fitness pass costs about one more iteration's worth of searches
  // (the scores at the planar pose are part of scoring, as Autoware's NDT,
  // whose costs the profile holds, computes its nearest-voxel likelihood).
  result.work_units = static_cast<int64_t>(result.iterations + 1) *
                      static_cast<int64_t>(result.points_used);
  return result;
}

// ------------------------------------------------------------- filters

Points VoxelDownsample(const Points& points, double leaf_m) {
  if (!(leaf_m > 0.0) || points.empty()) return points;
  try {
    Cloud::Ptr cloud = ToCloud(points);
    pcl::VoxelGrid<pcl::PointXYZ> grid;
    const float leaf = static_cast<float>(leaf_m);
    grid.setLeafSize(leaf, leaf, leaf);
    grid.setInputCloud(cloud);
    Cloud out;
    grid.filter(out);
    Points result;
    result.reserve(out.size());
    for (const pcl::PointXYZ& p : out.points) {
      result.emplace_back(p.x, p.y, p.z);
    }
    return result;
  } catch (const std::exception&) {
    return points;  // PCL failing to downsample must not stop the stack
  }
}

std::vector<std::vector<int>> EuclideanClusters(
    const std::vector<Eigen::Vector3f>& points, double tolerance_m,
    int min_points, int max_points) {
  std::vector<std::vector<int>> clusters;
  if (points.empty() || !(tolerance_m > 0.0) || max_points < 1) {
    return clusters;
  }
  // Indices refer to the input, so non-finite points must not shift them:
  // they are moved far away, where they form no cluster with real ones.
  auto cloud = std::make_shared<Cloud>();
  cloud->points.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    if (p.allFinite()) {
      cloud->points.emplace_back(p.x(), p.y(), p.z());
    } else {
      cloud->points.emplace_back(1e9f, 1e9f, 1e9f);
    }
  }
  cloud->width = static_cast<uint32_t>(cloud->points.size());
  cloud->height = 1;
  try {
    auto tree = std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>();
    tree->setInputCloud(cloud);
    pcl::EuclideanClusterExtraction<pcl::PointXYZ> extraction;
    extraction.setClusterTolerance(tolerance_m);
    extraction.setMinClusterSize(std::max(1, min_points));
    extraction.setMaxClusterSize(max_points);
    extraction.setSearchMethod(tree);
    extraction.setInputCloud(cloud);
    std::vector<pcl::PointIndices> found;
    extraction.extract(found);
    clusters.reserve(found.size());
    for (pcl::PointIndices& indices : found) {
      std::vector<int> cluster;
      cluster.reserve(indices.indices.size());
      for (int i : indices.indices) {
        if (points[i].allFinite()) cluster.push_back(i);
      }
      if (static_cast<int>(cluster.size()) < min_points) continue;
      std::sort(cluster.begin(), cluster.end());
      clusters.push_back(std::move(cluster));
    }
  } catch (const std::exception&) {
    clusters.clear();
  }
  return clusters;
}

}  // namespace adse::algorithms
