// World itself (with world_route.cc, world_signals.cc and world_traffic.cc
// the only places adse talks to libsumo). libsumo reports errors as
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
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <set>

#include "stack/algorithms/freespace_planner.h"
#include "stack/algorithms/planning.h"
#include "stack/base/files.h"
#include "stack/base/hash.h"
#include "stack/base/random.h"
#include "stack/world/internal/world_impl.h"
#include "stack/world/map_cloud.h"
#include "stack/world/parking_goal.h"
#include "stack/world/roadside_poles.h"

namespace adse::world {
namespace {

namespace fs = std::filesystem;
using internal::kEgoId;
using internal::kOffRoadSlackM;
using internal::ToPoints;
using internal::Vec2;
using internal::YawToSumoAngle;

std::atomic<bool> g_world_open{false};

// A car within the goal's tolerance projects at most that far before the
// route's end; this much more for the projection on a bend.
constexpr double kGoalSlackM = 1.0;
constexpr double kValetSlackM = 8.0;
// A car within this of a three-point turn's end pose, or of the lane on
// from it up to kTurnedAheadM past it (and 0.5 rad of its heading), has
// turned: a little looser than the stack's own test (1 m, 5 m, 0.35 rad),
// which judges by its pose estimate. Not much looser: drivers are let on
// once the car has turned, and with 2 m they came up behind a car the
// stack had not yet turned (1.4 m off the lane's centre line) and held
// its last move until the stall timeout.
constexpr double kTurnedSlackM = 1.25;
constexpr double kTurnedAheadM = 8.0;
constexpr double kTurnedYawRad = 0.5;
// From this far before a turn's start its manoeuvre may be under way (the
// stack hands a turn to its freespace planner within 3 m of it).
constexpr double kTurnBeginsM = 5.0;

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

// Starts SUMO with `args`. SUMO prints the cause of a load failure to
// stderr and throws a bare "Process Error": stderr is captured while it
// starts (into a file in `folder`) and its text returned as `*cause`.
Status StartCapturingCause(const std::vector<std::string>& args,
                           const std::string& folder, std::string* cause) {
  const std::string log = folder + "/sumo-stderr." +
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
  cause->clear();
  if (Result<std::string> text = ReadFile(log, 1 << 20); text.ok())
    *cause = *text;
  std::error_code ec;
  fs::remove(log, ec);
  while (!cause->empty() &&
         std::isspace(static_cast<unsigned char>(cause->back()))) {
    cause->pop_back();
  }
  if (cause->empty() && !status.ok()) *cause = status.message();
  return status;
}

}  // namespace

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
  const std::vector<std::string> net_only = args;
  if (!map.polygons_path.empty()) {
    args.push_back("--additional-files");
    args.push_back(map.polygons_path);
  }
  if (std::getenv("SUMO_HOME") == nullptr) {
    ::setenv("SUMO_HOME", "/usr/share/sumo", 0);
  }
  std::string cause;
  if (!StartCapturingCause(args, map.cache_folder, &cause).ok()) {
    // Which file SUMO could not load: the network alone, tried again,
    // says whether it is the polygons'.
    std::string net_cause;
    if (!map.polygons_path.empty() &&
        StartCapturingCause(net_only, map.cache_folder, &net_cause).ok()) {
      (void)Guard("closing SUMO", [] { libsumo::Simulation::close(); });
      return Status::InvalidArgument(
          fmt::format("world.map.polygons: SUMO cannot load '{}': {}",
                      map.polygons_path, cause));
    }
    return Status::InvalidArgument(fmt::format(
        "world.map.net: SUMO cannot load '{}': {}", map.net_path, cause));
  }
  sumo_running = true;
  return Status::Ok();
}

