#include "stack/world/roadside_poles.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <set>
#include <utility>

#include "stack/geometry/geometry.h"

namespace adse::world {

using Vec2 = Eigen::Vector2d;

std::string EdgeOfLane(const std::string& lane_id) {
  return lane_id.substr(0, lane_id.rfind('_'));
}

int IndexOfLane(const std::string& lane_id) {
  return std::atoi(lane_id.substr(lane_id.rfind('_') + 1).c_str());
}

std::vector<Obstacle> RoadsidePoles(const std::vector<LaneGeometry>& lanes) {
  // Bucket lane segments in a coarse grid: checking every candidate pole
  // against every lane is quadratic in the size of a city.
  constexpr double kCell = 25.0;
  std::map<std::pair<int, int>, std::vector<std::pair<int, int>>> grid;
  auto cell_of = [&](const Vec2& p) {
    return std::make_pair(static_cast<int>(std::floor(p.x() / kCell)),
                          static_cast<int>(std::floor(p.y() / kCell)));
  };
  for (size_t index = 0; index < lanes.size(); ++index) {
    const std::vector<Vec2>& points = lanes[index].points;
    for (size_t k = 0; k + 1 < points.size(); ++k) {
      const Vec2 a = points[k], b = points[k + 1];
      const int steps = 1 + static_cast<int>((b - a).norm() / (kCell / 2));
      std::set<std::pair<int, int>> cells;
      for (int j = 0; j <= steps; ++j)
        cells.insert(cell_of(a + (b - a) * j / steps));
      for (const auto& c : cells) {
        grid[c].push_back({static_cast<int>(index), static_cast<int>(k)});
      }
    }
  }
  auto clear_of_roads = [&](const Vec2& p) {
    const auto [cx, cy] = cell_of(p);
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        auto it = grid.find({cx + dx, cy + dy});
        if (it == grid.end()) continue;
        for (const auto& [lane, k] : it->second) {
          const Vec2 a = lanes[lane].points[k], b = lanes[lane].points[k + 1];
          const double len2 = (b - a).squaredNorm();
          const double u =
              len2 > 0 ? std::clamp((p - a).dot(b - a) / len2, 0.0, 1.0) : 0.0;
          if ((a + u * (b - a) - p).norm() < lanes[lane].half_width_m + 0.5)
            return false;
        }
      }
    }
    return true;
  };
  // The outermost lanes of each normal edge carry its roadsides: the
  // rightmost (index 0) and the leftmost, whose poles stand on the far
  // side of a one-way street (on a two-way road, the other direction's
  // lanes are there, and clear_of_roads skips them). With the right side
  // only, a one-way street left the LiDAR one or two poles in 40 m, too
  // few for NDT (localization lost on sumo-tools' acosta).
  std::map<std::string, int> leftmost;  // edge -> highest lane index
  for (const LaneGeometry& lane : lanes) {
    if (lane.id[0] == ':') continue;
    const int index = IndexOfLane(lane.id);
    int& top = leftmost.try_emplace(EdgeOfLane(lane.id), index).first->second;
    top = std::max(top, index);
  }
  std::vector<Obstacle> poles;
  for (const LaneGeometry& lane : lanes) {
    if (lane.id[0] == ':') continue;
    const int index = IndexOfLane(lane.id);
    std::vector<double> sides;  // +1 right, -1 left
    if (index == 0) sides.push_back(1.0);
    if (index == leftmost[EdgeOfLane(lane.id)]) sides.push_back(-1.0);
    if (sides.empty()) continue;
    geometry::Path2 shape;
    shape.points = lane.points;
    shape.UpdateArcLength();
    const double offset = lane.half_width_m + 1.0;
    for (const double side : sides) {
      for (double s = 10.0; s < shape.length_m() - 5.0; s += 20.0) {
        const double h = shape.HeadingAt(s);
        const Vec2 p =
            shape.PointAt(s) + side * offset * Vec2(std::sin(h), -std::cos(h));
        if (!clear_of_roads(p)) continue;
        Obstacle pole;
        pole.kind = ObstacleKind::kPole;
        pole.z_max_m = 5.0;
        const double r = 0.15;
        pole.footprint = {p + Vec2(-r, -r), p + Vec2(r, -r), p + Vec2(r, r),
                          p + Vec2(-r, r)};
        poles.push_back(std::move(pole));
      }
    }
  }
  return poles;
}

}  // namespace adse::world
