#include "stack/algorithms/freespace_planner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <unordered_map>
#include <unordered_set>

#include <fmt/format.h>

namespace adse::algorithms {
namespace {

using geometry::Pose2;
constexpr double kTwoPi = 2.0 * M_PI;
constexpr float kUnreached = std::numeric_limits<float>::infinity();

// A search node: a pose reached by one motion primitive from its parent.
struct Node {
  Pose2 pose;
  int gear = 0;  // +1 forwards, -1 reverse, 0 the start (no motion yet)
  double g = 0.0;
  int parent = -1;
  double curvature_1pm = 0.0;  // of the primitive from the parent
  double rs_to_goal_m = 0.0;   // Reeds–Shepp distance to the goal
};

struct OpenEntry {
  double f;
  int64_t order;  // insertion order: ties go to the older entry
  int node;
  bool operator>(const OpenEntry& o) const {
    return f != o.f ? f > o.f : order > o.order;
  }
};

// Shortest 8-connected distance from `goal` to every cell for a point that
// keeps `clearance_m` from obstacles: an obstacle-aware lower bound on the
// rear axle's travel, and a quick proof that start and goal are not
// connected.
std::vector<float> HolonomicDistances(const OccupancyGrid& grid,
                                      const Eigen::Vector2d& goal,
                                      double clearance_m, int64_t* work) {
  const int nx = grid.width_cells(), ny = grid.height_cells();
  const double res = grid.resolution_m();
  std::vector<uint8_t> blocked(static_cast<size_t>(nx) * ny, 0);
  const int r = static_cast<int>(std::floor(std::max(clearance_m, 0.0) / res));
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      if (!grid.Occupied(ix, iy)) continue;
      blocked[iy * nx + ix] = 1;
      // Only cells at the edge of an obstacle grow it.
      const bool edge =
          !grid.Occupied(ix - 1, iy) || !grid.Occupied(ix + 1, iy) ||
          !grid.Occupied(ix, iy - 1) || !grid.Occupied(ix, iy + 1);
      if (!edge) continue;
      for (int dy = -r; dy <= r; ++dy) {
        for (int dx = -r; dx <= r; ++dx) {
          if ((dx * dx + dy * dy) * res * res > clearance_m * clearance_m)
            continue;
          if (grid.InBounds(ix + dx, iy + dy))
            blocked[(iy + dy) * nx + ix + dx] = 1;
        }
      }
    }
  }
  std::vector<float> dist(blocked.size(), kUnreached);
  int gx, gy;
  grid.CellOf(goal, &gx, &gy);
  if (!grid.InBounds(gx, gy)) return dist;
  using Item = std::pair<float, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  dist[gy * nx + gx] = 0.0f;
  open.push({0.0f, gy * nx + gx});
  const float diag = static_cast<float>(res * std::sqrt(2.0));
  while (!open.empty()) {
    const auto [d, c] = open.top();
    open.pop();
    if (d > dist[c]) continue;
    ++*work;
    const int cx = c % nx, cy = c / nx;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0) continue;
        const int x = cx + dx, y = cy + dy;
        if (!grid.InBounds(x, y) || blocked[y * nx + x]) continue;
        const float nd = d + (dx != 0 && dy != 0 ? diag : float(res));
        if (nd < dist[y * nx + x]) {
          dist[y * nx + x] = nd;
          open.push({nd, y * nx + x});
        }
      }
    }
  }
  return dist;
}

}  // namespace

