// Three-point turns: where the road part turns around tighter than the car
// can, the area the car may use there and the manoeuvre a perfect driver
// makes, planned with the stack's own freespace planner on the ground truth.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "stack/algorithms/freespace_planner.h"
#include "stack/algorithms/planning.h"
#include "stack/world/ideal_driver.h"
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

// A stretch where the ideal driver, rehearsed on the car's model, strays
// from the road part by more than this (the bound issue 17 sets the
// ground-truth driver) is driven as a manoeuvre, as a tight U-turn is,
// from kCornerLeadM before it to kCornerRejoinM past it. Strays closer
// than the two together make one stretch.
constexpr double kMaxCornerStrayM = 1.0;
constexpr double kCornerLeadM = 10.0;
constexpr double kCornerRejoinM = 10.0;

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

// Within kAreaRadiusM of one of the points `around`.
bool Near(const std::vector<Vec2>& shape, const std::vector<Vec2>& around) {
  for (const Vec2& at : around) {
    if (DistanceToPolyline(shape, at) <= kAreaRadiusM) return true;
  }
  return false;
}

// Where no manoeuvre keeps to the lanes and junctions (a corner or U-turn
// where single lanes of 3.2 m meet at a sharp angle), it may use the
// road's shoulders (a lanelet map's road_shoulder): this much beyond each
// lane's edges, out to the line of the roadside poles, which it keeps
// clear of as of all structure. The nets draw neither kerbs nor shoulders.
constexpr double kShoulderM = 1.0;

// The lanes open to cars, each with `shoulder_m` more on either side, and
// the junctions near the points `around`.
Polygons DrivableAround(const std::vector<Vec2>& around, double shoulder_m) {
  Polygons out;
  for (const std::string& lane : libsumo::Lane::getIDList()) {
    if (!OpenToCars(lane)) continue;
    const std::vector<Vec2> shape = ToPoints(libsumo::Lane::getShape(lane));
    if (!Near(shape, around)) continue;
    AddLaneArea(shape, libsumo::Lane::getWidth(lane) + 2.0 * shoulder_m, &out);
  }
  for (const std::string& junction : libsumo::Junction::getIDList()) {
    const libsumo::TraCIPosition p = libsumo::Junction::getPosition(junction);
    if (!Near({Vec2(p.x, p.y)}, around)) continue;
    std::vector<Vec2> shape = ToPoints(libsumo::Junction::getShape(junction));
    if (shape.size() >= 3) out.push_back(std::move(shape));
  }
  return out;
}

// The ground truth near the points `around` (a U-turn's place, or every
// few metres of a corner's stretch, which may be long): the lanes and
// junctions a manoeuvre there keeps to, and the structure standing there.
void SetAreaAbout(const std::vector<Vec2>& around, const Scene& scene,
                  double shoulder_m, RouteTurnaround* turn) {
  turn->drivable = DrivableAround(around, shoulder_m);
  turn->obstacles.clear();
  for (std::vector<Vec2>& outline : ObstacleOutlines(scene)) {
    if (Near(outline, around)) turn->obstacles.push_back(std::move(outline));
  }
}

// The freespace planner's manoeuvre from `from` to `turn->goal` within the
// lanes and junctions about `around`, or where none fits there, within
// them and their shoulders. On success `turn` holds the area it was
// planned in.
Result<algorithms::FreespacePath> PlanWithinRoad(
    algorithms::FreespacePlanner& planner, const geometry::Pose2& from,
    const std::vector<Vec2>& around, const Scene& scene,
    RouteTurnaround* turn) {
  SetAreaAbout(around, scene, 0.0, turn);
  Result<algorithms::FreespacePath> manoeuvre =
      planner.Plan(from, turn->goal, turn->obstacles, turn->drivable);
  if (manoeuvre.ok()) return manoeuvre;
  SetAreaAbout(around, scene, kShoulderM, turn);
  Result<algorithms::FreespacePath> wider =
      planner.Plan(from, turn->goal, turn->obstacles, turn->drivable);
  turn->on_shoulders = wider.ok();
  // The lanes' own failure says more when the shoulders do not help.
  return wider.ok() ? std::move(wider) : std::move(manoeuvre);
}

}  // namespace

int ManoeuvreMoves(const std::vector<algorithms::GearedPose>& manoeuvre) {
  int moves = manoeuvre.empty() ? 0 : 1;
  for (size_t i = 1; i < manoeuvre.size(); ++i) {
    moves += manoeuvre[i].reverse != manoeuvre[i - 1].reverse;
  }
  return moves;
}

