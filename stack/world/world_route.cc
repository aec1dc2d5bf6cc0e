// The route and the ideal path: where start, goal and waypoints lie on the
// network, the edges between them, and the path a perfect driver follows
// (for valet parking, the road part and then the reference manoeuvre).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <queue>
#include <set>
#include <utility>

#include "stack/algorithms/freespace_planner.h"
#include "stack/world/internal/world_impl.h"
#include "stack/world/parking_goal.h"
#include "stack/world/roadside_poles.h"

namespace adse::world {
namespace internal {

// The internal (junction) lanes a connection drives through, starting at its
// `via` lane. An internal lane's link names the final normal lane as
// approachedLane and the next internal lane, if any, as approachedInternal.
std::vector<std::string> InternalChain(const std::string& via,
                                       std::string* arrives_on) {
  std::vector<std::string> chain;
  std::string internal = via;
  for (int guard = 0; guard < 16 && !internal.empty(); ++guard) {
    chain.push_back(internal);
    const auto links = libsumo::Lane::getLinks(internal);
    if (links.empty()) break;
    if (arrives_on) *arrives_on = links.front().approachedLane;
    internal = links.front().approachedInternal;
  }
  return chain;
}

// Part of `shape` between arc lengths s0 and s1.
std::vector<Vec2> Slice(const std::vector<Vec2>& shape, double s0, double s1) {
  geometry::Path2 path;
  path.points = shape;
  path.UpdateArcLength();
  s0 = std::clamp(s0, 0.0, path.length_m());
  s1 = std::clamp(s1, 0.0, path.length_m());
  std::vector<Vec2> out = {path.PointAt(s0)};
  for (size_t i = 0; i < shape.size(); ++i) {
    if (path.s_m[i] > s0 && path.s_m[i] < s1) out.push_back(shape[i]);
  }
  out.push_back(path.PointAt(s1));
  return out;
}

double ShapeS(const std::vector<Vec2>& shape, double lane_length_m,
              double pos_m) {
  // Differences below this are the rounding of the net's coordinates.
  constexpr double kRoundingM = 0.05;
  double shape_m = 0.0;
  for (size_t i = 1; i < shape.size(); ++i) {
    shape_m += (shape[i] - shape[i - 1]).norm();
  }
  if (lane_length_m <= 0.0 || std::abs(shape_m - lane_length_m) <= kRoundingM) {
    return pos_m;
  }
  return pos_m * shape_m / lane_length_m;
}

geometry::Path2 Resample(const std::vector<Vec2>& points, double step) {
  geometry::Path2 raw;
  for (const Vec2& p : points) {
    if (raw.points.empty() || (p - raw.points.back()).norm() > 1e-6) {
      raw.points.push_back(p);
    }
  }
  raw.UpdateArcLength();
  geometry::Path2 out;
  const double length = raw.length_m();
  const int n = std::max(1, static_cast<int>(std::ceil(length / step)));
  for (int i = 0; i <= n; ++i)
    out.points.push_back(raw.PointAt(length * i / n));
  out.UpdateArcLength();
  return out;
}

// Whether passenger cars may use the lane (not a sidewalk, bus lane, ...).
bool OpenToCars(const std::string& lane_id) {
  const std::vector<std::string> disallowed =
      libsumo::Lane::getDisallowed(lane_id);
  return std::find(disallowed.begin(), disallowed.end(), "passenger") ==
         disallowed.end();
}

double UTurnWidthM(const std::string& from_lane, const std::string& to_lane) {
  const std::vector<Vec2> from = ToPoints(libsumo::Lane::getShape(from_lane));
  const std::vector<Vec2> to = ToPoints(libsumo::Lane::getShape(to_lane));
  if (from.size() < 2 || to.empty()) return 0.0;
  const Vec2 heading = (from.back() - from[from.size() - 2]).normalized();
  const Vec2 d = to.front() - from.back();
  return std::abs(heading.x() * d.y() - heading.y() * d.x());
}

}  // namespace internal

using internal::InternalChain;
using internal::kResampleStepM;
using internal::OpenToCars;
using internal::Resample;
using internal::ShapeS;
using internal::Slice;
using internal::ToPoints;
using internal::UTurnWidthM;
using internal::Vec2;

Result<RoadLocation> World::Impl::Resolve(const Location& location,
                                          const std::string& field,
                                          double slack_m) {
  RoadLocation out;
  try {
    if (location.by_edge) {
      const std::vector<std::string> edges = libsumo::Edge::getIDList();
      if (std::find(edges.begin(), edges.end(), location.edge) == edges.end() ||
          location.edge.empty() || location.edge[0] == ':') {
        return Status::InvalidArgument(fmt::format(
            "{}.edge: no edge '{}' in the network", field, location.edge));
      }
      const int lanes = libsumo::Edge::getLaneNumber(location.edge);
      if (location.lane < 0 || location.lane >= lanes) {
        return Status::InvalidArgument(
            fmt::format("{}.lane: edge '{}' has lanes 0..{}, found {}", field,
                        location.edge, lanes - 1, location.lane));
      }
      const std::string lane_id =
          location.edge + "_" + std::to_string(location.lane);
      if (!OpenToCars(lane_id)) {
        return Status::InvalidArgument(fmt::format(
            "{}.edge: lane {} of edge '{}' is closed to passenger cars", field,
            location.lane, location.edge));
      }
      const double length = libsumo::Lane::getLength(lane_id);
      if (location.pos_m < 0 || location.pos_m > length) {
        return Status::InvalidArgument(
            fmt::format("{}.pos_m: edge '{}' is {:.1f} m long, found {}", field,
                        location.edge, length, location.pos_m));
      }
      out.edge = location.edge;
      out.lane = location.lane;
      out.pos_m = location.pos_m;
    } else {
      const libsumo::TraCIRoadPosition road = libsumo::Simulation::convertRoad(
          location.x_m, location.y_m, false, "passenger");
      if (road.edgeID.empty()) {
        return Status::InvalidArgument(
            fmt::format("{}: ({}, {}) is not near any road of the network",
                        field, location.x_m, location.y_m));
      }
      std::string lane_id = road.edgeID + "_" + std::to_string(road.laneIndex);
      const auto snapped =
          libsumo::Simulation::convert2D(road.edgeID, road.pos, road.laneIndex);
      const double off =
          std::hypot(snapped.x - location.x_m, snapped.y - location.y_m);
      const double half_width = libsumo::Lane::getWidth(lane_id) / 2;
      if (off > half_width + slack_m) {
        return Status::InvalidArgument(fmt::format(
            "{}: ({}, {}) is off the road network: the nearest lane '{}' is "
            "{:.1f} m away (expected within {:.1f} m of a lane centre)",
            field, location.x_m, location.y_m, lane_id, off,
            half_width + slack_m));
      }
      out.edge = road.edgeID;
      out.lane = road.laneIndex;
      out.pos_m = road.pos;
      // Inside a junction: continue on the lane the internal lane leads to.
      while (!out.edge.empty() && out.edge[0] == ':') {
        const auto links = libsumo::Lane::getLinks(lane_id);
        if (links.empty()) {
          return Status::InvalidArgument(
              fmt::format("{}: ({}, {}) lies inside a junction with no way out",
                          field, location.x_m, location.y_m));
        }
        lane_id = links.front().approachedLane;
        out.edge = EdgeOfLane(lane_id);
        out.lane = IndexOfLane(lane_id);
        out.pos_m = 0.0;
      }
    }
    const auto p =
        libsumo::Simulation::convert2D(out.edge, out.pos_m, out.lane);
    out.xy = Vec2(p.x, p.y);
  } catch (const std::exception& e) {
    return Status::InvalidArgument(field + ": " + e.what());
  }
  return out;
}

namespace {

// A path vertex turning by more than 150 degrees folds the path back.
constexpr double kFoldCos = -0.866;
// A folded stretch that runs past the next lane's start ends this far
// short of it.
constexpr double kFoldLeadM = 10.0;

// Whether `link` from `from_lane` is a U-turn narrower than two turning
// radii: a car that turns no tighter than `min_radius_m` needs that much
// road to turn around without reversing.
bool TooTightUTurn(const std::string& from_lane,
                   const libsumo::TraCIConnection& link, double min_radius_m) {
  return link.direction == "t" &&
         UTurnWidthM(from_lane, link.approachedLane) < 2.0 * min_radius_m;
}

// The edges a car may drive to from `edge` (through any link but a
// TooTightUTurn) into `drivable`; returns those reached only by such a
// U-turn. Only links between lanes open to passenger cars.
std::set<std::string> Successors(const std::string& edge, double min_radius_m,
                                 std::set<std::string>* drivable) {
  std::set<std::string> tight;
  for (int l = 0; l < libsumo::Edge::getLaneNumber(edge); ++l) {
    const std::string lane_id = edge + "_" + std::to_string(l);
    if (!OpenToCars(lane_id)) continue;
    for (const auto& link : libsumo::Lane::getLinks(lane_id)) {
      if (!OpenToCars(link.approachedLane)) continue;
      const std::string next = EdgeOfLane(link.approachedLane);
      if (TooTightUTurn(lane_id, link, min_radius_m)) {
        tight.insert(next);
      } else {
        drivable->insert(next);
      }
    }
  }
  for (const std::string& next : *drivable) tight.erase(next);
  return tight;
}

// Whether `route` takes a U-turn the car cannot drive in one move.
bool HasTightUTurn(const std::vector<std::string>& route, double min_radius_m) {
  for (size_t i = 0; i + 1 < route.size(); ++i) {
    std::set<std::string> drivable;
    if (Successors(route[i], min_radius_m, &drivable).count(route[i + 1])) {
      return true;
    }
  }
  return false;
}

// The quickest route (travel time at the lanes' speed limits, as SUMO's
// router weighs it) from `from` to `to` that leaves `from` and takes only
// turns the car can drive; empty when there is none. `to` may equal
// `from` (the goal behind the start): then the route comes round to it.
std::vector<std::string> DrivableRoute(const std::string& from,
                                       const std::string& to,
                                       double min_radius_m) {
  std::map<std::string, double> best;
  std::map<std::string, std::string> previous;
  using Entry = std::pair<double, std::string>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  auto relax = [&](const std::string& edge, double t) {
    std::set<std::string> drivable;
    Successors(edge, min_radius_m, &drivable);
    for (const std::string& next : drivable) {
      const std::string lane = next + "_0";
      const double cost =
          t + libsumo::Lane::getLength(lane) /
                  std::max(0.1, libsumo::Lane::getMaxSpeed(lane));
      auto it = best.find(next);
      if (it == best.end() || cost < it->second) {
        best[next] = cost;
        previous[next] = edge;
        open.emplace(cost, next);
      }
    }
  };
  relax(from, 0.0);
  std::set<std::string> settled;
  while (!open.empty()) {
    const auto [t, edge] = open.top();
    open.pop();
    if (!settled.insert(edge).second) continue;
    if (edge == to) {
      // Back along the predecessors to `from`, which the search left at
      // time 0, so every chain ends there.
      std::vector<std::string> route = {to};
      std::string e = to;
      do {
        e = previous.at(e);
        route.push_back(e);
      } while (e != from);
      std::reverse(route.begin(), route.end());
      return route;
    }
    relax(edge, t);
  }
  return {};
}

}  // namespace

Result<std::vector<std::string>> World::Impl::RouteLeg(
    const RoadLocation& from, const RoadLocation& to,
    const std::string& to_field, const std::string& from_field) {
  try {
    if (from.edge == to.edge && to.pos_m >= from.pos_m) {
      return std::vector<std::string>{from.edge};
    }
    // The target may lie behind the start on the same edge: leave the edge
    // first. Otherwise a plain shortest route.
    std::vector<std::string> best;
    double best_length = std::numeric_limits<double>::infinity();
    if (from.edge == to.edge) {
      std::set<std::string> next_edges;
      for (int l = 0; l < libsumo::Edge::getLaneNumber(from.edge); ++l) {
        for (const auto& link :
             libsumo::Lane::getLinks(from.edge + "_" + std::to_string(l))) {
          next_edges.insert(EdgeOfLane(link.approachedLane));
        }
      }
      for (const std::string& next : next_edges) {
        const libsumo::TraCIStage stage =
            libsumo::Simulation::findRoute(next, to.edge);
        if (!stage.edges.empty() && stage.length < best_length) {
          best_length = stage.length;
          best = {from.edge};
          best.insert(best.end(), stage.edges.begin(), stage.edges.end());
        }
      }
    } else {
      const libsumo::TraCIStage stage =
          libsumo::Simulation::findRoute(from.edge, to.edge);
      best = stage.edges;
    }
    if (best.empty()) {
      return Status::InvalidArgument(fmt::format(
          "{}: unreachable from {} (no route from edge '{}' to edge '{}')",
          to_field, from_field, from.edge, to.edge));
    }
    // SUMO's router turns around wherever the net has a turnaround link;
    // a car cannot follow a U-turn narrower than its turning circle
    // without reversing, so such a route goes round the block instead
    // where it can, and turns in several moves where it cannot (a
    // cul-de-sac, a start heading into a dead end; PlanTurnarounds).
    const double min_radius_m = MinTurningRadiusM();
    if (HasTightUTurn(best, min_radius_m)) {
      std::vector<std::string> round =
          DrivableRoute(from.edge, to.edge, min_radius_m);
      if (!round.empty()) best = std::move(round);
    }
    return best;
  } catch (const std::exception& e) {
    return Status::InvalidArgument(to_field + ": routing failed: " + e.what());
  }
}

Status World::Impl::PlanRoute() {
  // Start, each waypoint, goal: the shortest leg between each and the next,
  // joined where one leg's last edge is the next one's first.
  std::vector<const RoadLocation*> stops = {&start};
  std::vector<std::string> fields = {"task.start"};
  for (size_t i = 0; i < via.size(); ++i) {
    stops.push_back(&via[i]);
    fields.push_back(fmt::format("task.via[{}]", i));
  }
  stops.push_back(&goal);
  fields.push_back("task.goal");
  route.clear();
  for (size_t i = 0; i + 1 < stops.size(); ++i) {
    Result<std::vector<std::string>> leg =
        RouteLeg(*stops[i], *stops[i + 1], fields[i + 1], fields[i]);
    if (!leg.ok()) return leg.status();
    route.insert(route.end(), leg->begin() + (route.empty() ? 0 : 1),
                 leg->end());
  }
  return Status::Ok();
}

double World::Impl::RoadS(double raw_s_m) const {
  // Resample() put road point i at raw arc length L * i / n; a raw arc
  // length maps to the road's between its neighbours.
  const int n = static_cast<int>(road.points.size()) - 1;
  if (n < 1) return 0.0;
  const double f =
      raw_length_m > 0 ? std::clamp(raw_s_m / raw_length_m, 0.0, 1.0) * n : 0.0;
  const int i = std::min(static_cast<int>(std::floor(f)), n - 1);
  return road.s_m[i] + (f - i) * (road.s_m[i + 1] - road.s_m[i]);
}

Status World::Impl::BuildIdealPath() {
  try {
    // Pick, from the goal backwards, a lane on each edge that connects to
    // the lane chosen on the next edge.
    const size_t n = route.size();
    std::vector<int> lane(n, 0);
    lane[n - 1] = goal.lane;
    std::vector<std::string> via(n);  // internal lane chain start after edge i
    for (size_t i = n - 1; i-- > 0;) {
      const std::string target =
          route[i + 1] + "_" + std::to_string(lane[i + 1]);
      const int lanes = libsumo::Edge::getLaneNumber(route[i]);
      int chosen = -1;
      std::string chosen_via;
      std::string fallback_target, fallback_via;
      int fallback = -1;
      for (int l = 0; l < lanes && chosen < 0; ++l) {
        const std::string lane_id = route[i] + "_" + std::to_string(l);
        if (!OpenToCars(lane_id)) continue;  // sidewalks, bus lanes, ...
        for (const auto& link : libsumo::Lane::getLinks(lane_id)) {
          if (link.approachedLane == target) {
            chosen = l;
            chosen_via = link.approachedInternal;
            break;
          }
          if (fallback < 0 && EdgeOfLane(link.approachedLane) == route[i + 1]) {
            fallback = l;
            fallback_target = link.approachedLane;
            fallback_via = link.approachedInternal;
          }
        }
      }
      if (chosen < 0) {
        if (fallback < 0) {
          return Status::Internal(
              fmt::format("route edge '{}' has no connection to '{}'", route[i],
                          route[i + 1]));
        }
        // Enter the next edge on another lane; the path changes lanes there.
        chosen = fallback;
        chosen_via = fallback_via;
        (void)fallback_target;
      }
      lane[i] = chosen;
      via[i] = chosen_via;
    }
    if (route.size() == 1) lane[0] = start.lane;

    std::vector<Vec2> points;
    double raw_s = 0.0;  // arc length of `points`
    auto append = [&](const std::vector<Vec2>& part) {
      if (!points.empty() && !part.empty()) {
        max_join_gap_m =
            std::max(max_join_gap_m, (part.front() - points.back()).norm());
      }
      for (const Vec2& p : part) {
        if (!points.empty() && (p - points.back()).norm() < 1e-6) continue;
        // OSM-derived lane shapes can fold back on themselves (acosta's
        // edge 224[1] starts 9 m past its corner and comes back): no car
        // drives a vertex that reverses the path, so it is dropped. Where
        // `p` lies beside the last stretch (a junction's lane starting
        // well before the edge's shape ends, a little to its side), the
        // stretch ends kFoldLeadM short of `p`, not at its start: joined
        // from the start, pasubio's edge 30 drifted 2.2 m across its road
        // over 90 m, into the roadside poles.
        while (points.size() >= 2) {
          const Vec2 a = points[points.size() - 2];
          const Vec2 in = points.back() - a;
          const Vec2 out = p - points.back();
          if (out.norm() < 1e-6 ||
              in.dot(out) > kFoldCos * in.norm() * out.norm()) {
            break;
          }
          const double along_m = (p - a).dot(in) / in.norm() - kFoldLeadM;
          if (along_m > 1e-3) {
            const Vec2 cut = a + in * (along_m / in.norm());
            raw_s -= (points.back() - cut).norm();
            points.back() = cut;
          } else {
            raw_s -= in.norm();
            points.pop_back();
          }
          // A crossing recorded on the cut or dropped part lies where the
          // path ends now.
          for (Crossing& c : crossings) c.raw_s_m = std::min(c.raw_s_m, raw_s);
        }
        if (!points.empty()) raw_s += (p - points.back()).norm();
        points.push_back(p);
      }
    };
    crossings.clear();
    lane_changes.clear();
    double width_sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
      // Entry lane: the one the previous connection arrives on.
      int entry = lane[i];
      if (i == 0) {
        entry = start.lane;
      } else if (!via[i - 1].empty()) {
        std::string arrives_on;
        InternalChain(via[i - 1], &arrives_on);
        if (EdgeOfLane(arrives_on) == route[i]) entry = IndexOfLane(arrives_on);
      }
      const std::string entry_id = route[i] + "_" + std::to_string(entry);
      const std::string exit_id = route[i] + "_" + std::to_string(lane[i]);
      const double length = libsumo::Lane::getLength(exit_id);
      const std::vector<Vec2> exit_shape =
          ToPoints(libsumo::Lane::getShape(exit_id));
      const double s0 = i == 0 ? ShapeS(exit_shape, length, start.pos_m) : 0.0;
      const double s1 =
          ShapeS(exit_shape, length, i == n - 1 ? goal.pos_m : length);
      width_sum += libsumo::Lane::getWidth(exit_id);
      std::vector<Vec2> part = Slice(exit_shape, s0, s1);
      if (entry != lane[i]) {
        // A lane change: blend from the entry lane into the exit lane over
        // the middle of the edge (lane s here; the route's section below).
        geometry::Path2 from, to;
        from.points = ToPoints(libsumo::Lane::getShape(entry_id));
        from.UpdateArcLength();
        to.points = ToPoints(libsumo::Lane::getShape(exit_id));
        to.UpdateArcLength();
        algorithms::LaneChangeSection blend;
        blend.start_s_m = s0 + 0.25 * (s1 - s0);
        blend.end_s_m = s0 + 0.75 * (s1 - s0);
        part.clear();
        for (double s = s0; s <= s1 + 1e-9; s += kResampleStepM) {
          const double w = blend.Weight(s);
          part.push_back((1 - w) * from.PointAt(s) + w * to.PointAt(s));
        }
        // SUMO numbers a road's lanes from the right.
        const double width = libsumo::Lane::getWidth(exit_id);
        const double raw_at_s0 =
            raw_s + (points.empty() || part.empty()
                         ? 0.0
                         : (part.front() - points.back()).norm());
        blend.start_s_m += raw_at_s0 - s0;
        blend.end_s_m += raw_at_s0 - s0;
        blend.shift_m = (lane[i] - entry) * width;
        blend.lane_width_m = width;
        lane_changes.push_back(blend);
      }
      append(part);
      if (i + 1 < n) {
        std::string to_lane = route[i + 1] + "_" + std::to_string(lane[i + 1]);
        if (!via[i].empty()) InternalChain(via[i], &to_lane);
        bool tight = false;
        for (const auto& link : libsumo::Lane::getLinks(exit_id)) {
          tight |= link.approachedLane == to_lane &&
                   TooTightUTurn(exit_id, link, MinTurningRadiusM());
        }
        crossings.push_back({exit_id, via[i], to_lane, raw_s, tight});
      }
      if (i + 1 < n && !via[i].empty()) {
        for (const std::string& internal : InternalChain(via[i], nullptr)) {
          append(ToPoints(libsumo::Lane::getShape(internal)));
        }
      }
    }
    lane_width_m = width_sum / static_cast<double>(n);
    goal_xy = goal.xy;

    road = Resample(points, kResampleStepM);
    raw_length_m = raw_s;
    for (algorithms::LaneChangeSection& c : lane_changes) {
      c.start_s_m = RoadS(c.start_s_m);
      c.end_s_m = RoadS(c.end_s_m);
    }
    ideal = road;  // PlanTurnarounds adds the manoeuvres
    if (valet) {
      // The reference manoeuvre: the freespace planner's path from where the
      // road part ends into the slot, on the ground-truth lot. When it finds
      // none the ideal path is the road part (the stack will find none
      // either and say so).
      const geometry::Pose2 from{road.points.back().x(), road.points.back().y(),
                                 road.HeadingAt(road.length_m())};
      algorithms::FreespacePlanner planner(
          {},
          algorithms::FootprintOfBody(setup.ego.length_m, setup.ego.wheelbase_m,
                                      setup.ego.width_m));
      Result<algorithms::FreespacePath> manoeuvre =
          planner.Plan(from, parking_goal, ObstacleOutlines(scene));
      if (manoeuvre.ok()) {
        // A manoeuvre with gear changes passes its cusps twice: appended
        // as planned, not resampled.
        for (const algorithms::GearedPose& p : manoeuvre->poses) {
          const Vec2 point(p.pose.x_m, p.pose.y_m);
          if (ideal.points.empty() ||
              (point - ideal.points.back()).norm() > 1e-6) {
            ideal.points.push_back(point);
          }
        }
        reference = manoeuvre->poses;
      }
      ideal.UpdateArcLength();
      goal_xy = Vec2(parking_goal.x_m, parking_goal.y_m);
    }
  } catch (const std::exception& e) {
    return Status::Internal(std::string("building the ideal path: ") +
                            e.what());
  }
  return Status::Ok();
}

}  // namespace adse::world
