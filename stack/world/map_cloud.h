// The localization map: a dense point cloud sampled from the static scene
// (what a survey vehicle's LiDAR map would hold), and PCD file I/O for it.
#ifndef ADSE_STACK_WORLD_MAP_CLOUD_H_
#define ADSE_STACK_WORLD_MAP_CLOUD_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "stack/base/status.h"
#include "stack/world/scene.h"

namespace adse::world {

struct MapCloudOptions {
  // Grid step over every obstacle's vertical faces.
  double spacing_m = 0.2;
  // Ground points (z = 0): a sparse grid, enough to pin down height and
  // tilt in scan matching; <= 0 leaves the ground out.
  double ground_spacing_m = 1.0;
  // The ground grid covers the scene bounds grown by this much: as far as
  // the LiDAR sees (LidarParams::range_m) past the outermost structure. With
  // 10 m, a car starting at the fringe of a bare network saw its ground
  // off the map behind it, never localized and stood the whole run.
  double ground_margin_m = 60.0;
  // The route the car will drive (world x, y); empty: the whole scene.
  // With a route, only the part of the map within corridor_half_width_m of
  // it is sampled (a little more, cell-wise): the LiDAR sees 60 m, and a
  // city's whole map would take gigabytes per run.
  std::vector<Eigen::Vector2d> corridor;
  double corridor_half_width_m = 150.0;
};

// Points on every obstacle face (footprint edges from z_min to z_max,
// corners and top/bottom rims included) plus the ground grid, skipping
// ground points inside closed footprints (under buildings, parked cars),
// all within the corridor when there is one. Deterministic: same scene and
// options, same points in the same order; a corridor that covers the whole
// scene gives the same points as none.
std::vector<Eigen::Vector3f> SampleSceneSurface(const Scene& scene,
                                                const MapCloudOptions& options);

// Writes a binary PCD v0.7 (x y z float32, unorganized) atomically.
Status WritePcd(const std::string& path,
                const std::vector<Eigen::Vector3f>& points);

// Reads a PCD v0.7 with DATA ascii or binary whose x, y and z fields are
// float32 or float64 (other fields are skipped). Non-finite points (the
// "no return" markers of organized clouds) are dropped. A malformed or
// truncated file gives Corruption naming the file and the problem; a
// missing one NotFound; binary_compressed InvalidArgument.
Result<std::vector<Eigen::Vector3f>> ReadPcd(const std::string& path);

}  // namespace adse::world

#endif  // ADSE_STACK_WORLD_MAP_CLOUD_H_