Status World::Impl::BuildScene() {
  // A polygon adse cannot read is an error naming it, not an obstacle
  // dropped or given a default height.
  Status unreadable;
  auto refuse = [&](const std::string& id, const std::string& type,
                    const std::string& expected, const std::string& found) {
    unreadable = Status::InvalidArgument(fmt::format(
        "world.map.polygons: {}: polygon '{}' (type '{}'): expected {}, "
        "found {}",
        map.polygons_path.empty() ? "the map's polygons" : map.polygons_path,
        id, type, expected, found));
  };
  Status built = Guard("building the scene", [&] {
    std::vector<std::string> polygon_ids = libsumo::Polygon::getIDList();
    std::sort(polygon_ids.begin(), polygon_ids.end());
    bool any_static = false;
    for (const std::string& id : polygon_ids) {
      const std::string type = libsumo::Polygon::getType(id);
      const std::vector<Vec2> shape = ToPoints(libsumo::Polygon::getShape(id));
      if (shape.size() < 2) continue;
      const std::string height_text =
          libsumo::Polygon::getParameter(id, "height_m");
      double height = 0.0;
      if (!height_text.empty()) {
        const char* end = height_text.data() + height_text.size();
        const auto [ptr, ec] = std::from_chars(height_text.data(), end, height);
        if (ec != std::errc() || ptr != end || !std::isfinite(height) ||
            height < 0.0) {
          refuse(id, type, "height_m as a number of metres >= 0",
                 "'" + height_text + "'");
          return;
        }
      }
      if (type == "adse.parking_slot" && shape.size() < 4) {
        refuse(id, type, "a slot of 4 corners",
               fmt::format("{} points", shape.size()));
        return;
      }
      if (type == "adse.parking_slot") {
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
      std::vector<std::string> ids = libsumo::Lane::getIDList();
      std::sort(ids.begin(), ids.end());
      std::vector<LaneGeometry> lanes;
      lanes.reserve(ids.size());
      for (const std::string& id : ids) {
        lanes.push_back({id, ToPoints(libsumo::Lane::getShape(id)),
                         libsumo::Lane::getWidth(id) / 2});
      }
      for (Obstacle& pole : RoadsidePoles(lanes)) {
        scene.AddObstacle(std::move(pole));
      }
    }
  });
  return unreadable.ok() ? built : unreadable;
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
  for (const Obstacle& o : impl->scene.obstacles()) {
    Vec2 centre = Vec2::Zero();
    for (const Vec2& p : o.footprint) centre += p;
    if (!o.footprint.empty()) centre /= static_cast<double>(o.footprint.size());
    double radius = 0.0;
    for (const Vec2& p : o.footprint) {
      radius = std::max(radius, (p - centre).norm());
    }
    impl->structure_bounds.emplace_back(centre, radius);
  }
  ADSE_RETURN_IF_ERROR(impl->BuildIdealPath());
  // A goal within its tolerance of the start leaves nothing to drive:
  // every design would "arrive" at once.
  const double tolerance_m = impl->setup.task.goal_tolerance_m;
  if (impl->ideal.length_m() <= tolerance_m) {
    return Status::InvalidArgument(fmt::format(
        "task.goal: expected a goal farther along the road from the start "
        "than its tolerance_m ({:g} m), found one {:.2f} m from it",
        tolerance_m, impl->ideal.length_m()));
  }
  ADSE_RETURN_IF_ERROR(impl->FindRouteSignals());
  ADSE_RETURN_IF_ERROR(impl->PlanTurnarounds());
  ADSE_RETURN_IF_ERROR(impl->FindSwitchedSignals());
  ADSE_RETURN_IF_ERROR(impl->SetUpTraffic());
  ADSE_RETURN_IF_ERROR(impl->AddEgo());
  impl->UpdateProgress();
  world->impl_ = std::move(impl);
  return world;
}

Status World::Step(const ControlCommand& command) {
  Impl& w = *impl_;
  const double dt = w.setup.world.step_s;
  w.ego->Step(command, dt);
  w.UpdateProgress();
  return Guard("world step", [&] {
    w.InsertFlows();
    w.PushEgo();
    w.YieldToEgo();
    w.SwitchSignalPrograms();
    libsumo::Simulation::step();
    w.time_s += dt;
    w.ReadOthers();
    const geometry::OrientedBox body = w.ego->Body();
    std::set<std::string> contact;
    w.new_contacts.clear();
    auto touch = [&](Contact c) {
      contact.insert(c.id);
      if (w.in_contact.count(c.id)) return;
      ++w.collisions;
      w.new_contacts.push_back(std::move(c));
    };
    for (const OtherVehicle& v : w.others) {
      if (geometry::BoxesOverlap(body, v.box)) {
        touch(
            {v.id, false,
             EgoCausedContact(w.ego->state(), w.ego->yaw_rate_rps(), body, v)});
      }
    }
    const double reach_m = 0.5 * std::hypot(body.length_m, body.width_m);
    const std::vector<Obstacle>& structure = w.scene.obstacles();
    for (size_t i = 0; i < structure.size(); ++i) {
      const auto& [centre, radius] = w.structure_bounds[i];
      if ((centre - body.center).norm() > radius + reach_m) continue;
      if (geometry::BoxTouchesOutline(body, structure[i].footprint)) {
        touch({fmt::format("{} {}", ObstacleKindToString(structure[i].kind), i),
               true, true});
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
const std::vector<Contact>& World::new_contacts() const {
  return impl_->new_contacts;
}
double World::distance_to_goal_m() const {
  const VehicleState& s = impl_->ego->state();
  return (Vec2(s.x_m, s.y_m) - impl_->goal_xy).norm();
}
bool EgoCausedContact(const VehicleState& ego, double ego_yaw_rate_rps,
                      const geometry::OrientedBox& ego_body,
                      const OtherVehicle& other) {
  const geometry::BoxContact contact =
      geometry::ContactOfBoxes(ego_body, other.box);
  // A rigid body's velocity at `p`: its reference point's, plus its
  // turning about that point.
  auto velocity_at = [&](const Vec2& reference, double speed_mps,
                         double yaw_rad, double yaw_rate_rps) {
    const Vec2 r = contact.point - reference;
    return Vec2(speed_mps * std::cos(yaw_rad) - yaw_rate_rps * r.y(),
                speed_mps * std::sin(yaw_rad) + yaw_rate_rps * r.x());
  };
  const Vec2 ego_v = velocity_at(Vec2(ego.x_m, ego.y_m), ego.v_mps, ego.yaw_rad,
                                 ego_yaw_rate_rps);
  const Vec2 heading(std::cos(other.box.yaw_rad), std::sin(other.box.yaw_rad));
  const Vec2 other_v =
      velocity_at(other.box.center + 0.5 * other.box.length_m * heading,
                  other.speed_mps, other.box.yaw_rad, other.yaw_rate_rps);
  return ego_v.dot(contact.normal) >= other_v.dot(-contact.normal);
}

void World::Impl::UpdateProgress() {
  const VehicleState& s = ego->state();
  const algorithms::PathPlannerParams window;
  // Turned round in a three-point turn, standing on the lane it leaves
  // on: the progress resumes there (the turn itself is off the road part).
  // Until then the car's moves do not take the progress past the turn's
  // end: a move backing it onto the lane it turns onto, still facing the
  // other way, would end the turn for the drivers about it, who would come
  // on into the space of its next move.
  double turn_end_s = INFINITY;
  const geometry::Pose2 pose{s.x_m, s.y_m, s.yaw_rad};
  for (const RouteTurnaround& turn : turnarounds) {
    if (road_progress_m < turn.start_s_m - kTurnBeginsM ||
        road_progress_m >= turn.end_s_m) {
      continue;
    }
    if (geometry::WithinToleranceOrAhead(pose, turn.goal, kTurnedSlackM,
                                         kTurnedAheadM, kTurnedYawRad)) {
      road_progress_m = turn.end_s_m;
    } else {
      turn_end_s = std::min(turn_end_s, turn.end_s_m);
    }
  }
  double lateral = 0.0;
  const double projected = algorithms::ProjectOnPath(
      road, Vec2(s.x_m, s.y_m), road_progress_m - window.projection_back_m,
      road_progress_m + window.projection_ahead_m, road_progress_m, &lateral,
      &road_offset_m);
  road_progress_m =
      std::max(road_progress_m, std::min(projected, turn_end_s - 1e-3));
}

bool World::goal_reached() const {
  const Impl& w = *impl_;
  if (!w.valet) {
    // Near the goal at the end of the route, not where the route passes
    // the goal earlier on the other side of the street.
    const double tolerance = w.setup.task.goal_tolerance_m;
    return distance_to_goal_m() <= tolerance &&
           w.road_progress_m >= w.road.length_m() - tolerance - kGoalSlackM;
  }
  // Parked: standing in the slot, as the tolerances allow. The rear axles'
  // distance equals the bodies' (same heading up to the tolerance).
  const VehicleState& s = w.ego->state();
  return std::abs(s.v_mps) < 0.05 &&
         geometry::WithinTolerance(
             {s.x_m, s.y_m, s.yaw_rad}, w.parking_goal,
             w.setup.task.goal_tolerance_m,
             w.setup.task.goal_yaw_tolerance_deg * M_PI / 180.0);
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
double World::road_progress_m() const { return impl_->road_progress_m; }
double World::road_offset_m() const { return impl_->road_offset_m; }
const std::vector<RouteTurnaround>& World::route_turnarounds() const {
  return impl_->turnarounds;
}
const std::vector<algorithms::GearedPose>& World::reference_manoeuvre() const {
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
  options.corridor = w.ideal.points;
  ContentHasher hasher;
  // v2: bare networks' roadside poles also on the left of one-way streets
  // (a cloud cached before would miss them). v3: only the route's corridor.
  hasher.Add("adse-cloud-v3")
      .Add(w.map.key)
      .Add(static_cast<long long>(w.setup.world.traffic.seed))
      .Add(w.setup.world.traffic.parked_occupancy)
      .Add(options.spacing_m)
      .Add(options.ground_spacing_m)
      .Add(options.ground_margin_m)
      .Add(options.corridor_half_width_m);
  for (const Eigen::Vector2d& p : options.corridor)
    hasher.Add(p.x()).Add(p.y());
  const std::string path =
      w.map.cache_folder + "/cloud-" + hasher.Hex().substr(0, 16) + ".pcd";
  std::error_code ec;
  if (fs::exists(path, ec)) return path;
  ADSE_RETURN_IF_ERROR(WritePcd(path, SampleSceneSurface(w.scene, options)));
  return path;
}

}  // namespace adse::world
