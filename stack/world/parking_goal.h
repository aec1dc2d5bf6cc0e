// The valet task's side of the world: which slot the goal names, the pose
// the car parks in, which slots hold parked cars, and the outlines a
// parking planner avoids. Errors start with the scenario field they
// concern. Eigen and std types only.
#ifndef ADSE_STACK_WORLD_PARKING_GOAL_H_
#define ADSE_STACK_WORLD_PARKING_GOAL_H_

#include <string>
#include <vector>

#include "stack/base/status.h"
#include "stack/geometry/geometry.h"
#include "stack/world/scene.h"
#include "stack/world/vehicle_model.h"
#include "stack/world/world_options.h"

namespace adse::world {

// The slot a valet goal names: {slot: name} or {x, y} inside it.
Result<ParkingSlot> FindGoalSlot(const std::vector<ParkingSlot>& slots,
                                 const Location& goal);

// The rear-axle pose of `car` parked in `slot` with the goal's heading, its
// body centred in the slot. The heading must run along the slot's axis
// (into it or out of it, within 20 degrees).
Result<geometry::Pose2> ParkedPose(const ParkingSlot& slot,
                                   const Location& goal,
                                   const VehicleLimits& car);

// `scene` with parked cars: in exactly traffic.parked_slots when that is
// given (a name the map lacks, or the goal's slot, is an error), else in a
// seeded share parked_occupancy of the slots, never `goal_slot` (empty:
// none is spared).
Result<Scene> WithParkedCars(const Scene& scene, const TrafficOptions& traffic,
                             const std::string& goal_slot);

// Footprints of the walls, poles, buildings and parked cars: what the car's
// map of the lot holds and a parking planner must keep clear of.
std::vector<std::vector<Eigen::Vector2d>> ObstacleOutlines(const Scene& scene);

}  // namespace adse::world

#endif  // ADSE_STACK_WORLD_PARKING_GOAL_H_
