// The only place adse talks to libsumo. libsumo reports errors as
// libsumo::TraCIException (or a bare "Process Error" whose cause goes to
// SUMO's error log): both are caught here and turned into Status.
#include "stack/world/world.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <libsumo/libsumo.h>

#include <unistd.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <set>

#include "stack/algorithms/freespace_planner.h"
#include "stack/base/files.h"
#include "stack/base/hash.h"
#include "stack/base/random.h"
#include "stack/world/map_cloud.h"
#include "stack/world/parking_goal.h"

namespace adse::world {
namespace {

namespace fs = std::filesystem;
using Vec2 = Eigen::Vector2d;

std::atomic<bool> g_world_open{false};

constexpr char kEgoId[] = "ego";
constexpr double kResampleStepM = 0.5;
// How far a start/goal may lie from a lane centre, beyond half its width.
constexpr double kOffRoadSlackM = 1.5;
constexpr double kValetSlackM = 8.0;

double SumoAngleToYaw(double angle_deg) {
  return (90.0 - angle_deg) * M_PI / 180.0;
}
double YawToSumoAngle(double yaw_rad) {
  double a = 90.0 - yaw_rad * 180.0 / M_PI;
  a = std::fmod(a, 360.0);
  return a < 0 ? a + 360.0 : a;
}

std::vector<Vec2> ToPoints(const libsumo::TraCIPositionVector& shape) {
  std::vector<Vec2> out;
  out.reserve(shape.value.size());
  for (const auto& p : shape.value) out.emplace_back(p.x, p.y);
  return out;
}

std::string EdgeOfLane(const std::string& lane_id) {
  return lane_id.substr(0, lane_id.rfind('_'));
}
int IndexOfLane(const std::string& lane_id) {
  return std::atoi(lane_id.substr(lane_id.rfind('_') + 1).c_str());
}

// Runs `fn`, turning libsumo exceptions into Status.
template <typename Fn>
Status Guard(const std::string& what, Fn&& fn) {
  try {
    fn();
    return Status::Ok();
  } catch (const std::exception& e) {
    return Status::IoError(what + ": " + e.what());
  }
}

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

}  // namespace

struct World::Impl {
  WorldSetup setup;
  MapArtifacts map;
  RoadLocation start, goal;
  std::vector<RoadLocation> via;  // task.via, resolved
  Vec2 goal_xy = Vec2::Zero();    // final target (rear axle when valet)
  bool valet = false;
  ParkingSlot goal_slot;                 // valet: the slot parked in
  geometry::Pose2 parking_goal;          // valet: rear axle parked
  geometry::Path2 road;                  // the route's road part
  std::vector<ManoeuvrePose> reference;  // valet: the reference manoeuvre
  std::vector<std::string> route;
  geometry::Path2 ideal;
  double lane_width_m = 3.2;
  double max_join_gap_m = 0.0;
  Scene scene;
  std::unique_ptr<BicycleModel> ego;
  std::vector<OtherVehicle> others;
  std::set<std::string> in_contact;
  std::vector<std::string> new_contacts;
  int collisions = 0;
  double time_s = 0.0;
  bool sumo_running = false;

  struct FlowState {
    std::string route_id;
    double probability_per_step = 0.0;
    int spawned = 0;
  };
  std::vector<FlowState> flows;
  std::unique_ptr<Random> traffic_random;
  std::map<std::string, Vec2> dims;  // vehicle id -> (length, width)

  ~Impl() {
    if (sumo_running) {
      try {
        libsumo::Simulation::close();
      } catch (...) {
      }
    }
  }

