// Three-point turns: where the road part turns around tighter than the car
// can, the area the car may use there and the manoeuvre a perfect driver
// makes, planned with the stack's own freespace planner on the ground truth.
#include <fmt/format.h>

#include <algorithm>
#include <limits>

#include "stack/algorithms/freespace_planner.h"
#include "stack/algorithms/planning.h"
#include "stack/world/internal/world_impl.h"
#include "stack/world/parking_goal.h"
#include "stack/world/roadside_poles.h"

namespace adse::world {
namespace {

using internal::OpenToCars;
using internal::ToPoints;
using internal::Vec2;
using Polygons = std::vector<std::vector<Vec2>>;

// The car stops with its rear axle this far before the end of the lane it
// arrives on, its front short of the junction.
constexpr double kStopBeforeLaneEndM = 4.0;
// It drives on from this far along the lane it leaves on.
constexpr double kRejoinAlongM = 10.0;
// Lanes, junctions and structure this near the turn bound the manoeuvre
// (the planner searches 15 m about its start and goal).
constexpr double kAreaRadiusM = 40.0;

// Lanes count this much wider on each side: a road's two directions may
// lie a few centimetres further apart than their widths (joined's b38 and
// b39, 3.31 m apart and 3.2 m wide), and the strip between is road.
constexpr double kLaneSlackM = 0.1;

// A lane as one quad per segment of its centre line, reaching half a
// width past interior vertices so the outer side of a bend is covered.
void AddLaneArea(const std::vector<Vec2>& shape, double width_m,
                 Polygons* out) {
  const double h = 0.5 * width_m + kLaneSlackM;
  for (size_t i = 0; i + 1 < shape.size(); ++i) {
    Vec2 d = shape[i + 1] - shape[i];
    const double length = d.norm();
    if (length < 1e-6) continue;
    d /= length;
    const Vec2 n(-d.y(), d.x());
    const Vec2 a = shape[i] - (i > 0 ? h : 0.0) * d;
    const Vec2 b = shape[i + 1] + (i + 2 < shape.size() ? h : 0.0) * d;
    out->push_back({a + h * n, b + h * n, b - h * n, a - h * n});
  }
}

double DistanceToPolyline(const std::vector<Vec2>& line, const Vec2& p) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i + 1 < line.size(); ++i) {
    best = std::min(best, geometry::DistanceToSegment(p, line[i], line[i + 1]));
  }
  if (line.size() == 1) best = (line[0] - p).norm();
  return best;
}

// The lanes open to cars and the junctions within kAreaRadiusM of `at`.
Polygons DrivableAround(const Vec2& at) {
  Polygons out;
  for (const std::string& lane : libsumo::Lane::getIDList()) {
    if (!OpenToCars(lane)) continue;
    const std::vector<Vec2> shape = ToPoints(libsumo::Lane::getShape(lane));
    if (DistanceToPolyline(shape, at) > kAreaRadiusM) continue;
    AddLaneArea(shape, libsumo::Lane::getWidth(lane), &out);
  }
  for (const std::string& junction : libsumo::Junction::getIDList()) {
    const libsumo::TraCIPosition p = libsumo::Junction::getPosition(junction);
    if ((Vec2(p.x, p.y) - at).norm() > kAreaRadiusM) continue;
    std::vector<Vec2> shape = ToPoints(libsumo::Junction::getShape(junction));
    if (shape.size() >= 3) out.push_back(std::move(shape));
  }
  return out;
}

}  // namespace

int ManoeuvreMoves(const std::vector<algorithms::GearedPose>& manoeuvre) {
  int moves = manoeuvre.empty() ? 0 : 1;
  for (size_t i = 1; i < manoeuvre.size(); ++i) {
    moves += manoeuvre[i].reverse != manoeuvre[i - 1].reverse;
  }
  return moves;
}

