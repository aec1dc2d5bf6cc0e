// Options of the simulated world and the driving task, as the scenario's
// `world:` and `task:` sections give them. Filled by harness/spec; read by
// stack/world. Units are in the names.
#ifndef ADSE_STACK_WORLD_WORLD_OPTIONS_H_
#define ADSE_STACK_WORLD_WORLD_OPTIONS_H_

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace adse::world {

enum class Weather { kClear, kRain, kFog };

struct MapOptions {
  // Absolute path of a SUMO .net.xml. Empty when `generator` is set.
  std::string net_path;
  // Optional SUMO polygon file (.poly.xml) with walls, poles, buildings.
  std::string polygons_path;
  // "parking_lot" or "grid"; empty when `net_path` is set.
  std::string generator;
  // Generator parameters by name (see scenarios/README.md).
  std::map<std::string, double> generator_params;
};

// A place on the map: either a world coordinate or an edge position.
struct Location {
  static Location Xy(double x_m, double y_m) {
    Location l;
    l.x_m = x_m;
    l.y_m = y_m;
    return l;
  }
  static Location OnEdge(std::string edge, double pos_m, int lane = 0) {
    Location l;
    l.by_edge = true;
    l.edge = std::move(edge);
    l.pos_m = pos_m;
    l.lane = lane;
    return l;
  }

  bool by_edge = false;
  double x_m = 0.0;
  double y_m = 0.0;
  std::string edge;
  double pos_m = 0.0;
  int lane = 0;
  // A parking slot by name (a valet goal): its centre is the place.
  std::string slot;
  // Heading at the place (a valet goal's parked heading), degrees
  // counter-clockwise from +x.
  bool has_yaw = false;
  double yaw_deg = 0.0;
};

struct Flow {
  std::string from_edge;
  std::string to_edge;
  double vehicles_per_hour = 60.0;
};

struct TrafficOptions {
  // Seeds SUMO's randomness and the parked-car layout.
  uint64_t seed = 1;
  std::vector<Flow> flows;
  // Fraction of parking slots holding a parked car, in [0, 1].
  double parked_occupancy = 0.0;
  // Slots (by name) holding a parked car; when given, exactly these do and
  // parked_occupancy is not drawn.
  std::vector<std::string> parked_slots;
  // Road users that stand where they are placed for the whole run (a
  // broken-down car, a delivery van): SUMO vehicles held at speed 0.
  std::vector<Location> stopped_vehicles;
  // A signal whose running program keeps links red through its whole
  // cycle that another of its programs turns green (SUMO's game nets hold
  // each direction green for 1,000-10,000 s until a player switches the
  // program) goes on to its next program after this long, as a player
  // would switch it; 0 keeps the net's programs as they are.
  double signal_program_switch_s = 30.0;
};

struct WorldOptions {
  MapOptions map;
  TrafficOptions traffic;
  Weather weather = Weather::kClear;
  // World (SUMO and ego dynamics) step.
  double step_s = 0.05;
};

enum class TaskKind { kLaneDriving, kValetParking };

struct TaskOptions {
  TaskKind kind = TaskKind::kLaneDriving;
  Location start;
  // Places the route passes through, in order, between start and goal: the
  // route is the shortest one from each to the next.
  std::vector<Location> via;
  Location goal;
  // The goal counts as reached within this distance (valet_parking: of the
  // parked body's centre from the slot's target, standing still).
  double goal_tolerance_m = 2.0;
  // valet_parking: the parked heading's tolerance.
  double goal_yaw_tolerance_deg = 10.0;
  double speed_limit_kmh = 30.0;
  // Simulated time after the start event at which a run is abandoned.
  double timeout_s = 1500.0;
  // A car that has stood this long without a break, held by something no
  // other traffic or signal will release, ends the run as stalled; 0: never.
  double stall_timeout_s = 60.0;
  // A car that has stood this long without a break held by other road
  // users (one that never moves on) ends the run as stalled; 0: never.
  // Longer than a signal's red phase, so a queue at a red light never does.
  double traffic_stall_timeout_s = 300.0;
};

// Names as written in scenario files and run records: the one list each
// (stack/base/vocabulary.h).
const char* WeatherToString(Weather weather);
bool StringToWeather(std::string_view name, Weather* weather);
std::vector<std::string> WeatherNames();

const char* TaskKindToString(TaskKind kind);
bool StringToTaskKind(std::string_view name, TaskKind* kind);
std::vector<std::string> TaskKindNames();

// A parameter of a map generator (`world.map.params`), like a stack knob:
// the parser's bounds, the generator's default and the docs' row.
struct MapGeneratorParam {
  const char* name;
  bool integer;  // only whole numbers allowed
  double min_value;
  double max_value;
  double default_value;
  const char* doc;  // one line, with the unit
};

// The generators, in the order the docs list them: parking_lot, grid.
std::vector<std::string> MapGeneratorNames();
// The parameters of `generator`; nullptr for an unknown generator.
const std::vector<MapGeneratorParam>* MapGeneratorParams(
    std::string_view generator);
// `options.generator_params[name]`, or the parameter's default.
double MapGeneratorParamValue(const MapOptions& options,
                              const std::string& name);

}  // namespace adse::world

#endif  // ADSE_STACK_WORLD_WORLD_OPTIONS_H_
