// Obstacle detection: Euclidean clustering of obstacle points and a 2D box
// per cluster. Eigen and std types only.
#ifndef ADSE_STACK_ALGORITHMS_CLUSTERING_H_
#define ADSE_STACK_ALGORITHMS_CLUSTERING_H_

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "stack/geometry/geometry.h"

namespace adse::algorithms {

// Indices of each cluster (pcl::EuclideanClusterExtraction with a KdTree):
// points closer than tolerance_m are chained into one cluster; clusters
// with fewer than min_points or more than max_points are dropped. Largest
// first. Empty on bad arguments. Work units: points in.
std::vector<std::vector<int>> EuclideanClusters(
    const std::vector<Eigen::Vector3f>& points, double tolerance_m,
    int min_points, int max_points);

struct ClusteringParams {
  double tolerance_m = 0.7;  // max gap between points of one object
  int min_points = 4;        // smaller clusters are noise
  int max_points = 20000;    // larger clusters are dropped (PCL limit)
  // Cluster on (x, y) only: a sparse LiDAR's rings on one car are further
  // apart vertically than horizontally.
  bool cluster_in_2d = true;
  // Minimum-area rectangle (true) or axis-aligned box (false).
  bool oriented_boxes = true;
  double min_extent_m = 0.2;  // boxes are at least this long and wide
  // Points are first thinned to one per voxel of this edge (0: not), as
  // production clustering pipelines do: object shapes survive a 0.2 m grid
  // and the clustering cost drops.
  double downsample_leaf_m = 0.2;
};

// A 2D box around a cluster; in the frame of the input points.
struct Detection {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  double length_m = 0.0;  // extent along yaw (>= width for oriented boxes)
  double width_m = 0.0;
  double yaw_rad = 0.0;  // in (-pi/2, pi/2]; a box has no front
  double z_min_m = 0.0;
  double z_max_m = 0.0;
  int point_count = 0;
};

struct DetectionResult {
  std::vector<Detection> detections;
  int64_t work_units = 0;  // points clustered
};

// Clusters obstacle points (ground already removed) into boxes. Work units:
// the points clustered (after downsampling).
DetectionResult DetectObjects(const std::vector<Eigen::Vector3f>& points,
                              const ClusteringParams& params);

// The box around the given points (all of them when indices is empty).
Detection FitBox(const std::vector<Eigen::Vector3f>& points,
                 const std::vector<int>& indices, bool oriented,
                 double min_extent_m);

// Moves a detection from the vehicle frame to the map frame.
Detection ToMapFrame(const Detection& detection,
                     const geometry::Pose2& vehicle_pose);

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_CLUSTERING_H_