Status ValidateFreespacePlannerParams(const FreespacePlannerParams& p) {
  auto positive = [](double v, const char* name) {
    return v > 0.0 && std::isfinite(v)
               ? Status::Ok()
               : Status::InvalidArgument(fmt::format(
                     "{}: expected a positive number, found {}", name, v));
  };
  ADSE_RETURN_IF_ERROR(positive(p.turning_radius_m, "turning_radius_m"));
  ADSE_RETURN_IF_ERROR(positive(p.grid_resolution_m, "grid_resolution_m"));
  ADSE_RETURN_IF_ERROR(positive(p.search_cell_m, "search_cell_m"));
  if (p.yaw_bins < 8 || p.yaw_bins > 720) {
    return Status::InvalidArgument(
        fmt::format("yaw_bins: expected 8..720, found {}", p.yaw_bins));
  }
  if (!(p.step_m > p.search_cell_m * std::sqrt(2.0))) {
    return Status::InvalidArgument(fmt::format(
        "step_m: expected more than a search cell's diagonal ({:.3f} m), "
        "found {}",
        p.search_cell_m * std::sqrt(2.0), p.step_m));
  }
  if (p.steer_samples < 1 || p.steer_samples % 2 == 0) {
    return Status::InvalidArgument(
        fmt::format("steer_samples: expected an odd number >= 1, found {}",
                    p.steer_samples));
  }
  if (!(p.reverse_penalty >= 1.0)) {
    return Status::InvalidArgument(fmt::format(
        "reverse_penalty: expected >= 1, found {}", p.reverse_penalty));
  }
  if (!(p.gear_switch_penalty_m >= 0.0) || !(p.steer_penalty >= 0.0) ||
      !(p.collision_margin_m >= 0.0)) {
    return Status::InvalidArgument(!(p.gear_switch_penalty_m >= 0.0)
                                       ? "gear_switch_penalty_m: expected >= 0"
                                   : !(p.steer_penalty >= 0.0)
                                       ? "steer_penalty: expected >= 0"
                                       : "collision_margin_m: expected >= 0");
  }
  if (!(p.min_start_clearance_m >= 0.0)) {
    return Status::InvalidArgument(
        fmt::format("min_start_clearance_m: expected >= 0, found {}",
                    p.min_start_clearance_m));
  }
  if (!(p.heuristic_weight >= 1.0)) {
    return Status::InvalidArgument(fmt::format(
        "heuristic_weight: expected >= 1, found {}", p.heuristic_weight));
  }
  ADSE_RETURN_IF_ERROR(positive(p.search_margin_m, "search_margin_m"));
  ADSE_RETURN_IF_ERROR(positive(p.analytic_range_m, "analytic_range_m"));
  ADSE_RETURN_IF_ERROR(positive(p.output_step_m, "output_step_m"));
  if (p.analytic_candidates < 1) {
    return Status::InvalidArgument("analytic_candidates: expected >= 1");
  }
  if (p.max_expansions < 1) {
    return Status::InvalidArgument("max_expansions: expected >= 1");
  }
  return Status::Ok();
}

FreespacePlanner::FreespacePlanner(const FreespacePlannerParams& params,
                                   const VehicleFootprint& footprint)
    : params_(params), footprint_(footprint) {}