std::vector<RouteTurnaround> World::Impl::SharpCorners(
    algorithms::FreespacePlanner& planner) const {
  // Corners the car cannot follow closely: the ideal driver, rehearsed on
  // the car's model along the road part between the U-turns, strays more
  // than kMaxCornerStrayM from it. Each such stretch is driven as the
  // freespace planner's manoeuvre from kCornerLeadM before it to
  // kCornerRejoinM past it; one with a signal's stop line or a lane change
  // in it, or without a manoeuvre, keeps its lanes.
  const IdealDriverOptions driver;
  const SpeedProfile speed = CurveSpeedProfile(
      road, setup.task.speed_limit_kmh / 3.6, driver.max_lateral_accel_mps2,
      driver.comfort_decel_mps2);
  std::vector<std::pair<double, double>> gaps;  // between the U-turns
  double gap_from = 0.0;
  for (const RouteTurnaround& turn : turnarounds) {
    gaps.emplace_back(gap_from, turn.start_s_m);
    gap_from = turn.end_s_m;
  }
  gaps.emplace_back(gap_from, road.length_m());
  // A corner turned in moves from start_s to end_s along the road part, or
  // none where it must keep its lanes or no manoeuvre fits.
  auto corner_turn = [&](double start_s,
                         double end_s) -> std::optional<RouteTurnaround> {
    RouteTurnaround turn;
    turn.start_s_m = start_s;
    turn.end_s_m = end_s;
    if (std::any_of(signals.begin(), signals.end(),
                    [&](const RouteSignal& x) {
                      return x.stop_line_s_m >= turn.start_s_m &&
                             x.stop_line_s_m <= turn.end_s_m;
                    }) ||
        std::any_of(lane_changes.begin(), lane_changes.end(),
                    [&](const algorithms::LaneChangeSection& c) {
                      return c.start_s_m <= turn.end_s_m &&
                             c.end_s_m >= turn.start_s_m;
                    })) {
      return std::nullopt;
    }
    const Vec2 a = road.PointAt(turn.start_s_m);
    const Vec2 b = road.PointAt(turn.end_s_m);
    const geometry::Pose2 start{a.x(), a.y(), road.HeadingAt(turn.start_s_m)};
    turn.goal = {b.x(), b.y(), road.HeadingAt(turn.end_s_m)};
    std::vector<Vec2> stretch;
    for (double s_m = turn.start_s_m; s_m < turn.end_s_m; s_m += 10.0) {
      stretch.push_back(road.PointAt(s_m));
    }
    stretch.push_back(b);
    Result<algorithms::FreespacePath> manoeuvre =
        PlanWithinRoad(planner, start, stretch, scene, &turn);
    if (!manoeuvre.ok()) return std::nullopt;
    turn.reference = manoeuvre->poses;
    turn.corner = true;
    return turn;
  };
  std::vector<RouteTurnaround> corners;
  for (const auto& [gap_start, gap_end] : gaps) {
    // The driver is rehearsed as it will drive: on from where the car
    // stands (the route's start, a U-turn's or a corner's end), so that
    // it reaches each corner as fast as it will; a corner rehearsed from
    // the speed limit alone was met faster live than rehearsed after a
    // standing start (A10KW-2 of seed 3: 0.90 m rehearsed, 1.05 m live).
    double from_s = gap_start;
    bool restart = true;
    while (restart) {
      restart = false;
      std::vector<std::pair<double, double>> strays;  // [first, last] s off
      for (const RehearsalSample& sample :
           RehearseFollowing(road, speed, from_s, gap_end, 0.0, setup.ego,
                             driver.steering, setup.world.step_s)) {
        if (sample.distance_m <= kMaxCornerStrayM) continue;
        if (!strays.empty() &&
            sample.s_m - strays.back().second < kCornerLeadM + kCornerRejoinM) {
          strays.back().second = std::max(strays.back().second, sample.s_m);
        } else {
          strays.emplace_back(sample.s_m, sample.s_m);
        }
      }
      for (const auto& [first, last] : strays) {
        // A stray soon after the corner the car has just turned makes one
        // stretch with it, as strays in one rehearsal do: one manoeuvre,
        // not two back to back.
        const double end_s = std::min(gap_end, last + kCornerRejoinM);
        const bool joins = from_s > gap_start &&
                           first - from_s < kCornerLeadM + kCornerRejoinM;
        std::optional<RouteTurnaround> turn;
        if (joins) turn = corner_turn(corners.back().start_s_m, end_s);
        if (turn) {
          corners.back() = std::move(*turn);
        } else {
          turn = corner_turn(std::max(from_s, first - kCornerLeadM), end_s);
          if (!turn) continue;
          corners.push_back(std::move(*turn));
        }
        // The car stands at the turn's end: rehearsed on from there.
        from_s = corners.back().end_s_m;
        restart = true;
        break;
      }
    }
  }
  return corners;
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
    Result<algorithms::FreespacePath> manoeuvre = PlanWithinRoad(
        planner, from, {arrive.empty() ? stop : arrive.back()}, scene, &turn);
    if (!manoeuvre.ok()) {
      return Status::InvalidArgument(fmt::format(
          "task.goal: unreachable from task.start: the route turns around "
          "from lane '{}' to lane '{}', {:.1f} m across (the car turns no "
          "tighter than {:.1f} m), no way round the block leads on, and no "
          "turn in several moves fits in the lanes, junctions and shoulders "
          "there ({})",
          crossing.from_lane, crossing.to_lane,
          internal::UTurnWidthM(crossing.from_lane, crossing.to_lane),
          MinTurningRadiusM(), manoeuvre.status().message()));
    }
    turn.reference = manoeuvre->poses;
    turnarounds.push_back(std::move(turn));
  }

  for (RouteTurnaround& turn : SharpCorners(planner)) {
    turnarounds.push_back(std::move(turn));
  }
  std::sort(turnarounds.begin(), turnarounds.end(),
            [](const RouteTurnaround& a, const RouteTurnaround& b) {
              return a.start_s_m < b.start_s_m;
            });
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
