// Internal to stack/world: the state behind World and the helpers its
// files share. Holds libsumo types, hence _impl.h.
#ifndef ADSE_STACK_WORLD_INTERNAL_WORLD_IMPL_H_
#define ADSE_STACK_WORLD_INTERNAL_WORLD_IMPL_H_

#include <libsumo/libsumo.h>

#include <Eigen/Core>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "stack/base/random.h"
#include "stack/base/status.h"
#include "stack/geometry/geometry.h"
#include "stack/world/scene.h"
#include "stack/world/vehicle_model.h"
#include "stack/world/world.h"

namespace adse::algorithms {
class FreespacePlanner;
}  // namespace adse::algorithms

namespace adse::world {
namespace internal {

using Vec2 = Eigen::Vector2d;

// The ego's vehicle id in SUMO.
inline constexpr char kEgoId[] = "ego";
// How far a start/goal may lie from a lane centre, beyond half its width.
inline constexpr double kOffRoadSlackM = 1.5;

// SUMO's angles are compass degrees (0 north, clockwise).
inline double SumoAngleToYaw(double angle_deg) {
  return (90.0 - angle_deg) * M_PI / 180.0;
}
inline double YawToSumoAngle(double yaw_rad) {
  const double a = std::fmod(90.0 - yaw_rad * 180.0 / M_PI, 360.0);
  return a < 0 ? a + 360.0 : a;
}

// Spacing of the ideal path's points.
inline constexpr double kResampleStepM = 0.5;

inline std::vector<Vec2> ToPoints(const libsumo::TraCIPositionVector& shape) {
  std::vector<Vec2> out;
  out.reserve(shape.value.size());
  for (const auto& p : shape.value) out.emplace_back(p.x, p.y);
  return out;
}

// The internal (junction) lanes a connection drives through, starting at
// its `via` lane; `arrives_on` gets the normal lane it ends on.
std::vector<std::string> InternalChain(const std::string& via,
                                       std::string* arrives_on);

// How far across the road a U-turn from `from_lane` to `to_lane` must
// turn: the arrival lane's start off the departure lane's end, square to
// its last heading.
double UTurnWidthM(const std::string& from_lane, const std::string& to_lane);

// Whether passenger cars may use the lane (not a sidewalk, bus lane, ...).
bool OpenToCars(const std::string& lane_id);

// Part of `shape` between arc lengths s0 and s1.
std::vector<Vec2> Slice(const std::vector<Vec2>& shape, double s0, double s1);

// SUMO's position `pos_m` along a lane as arc length along its `shape`. A
// lane's length (SUMO's positions) may differ from its shape's: a lane
// of an edge with its own length (grid6's are 80 m on 94-112 m shapes),
// the inner lane of a bend (all lanes of an edge share the edge's
// length). SUMO scales positions onto the shape; so does this, where the
// two differ by more than SUMO's rounding of both to 0.01 m.
double ShapeS(const std::vector<Vec2>& shape, double lane_length_m,
              double pos_m);

// `points` without repeats, resampled every `step` metres.
geometry::Path2 Resample(const std::vector<Vec2>& points, double step);

}  // namespace internal

struct World::Impl {
  WorldSetup setup;
  MapArtifacts map;
  RoadLocation start, goal;
  std::vector<RoadLocation> via;  // task.via, resolved
  Eigen::Vector2d goal_xy =
      Eigen::Vector2d::Zero();  // final target (rear axle when valet)
  bool valet = false;
  ParkingSlot goal_slot;         // valet: the slot parked in
  geometry::Pose2 parking_goal;  // valet: rear axle parked
  geometry::Path2 road;          // the route's road part
  // valet: the reference manoeuvre
  std::vector<algorithms::GearedPose> reference;
  std::vector<std::string> route;
  // Where the road part leaves each route edge but the last for the next:
  // the lane it leaves, the connection's first internal lane (empty on
  // nets without them), the lane it arrives on, and the arc length of the
  // joined lane pieces there (before resampling).
  struct Crossing {
    std::string from_lane, via_lane, to_lane;
    double raw_s_m = 0.0;
    // A U-turn narrower than the car's turning circle: a three-point turn.
    bool tight_uturn = false;
  };
  std::vector<Crossing> crossings;
  double raw_length_m = 0.0;  // of the joined lane pieces of the road part
  // Where the road part changes lane (route s of the road part).
  std::vector<algorithms::LaneChangeSection> lane_changes;
  std::vector<RouteSignal> signals;  // the crossings a traffic light controls
  // Signals switched from program to program as a player would
  // (traffic.signal_program_switch_s), in the net's order of programs.
  struct SwitchedSignal {
    std::string id;
    std::vector<std::string> programs;
    size_t current = 0;
  };
  std::vector<SwitchedSignal> switched_signals;
  double next_program_switch_s = 0.0;
  std::vector<RouteTurnaround> turnarounds;  // the tight U-turns' manoeuvres
  geometry::Path2 ideal;
  // The ego on the road part: arc length reached so far and its distance
  // from the road part there (UpdateProgress).
  double road_progress_m = 0.0;
  double road_offset_m = 0.0;
  double lane_width_m = 3.2;
  double max_join_gap_m = 0.0;
  Scene scene;
  std::unique_ptr<BicycleModel> ego;
  std::vector<OtherVehicle> others;
  // Per obstacle of the scene: the centre and radius of a circle round
  // its outline, to skip the far ones in the contact test.
  std::vector<std::pair<Eigen::Vector2d, double>> structure_bounds;
  std::set<std::string> in_contact;
  std::vector<Contact> new_contacts;
  int collisions = 0;
  double time_s = 0.0;
  bool sumo_running = false;

