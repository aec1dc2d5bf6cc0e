#include "stack/world/parking_goal.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <set>

#include "stack/base/random.h"

namespace adse::world {
namespace {

using Vec2 = Eigen::Vector2d;

bool Contains(const ParkingSlot& slot, const Vec2& p) {
  const Vec2 local =
      Eigen::Rotation2Dd(-slot.box.yaw_rad) * (p - slot.box.center);
  return std::abs(local.x()) <= slot.box.length_m / 2 &&
         std::abs(local.y()) <= slot.box.width_m / 2;
}

// A few slot names for an error message.
std::string SomeNames(const std::vector<ParkingSlot>& slots) {
  std::string out;
  for (size_t i = 0; i < slots.size() && i < 4; ++i) {
    out += (i ? ", " : "") + slots[i].name;
  }
  if (slots.size() > 4) out += fmt::format(", ... ({} in all)", slots.size());
  return out.empty() ? "none" : out;
}

}  // namespace

Result<ParkingSlot> FindGoalSlot(const std::vector<ParkingSlot>& slots,
                                 const Location& goal) {
  if (!goal.slot.empty()) {
    for (const ParkingSlot& s : slots) {
      if (s.name == goal.slot) return s;
    }
    return Status::InvalidArgument(
        fmt::format("task.goal.slot: the map has no parking slot '{}' (its "
                    "slots: {})",
                    goal.slot, SomeNames(slots)));
  }
  if (goal.by_edge) {
    return Status::InvalidArgument(
        "task.goal: valet_parking needs the goal as {slot} or {x, y} inside "
        "a slot");
  }
  const Vec2 target(goal.x_m, goal.y_m);
  for (const ParkingSlot& s : slots) {
    if (Contains(s, target)) return s;
  }
  return Status::InvalidArgument(
      fmt::format("task.goal: ({}, {}) is in no parking slot of the map",
                  goal.x_m, goal.y_m));
}

Result<geometry::Pose2> ParkedPose(const ParkingSlot& slot,
                                   const Location& goal,
                                   const VehicleLimits& car) {
  if (!goal.has_yaw) {
    return Status::InvalidArgument(fmt::format(
        "task.goal.yaw_deg: valet_parking needs the heading the car parks "
        "with; slot '{}' runs at {:.0f} or {:.0f} degrees",
        slot.name, slot.box.yaw_rad * 180 / M_PI,
        std::remainder(slot.box.yaw_rad + M_PI, 2 * M_PI) * 180 / M_PI));
  }
  const double yaw = goal.yaw_deg * M_PI / 180.0;
  // Along the axis either way: the difference modulo a half turn is small.
  const double off = std::abs(std::remainder(yaw - slot.box.yaw_rad, M_PI));
  if (off > 20.0 * M_PI / 180.0) {
    return Status::InvalidArgument(fmt::format(
        "task.goal.yaw_deg: {} is across slot '{}', which runs at {:.0f} or "
        "{:.0f} degrees",
        goal.yaw_deg, slot.name, slot.box.yaw_rad * 180 / M_PI,
        std::remainder(slot.box.yaw_rad + M_PI, 2 * M_PI) * 180 / M_PI));
  }
  // The body's centre is half a wheelbase ahead of the rear axle.
  const double half_wb = 0.5 * car.wheelbase_m;
  return geometry::Pose2{slot.box.center.x() - half_wb * std::cos(yaw),
                         slot.box.center.y() - half_wb * std::sin(yaw),
                         std::remainder(yaw, 2 * M_PI)};
}

Result<Scene> WithParkedCars(const Scene& scene, const TrafficOptions& traffic,
                             const std::string& goal_slot) {
  std::set<std::string> listed;
  for (size_t i = 0; i < traffic.parked_slots.size(); ++i) {
    const std::string& name = traffic.parked_slots[i];
    const bool known =
        std::any_of(scene.parking_slots().begin(), scene.parking_slots().end(),
                    [&](const ParkingSlot& s) { return s.name == name; });
    if (!known) {
      return Status::InvalidArgument(fmt::format(
          "world.traffic.parked_slots[{}]: the map has no parking slot '{}'", i,
          name));
    }
    if (name == goal_slot) {
      return Status::InvalidArgument(fmt::format(
          "task.goal.slot: slot '{}' is occupied (world.traffic.parked_slots "
          "lists it); a valet goal needs a free slot",
          name));
    }
    listed.insert(name);
  }
  Random random(Random::DeriveSeed(traffic.seed, "traffic.parked"));
  Scene out;
  for (const Obstacle& o : scene.obstacles()) out.AddObstacle(o);
  for (ParkingSlot slot : scene.parking_slots()) {
    // The draws are made for every slot, so a listed layout or a spared
    // goal leaves the other slots' cars where they were.
    const bool draw = random.Bernoulli(traffic.parked_occupancy);
    const double jitter_x = random.Uniform(-0.15, 0.15);
    const double jitter_y = random.Uniform(-0.15, 0.15);
    const double jitter_yaw = random.Uniform(-0.05, 0.05);
    const bool parked = traffic.parked_slots.empty()
                            ? draw && slot.name != goal_slot
                            : listed.count(slot.name) > 0;
    if (parked) {
      slot.occupied = true;
      geometry::OrientedBox car;
      car.center = slot.box.center + Vec2(jitter_x, jitter_y);
      car.yaw_rad = slot.box.yaw_rad + jitter_yaw;
      car.length_m = std::min(4.5, slot.box.length_m - 0.4);
      car.width_m = std::min(1.8, slot.box.width_m - 0.4);
      car.height_m = 1.5;
      Obstacle obstacle;
      obstacle.kind = ObstacleKind::kParkedCar;
      obstacle.footprint = geometry::BoxCorners(car);
      obstacle.z_max_m = car.height_m;
      out.AddObstacle(std::move(obstacle));
    }
    out.AddParkingSlot(slot);
  }
  out.Finalize();
  return out;
}

std::vector<std::vector<Eigen::Vector2d>> ObstacleOutlines(const Scene& scene) {
  std::vector<std::vector<Eigen::Vector2d>> out;
  out.reserve(scene.obstacles().size());
  for (const Obstacle& o : scene.obstacles()) out.push_back(o.footprint);
  return out;
}

}  // namespace adse::world