Status World::Impl::PlanTurnarounds() {
  turnarounds.clear();
  if (valet) return Status::Ok();
  const algorithms::FreespacePlannerParams params;
  algorithms::FreespacePlanner planner(
      params,
      algorithms::FootprintOfBody(setup.ego.length_m, setup.ego.wheelbase_m,
                                  setup.ego.width_m));
  for (const Crossing& crossing : crossings) {
    if (!crossing.tight_uturn) continue;
    RouteTurnaround turn;
    turn.start_s_m =
        RoadS(std::max(0.0, crossing.raw_s_m - kStopBeforeLaneEndM));
    geometry::Path2 leave;
    leave.points = ToPoints(libsumo::Lane::getShape(crossing.to_lane));
    leave.UpdateArcLength();
    double along = std::min(kRejoinAlongM, leave.length_m());
    if (EdgeOfLane(crossing.to_lane) == goal.edge) {
      along = std::min(
          along, internal::ShapeS(leave.points,
                                  libsumo::Lane::getLength(crossing.to_lane),
                                  goal.pos_m));
    }
    const Vec2 rejoin = leave.PointAt(along);
    turn.goal = {rejoin.x(), rejoin.y(), leave.HeadingAt(along)};
    double lateral = 0.0, distance = 0.0;
    turn.end_s_m = algorithms::ProjectOnPath(
        road, rejoin, turn.start_s_m, turn.start_s_m + 4 * kAreaRadiusM,
        turn.start_s_m, &lateral, &distance);
    const Vec2 stop = road.PointAt(turn.start_s_m);
    const geometry::Pose2 from{stop.x(), stop.y(),
                               road.HeadingAt(turn.start_s_m)};
    const std::vector<Vec2> arrive =
        ToPoints(libsumo::Lane::getShape(crossing.from_lane));
    const Vec2 at = arrive.empty() ? stop : arrive.back();
    turn.drivable = DrivableAround(at);
    for (std::vector<Vec2>& outline : ObstacleOutlines(scene)) {
      if (DistanceToPolyline(outline, at) <= kAreaRadiusM) {
        turn.obstacles.push_back(std::move(outline));
      }
    }
    Result<algorithms::FreespacePath> manoeuvre =
        planner.Plan(from, turn.goal, turn.obstacles, turn.drivable);
    if (!manoeuvre.ok()) {
      return Status::InvalidArgument(fmt::format(
          "task.goal: unreachable from task.start: the route turns around "
          "from lane '{}' to lane '{}', {:.1f} m across (the car turns no "
          "tighter than {:.1f} m), no way round the block leads on, and no "
          "turn in several moves fits in the lanes and junctions there ({})",
          crossing.from_lane, crossing.to_lane,
          internal::UTurnWidthM(crossing.from_lane, crossing.to_lane),
          MinTurningRadiusM(), manoeuvre.status().message()));
    }
    turn.reference = manoeuvre->poses;
    turnarounds.push_back(std::move(turn));
  }
  if (turnarounds.empty()) return Status::Ok();
  // The ideal path: the road part with each turn's stretch replaced by its
  // manoeuvre, whose cusps it passes twice (appended as planned).
  ideal = geometry::Path2();
  auto add = [&](const Vec2& p) {
    if (ideal.points.empty() || (p - ideal.points.back()).norm() > 1e-6) {
      ideal.points.push_back(p);
    }
  };
  auto add_road = [&](double s0, double s1) {
    add(road.PointAt(s0));
    for (size_t i = 0; i < road.points.size(); ++i) {
      if (road.s_m[i] > s0 && road.s_m[i] < s1) add(road.points[i]);
    }
    add(road.PointAt(s1));
  };
  double from_s = 0.0;
  for (const RouteTurnaround& turn : turnarounds) {
    add_road(from_s, turn.start_s_m);
    for (const algorithms::GearedPose& p : turn.reference) {
      add(Vec2(p.pose.x_m, p.pose.y_m));
    }
    from_s = turn.end_s_m;
  }
  add_road(from_s, road.length_m());
  ideal.UpdateArcLength();
  return Status::Ok();
}

}  // namespace adse::world
