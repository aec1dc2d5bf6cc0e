// Everything one run stores: the in-memory form of a run file (HDF5, see
// results-schema/). Plain data: no HDF5 types here.
#ifndef ADSE_ANALYSIS_RUNFILE_RUN_DATA_H_
#define ADSE_ANALYSIS_RUNFILE_RUN_DATA_H_

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "stack/algorithms/signal_state.h"
#include "stack/algorithms/stop_reason.h"
#include "stack/runtime/trace.h"

namespace adse::runfile {

struct EgoSample {
  double t_s, x_m, y_m, yaw_rad, v_mps, steer_rad, accel_mps2;
};

struct PathPoint {
  double s_m, x_m, y_m;
};

// One vertex of a lane centreline (for pictures); the vertices of one lane
// are consecutive rows, in driving order.
struct LanePoint {
  int32_t lane;  // 0-based lane number within the run file
  double x_m, y_m;
};

// Other vehicles, decimated (e.g. every 0.5 s).
struct VehicleSample {
  double t_s;
  std::string id;
  double x_m, y_m, yaw_rad, speed_mps, length_m, width_m;
};

// A control command as the vehicle received it.
struct ControlSample {
  double t_s;      // publish time
  double stamp_s;  // originating sensor time (through localization)
  double accel_mps2, steer_rad;
  // The scan whose tracked objects the followed trajectory was checked
  // against (the chain through perception); -1 when none.
  double perception_stamp_s = -1.0;
};

// Why the planner's trajectory stops, as published on /planning/stop_reason.
struct StopSample {
  double t_s;      // publish time
  double stamp_s;  // the pose the trajectory was planned from
  StopReason reason;
  double stop_distance_m;    // ego rear axle to the stop; 0 there, -1 none
  int32_t track_id;          // kObstacle: the track; else -1
  double obstacle_gap_m;     // kObstacle: front bumper to its near edge
  int32_t static_structure;  // kObstacle: 1 when the map has structure there
};

// What the car's signal detector reported, as published on
// /perception/traffic_signal (only on routes with signals).
struct SignalSample {
  double t_s;      // publish time: the look plus the detector's latency
  double stamp_s;  // when the detector looked
  SignalState state;
  double stop_line_distance_m;  // along the route to it; -1 none in range
  std::string tls_id;           // the signal; empty when none is in range
};

// A confirmed track as published on /perception/objects: what the stack
// saw, in the map frame.
struct ObjectSample {
  double t_s;      // publish time
  double stamp_s;  // the scan the tracks were last updated from
  int32_t track_id;
  double x_m, y_m;  // box centre
  double vx_mps, vy_mps;
  double length_m, width_m;
  double yaw_rad;  // of the box's length, modulo a half turn
  int32_t age;     // tracker updates since the track's birth
};

struct CollisionEvent {
  double t_s;
  std::string other_id;
  // 1: the ego caused it (at the contact it moved towards the other at
  // least as fast as the other moved towards it); 0: the other drove into
  // it; -1: not known (files written before it was recorded).
  int32_t ego_caused = -1;
};

// valet_parking: a parking slot of the lot.
struct ParkingSlotRow {
  double x_m, y_m, yaw_rad;  // centre; yaw along the slot's depth
  double length_m, width_m;
  int32_t occupied;  // 1: a parked car stands in it
  int32_t target;    // 1: the goal's slot
};

// valet_parking: one vertex of an obstacle's footprint (wall, pole, parked
// car, building); the vertices of one obstacle are consecutive rows.
struct OutlinePoint {
  int32_t obstacle;  // 0-based obstacle number within the file
  double x_m, y_m;
};

// valet_parking: a pose of the stack's planned manoeuvre (rear axle).
struct ParkingPathRow {
  double x_m, y_m, yaw_rad;
  int32_t reverse;  // 1: driven in reverse
};

// A pose of a plan that a later one replaced.
struct EarlierPlanRow {
  int32_t plan;  // 0: the first plan, then in order
  double x_m, y_m, yaw_rad;
  int32_t reverse;
};

// valet_parking's record (the /parking group): the goal and the lot the
// manoeuvre was planned in, and the plan itself.
struct ParkingRecord {
  bool present = false;  // false: not a valet_parking run (no /parking)
  std::string slot;      // the goal slot's name
  // The parked pose (rear axle) and its tolerances.
  double goal_x_m = 0.0, goal_y_m = 0.0, goal_yaw_rad = 0.0;
  double tolerance_m = 0.0, yaw_tolerance_rad = 0.0;
  // The ego's body (the rear axle is half a wheelbase behind its centre).
  double wheelbase_m = 2.7, length_m = 4.6, width_m = 1.9;
  // When the stack planned the manoeuvre (-1: it never did) and whether
  // it found one: its last plan, the one planned_path holds.
  double planned_at_s = -1.0;
  int32_t path_found = 0;
  // Its first plan (-1: none), and the paths found after it, each planned
  // where the car stood after leaving the course of the one before or at
  // its end outside the tolerances. Files written before re-planning read
  // as planned_at_s and 0.
  double first_planned_at_s = -1.0;
  int32_t replans = 0;
  std::vector<ParkingSlotRow> slots;
  std::vector<OutlinePoint> obstacles;
  std::vector<ParkingPathRow> planned_path;  // empty when none was found
  // The paths the last one replaced, in order (empty without re-plans and
  // in files written before they were kept).
  std::vector<EarlierPlanRow> earlier_plans;
};

// What makes a callback ready. A new kind needs its token in run_file.cc's
// CallbackKindTerms.
enum class CallbackKind {
  kSubscription,  // a message on `topic`
  kTimer,         // its period
};
// The token of a kind ("timer"), as /trace/callback_info stores it.
const char* CallbackKindToString(CallbackKind kind);
// False when `name` is no kind's token; `kind` is then unchanged.
bool StringToCallbackKind(std::string_view name, CallbackKind* kind);
// Every token, in enum order.
std::vector<std::string> CallbackKindNames();

struct NamedCallback {
  std::string name;  // "<node>/<callback>"
  int32_t node = -1;
  CallbackKind kind = CallbackKind::kSubscription;
  int32_t topic = -1;
  double period_s = 0.0;
};

// A run's status. complete: the simulation ended at the goal or the
// timeout; infeasible: it was ended early because a constraint was
// certainly violated (early stop); stalled: it was ended early because the
// car stood for task.stall_timeout_s and nothing would release it. The
// metrics of both are censored. failed: it could not finish.
inline constexpr char kRunComplete[] = "complete";
inline constexpr char kRunInfeasible[] = "infeasible";
inline constexpr char kRunStalled[] = "stalled";
inline constexpr char kRunFailed[] = "failed";

// Whether a run with this status was ended early, before the goal or the
// timeout, so that its metrics are measured only up to then (censored).
inline bool EndedEarly(const std::string& status) {
  return status == kRunInfeasible || status == kRunStalled;
}

// The termination reason of an early-stopped run is this prefix followed
// by the constraint, exactly as the scenario writes it.
inline constexpr char kConstraintViolatedPrefix[] = "constraint_violated: ";

// The termination reason of a stalled run is this prefix followed by the
// stop reason that held the car (StopReasonToString).
inline constexpr char kStalledPrefix[] = "stalled: ";

// What follows `prefix` in `reason`; empty when it does not start so.
inline std::string ReasonAfter(const std::string& reason, const char* prefix) {
  const std::string p = prefix;
  return reason.compare(0, p.size(), p) == 0 ? reason.substr(p.size())
                                             : std::string();
}

// The constraint an early-stopped run's reason names; empty for any other
// reason.
inline std::string ViolatedConstraint(const std::string& reason) {
  return ReasonAfter(reason, kConstraintViolatedPrefix);
}

struct RunData {
  // Identity and provenance (root attributes).
  std::string status = kRunComplete;  // one of the statuses above
  // goal_reached | timeout | constraint_violated: <constraint> |
  // stalled: <stop reason> | error text;
  // no_path (the freespace planner found no manoeuvre: valet parking, or
  // a three-point turn on the route); valet_parking also:
  // parked_out_of_tolerance (the manoeuvre ended outside the tolerances)
  std::string termination_reason;
  // What ended it, in words, where the reason alone does not say: for
  // no_path, the freespace planner's failure. Empty otherwise.
  std::string termination_detail;
  std::string scenario_name;
  std::string scenario_text;  // the scenario file, verbatim
  std::string scenario_hash;  // sha256 of scenario_text
  // The scenario's task.cases entry the run drove; empty without cases.
  std::string task_case;
  std::string content_key;  // run key (empty until the harness sets it)
  std::string adse_version;
  std::string host;         // hostname, CPU model, cores
  std::string created_utc;  // ISO 8601
  uint64_t seed = 0;
  std::map<std::string, double> design_point;
  std::map<std::string, std::string>
      platform;  // kind, cores, freq_ghz, cost_model, ...

  // World.
  std::vector<EgoSample> ego;
  std::vector<PathPoint> ideal_path;
  double lane_width_m = 3.5;
  std::vector<LanePoint> lanes;  // may be empty (not recorded)
  std::vector<VehicleSample> vehicles;
  std::vector<CollisionEvent> collisions;
  ParkingRecord parking;

  // Stack and trace.
  std::vector<std::string> node_names;
  std::vector<NamedCallback> callback_info;
  std::vector<std::string> topic_names;
  stack::Trace trace;
  std::vector<ControlSample> controls;
  std::vector<StopSample> stop_reasons;  // may be empty (older files)
  // May be empty (no signals on the route, or older files).
  std::vector<SignalSample> signals;
  std::vector<ObjectSample> objects;  // may be empty (older files)

  // Metrics by name (see scenarios/README.md); booleans as 0/1.
  std::map<std::string, double> metrics;
};

}  // namespace adse::runfile

#endif  // ADSE_ANALYSIS_RUNFILE_RUN_DATA_H_