  Status StartSumo();
  Result<RoadLocation> Resolve(const Location& location,
                               const std::string& field, double slack_m);
  // The edges from `from` to `to`, both included; errors name the fields.
  Result<std::vector<std::string>> RouteLeg(const RoadLocation& from,
                                            const RoadLocation& to,
                                            const std::string& to_field,
                                            const std::string& from_field);
  Status PlanRoute();
  Status BuildIdealPath();
  Status BuildScene();
  Status SetUpTraffic();
  Status AddEgo();
  void PushEgo();
  Status ReadOthers();
};

Status World::Impl::StartSumo() {
  std::vector<std::string> args = {
      "sumo",
      "-n",
      map.net_path,
      "--step-length",
      fmt::format("{}", setup.world.step_s),
      "--seed",
      std::to_string(setup.world.traffic.seed % 2147483647),
      "--no-step-log",
      "true",
      "--no-warnings",
      "true",
      "--collision.action",
      "none",
      "--time-to-teleport",
      "-1",
      "--ignore-route-errors",
      "true"};
  if (!map.polygons_path.empty()) {
    args.push_back("--additional-files");
    args.push_back(map.polygons_path);
  }
  if (std::getenv("SUMO_HOME") == nullptr) {
    ::setenv("SUMO_HOME", "/usr/share/sumo", 0);
  }
  // SUMO prints the cause of a load failure to stderr and throws a bare
  // "Process Error": capture stderr while it starts and report the cause.
  const std::string log = map.cache_folder + "/sumo-stderr." +
                          std::to_string(static_cast<long>(::getpid())) +
                          ".log";
  std::fflush(stderr);
  const int saved = ::dup(STDERR_FILENO);
  const int capture = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (capture >= 0) ::dup2(capture, STDERR_FILENO);
  Status status =
      Guard("starting SUMO", [&] { libsumo::Simulation::start(args); });
  std::fflush(stderr);
  if (saved >= 0) {
    ::dup2(saved, STDERR_FILENO);
    ::close(saved);
  }
  if (capture >= 0) ::close(capture);
  std::string cause;
  if (Result<std::string> text = ReadFile(log, 1 << 20); text.ok())
    cause = *text;
  std::error_code ec;
  fs::remove(log, ec);
  if (!status.ok()) {
    while (!cause.empty() &&
           std::isspace(static_cast<unsigned char>(cause.back()))) {
      cause.pop_back();
    }
    return Status::InvalidArgument(
        fmt::format("world.map.net: SUMO cannot load '{}': {}", map.net_path,
                    cause.empty() ? status.message() : cause));
  }
  sumo_running = true;
  return Status::Ok();
}

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
      const std::vector<std::string> disallowed =
          libsumo::Lane::getDisallowed(lane_id);
      if (std::find(disallowed.begin(), disallowed.end(), "passenger") !=
          disallowed.end()) {
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
        const std::vector<std::string> disallowed =
            libsumo::Lane::getDisallowed(lane_id);
        if (std::find(disallowed.begin(), disallowed.end(), "passenger") !=
            disallowed.end()) {
          continue;  // sidewalks, bus lanes, ...
        }
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
    auto append = [&](const std::vector<Vec2>& part) {
      if (!points.empty() && !part.empty()) {
        max_join_gap_m =
            std::max(max_join_gap_m, (part.front() - points.back()).norm());
      }
      points.insert(points.end(), part.begin(), part.end());
    };
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
      const double s0 = i == 0 ? start.pos_m : 0.0;
      const double s1 = i == n - 1 ? goal.pos_m : length;
      width_sum += libsumo::Lane::getWidth(exit_id);
      std::vector<Vec2> part =
          Slice(ToPoints(libsumo::Lane::getShape(exit_id)), s0, s1);
      if (entry != lane[i]) {
        // A lane change: blend from the entry lane into the exit lane over
        // the middle of the edge.
        geometry::Path2 from, to;
        from.points = ToPoints(libsumo::Lane::getShape(entry_id));
        from.UpdateArcLength();
        to.points = ToPoints(libsumo::Lane::getShape(exit_id));
        to.UpdateArcLength();
        part.clear();
        for (double s = s0; s <= s1 + 1e-9; s += kResampleStepM) {
          const double u = (s1 - s0) > 1e-6 ? (s - s0) / (s1 - s0) : 1.0;
          const double alpha = std::clamp((u - 0.25) / 0.5, 0.0, 1.0);
          const double w = alpha * alpha * (3 - 2 * alpha);  // smoothstep
          part.push_back((1 - w) * from.PointAt(s) + w * to.PointAt(s));
        }
      }
      append(part);
      if (i + 1 < n && !via[i].empty()) {
        for (const std::string& internal : InternalChain(via[i], nullptr)) {
          append(ToPoints(libsumo::Lane::getShape(internal)));
        }
      }
    }
    lane_width_m = width_sum / static_cast<double>(n);
    goal_xy = goal.xy;

