// The freespace planner of a parking manoeuvre, as Autoware's
// freespace_planning_algorithms does it: Hybrid A* over (x, y, yaw, gear)
// on an occupancy grid, with Reeds–Shepp shots to the goal, the car's
// rectangular footprint collision-checked against parked cars, walls and
// poles. Eigen and std types only.
#ifndef ADSE_STACK_ALGORITHMS_FREESPACE_PLANNER_H_
#define ADSE_STACK_ALGORITHMS_FREESPACE_PLANNER_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "stack/algorithms/occupancy_grid.h"
#include "stack/algorithms/reeds_shepp.h"
#include "stack/base/status.h"
#include "stack/geometry/geometry.h"

namespace adse::algorithms {

struct FreespacePlannerParams {
  // Tightest turn the path may ask for (rear axle); above the car's own
  // minimum (wheelbase / tan(max steer)) so the controller can track it.
  double turning_radius_m = 5.0;
  // Edge of an occupancy cell.
  double grid_resolution_m = 0.2;
  // Edge of a search cell: one node per (cell, heading bin, gear) is kept.
  double search_cell_m = 0.5;
  // Heading bins per turn.
  int yaw_bins = 72;
  // Arc length of one motion primitive (longer than a search cell's
  // diagonal, so every expansion leaves its cell).
  double step_m = 0.8;
  // Steering choices per gear, from full left to full right (odd: one is
  // straight).
  int steer_samples = 5;
  // Cost per metre in reverse, relative to 1 per metre forwards.
  double reverse_penalty = 2.0;
  // Cost of each change between forward and reverse, metres.
  double gear_switch_penalty_m = 4.0;
  // Extra cost per metre at full steering (prefers straighter paths).
  double steer_penalty = 0.3;
  // Heuristic weight: above 1 trades optimality for speed.
  double heuristic_weight = 1.5;
  // Footprint grown by this on every side in every collision check. A car
  // already standing closer than this to an obstacle (correcting its pose
  // in a tight slot) is planned for with the clearance it has, down to
  // min_start_clearance_m; closer than that, there is no path.
  double collision_margin_m = 0.25;
  double min_start_clearance_m = 0.05;
  // The grid spans start and goal plus this margin on every side.
  double search_margin_m = 15.0;
  // A Reeds–Shepp shot to the goal is tried from nodes within this
  // (obstacle-free Reeds–Shepp) distance of it.
  double analytic_range_m = 25.0;
  // Shortest Reeds–Shepp candidates tried per shot.
  int analytic_candidates = 4;
  // Node expansions before giving up: the deterministic limit on effort.
  int max_expansions = 50000;
  // Spacing of the returned poses.
  double output_step_m = 0.25;
};

// The first field of `params` out of its range, by name; Ok otherwise.
Status ValidateFreespacePlannerParams(const FreespacePlannerParams& params);

struct FreespacePath {
  // From the start pose to the goal pose; `reverse` is the gear each pose
  // is driven in. At a gear change the cusp pose appears with the old gear
  // and the next pose carries the new one.
  std::vector<GearedPose> poses;
  double length_m = 0.0;
  int gear_changes = 0;
};

// What one Plan() did, whether or not it found a path.
struct FreespaceStats {
  int64_t expansions = 0;      // nodes expanded
  int64_t analytic_shots = 0;  // Reeds–Shepp shots tried
  // Footprint points tested and grid cells rasterised: the work units the
  // platform charges.
  int64_t work_units = 0;
  // The margin the search kept: collision_margin_m, or less for a start
  // already closer than that to an obstacle.
  double collision_margin_m = 0.0;
};

// Where the car, driving `path` on from pose `from`, first comes within
// `margin_m` of one of `boxes` (road users the car sees) before the move
// under way ends (at the next gear change, or the path's end): that pose's
// index, or -1 when the move is clear. Autoware's freespace planner checks
// its trajectory against the costmap's objects the same way and plans
// again when it collides.
int FirstBlockedPose(const std::vector<GearedPose>& path, size_t from,
                     const std::vector<geometry::OrientedBox>& boxes,
                     const VehicleFootprint& footprint, double margin_m);

class FreespacePlanner {
 public:
  // `params` must pass ValidateFreespacePlannerParams.
  FreespacePlanner(const FreespacePlannerParams& params,
                   const VehicleFootprint& footprint);

  // A path from `start` to `goal` (rear axle poses, map frame) among
  // `obstacles` (outlines as OccupancyGrid::AddObstacle takes them),
  // inside `drivable` when that is given (OccupancyGrid::KeepInside).
  // NotFound with the reason when there is none: the goal or start
  // footprint collides, the two are not connected for a car this wide, or
  // the search ran out of expansions.
  Result<FreespacePath> Plan(
      const geometry::Pose2& start, const geometry::Pose2& goal,
      const std::vector<std::vector<Eigen::Vector2d>>& obstacles,
      const std::vector<std::vector<Eigen::Vector2d>>& drivable = {});

  const FreespaceStats& last_stats() const { return stats_; }
  const FreespacePlannerParams& params() const { return params_; }
  const VehicleFootprint& footprint() const { return footprint_; }

 private:
  FreespacePlannerParams params_;
  VehicleFootprint footprint_;
  FreespaceStats stats_;
};

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_FREESPACE_PLANNER_H_