Result<FreespacePath> FreespacePlanner::Plan(
    const Pose2& start, const Pose2& goal,
    const std::vector<std::vector<Eigen::Vector2d>>& obstacles,
    const std::vector<std::vector<Eigen::Vector2d>>& drivable) {
  const FreespacePlannerParams& p = params_;
  stats_ = {};
  const Eigen::Vector2d s_xy(start.x_m, start.y_m), g_xy(goal.x_m, goal.y_m);
  const Eigen::Vector2d margin(p.search_margin_m, p.search_margin_m);
  OccupancyGrid grid(s_xy.cwiseMin(g_xy) - margin, s_xy.cwiseMax(g_xy) + margin,
                     p.grid_resolution_m);
  for (const auto& outline : obstacles) grid.AddObstacle(outline);
  if (!drivable.empty()) {
    // Where the car stands is drivable, however near the area's edge it
    // has come: a lane's edge on a map is no kerb, and a car that brushed
    // it in a tight turn must still be able to go on.
    std::vector<std::vector<Eigen::Vector2d>> area = drivable;
    area.push_back(geometry::BoxCorners(FootprintBox(
        start, footprint_, p.collision_margin_m + 2 * p.grid_resolution_m)));
    grid.KeepInside(area);
  }
  grid.ComputeDistances();
  stats_.work_units +=
      static_cast<int64_t>(grid.width_cells()) * grid.height_cells();
  double margin_m = p.collision_margin_m;
  auto collides = [&](const Pose2& pose) {
    return grid.FootprintCollides(pose, footprint_, margin_m,
                                  &stats_.work_units);
  };
  if (collides(goal)) {
    return Status::NotFound(fmt::format(
        "no path: the car does not fit at the goal ({:.2f}, {:.2f}, yaw "
        "{:.2f}) with {:.2f} m to spare",
        goal.x_m, goal.y_m, goal.yaw_rad, p.collision_margin_m));
  }
  if (collides(start)) {
    // Standing closer than the margin already: the path keeps the
    // clearance the car has (to 1 cm), if that is enough.
    double fits_m = std::min(p.min_start_clearance_m, p.collision_margin_m);
    margin_m = fits_m;
    if (collides(start)) {
      return Status::NotFound(fmt::format(
          "no path: the car at the start ({:.2f}, {:.2f}) is within {:.2f} m "
          "of an obstacle",
          start.x_m, start.y_m, fits_m));
    }
    double too_close_m = p.collision_margin_m;
    while (too_close_m - fits_m > 0.01) {
      margin_m = 0.5 * (fits_m + too_close_m);
      (collides(start) ? too_close_m : fits_m) = margin_m;
    }
    margin_m = fits_m;
  }
  stats_.collision_margin_m = margin_m;
  // The rear axle is at least this far inside the body's outline.
  const double axle_clearance =
      std::min(
          {0.5 * footprint_.width_m, footprint_.rear_m, footprint_.front_m}) +
      margin_m - 1.5 * p.grid_resolution_m;
  const std::vector<float> holonomic =
      HolonomicDistances(grid, g_xy, axle_clearance, &stats_.work_units);
  auto holonomic_at = [&](const Pose2& pose) -> double {
    int ix, iy;
    grid.CellOf(Eigen::Vector2d(pose.x_m, pose.y_m), &ix, &iy);
    return grid.InBounds(ix, iy) ? holonomic[iy * grid.width_cells() + ix]
                                 : kUnreached;
  };
  if (holonomic_at(start) == kUnreached) {
    return Status::NotFound(fmt::format(
        "no path: no passage {:.2f} m wide leads from the start to the goal",
        2 * axle_clearance));
  }

  // Search lattice: (x, y) cells of search_cell_m, heading bins, gear.
  const Eigen::Vector2d lo = grid.min_corner();
  const int64_t nx = static_cast<int64_t>(
      std::ceil(grid.width_cells() * p.grid_resolution_m / p.search_cell_m));
  const int64_t ny = static_cast<int64_t>(
      std::ceil(grid.height_cells() * p.grid_resolution_m / p.search_cell_m));
  auto key_of = [&](const Pose2& pose, int gear) -> int64_t {
    const int64_t ix =
        static_cast<int64_t>(std::floor((pose.x_m - lo.x()) / p.search_cell_m));
    const int64_t iy =
        static_cast<int64_t>(std::floor((pose.y_m - lo.y()) / p.search_cell_m));
    double yaw = std::fmod(pose.yaw_rad, kTwoPi);
    if (yaw < 0) yaw += kTwoPi;
    const int64_t it = std::min<int64_t>(
        p.yaw_bins - 1, static_cast<int64_t>(yaw / kTwoPi * p.yaw_bins));
    return ((it * 3 + (gear + 1)) * ny + iy) * nx + ix;
  };
  // The heuristic of `node`, whose Reeds–Shepp distance to the goal it
  // keeps for the analytic expansion.
  auto heuristic = [&](Node* node) {
    const double h2 = holonomic_at(node->pose);
    const double rs = ReedsSheppDistance(node->pose, goal, p.turning_radius_m);
    node->rs_to_goal_m = rs;
    return p.heuristic_weight * (h2 == kUnreached ? rs : std::max(h2, rs));
  };

  std::vector<Node> nodes;
  std::unordered_map<int64_t, double> best_g;
  std::unordered_set<int64_t> closed;
  std::priority_queue<OpenEntry, std::vector<OpenEntry>,
                      std::greater<OpenEntry>>
      open;
  int64_t order = 0;
  nodes.push_back({start, 0, 0.0, -1, 0.0});
  open.push({heuristic(&nodes.back()), order++, 0});

  // Curvatures of the primitives: full left to full right.
  std::vector<double> curvatures;
  for (int k = 0; k < p.steer_samples; ++k) {
    curvatures.push_back(p.steer_samples == 1
                             ? 0.0
                             : (1.0 - 2.0 * k / (p.steer_samples - 1)) /
                                   p.turning_radius_m);
  }
  const int substeps =
      std::max(1, static_cast<int>(std::ceil(p.step_m / p.grid_resolution_m)));

  int final_node = -1;
  ReedsSheppPath shot;
  while (!open.empty() && final_node < 0) {
    const OpenEntry top = open.top();
    open.pop();
    const Node node = nodes[top.node];
    const int64_t key = key_of(node.pose, node.gear);
    if (!closed.insert(key).second) continue;
    if (++stats_.expansions > p.max_expansions) break;

    // Analytic expansion: a collision-free Reeds–Shepp path to the goal.
    if (node.rs_to_goal_m <= p.analytic_range_m) {
      ++stats_.analytic_shots;
      const std::vector<ReedsSheppPath> candidates =
          ReedsSheppCandidates(node.pose, goal, p.turning_radius_m);
      const int tries = std::min<int>(p.analytic_candidates, candidates.size());
      for (int c = 0; c < tries && final_node < 0; ++c) {
        // From the goal backwards: shots mostly fail at the slot's mouth.
        const std::vector<GearedPose> samples = SampleReedsShepp(
            node.pose, candidates[c], p.turning_radius_m, p.grid_resolution_m);
        bool free = true;
        for (auto it = samples.rbegin(); it != samples.rend() && free; ++it) {
          free = !collides(it->pose);
        }
        if (free) {
          final_node = top.node;
          shot = candidates[c];
        }
      }
      if (final_node >= 0) break;
    }

    for (int gear : {1, -1}) {
      for (double kappa : curvatures) {
        const double length = gear * p.step_m;
        Pose2 child = node.pose;
        bool free = true;
        for (int i = 1; i <= substeps && free; ++i) {
          child = AdvanceArc(node.pose, kappa, length * i / substeps);
          free = !collides(child);
        }
        if (!free) continue;
        const int64_t child_key = key_of(child, gear);
        if (closed.count(child_key)) continue;
        double g =
            node.g + p.step_m * (gear < 0 ? p.reverse_penalty : 1.0) +
            p.steer_penalty * std::abs(kappa) * p.turning_radius_m * p.step_m;
        if (node.gear != 0 && node.gear != gear) g += p.gear_switch_penalty_m;
        auto it = best_g.find(child_key);
        if (it != best_g.end() && it->second <= g) continue;
        best_g[child_key] = g;
        nodes.push_back({child, gear, g, top.node, kappa});
        open.push({g + heuristic(&nodes.back()), order++,
                   static_cast<int>(nodes.size()) - 1});
      }
    }
  }
  if (final_node < 0) {
    return Status::NotFound(fmt::format(
        "no path: the search ended after {} expansions without reaching the "
        "goal",
        std::min<int64_t>(stats_.expansions, p.max_expansions)));
  }

  // The path: the primitives from the start to the shot's node, resampled,
  // then the shot.
  std::vector<int> chain;
  for (int n = final_node; n >= 0; n = nodes[n].parent) chain.push_back(n);
  std::reverse(chain.begin(), chain.end());
  FreespacePath path;
  path.poses.push_back({start, false});
  for (size_t i = 1; i < chain.size(); ++i) {
    const Node& from = nodes[chain[i - 1]];
    const Node& to = nodes[chain[i]];
    const int n =
        std::max(1, static_cast<int>(std::ceil(p.step_m / p.output_step_m)));
    for (int k = 1; k <= n; ++k) {
      path.poses.push_back(
          {AdvanceArc(from.pose, to.curvature_1pm, to.gear * p.step_m * k / n),
           to.gear < 0});
    }
  }
  const std::vector<GearedPose> tail = SampleReedsShepp(
      nodes[final_node].pose, shot, p.turning_radius_m, p.output_step_m);
  path.poses.insert(path.poses.end(), tail.begin() + 1, tail.end());
  if (path.poses.size() > 1) path.poses[0].reverse = path.poses[1].reverse;
  for (size_t i = 1; i < path.poses.size(); ++i) {
    const GearedPose& a = path.poses[i - 1];
    const GearedPose& b = path.poses[i];
    path.length_m +=
        std::hypot(b.pose.x_m - a.pose.x_m, b.pose.y_m - a.pose.y_m);
    if (a.reverse != b.reverse) ++path.gear_changes;
  }
  return path;
}

int FirstBlockedPose(const std::vector<GearedPose>& path, size_t from,
                     const std::vector<geometry::OrientedBox>& boxes,
                     const VehicleFootprint& footprint, double margin_m) {
  if (boxes.empty()) return -1;
  for (size_t i = from; i < path.size(); ++i) {
    // The cusp pose carries the old gear; the next one starts a new move.
    if (i > from && path[i].reverse != path[i - 1].reverse) break;
    const geometry::OrientedBox body =
        FootprintBox(path[i].pose, footprint, margin_m);
    for (const geometry::OrientedBox& box : boxes) {
      if (geometry::BoxesOverlap(body, box)) return static_cast<int>(i);
    }
  }
  return -1;
}

}  // namespace adse::algorithms