    road = Resample(points, kResampleStepM);
    std::vector<Vec2> manoeuvre_points;
    if (valet) {
      // The reference manoeuvre: the freespace planner's path from where the
      // road part ends into the slot, on the ground-truth lot. When it finds
      // none the ideal path is the road part (the stack will find none
      // either and say so).
      const geometry::Pose2 from{road.points.back().x(), road.points.back().y(),
                                 road.HeadingAt(road.length_m())};
      algorithms::VehicleFootprint footprint;
      footprint.front_m = 0.5 * (setup.ego.wheelbase_m + setup.ego.length_m);
      footprint.rear_m = 0.5 * (setup.ego.length_m - setup.ego.wheelbase_m);
      footprint.width_m = setup.ego.width_m;
      algorithms::FreespacePlanner planner({}, footprint);
      Result<algorithms::FreespacePath> manoeuvre =
          planner.Plan(from, parking_goal, ObstacleOutlines(scene));
      if (manoeuvre.ok()) {
        for (const algorithms::GearedPose& p : manoeuvre->poses) {
          manoeuvre_points.emplace_back(p.pose.x_m, p.pose.y_m);
          reference.push_back({p.pose, p.reverse});
        }
      }
      goal_xy = Vec2(parking_goal.x_m, parking_goal.y_m);
    }
    // A manoeuvre with gear changes passes its cusps twice: no resampling.
    if (valet) {
      ideal.points = road.points;
      for (const Vec2& p : manoeuvre_points) {
        if (ideal.points.empty() || (p - ideal.points.back()).norm() > 1e-6)
          ideal.points.push_back(p);
      }
      ideal.UpdateArcLength();
    } else {
      ideal = road;
    }
  } catch (const std::exception& e) {
    return Status::Internal(std::string("building the ideal path: ") +
                            e.what());
  }
  return Status::Ok();
}

