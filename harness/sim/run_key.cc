#include "harness/sim/run_key.h"

#include <algorithm>

#include <fmt/format.h>

#include "harness/sim/early_stop.h"
#include "stack/base/files.h"
#include "stack/base/hash.h"
#include "stack/base/random.h"

namespace adse::sim {
namespace {

// Bump when the meaning of a run changes without any input changing. v2:
// NDT's acceptance and the map filter changed (issue 17), so runs cached
// by earlier versions are not reused. v3: a car that stands held by
// something traffic will not release ends the run as stalled
// (task.stall_timeout_s), where it used to drive on to the timeout. v4: a
// parking car is parked only once its manoeuvre is over (it used to count
// as parked standing within the tolerances at a cusp). v5: the freespace
// planner says when the car is parked and corrects a manoeuvre ending
// outside the tolerances. v6: the tracker publishes on its own timer,
// its tracks predicted to that time (Autoware 2022.12's), not per scan.
// v7: a route goes round the block where SUMO's turns around tighter than
// the car can, the ideal path drops lane shapes' folds, and a lane-driving
// goal is reached only near the route's end. v8: tracked objects carry
// their heading to planning (they were axis-aligned boxes there). v9:
// perception places a scan by the pose at its stamp (it used the newest).
// v10: the obstacle stop also sweeps the car's footprint along the path.
// v11: the planner changes lane only when the target lane has a gap.
// v12: a track born near a confirmed one starts at its velocity. v13: a
// flow's car enters only when the ego is clear of where it would, and
// SUMO's drivers brake for the ego in the lanes ahead of them. v14:
// drivers wait short of a turn in several moves, and those whose link
// yields keep the ego's way through a junction free; a driver touching the
// ego is left to SUMO. v15: alongside the car, the obstacle stop counts
// only what its body would touch driving off (not the path's corridor).
// v16: a driver past its left turn's waiting point in a junction still
// yields to the ego's way through it. v17: a moving track's box is
// measured as a view of part of its object, and the crossing yield sees a
// car in a farther part of the path's corridor where it crosses nearer.
// v18: a driver SUMO holds for the ego, the ego clear of its way, drives
// on once both have stood 3 s. v19: a corner the ideal driver cannot
// follow within 1 m is turned as a manoeuvre, as a tight U-turn is. v20:
// touching the scene's structure (a pole, a wall, a building, a parked
// car) is a collision, and the car turns its wheels standing before each
// move of a manoeuvre. v21: a car standing on the lane a turn goes onto
// has turned (mid-manoeuvre too, and up to 5 m past its end), a turn in
// several moves through a signal starts only when the signal lets the car
// in, the world counts a turn made only once the car stands on that lane
// (not when its moves back it past the turn's end), and drivers on the
// ego's road wait 1.5 m farther short of its turn. v22: a contact is
// blamed across the face the bodies met through, with each body's velocity
// at the contact point (its turning included); a turn in several moves
// that fits nowhere in the lanes and junctions may use their 1 m
// shoulders; detections within a confirmed track's box that each show
// part of its object are joined into one box first. v23: the corner rule
// rehearses the ideal driver as it drives, on from where the car stands,
// and a stray soon after a corner's turn joins that turn. v24: a
// subscription waits from the oldest message it has not taken, however
// often its keep-last queue turned over since, so an overrunning timer no
// longer starves its node's subscriptions.
constexpr char kKeyVersion[] = "adse-run-key-v24";

Status AddFile(ContentHasher* h, const std::string& label,
               const std::string& path) {
  h->Add(label);
  if (path.empty()) return Status::Ok();
  Result<std::string> bytes = ReadFile(path, 1u << 30);
  if (!bytes.ok()) return bytes.status().WithContext(label);
  h->Add(Sha256Hex(*bytes));
  return Status::Ok();
}

// Whether a map may have traffic lights: a net given by path whose text
// has a signal program (a gzipped one is not looked into: it may). The
// generated maps (parking_lot, grid) have none.
Result<bool> MapMayHaveSignals(const world::MapOptions& map) {
  if (map.net_path.empty()) return false;
  Result<std::string> bytes = ReadFile(map.net_path, 1u << 30);
  if (!bytes.ok()) return bytes.status().WithContext("world.map.net");
  const bool gzipped = bytes->size() >= 2 &&
                       static_cast<unsigned char>((*bytes)[0]) == 0x1f &&
                       static_cast<unsigned char>((*bytes)[1]) == 0x8b;
  return gzipped || bytes->find("<tlLogic") != std::string::npos;
}

void AddLocation(ContentHasher* h, const world::Location& l) {
  h->Add(static_cast<long long>(l.by_edge));
  if (l.by_edge) {
    h->Add(l.edge).Add(l.pos_m).Add(static_cast<long long>(l.lane));
  } else {
    h->Add(l.x_m).Add(l.y_m);
  }
  // Places without a slot or heading key as they did before either existed.
  if (!l.slot.empty()) h->Add("slot").Add(l.slot);
  if (l.has_yaw) h->Add("yaw_deg").Add(l.yaw_deg);
}

// Whether a stack knob can change what a run does; see StackKnobActs.
bool KnobActs(const std::string& path, bool valet, bool signals) {
  if (!valet && path.rfind("parking.", 0) == 0) return false;
  if (!signals && path.rfind("traffic_light.", 0) == 0) return false;
  return true;
}

}  // namespace

Status CheckKnobsAct(const spec::Spec& spec) {
  Result<bool> signals = MapMayHaveSignals(spec.world.map);
  if (!signals.ok()) return signals.status();
  bool valet = false;
  const size_t cases = std::max<size_t>(1, spec.cases.size());
  for (size_t c = 0; c < cases; ++c) {
    valet = valet || CaseSpec(spec, static_cast<int>(c)).task.kind ==
                         world::TaskKind::kValetParking;
  }
  for (const spec::DesignParameter& p : spec.design_space.parameters) {
    if (p.bind.rfind("stack.", 0) != 0) continue;
    const std::string knob = p.bind.substr(6);
    if (KnobActs(knob, valet, *signals)) continue;
    return Status::InvalidArgument(fmt::format(
        "design_space.{}: binds {}, which acts only {}; every point would "
        "drive alike. Sweep it in a scenario where it acts, or drop it",
        p.name, p.bind,
        knob.rfind("parking.", 0) == 0
            ? "in valet_parking tasks, and task.kind is lane_driving"
            : "on maps with traffic signals, and world.map has none"));
  }
  return Status::Ok();
}

Result<std::string> RunKey(const spec::Spec& spec,
                           const spec::DesignPoint& point, uint64_t seed) {
  if (!spec.cases.empty()) {
    return Status::InvalidArgument(
        "task.cases: a run drives one case; its key is its case's");
  }
  ContentHasher h;
  h.Add(kKeyVersion).Add(ADSE_VERSION);
  // World.
  const world::WorldOptions& w = spec.world;
  h.Add("map").Add(w.map.generator);
  for (const auto& [name, value] : w.map.generator_params)
    h.Add(name).Add(value);
  ADSE_RETURN_IF_ERROR(AddFile(&h, "world.map.net", w.map.net_path));
  // Since 2026-11-28 a lane position is scaled onto the lane's shape where
  // a net gives the lane another length: keys of net files changed, those
  // of generated maps (whose lanes' lengths are their shapes') did not.
  if (!w.map.net_path.empty()) h.Add("lane-positions-on-shapes");
  // Generated maps have one program per signal, which is never switched.
  if (!w.map.net_path.empty()) {
    h.Add("signal_program_switch_s").Add(w.traffic.signal_program_switch_s);
  }
  ADSE_RETURN_IF_ERROR(AddFile(&h, "world.map.polygons", w.map.polygons_path));
  h.Add("traffic").Add(w.traffic.parked_occupancy);
  for (const world::Flow& f : w.traffic.flows) {
    h.Add(f.from_edge).Add(f.to_edge).Add(f.vehicles_per_hour);
  }
  if (!w.traffic.parked_slots.empty()) {
    h.Add("parked_slots");
    for (const std::string& name : w.traffic.parked_slots) h.Add(name);
  }
  // Keys of scenarios without them stay as they were.
  if (!w.traffic.stopped_vehicles.empty()) {
    h.Add("stopped_vehicles");
    for (const world::Location& l : w.traffic.stopped_vehicles) {
      AddLocation(&h, l);
    }
  }
  h.Add(static_cast<long long>(w.weather)).Add(w.step_s);
  // Task.
  const world::TaskOptions& t = spec.task;
  h.Add("task").Add(static_cast<long long>(t.kind));
  AddLocation(&h, t.start);
  AddLocation(&h, t.goal);
  // Keys of runs without waypoints stay as they were.
  if (!t.via.empty()) {
    h.Add("via");
    for (const world::Location& l : t.via) AddLocation(&h, l);
  }
  h.Add(t.goal_tolerance_m).Add(t.speed_limit_kmh).Add(t.timeout_s);
  h.Add("stall_timeout_s").Add(t.stall_timeout_s);
  h.Add("traffic_stall_timeout_s").Add(t.traffic_stall_timeout_s);
  const bool valet = t.kind == world::TaskKind::kValetParking;
  if (valet) h.Add("goal_yaw_tolerance_deg").Add(t.goal_yaw_tolerance_deg);
  // Stack: every knob's effective value, so a changed default changes keys.
  // The parking knobs act only on valet_parking, whose keys alone hold them
  // (lane-driving keys stay as they were before they existed); the traffic
  // light knobs only on maps with signals, whose keys alone hold them (and
  // so changed when the ego began to obey signals; keys of maps without
  // signals stay as they were).
  Result<bool> signals = MapMayHaveSignals(w.map);
  if (!signals.ok()) return signals.status();
  h.Add("stack");
  for (const KnobInfo& knob : StackKnobs()) {
    if (!KnobActs(knob.path, valet, *signals)) continue;
    h.Add(knob.path).Add(spec.stack.Get(knob.path));
  }
  // Platform.
  const spec::PlatformOptions& p = spec.platform;
  h.Add("platform").Add(static_cast<long long>(p.kind)).Add(p.reference_ghz);
  h.Add(static_cast<long long>(p.cost_model)).Add(p.cost_scale);
  h.Add(static_cast<long long>(p.cores)).Add(p.freq_ghz);
  // Keys of runs to completion stay as they were before processor sharing.
  if (p.kind == spec::PlatformKind::kVirtual &&
      p.dispatch == spec::Dispatch::kProcessorSharing) {
    h.Add("dispatch_processor_sharing");
  }
  // Keys of virtual runs stay as they were before the real-time platform.
  if (p.kind == spec::PlatformKind::kCgroup) {
    h.Add("time_dilation").Add(p.time_dilation);
    // Keys of padded runs stay as they were before quotas.
    if (p.clock_by == spec::ClockBy::kQuota) {
      h.Add("clock_by_quota").Add(p.host_ghz);
    } else if (p.clock_by == spec::ClockBy::kCpufreq) {
      h.Add("clock_by_cpufreq");
    }
  }
  if (p.cost_model == spec::CostModel::kCounted) {
    // Keys of calibrated runs stay as they were before profiles existed.
    if (p.profile.empty()) {
      ADSE_RETURN_IF_ERROR(AddFile(&h, "platform.calibration", p.calibration));
    } else {
      ADSE_RETURN_IF_ERROR(AddFile(&h, "platform.profile", p.profile));
    }
  }
  // Constraints end a run early (harness.early_stop) and so change what it
  // records; keys of runs no constraint can stop stay as they were.
  const std::vector<std::string> stoppable = EarlyStoppableConstraints(spec);
  if (!stoppable.empty()) {
    h.Add("early_stop");
    for (const std::string& c : stoppable) h.Add(c);
  }
  // The point (with its bindings: the same name may bind another knob) and
  // the seed.
  h.Add("point");
  for (const auto& [name, value] : point) {
    const spec::DesignParameter* param = spec.design_space.Find(name);
    h.Add(name).Add(param ? param->bind : std::string()).Add(value);
  }
  h.Add("seed").Add(static_cast<long long>(seed));
  return h.Hex();
}

uint64_t ReplicaSeed(const spec::Spec& spec, int replica) {
  const uint64_t seed = spec.world.traffic.seed;
  if (replica == 0) return seed;
  return Random::DeriveSeed(seed, "replica " + std::to_string(replica));
}

std::vector<PointRun> PointRuns(const spec::Spec& spec) {
  std::vector<PointRun> runs;
  for (int c = 0; c < spec::CaseCount(spec); ++c) {
    for (int r = 0; r < std::max(1, spec.harness.replicas); ++r) {
      runs.push_back({c, r});
    }
  }
  return runs;
}

spec::Spec CaseSpec(const spec::Spec& spec, int task_case) {
  return spec.cases.empty() ? spec : spec::ForCase(spec, task_case);
}

Result<std::vector<std::string>> PointRunKeys(const spec::Spec& spec,
                                              const spec::DesignPoint& point) {
  std::vector<spec::Spec> cases;
  for (int c = 0; c < spec::CaseCount(spec); ++c) {
    cases.push_back(CaseSpec(spec, c));
  }
  std::vector<std::string> keys;
  for (const PointRun& run : PointRuns(spec)) {
    Result<std::string> key =
        RunKey(cases[run.task_case], point, ReplicaSeed(spec, run.replica));
    if (!key.ok()) return key.status();
    keys.push_back(*std::move(key));
  }
  return keys;
}

}  // namespace adse::sim