  struct FlowState {
    std::string route_id;
    std::vector<std::string> depart_lanes;  // the lanes of its first edge
    double probability_per_step = 0.0;
    int spawned = 0;
    int pending = 0;  // drawn, waiting for the ego to clear the way in
  };
  std::vector<FlowState> flows;
  std::set<std::string> held_still;  // traffic.stopped_vehicles
  std::set<std::string> yielding;    // cars told to slow for the ego
  // Drivers let past SUMO's junction logic's view of the ego (YieldToEgo),
  // with the lane they were on then: the ego is theirs to see again once
  // they have left it.
  std::map<std::string, std::string> ignoring_ego;
  // Each turn's reference manoeuvre as the ego's body every metre or so:
  // where SUMO's drivers wait while the ego turns (YieldToEgo).
  std::vector<std::vector<geometry::OrientedBox>> turn_sweeps;
  // The ego's way through each crossing's junction as its body every metre
  // or so, from its front at the junction to its rear out of it: where
  // drivers whose link yields to the ego's wait (YieldToEgo). Empty for the
  // tight U-turns (turn_sweeps).
  struct JunctionClaim {
    double entry_s_m = 0.0;  // road s where the junction starts
    double last_s_m = 0.0;   // rear-axle road s of the last body
    // The edge the ego arrives on: its drivers lead or follow the ego.
    std::string from_edge;
    std::vector<std::pair<double, geometry::OrientedBox>> bodies;  // by s
  };
  std::vector<JunctionClaim> junction_claims;
  // Each internal lane's way into its junction: the lane it comes from and
  // the internal lanes of the connection before it (the first one is the
  // approach link's). Built on first use (CameInYielding).
  struct InternalWay {
    std::string approach_lane;
    std::vector<std::string> before;
  };
  std::map<std::string, InternalWay> internal_ways;
  bool internal_ways_built = false;
  double ego_standing_s = 0.0;  // how long the ego has stood still
  std::map<std::string, std::vector<Eigen::Vector2d>>
      lane_shapes;  // by lane id
  std::unique_ptr<Random> traffic_random;
  // What SUMO's vehicles keep for life, asked once per vehicle.
  struct VehicleType {
    double length_m = 0.0;
    double width_m = 0.0;
    double decel_mps2 = 0.0;  // its comfortable deceleration
  };
  std::map<std::string, VehicleType> types;  // by vehicle id
  // Their headings at the last step, for their yaw rates.
  std::map<std::string, double> last_yaw_rad;  // by vehicle id

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
  // The manoeuvre of each tight U-turn of the road part, and of each
  // corner the car cannot follow closely (world_turnaround.cc); an error
  // naming task.goal where a U-turn has none (a corner without one keeps
  // its lanes). After FindRouteSignals: a signal's stop line stays on the
  // lanes.
  Status PlanTurnarounds();
  // The corners' manoeuvres, between the U-turns' (`turnarounds`), in
  // route order.
  std::vector<RouteTurnaround> SharpCorners(
      algorithms::FreespacePlanner& planner) const;
  // The car's tightest turn (rear axle), from its wheelbase and steering.
  double MinTurningRadiusM() const {
    return setup.ego.wheelbase_m / std::tan(setup.ego.max_steer_rad);
  }
  // The road part's arc length at `raw_s_m` along the joined lane pieces.
  double RoadS(double raw_s_m) const;
  // The crossings' traffic lights (world_signals.cc).
  Status FindRouteSignals();
  // The signals a player would switch (world_signals.cc).
  Status FindSwitchedSignals();
  // Throws libsumo's exceptions (World::Step guards).
  void SwitchSignalPrograms();
  Status BuildScene();
  // world_traffic.cc: the flows and standing cars; a flow's car enters
  // only when the ego is clear of where it would enter; SUMO's drivers
  // brake for the ego in their lane ahead (its moveToXY placement does not
  // make SUMO's car-following and junction models see it everywhere).
  Status SetUpTraffic();
  // Both throw libsumo's exceptions (World::Step guards).
  void InsertFlows();
  void YieldToEgo();
  // Lets a driver that SUMO holds for the ego, the ego clear of its way
  // (`lane`: where it is; `lookahead_m`: how far it looks), drive on once
  // both have stood kMutualWaitS.
  void ReleaseFromEgo(const OtherVehicle& v, const std::string& lane,
                      double lookahead_m);
  // The junction the ego claims now (YieldToEgo), or null: the next one on
  // its route, when its front is in it, or near it with a link that has
  // the right of way (as SUMO's drivers would see an approaching car).
  const JunctionClaim* ActiveJunctionClaim();
  // Whether a driver on internal lane `lane` came into its junction over a
  // link that yields. The part of a left turn past its waiting point in
  // the junction has a link of its own with the right of way, though the
  // turn yields. Throws libsumo's exceptions.
  bool CameInYielding(const std::string& lane);
  const std::vector<Eigen::Vector2d>& LaneShape(const std::string& lane_id);
  Status AddEgo();
  void PushEgo();
  // Projects the ego on the road part near its progress so far, as the
  // stack's path planner does: a route that comes back along the other
  // side of a street passes a lane width from where the car is.
  void UpdateProgress();
  // Throws libsumo's exceptions (World::Step guards).
  void ReadOthers();
};

}  // namespace adse::world

#endif  // ADSE_STACK_WORLD_INTERNAL_WORLD_IMPL_H_