Status World::Impl::BuildScene() {
  return Guard("building the scene", [&] {
    std::vector<std::string> polygon_ids = libsumo::Polygon::getIDList();
    std::sort(polygon_ids.begin(), polygon_ids.end());
    bool any_static = false;
    for (const std::string& id : polygon_ids) {
      const std::string type = libsumo::Polygon::getType(id);
      const std::vector<Vec2> shape = ToPoints(libsumo::Polygon::getShape(id));
      if (shape.size() < 2) continue;
      const std::string height_text =
          libsumo::Polygon::getParameter(id, "height_m");
      if (type == "adse.parking_slot" && shape.size() >= 4) {
        ParkingSlot slot;
        slot.name = id;
        const Vec2 e1 = shape[1] - shape[0];
        const Vec2 e2 = shape[2] - shape[1];
        // Length along the slot's depth (the longer side).
        const bool first_long = e1.norm() >= e2.norm();
        const Vec2 along = first_long ? e1 : e2;
        slot.box.center = (shape[0] + shape[2]) / 2;
        slot.box.yaw_rad = std::atan2(along.y(), along.x());
        slot.box.length_m = std::max(e1.norm(), e2.norm());
        slot.box.width_m = std::min(e1.norm(), e2.norm());
        slot.box.height_m = 0.0;
        scene.AddParkingSlot(slot);
        continue;
      }
      Obstacle obstacle;
      obstacle.footprint = shape;
      if (obstacle.footprint.size() > 2 &&
          (obstacle.footprint.front() - obstacle.footprint.back()).norm() <
              1e-6) {
        obstacle.footprint.pop_back();  // closed implicitly
      }
      double height =
          height_text.empty() ? 0.0 : std::atof(height_text.c_str());
      if (type == "adse.wall") {
        obstacle.kind = ObstacleKind::kWall;
        if (height <= 0) height = 2.5;
      } else if (type == "adse.pole") {
        obstacle.kind = ObstacleKind::kPole;
        if (height <= 0) height = 5.0;
      } else if (type.rfind("building", 0) == 0 || height > 0) {
        obstacle.kind = ObstacleKind::kBuilding;
        if (height <= 0) height = 10.0;
      } else {
        continue;  // land use, water, ...: nothing a LiDAR sees above ground
      }
      obstacle.z_max_m = height;
      scene.AddObstacle(std::move(obstacle));
      any_static = true;
    }
    if (!any_static) {
      // A bare network: stand lamp poles along the roads (every 20 m, 1 m
      // beyond the outer lane edge) so the LiDAR and the localization map
      // have structure. Poles that would stand on another road are skipped.
      std::vector<std::string> lanes = libsumo::Lane::getIDList();
      std::sort(lanes.begin(), lanes.end());
      struct LaneShape {
        std::vector<Vec2> points;
        double half_width;
      };
      std::vector<LaneShape> shapes;
      // Bucket lane segments in a coarse grid: checking every candidate
      // pole against every lane is quadratic in the size of a city.
      constexpr double kCell = 25.0;
      std::map<std::pair<int, int>, std::vector<std::pair<int, int>>> grid;
      auto cell_of = [&](const Vec2& p) {
        return std::make_pair(static_cast<int>(std::floor(p.x() / kCell)),
                              static_cast<int>(std::floor(p.y() / kCell)));
      };
      for (const std::string& id : lanes) {
        LaneShape shape{ToPoints(libsumo::Lane::getShape(id)),
                        libsumo::Lane::getWidth(id) / 2};
        const int index = static_cast<int>(shapes.size());
        for (size_t k = 0; k + 1 < shape.points.size(); ++k) {
          const Vec2 a = shape.points[k], b = shape.points[k + 1];
          const int steps = 1 + static_cast<int>((b - a).norm() / (kCell / 2));
          std::set<std::pair<int, int>> cells;
          for (int j = 0; j <= steps; ++j)
            cells.insert(cell_of(a + (b - a) * j / steps));
          for (const auto& c : cells)
            grid[c].push_back({index, static_cast<int>(k)});
        }
        shapes.push_back(std::move(shape));
      }
      auto clear_of_roads = [&](const Vec2& p) {
        const auto [cx, cy] = cell_of(p);
        for (int dx = -1; dx <= 1; ++dx) {
          for (int dy = -1; dy <= 1; ++dy) {
            auto it = grid.find({cx + dx, cy + dy});
            if (it == grid.end()) continue;
            for (const auto& [lane, k] : it->second) {
              const Vec2 a = shapes[lane].points[k],
                         b = shapes[lane].points[k + 1];
              const double len2 = (b - a).squaredNorm();
              const double u =
                  len2 > 0 ? std::clamp((p - a).dot(b - a) / len2, 0.0, 1.0)
                           : 0.0;
              if ((a + u * (b - a) - p).norm() < shapes[lane].half_width + 0.5)
                return false;
            }
          }
        }
        return true;
      };
      // The outermost lanes of each normal edge carry its roadsides: the
      // rightmost (index 0) and the leftmost, whose poles stand on the far
      // side of a one-way street (on a two-way road, the other direction's
      // lanes are there, and clear_of_roads skips them). With the right
      // side only, a one-way street left the LiDAR one or two poles in
      // 40 m, too few for NDT (localization lost on sumo-tools' acosta).
      std::map<std::string, int> leftmost;  // edge -> highest lane index
      for (const std::string& id : lanes) {
        if (id[0] == ':') continue;
        const size_t cut = id.rfind('_');
        const int index = std::atoi(id.c_str() + cut + 1);
        int& top = leftmost.try_emplace(id.substr(0, cut), index).first->second;
        top = std::max(top, index);
      }
      for (size_t i = 0; i < lanes.size(); ++i) {
        if (lanes[i][0] == ':') continue;
        const size_t cut = lanes[i].rfind('_');
        const int index = std::atoi(lanes[i].c_str() + cut + 1);
        std::vector<double> sides;  // +1 right, -1 left
        if (index == 0) sides.push_back(1.0);
        if (index == leftmost[lanes[i].substr(0, cut)]) sides.push_back(-1.0);
        if (sides.empty()) continue;
        geometry::Path2 shape;
        shape.points = shapes[i].points;
        shape.UpdateArcLength();
        const double offset = shapes[i].half_width + 1.0;
        for (const double side : sides) {
          for (double s = 10.0; s < shape.length_m() - 5.0; s += 20.0) {
            const double h = shape.HeadingAt(s);
            const Vec2 p = shape.PointAt(s) +
                           side * offset * Vec2(std::sin(h), -std::cos(h));
            if (!clear_of_roads(p)) continue;
            Obstacle pole;
            pole.kind = ObstacleKind::kPole;
            pole.z_max_m = 5.0;
            const double r = 0.15;
            pole.footprint = {p + Vec2(-r, -r), p + Vec2(r, -r), p + Vec2(r, r),
                              p + Vec2(-r, r)};
            scene.AddObstacle(std::move(pole));
          }
        }
      }
    }
  });
}

