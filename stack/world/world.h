// The simulated world of one run: SUMO (via libsumo, hidden in world.cc)
// with its traffic, the ego vehicle on a kinematic bicycle model, the static
// scene and the ideal path. libsumo allows one simulation per process, so a
// process holds at most one open World.
#ifndef ADSE_STACK_WORLD_WORLD_H_
#define ADSE_STACK_WORLD_WORLD_H_

#include <memory>
#include <string>
#include <vector>

#include "stack/algorithms/lane_change.h"
#include "stack/algorithms/reeds_shepp.h"
#include "stack/algorithms/turnaround_section.h"
#include "stack/base/status.h"
#include "stack/geometry/geometry.h"
#include "stack/world/map_builder.h"
#include "stack/world/scene.h"
#include "stack/world/vehicle_model.h"
#include "stack/world/world_options.h"

namespace adse::world {

struct WorldSetup {
  WorldOptions world;
  TaskOptions task;
  VehicleLimits ego;
  // Root of the cache of generated maps and map clouds.
  std::string cache_dir;
};

// A location snapped to the road network.
struct RoadLocation {
  std::string edge;
  int lane = 0;
  double pos_m = 0.0;
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  // on the lane centre
};

struct OtherVehicle {
  std::string id;
  geometry::OrientedBox box;  // SUMO places it by its front bumper
  double speed_mps = 0.0;
  double yaw_rate_rps = 0.0;  // since the step before (0 on its first)
};

// Whether the ego caused its contact with `other`. At the point where the
// two bodies meet, across the face one came through (the separating axis
// of least overlap), the ego's body moved towards the other at least as
// fast as the other's moved towards it. Each body's velocity there counts
// its turning: the ego's about its rear axle (`ego_yaw_rate_rps`), the
// other's about its front bumper. A car standing or braking that is
// driven into from behind or the side did not cause it, nor one whose
// side a car cutting in sweeps with its swinging rear; one that drives
// into a slower car, or swings its own corner into a car beside it, did.
bool EgoCausedContact(const VehicleState& ego, double ego_yaw_rate_rps,
                      const geometry::OrientedBox& ego_body,
                      const OtherVehicle& other);

// A contact of the ego's body that began in the last step: with another
// vehicle (its SUMO id) or with the scene's structure ("pole 12": the
// obstacle's kind and index), which the ego always causes.
struct Contact {
  std::string id;
  bool structure = false;
  bool ego_caused = true;  // see EgoCausedContact
};

// A link the route takes through a signalised junction: the traffic light
// that controls it and the stop line at the end of the route's lane.
struct RouteSignal {
  std::string tls_id;
  int link_index = 0;          // the link's letter in the signal's state
  double stop_line_s_m = 0.0;  // along road_path()
};

// Where a lane-driving route turns around tighter than the car can and no
// way round the block leads on (s along road_path()), with the manoeuvre
// planned on the ground truth from the road part at start_s_m to `goal`.
struct RouteTurnaround : algorithms::TurnaroundSection {
  std::vector<algorithms::GearedPose> reference;  // rear axle poses
  // No manoeuvre fitted in the lanes and junctions: `drivable` reaches
  // past their edges onto the road's shoulders.
  bool on_shoulders = false;
};

// The moves of a manoeuvre: its runs in one gear (a three-point turn has 3).
int ManoeuvreMoves(const std::vector<algorithms::GearedPose>& manoeuvre);

// Errors from Open() start with the scenario field they concern
// ("task.goal: ...", "world.map.net: ...") so callers can cite its line.
class World {
 public:
  static Result<std::unique_ptr<World>> Open(const WorldSetup& setup);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  // Advances SUMO and the ego by one step under `command`.
  Status Step(const ControlCommand& command);

  double time_s() const;
  double step_s() const;
  const VehicleState& ego() const;
  const VehicleLimits& ego_limits() const;
  geometry::OrientedBox ego_body() const;
  // Other vehicles as of the last step.
  const std::vector<OtherVehicle>& others() const;
  // Collision events so far (ego overlapping another vehicle or the
  // scene's structure: a pole, a wall, a building, a parked car; counted
  // once per contact).
  int collisions() const;
  // The contacts that began in the last step.
  const std::vector<Contact>& new_contacts() const;
  // Lane driving: within goal_tolerance_m of the goal, at the end of the
  // route (see road_progress_m). valet_parking:
  // parked, i.e. standing with the body's centre within goal_tolerance_m of
  // the slot's and the heading within goal_yaw_tolerance_deg.
  bool goal_reached() const;
  double distance_to_goal_m() const;

  // valet_parking only: the goal's slot, the rear-axle pose parked in it,
  // the heading error now and the road part of the route (for lane
  // driving the whole route, through its U-turns as SUMO draws them),
  // which ends on the aisle beside the slot.
  bool parking_task() const;
  const ParkingSlot& goal_slot() const;
  const geometry::Pose2& parking_goal() const;
  double goal_yaw_error_rad() const;
  const geometry::Path2& road_path() const;
  // How far along the road part the ego has come (its projection, searched
  // near the progress so far, so a route that passes itself does not jump
  // ahead) and its distance from the road part there.
  double road_progress_m() const;
  double road_offset_m() const;
  // The reference manoeuvre from the road part's end into the slot (the
  // ideal path's last part), planned on the ground truth; empty when the
  // planner found none or for lane driving.
  const std::vector<algorithms::GearedPose>& reference_manoeuvre() const;

  // The signalised links along the road part, in route order (empty on
  // maps without traffic lights), and SUMO's state letter of each now
  // ('r', 'y', 'G', 'g', 'u', 'o', 's', ...), in the same order.
  const std::vector<RouteSignal>& route_signals() const;
  std::string RouteSignalStates() const;
  // The three-point turns along the road part, in route order.
  const std::vector<RouteTurnaround>& route_turnarounds() const;
  // Where the road part changes lane, in route order (along road_path()).
  const std::vector<algorithms::LaneChangeSection>& route_lane_changes() const;

  // The path a perfect driver takes: the road part, with each three-point
  // turn's stretch replaced by its manoeuvre and, for valet parking, the
  // manoeuvre into the slot after it.
  const geometry::Path2& ideal_path() const;
  const std::vector<std::string>& route_edges() const;
  // Largest gap between consecutive lane pieces (lanes and junction lanes)
  // joined into the ideal path, before resampling: a continuity check.
  double ideal_path_max_join_gap_m() const;
  // Mean lane width along the ideal path.
  double lane_width_m() const;
  const RoadLocation& start() const;
  const RoadLocation& goal() const;
  const Scene& scene() const;
  const MapArtifacts& map() const;
  // Lane centrelines of the whole network (for pictures).
  std::vector<std::vector<Eigen::Vector2d>> LaneShapes() const;

  // Path of the localization map cloud (PCD), built once per map, occupancy
  // and seed and cached next to the map.
  Result<std::string> MapCloudPath() const;

 private:
  struct Impl;
  explicit World(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace adse::world

#endif  // ADSE_STACK_WORLD_WORLD_H_