Status World::Impl::SetUpTraffic() {
  traffic_random = std::make_unique<Random>(
      Random::DeriveSeed(setup.world.traffic.seed, "traffic.flows"));
  const auto& flows_in = setup.world.traffic.flows;
  for (size_t i = 0; i < flows_in.size(); ++i) {
    const Flow& flow = flows_in[i];
    const std::string field = fmt::format("world.traffic.flows[{}]", i);
    try {
      const std::vector<std::string> edges = libsumo::Edge::getIDList();
      for (const std::string* e : {&flow.from_edge, &flow.to_edge}) {
        if (std::find(edges.begin(), edges.end(), *e) == edges.end()) {
          return Status::InvalidArgument(
              fmt::format("{}.{}: no edge '{}' in the network", field,
                          e == &flow.from_edge ? "from" : "to", *e));
        }
      }
      const libsumo::TraCIStage stage =
          libsumo::Simulation::findRoute(flow.from_edge, flow.to_edge);
      if (stage.edges.empty()) {
        return Status::InvalidArgument(
            fmt::format("{}: no route from '{}' to '{}'", field, flow.from_edge,
                        flow.to_edge));
      }
      FlowState state;
      state.route_id = fmt::format("adse_flow_{}", i);
      libsumo::Route::add(state.route_id, stage.edges);
      state.probability_per_step =
          std::min(1.0, flow.vehicles_per_hour / 3600.0 * setup.world.step_s);
      flows.push_back(state);
    } catch (const std::exception& e) {
      return Status::InvalidArgument(field + ": " + e.what());
    }
  }
  return Status::Ok();
}

void World::Impl::PushEgo() {
  const geometry::OrientedBox body = ego->Body();
  const double yaw = ego->state().yaw_rad;
  // SUMO places vehicles by their front bumper.
  const Vec2 front =
      body.center + body.length_m / 2 * Vec2(std::cos(yaw), std::sin(yaw));
  libsumo::Vehicle::moveToXY(kEgoId, "", -1, front.x(), front.y(),
                             YawToSumoAngle(yaw), 2);
}

Status World::Impl::AddEgo() {
  ego = std::make_unique<BicycleModel>(setup.ego);
  VehicleState state;
  state.x_m = ideal.points.front().x();
  state.y_m = ideal.points.front().y();
  state.yaw_rad = ideal.HeadingAt(0.0);
  ego->Reset(state);
  return Guard("adding the ego vehicle", [&] {
    libsumo::VehicleType::copy("DEFAULT_VEHTYPE", "adse_ego");
    libsumo::VehicleType::setLength("adse_ego", setup.ego.length_m);
    libsumo::VehicleType::setWidth("adse_ego", setup.ego.width_m);
    libsumo::VehicleType::setHeight("adse_ego", setup.ego.height_m);
    libsumo::Route::add("adse_ego_route", route);
    libsumo::Vehicle::add(kEgoId, "adse_ego_route", "adse_ego", "now",
                          std::to_string(start.lane), "base", "0", "current",
                          "max");
    // The ego is driven by adse, not by SUMO's car-following model.
    libsumo::Vehicle::setSpeedMode(kEgoId, 0);
    libsumo::Vehicle::setLaneChangeMode(kEgoId, 0);
    PushEgo();
  });
}

Status World::Impl::ReadOthers() {
  return Guard("reading vehicles", [&] {
    others.clear();
    for (const std::string& id : libsumo::Vehicle::getIDList()) {
      if (id == kEgoId) continue;
      auto it = dims.find(id);
      if (it == dims.end()) {
        it = dims.emplace(id, Vec2(libsumo::Vehicle::getLength(id),
                                   libsumo::Vehicle::getWidth(id)))
                 .first;
      }
      const auto p = libsumo::Vehicle::getPosition(id);
      const double yaw = SumoAngleToYaw(libsumo::Vehicle::getAngle(id));
      OtherVehicle v;
      v.id = id;
      v.box.yaw_rad = yaw;
      v.box.length_m = it->second.x();
      v.box.width_m = it->second.y();
      v.box.height_m = 1.5;
      v.box.center = Vec2(p.x, p.y) -
                     v.box.length_m / 2 * Vec2(std::cos(yaw), std::sin(yaw));
      v.speed_mps = libsumo::Vehicle::getSpeed(id);
      others.push_back(v);
    }
  });
}

World::World(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

World::~World() {
  impl_.reset();
  g_world_open = false;
}

Result<std::unique_ptr<World>> World::Open(const WorldSetup& setup) {
  if (setup.world.step_s <= 0) {
    return Status::InvalidArgument("world.step_s: expected a positive step");
  }
  bool expected = false;
  if (!g_world_open.compare_exchange_strong(expected, true)) {
    return Status::Unavailable(
        "a World is already open in this process (libsumo allows one "
        "simulation per process)");
  }
  auto impl = std::make_unique<Impl>();
  // Constructed early so that every early return below releases the flag.
  std::unique_ptr<World> world(new World(nullptr));
  impl->setup = setup;
  const std::string cache_dir =
      setup.cache_dir.empty() ? DefaultCacheDir() : setup.cache_dir;
  Result<MapArtifacts> map = PrepareMap(setup.world.map, cache_dir);
  if (!map.ok()) {
    return map.status().WithContext(setup.world.map.generator.empty()
                                        ? "world.map.net"
                                        : "world.map.generate");
  }
  impl->map = *map;
  ADSE_RETURN_IF_ERROR(impl->StartSumo());
  ADSE_RETURN_IF_ERROR(impl->BuildScene());
  // A valet goal names a slot (or a point in one) and the parked heading;
  // its place for the route is the slot's centre.
  impl->valet = setup.task.kind == TaskKind::kValetParking;
  if (impl->valet) {
    Result<ParkingSlot> slot =
        FindGoalSlot(impl->scene.parking_slots(), setup.task.goal);
    if (!slot.ok()) return slot.status();
    Result<geometry::Pose2> parked =
        ParkedPose(*slot, setup.task.goal, setup.ego);
    if (!parked.ok()) return parked.status();
    impl->goal_slot = *slot;
    impl->parking_goal = *parked;
    impl->setup.task.goal.x_m = slot->box.center.x();
    impl->setup.task.goal.y_m = slot->box.center.y();
  }
  Result<RoadLocation> start =
      impl->Resolve(setup.task.start, "task.start", kOffRoadSlackM);
  if (!start.ok()) return start.status();
  // A valet goal lies in a slot beside the aisle, so it may be further off.
  Result<RoadLocation> goal =
      impl->Resolve(impl->setup.task.goal, "task.goal",
                    impl->valet ? kValetSlackM : kOffRoadSlackM);
  if (!goal.ok()) return goal.status();
  impl->start = *start;
  impl->goal = *goal;
  for (size_t i = 0; i < setup.task.via.size(); ++i) {
    Result<RoadLocation> via = impl->Resolve(
        setup.task.via[i], fmt::format("task.via[{}]", i), kOffRoadSlackM);
    if (!via.ok()) return via.status();
    impl->via.push_back(*via);
  }
  ADSE_RETURN_IF_ERROR(impl->PlanRoute());
  // Parked cars: a seeded share of the slots (never the valet goal's), or
  // exactly the slots the scenario lists.
  Result<Scene> parked =
      WithParkedCars(impl->scene, setup.world.traffic,
                     impl->valet ? impl->goal_slot.name : "");
  if (!parked.ok()) return parked.status();
  impl->scene = std::move(parked).value();
  ADSE_RETURN_IF_ERROR(impl->BuildIdealPath());
  ADSE_RETURN_IF_ERROR(impl->SetUpTraffic());
  ADSE_RETURN_IF_ERROR(impl->AddEgo());
  world->impl_ = std::move(impl);
  return world;
}

Status World::Step(const ControlCommand& command) {
  Impl& w = *impl_;
  const double dt = w.setup.world.step_s;
  w.ego->Step(command, dt);
  return Guard("world step", [&] {
    for (size_t i = 0; i < w.flows.size(); ++i) {
      Impl::FlowState& flow = w.flows[i];
      if (w.traffic_random->Bernoulli(flow.probability_per_step)) {
        libsumo::Vehicle::add(fmt::format("flow{}.{}", i, flow.spawned++),
                              flow.route_id, "DEFAULT_VEHTYPE", "now", "best",
                              "base", "max");
      }
    }
    w.PushEgo();
    libsumo::Simulation::step();
    w.time_s += dt;
    Status read = w.ReadOthers();
    if (!read.ok()) throw std::runtime_error(read.message());
    const geometry::OrientedBox body = w.ego->Body();
    std::set<std::string> contact;
    w.new_contacts.clear();
    for (const OtherVehicle& v : w.others) {
      if (geometry::BoxesOverlap(body, v.box)) {
        contact.insert(v.id);
        if (!w.in_contact.count(v.id)) {
          ++w.collisions;
          w.new_contacts.push_back(v.id);
        }
      }
    }
    w.in_contact = std::move(contact);
  });
}

double World::time_s() const { return impl_->time_s; }
double World::step_s() const { return impl_->setup.world.step_s; }
const VehicleState& World::ego() const { return impl_->ego->state(); }
const VehicleLimits& World::ego_limits() const { return impl_->setup.ego; }
geometry::OrientedBox World::ego_body() const { return impl_->ego->Body(); }
const std::vector<OtherVehicle>& World::others() const { return impl_->others; }
int World::collisions() const { return impl_->collisions; }
const std::vector<std::string>& World::new_contacts() const {
  return impl_->new_contacts;
}
double World::distance_to_goal_m() const {
  const VehicleState& s = impl_->ego->state();
  return (Vec2(s.x_m, s.y_m) - impl_->goal_xy).norm();
}
bool World::goal_reached() const {
  const Impl& w = *impl_;
  if (!w.valet) return distance_to_goal_m() <= w.setup.task.goal_tolerance_m;
  // Parked: standing in the slot, as the tolerances allow. The rear axles'
  // distance equals the bodies' (same heading up to the tolerance).
  return std::abs(w.ego->state().v_mps) < 0.05 &&
         distance_to_goal_m() <= w.setup.task.goal_tolerance_m &&
         goal_yaw_error_rad() <=
             w.setup.task.goal_yaw_tolerance_deg * M_PI / 180.0;
}
bool World::parking_task() const { return impl_->valet; }
const ParkingSlot& World::goal_slot() const { return impl_->goal_slot; }
const geometry::Pose2& World::parking_goal() const {
  return impl_->parking_goal;
}
double World::goal_yaw_error_rad() const {
  if (!impl_->valet) return 0.0;
  return std::abs(std::remainder(
      impl_->ego->state().yaw_rad - impl_->parking_goal.yaw_rad, 2 * M_PI));
}
const geometry::Path2& World::road_path() const { return impl_->road; }
const std::vector<ManoeuvrePose>& World::reference_manoeuvre() const {
  return impl_->reference;
}
const geometry::Path2& World::ideal_path() const { return impl_->ideal; }
const std::vector<std::string>& World::route_edges() const {
  return impl_->route;
}
double World::ideal_path_max_join_gap_m() const {
  return impl_->max_join_gap_m;
}
double World::lane_width_m() const { return impl_->lane_width_m; }
const RoadLocation& World::start() const { return impl_->start; }
const RoadLocation& World::goal() const { return impl_->goal; }
const Scene& World::scene() const { return impl_->scene; }
const MapArtifacts& World::map() const { return impl_->map; }

std::vector<std::vector<Eigen::Vector2d>> World::LaneShapes() const {
  std::vector<std::vector<Eigen::Vector2d>> out;
  try {
    std::vector<std::string> lanes = libsumo::Lane::getIDList();
    std::sort(lanes.begin(), lanes.end());
    for (const std::string& id : lanes)
      out.push_back(ToPoints(libsumo::Lane::getShape(id)));
  } catch (const std::exception&) {
  }
  return out;
}

Result<std::string> World::MapCloudPath() const {
  const Impl& w = *impl_;
  MapCloudOptions options;
  ContentHasher hasher;
  // v2: bare networks' roadside poles also on the left of one-way streets
  // (a cloud cached before would miss them).
  hasher.Add("adse-cloud-v2")
      .Add(w.map.key)
      .Add(static_cast<long long>(w.setup.world.traffic.seed))
      .Add(w.setup.world.traffic.parked_occupancy)
      .Add(options.spacing_m)
      .Add(options.ground_spacing_m)
      .Add(options.ground_margin_m);
  const std::string path =
      w.map.cache_folder + "/cloud-" + hasher.Hex().substr(0, 16) + ".pcd";
  std::error_code ec;
  if (fs::exists(path, ec)) return path;
  ADSE_RETURN_IF_ERROR(WritePcd(path, SampleSceneSurface(w.scene, options)));
  return path;
}

}  // namespace adse::world
