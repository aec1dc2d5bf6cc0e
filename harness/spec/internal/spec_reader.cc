#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "harness/spec/internal/spec_reader.h"
#include "harness/spec/text_util.h"
#include "harness/spec/types.h"
#include "stack/base/platform_limits.h"
#include "stack/config/stack_config.h"

namespace adse::spec::internal {

namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kTopKeys = {
    "adse",        "name",         "world",   "task",       "stack",
    "platform",    "design_space", "cost",    "objectives", "constraints",
    "exploration", "llm",          "harness", "output"};
const std::vector<std::string> kWorldKeys = {"map", "traffic", "weather",
                                             "step_s"};
const std::vector<std::string> kMapKeys = {"generate", "params", "net",
                                           "polygons"};
const std::vector<std::string> kTrafficKeys = {"seed",
                                               "flows",
                                               "parked_occupancy",
                                               "parked_slots",
                                               "stopped_vehicles",
                                               "signal_program_switch_s"};
const std::vector<std::string> kFlowKeys = {"from", "to", "vehicles_per_hour"};
const std::vector<std::string> kTaskKeys = {"kind",
                                            "start",
                                            "via",
                                            "goal",
                                            "speed_limit_kmh",
                                            "timeout_s",
                                            "stall_timeout_s",
                                            "traffic_stall_timeout_s",
                                            "cases"};
const std::vector<std::string> kCaseKeys = {"name", "start", "via", "goal"};
// Each case is a run of every point: a few, not a sweep.
constexpr size_t kMaxCases = 16;
const std::vector<std::string> kStartKeys = {"x", "y", "edge", "pos_m", "lane"};
const std::vector<std::string> kGoalKeys = {
    "x",           "y",       "edge",
    "pos_m",       "lane",    "slot",
    "tolerance_m", "yaw_deg", "yaw_tolerance_deg"};
const std::vector<std::string> kPlatformKeys = {
    "kind",          "reference_ghz", "cost_model", "calibration",
    "profile",       "cores",         "freq_ghz",   "cost_scale",
    "time_dilation", "clock_by",      "host_ghz",   "dispatch"};

}  // namespace

// The models of the reference study, used for roles the file leaves out.
const std::map<std::string, std::string>& DefaultModels() {
  static const std::map<std::string, std::string> kModels = {
      {"dse", "deepseek-r1"},
      {"vision", "mistral-small3.1"},
      {"text", "llama4:scout"},
      {"command", "llama3.1"},
      {"interpretation", "llama3.1"}};
  return kModels;
}

std::vector<std::string> BindTargets() {
  std::vector<std::string> targets = {kPlatformCores, kPlatformFreq};
  for (const KnobInfo& knob : StackKnobs()) {
    targets.push_back("stack." + knob.path);
  }
  return targets;
}

std::vector<std::string> MetricNames() {
  std::vector<std::string> names;
  for (const MetricInfo& m : KnownMetrics()) names.push_back(m.name);
  return names;
}

bool IsIdentifier(std::string_view s) {
  if (s.empty() || s.size() > 64) return false;
  if (!(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) {
    return false;
  }
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

bool IsSpecName(std::string_view s) {
  if (s.empty() || s.size() > 100) return false;
  if (!std::isalnum(static_cast<unsigned char>(s[0]))) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' ||
           c == '-' || c == '.';
  });
}

// A usable name from a file stem: "my scenario.yaml" -> "my-scenario".
std::string NameFromFile(const std::string& file_name) {
  std::string stem = fs::path(file_name).stem().string();
  std::string name;
  for (char c : stem) {
    const bool ok = std::isalnum(static_cast<unsigned char>(c)) || c == '_' ||
                    c == '-' || c == '.';
    name += ok ? c : '-';
  }
  while (!name.empty() && !std::isalnum(static_cast<unsigned char>(name[0]))) {
    name.erase(0, 1);
  }
  if (name.size() > 100) name.resize(100);
  return name.empty() ? "scenario" : name;
}

// Slurm's --time formats: M, M:S, H:M:S, D-H, D-H:M, D-H:M:S.
bool IsSlurmTime(const std::string& s) {
  if (s == "UNLIMITED" || s == "INFINITE") return true;
  std::string rest = s;
  if (const size_t dash = s.find('-'); dash != std::string::npos) {
    const std::string days = s.substr(0, dash);
    if (days.empty() ||
        days.find_first_not_of("0123456789") != std::string::npos) {
      return false;
    }
    rest = s.substr(dash + 1);
  }
  int parts = 0;
  std::stringstream in(rest);
  std::string part;
  while (std::getline(in, part, ':')) {
    if (part.empty() || part.size() > 6 ||
        part.find_first_not_of("0123456789") != std::string::npos) {
      return false;
    }
    ++parts;
  }
  return parts >= 1 && parts <= 3 && rest.back() != ':';
}

void SpecReader::Read(const YAML::Node& root) {
  Val top;
  top.node = root;
  top.mark = root.Mark();
  top.key_mark = top.mark;
  if (!root.IsDefined() || root.IsNull()) {
    Error(YAML::Mark(), "",
          "a scenario map with adse, world, task and "
          "design_space",
          "an empty document");
    return;
  }
  Fields f;
  if (!ReadFields(top, &kTopKeys, &f,
                  "a scenario map with adse, world, task and design_space")) {
    return;
  }
  if (const Val* v = f.Get("adse")) {
    double version = 0;
    if (!v->node.IsScalar() || !ParseNumber(v->node.Scalar(), &version)) {
      Error(*v, "the spec version 1");
      return;
    }
    if (version != 1) {
      // A future format would only produce noise below: stop here.
      Error(*v, "1", " (unsupported spec version)");
      return;
    }
    spec_.version = 1;
  } else {
    Missing(top, "adse", "the spec version, 'adse: 1'");
  }

  if (const Val* v = f.Get("name")) {
    std::string name;
    if (ReadString(*v, &name)) {
      if (IsSpecName(name)) {
        spec_.name = name;
      } else {
        Error(*v,
              "a name of letters, digits, '_', '-' or '.' (it names the "
              "output folder), at most 100 characters");
      }
    }
  }
  if (const Val* v = f.Get("world")) {
    ReadWorld(*v);
  } else {
    Missing(top, "world", "a map with at least 'map'");
  }
  if (const Val* v = f.Get("task")) {
    ReadTask(*v);
  } else {
    Missing(top, "task", "a map with at least 'start' and 'goal'");
  }
  if (const Val* v = f.Get("stack")) ReadStack(*v, "");
  if (const Val* v = f.Get("platform")) ReadPlatform(*v);

  const size_t errors_before_space = error_count();
  if (const Val* v = f.Get("design_space")) {
    ReadDesignSpace(*v);
  } else {
    Missing(top, "design_space",
            "a map of parameters, e.g. {cores: {bind: platform.cores, "
            "range: [1, 8]}}");
  }
  space_ok_ = error_count() == errors_before_space &&
              !spec_.design_space.parameters.empty();

  if (const Val* v = f.Get("cost")) ReadCost(*v);
  if (const Val* v = f.Get("objectives")) {
    ReadObjectives(*v);
  } else {
    spec_.objectives = {{"hardware_cost", true}, {"nav_time_s", true}};
  }
  if (const Val* v = f.Get("constraints")) {
    ReadConstraints(*v);
  } else {
    spec_.constraints = {"completed"};
  }
  if (const Val* v = f.Get("exploration")) ReadExploration(*v);
  if (const Val* v = f.Get("llm")) ReadLlm(*v);
  for (const auto& [role, model] : DefaultModels()) {
    spec_.llm.models.emplace(role, model);  // keeps models the file set
  }
  if (const Val* v = f.Get("harness")) ReadHarness(*v);
  ReadOutput(f.Get("output"));
}

void SpecReader::ReadWorld(const Val& v) {
  Fields f;
  if (!ReadFields(v, &kWorldKeys, &f)) return;
  if (const Val* e = f.Get("map")) {
    ReadMapSource(*e);
  } else {
    Missing(v, "map",
            "{generate: parking_lot|grid, params: {...}} or "
            "{net: <file.net.xml>}");
  }
  if (const Val* e = f.Get("traffic")) ReadTraffic(*e);
  if (const Val* e = f.Get("weather")) {
    ReadEnum(*e, &spec_.world.weather, world::WeatherNames(),
             world::StringToWeather);
  }
  if (const Val* e = f.Get("step_s")) {
    // SUMO's smallest step is 1 ms.
    ReadNumber(*e, &spec_.world.step_s, Bounds::Closed(0.001, 1));
  }
}

void SpecReader::ReadMapSource(const Val& v) {
  const std::string expected =
      "{generate: parking_lot|grid, params: {...}} or {net: <file.net.xml>, "
      "polygons: <file.poly.xml>}";
  Fields f;
  if (!ReadFields(v, &kMapKeys, &f, expected)) return;
  world::MapOptions& map = spec_.world.map;
  const Val* generate = f.Get("generate");
  const Val* net = f.Get("net");
  if (generate && net) {
    Error(v.key_mark, v.path, "either 'generate' or 'net'", "both");
    return;
  }
  if (!generate && !net) {
    Error(v.key_mark, v.path, "either 'generate' or 'net'", "neither");
    return;
  }
  if (const Val* params = f.Get("params"); params && !generate) {
    Error(params->key_mark, params->path,
          "'params' only together with 'generate'", "'net'");
  }
  if (generate) {
    if (!ReadEnum(*generate, &map.generator, world::MapGeneratorNames())) {
      return;
    }
    const std::vector<world::MapGeneratorParam>& table =
        *world::MapGeneratorParams(map.generator);
    std::vector<std::string> names;
    for (const world::MapGeneratorParam& p : table) {
      names.push_back(p.name);
      map.generator_params[p.name] = p.default_value;
    }
    if (const Val* params = f.Get("params")) {
      Fields pf;
      if (ReadFields(*params, &names, &pf)) {
        for (const world::MapGeneratorParam& p : table) {
          const Val* e = pf.Get(p.name);
          if (e == nullptr) continue;
          const Bounds bounds = Bounds::Closed(p.min_value, p.max_value);
          if (p.integer) {
            int value = 0;
            if (ReadInt(*e, &value, bounds)) {
              map.generator_params[p.name] = value;
            }
          } else {
            ReadNumber(*e, &map.generator_params[p.name], bounds);
          }
        }
      }
    }
  }
  if (net) {
    std::string written;
    if (ReadPath(*net, &map.net_path, "a path to a SUMO network (.net.xml)")) {
      written = net->node.Scalar();
      std::error_code ec;
      if (!check_files_) {
        // Re-reading a stored scenario: the file need not exist here.
      } else if (!fs::is_regular_file(map.net_path, ec)) {
        Error(net->mark, net->path, "an existing SUMO network file (.net.xml)",
              Quote(written) + " (no such file: " + map.net_path + ")");
      } else {
        // Cheap sniff only; the world module loads it in SUMO later.
        std::ifstream in(map.net_path, std::ios::binary);
        std::string head(4096, '\0');
        in.read(head.data(), static_cast<std::streamsize>(head.size()));
        head.resize(static_cast<size_t>(in.gcount()));
        const bool gzipped = head.size() >= 2 &&
                             static_cast<unsigned char>(head[0]) == 0x1f &&
                             static_cast<unsigned char>(head[1]) == 0x8b;
        if (!gzipped && head.find("<net") == std::string::npos) {
          Error(net->mark, net->path,
                "a SUMO network file (.net.xml with a <net> element)",
                Quote(written) + ", whose first 4 KiB have no <net> element");
        }
      }
    }
  }
  if (const Val* e = f.Get("polygons")) {
    if (ReadPath(*e, &map.polygons_path,
                 "a path to a SUMO polygon file (.poly.xml)")) {
      std::error_code ec;
      if (check_files_ && !fs::is_regular_file(map.polygons_path, ec)) {
        Error(e->mark, e->path, "an existing SUMO polygon file (.poly.xml)",
              Quote(e->node.Scalar()) + " (no such file: " + map.polygons_path +
                  ")");
      }
    }
  }
}

void SpecReader::ReadTraffic(const Val& v) {
  Fields f;
  if (!ReadFields(v, &kTrafficKeys, &f)) return;
  world::TrafficOptions& traffic = spec_.world.traffic;
  if (const Val* e = f.Get("seed")) ReadSeed(*e, &traffic.seed);
  if (const Val* e = f.Get("parked_occupancy")) {
    ReadNumber(*e, &traffic.parked_occupancy, Bounds::Closed(0, 1));
  }
  if (const Val* e = f.Get("signal_program_switch_s")) {
    ReadNumber(*e, &traffic.signal_program_switch_s, Bounds::NonNegative());
  }
  if (const Val* e = f.Get("parked_slots")) {
    std::vector<Val> items;
    if (ReadList(*e, &items, "a list of parking slot names")) {
      traffic.parked_slots.assign(items.size(), std::string());
      for (size_t i = 0; i < items.size(); ++i)
        ReadString(items[i], &traffic.parked_slots[i], "a parking slot name");
    }
  }
  if (const Val* e = f.Get("stopped_vehicles")) {
    std::vector<Val> items;
    if (ReadList(*e, &items,
                 "a list of places {x, y} or {edge, pos_m, lane}")) {
      traffic.stopped_vehicles.assign(items.size(), world::Location());
      for (size_t i = 0; i < items.size(); ++i)
        ReadLocation(items[i], nullptr, &traffic.stopped_vehicles[i]);
    }
  }
  if (const Val* e = f.Get("flows")) {
    std::vector<Val> items;
    if (!ReadList(*e, &items,
                  "a list of {from: <edge>, to: <edge>, "
                  "vehicles_per_hour: <n>}")) {
      return;
    }
    for (const Val& item : items) {
      if (full()) return;
      Fields ff;
      if (!ReadFields(item, &kFlowKeys, &ff,
                      "a map {from: <edge>, to: <edge>, "
                      "vehicles_per_hour: <n>}")) {
        continue;
      }
      world::Flow flow;
      if (const Val* x = ff.Get("from")) {
        ReadString(*x, &flow.from_edge, "a SUMO edge id");
      } else {
        Missing(item, "from", "a SUMO edge id");
      }
      if (const Val* x = ff.Get("to")) {
        ReadString(*x, &flow.to_edge, "a SUMO edge id");
      } else {
        Missing(item, "to", "a SUMO edge id");
      }
      if (const Val* x = ff.Get("vehicles_per_hour")) {
        ReadNumber(*x, &flow.vehicles_per_hour, Bounds::Positive());
      }
      traffic.flows.push_back(std::move(flow));
    }
  }
}

void SpecReader::ReadTask(const Val& v) {
  Fields f;
  if (!ReadFields(v, &kTaskKeys, &f)) return;
  world::TaskOptions& task = spec_.task;
  if (const Val* e = f.Get("kind")) {
    ReadEnum(*e, &task.kind, world::TaskKindNames(), world::StringToTaskKind);
  }
  if (const Val* e = f.Get("start")) {
    ReadLocation(*e, nullptr, &task.start);
  } else {
    Missing(v, "start", "a place {x, y} or {edge, pos_m, lane}");
  }
  if (const Val* e = f.Get("via")) ReadVia(*e, &task.via);
  if (const Val* e = f.Get("goal")) {
    ReadLocation(*e, &task, &task.goal);
  } else {
    Missing(v, "goal", "a place {x, y} or {edge, pos_m, lane}");
  }
  if (const Val* e = f.Get("speed_limit_kmh")) {
    ReadNumber(*e, &task.speed_limit_kmh, {0, 300, true, false});
  }
  if (const Val* e = f.Get("timeout_s")) {
    ReadNumber(*e, &task.timeout_s, Bounds::Positive());
  }
  if (const Val* e = f.Get("stall_timeout_s")) {
    ReadNumber(*e, &task.stall_timeout_s, Bounds::NonNegative());
  }
  if (const Val* e = f.Get("traffic_stall_timeout_s")) {
    ReadNumber(*e, &task.traffic_stall_timeout_s, Bounds::NonNegative());
  }
  // Last: a case starts from the task as read above.
  if (const Val* e = f.Get("cases")) ReadCases(*e);
}

void SpecReader::ReadVia(const Val& v, std::vector<world::Location>* via) {
  std::vector<Val> items;
  const std::string expected =
      "a list of at most 100 places {x, y} or {edge, pos_m, lane}";
  if (ReadList(v, &items, expected) && items.size() > 100) {
    Error(v, expected, fmt::format(" with {} places", items.size()));
  } else if (!items.empty()) {
    via->assign(items.size(), world::Location());
    for (size_t i = 0; i < items.size(); ++i)
      ReadLocation(items[i], nullptr, &(*via)[i]);
  }
}

void SpecReader::ReadCases(const Val& v) {
  const std::string expected = fmt::format(
      "a list of 2 to {} cases {{name, start, via, goal}}, each changing "
      "the task's start, waypoints or goal",
      kMaxCases);
  std::vector<Val> items;
  if (!ReadList(v, &items, expected)) return;
  if (items.size() < 2 || items.size() > kMaxCases) {
    Error(v, expected, fmt::format(" with {} case(s)", items.size()));
    return;
  }
  for (const Val& item : items) {
    Fields f;
    if (!ReadFields(item, &kCaseKeys, &f, expected)) continue;
    TaskCase c;
    c.task = spec_.task;
    if (const Val* e = f.Get("name")) {
      const std::string what =
          "a case name of letters, digits and '_' (not starting with a "
          "digit), unique in task.cases";
      if (ReadString(*e, &c.name, what)) {
        if (!IsIdentifier(c.name)) {
          Error(*e, what);
        } else if (FindCase(spec_, c.name) >= 0) {
          Error(*e, what, " (a second case of that name)");
        }
      }
    } else {
      Missing(item, "name", "the case's name, e.g. nose_in");
    }
    // A place given replaces the task's whole place, tolerances aside.
    if (const Val* e = f.Get("start")) {
      c.task.start = world::Location();
      ReadLocation(*e, nullptr, &c.task.start);
    }
    if (const Val* e = f.Get("via")) {
      c.task.via.clear();
      ReadVia(*e, &c.task.via);
    }
    if (const Val* e = f.Get("goal")) {
      c.task.goal = world::Location();
      ReadLocation(*e, &c.task, &c.task.goal);
    }
    if (!f.Get("start") && !f.Get("via") && !f.Get("goal")) {
      Error(item, "a case that changes the task's start, via or goal");
    }
    spec_.cases.push_back(std::move(c));
  }
}

void SpecReader::ReadLocation(const Val& v, world::TaskOptions* goal_of,
                              world::Location* location) {
  const bool goal = goal_of != nullptr;
  const std::string expected =
      goal ? "a place {x, y, tolerance_m}, {edge, pos_m, lane, tolerance_m} "
             "or {slot, yaw_deg, tolerance_m, yaw_tolerance_deg}"
           : "a place {x, y} or {edge, pos_m, lane}";
  Fields f;
  if (!ReadFields(v, goal ? &kGoalKeys : &kStartKeys, &f, expected)) return;
  const bool by_xy = f.Get("x") || f.Get("y");
  const bool by_edge = f.Get("edge") || f.Get("pos_m") || f.Get("lane");
  const bool by_slot = f.Get("slot") != nullptr;
  const char* forms = goal ? "one of {x, y}, {edge, pos_m, lane} or {slot}"
                           : "either {x, y} or {edge, pos_m, lane}";
  if (int(by_xy) + int(by_edge) + int(by_slot) > 1) {
    Error(v.key_mark, v.path, forms, "fields of more than one");
  } else if (!by_xy && !by_edge && !by_slot) {
    Error(v.key_mark, v.path, forms, "none");
  } else if (by_slot) {
    location->by_edge = false;
    ReadString(*f.Get("slot"), &location->slot, "a parking slot name");
  } else if (by_xy) {
    location->by_edge = false;
    for (const char* key : {"x", "y"}) {
      double* out = key[0] == 'x' ? &location->x_m : &location->y_m;
      if (const Val* e = f.Get(key)) {
        ReadNumber(*e, out, Bounds{-1e7, 1e7});
      } else {
        Missing(v, key, "a coordinate in metres");
      }
    }
  } else {
    location->by_edge = true;
    if (const Val* e = f.Get("edge")) {
      ReadString(*e, &location->edge, "a SUMO edge id");
    } else {
      Missing(v, "edge", "a SUMO edge id");
    }
    if (const Val* e = f.Get("pos_m")) {
      ReadNumber(*e, &location->pos_m, Bounds::NonNegative());
    }
    if (const Val* e = f.Get("lane")) {
      ReadInt(*e, &location->lane, Bounds::Closed(0, 63));
    }
  }
  if (const Val* e = f.Get("tolerance_m")) {
    ReadNumber(*e, &goal_of->goal_tolerance_m, Bounds::Positive());
  }
  if (const Val* e = f.Get("yaw_deg")) {
    location->has_yaw = true;
    ReadNumber(*e, &location->yaw_deg, Bounds::Closed(-360, 360));
  }
  if (const Val* e = f.Get("yaw_tolerance_deg")) {
    ReadNumber(*e, &goal_of->goal_yaw_tolerance_deg,
               Bounds{0, 180, true, false});
  }
}

void SpecReader::ReadStack(const Val& v, const std::string& prefix) {
  // Valid keys at this level: the next path segment of every knob below
  // `prefix` (knob paths are short, so this recursion is shallow).
  std::vector<std::string> keys;
  const std::string dotted = prefix.empty() ? "" : prefix + ".";
  for (const KnobInfo& knob : StackKnobs()) {
    if (knob.path.compare(0, dotted.size(), dotted) != 0) continue;
    const std::string rest = knob.path.substr(dotted.size());
    const std::string segment = rest.substr(0, rest.find('.'));
    if (std::find(keys.begin(), keys.end(), segment) == keys.end()) {
      keys.push_back(segment);
    }
  }
  Fields f;
  if (!ReadFields(v, &keys, &f,
                  prefix.empty() ? "a map of stack components, e.g. "
                                   "{lidar: {rate_hz: 10}}"
                                 : "a map of parameters of " + prefix)) {
    return;
  }
  for (const std::string& key : f.order) {
    if (full()) return;
    const Val& e = *f.Get(key);
    const std::string path = dotted + key;
    const KnobInfo* knob = FindStackKnob(path);
    if (knob == nullptr) {
      ReadStack(e, path);
      continue;
    }
    const Bounds bounds = Bounds::Closed(knob->min_value, knob->max_value);
    double value = 0;
    const std::string noun = knob->integer ? "an integer" : "a number";
    if (!e.node.IsScalar() || !ParseNumber(e.node.Scalar(), &value) ||
        !bounds.Contains(value) ||
        (knob->integer && value != std::floor(value))) {
      Error(e, bounds.Describe(noun.c_str()) + " (" + knob->doc + ")");
      continue;
    }
    if (Status s = spec_.stack.Set(path, value); !s.ok()) {
      Error(e, s.message());
    }
  }
}

void SpecReader::ReadPlatform(const Val& v) {
  Fields f;
  if (!ReadFields(v, &kPlatformKeys, &f)) return;
  PlatformOptions& p = spec_.platform;
  if (const Val* e = f.Get("kind")) {
    ReadEnum(*e, &p.kind, PlatformKindNames(), StringToPlatformKind);
  }
  if (const Val* e = f.Get("reference_ghz")) {
    ReadNumber(*e, &p.reference_ghz, {0, kMaxPlatformFreqGhz, true, false});
  }
  if (const Val* e = f.Get("cost_model")) {
    ReadEnum(*e, &p.cost_model, CostModelNames(), StringToCostModel);
  }
  if (const Val* e = f.Get("calibration")) {
    if (ReadPath(*e, &p.calibration, "a path to a calibration file")) {
      std::error_code ec;
      if (check_files_ && !fs::is_regular_file(p.calibration, ec)) {
        Error(
            e->mark, e->path, "an existing calibration file",
            Quote(e->node.Scalar()) + " (no such file: " + p.calibration + ")");
      } else if (p.cost_model != CostModel::kCounted) {
        Error(e->mark, e->path, "cost_model: counted beside it",
              "cost_model: " + std::string(CostModelToString(p.cost_model)) +
                  " (a calibration costs the counted model's callbacks)");
      }
    }
  }
  if (const Val* e = f.Get("profile")) {
    if (ReadPath(*e, &p.profile, "a path to a cost profile")) {
      std::error_code ec;
      if (check_files_ && !fs::is_regular_file(p.profile, ec)) {
        Error(e->mark, e->path, "an existing cost profile file",
              Quote(e->node.Scalar()) + " (no such file: " + p.profile + ")");
      } else if (p.cost_model != CostModel::kCounted) {
        Error(e->mark, e->path, "cost_model: counted beside it",
              "cost_model: " + std::string(CostModelToString(p.cost_model)) +
                  " (a profile costs the counted model's callbacks)");
      } else if (!p.calibration.empty()) {
        Error(e->mark, e->path, "a profile or a calibration, not both",
              "both (the profile costs every callback; the calibration "
              "would be unused)");
      }
    }
  }
  if (const Val* e = f.Get("cores")) {
    ReadInt(*e, &p.cores, Bounds::Closed(1, kMaxPlatformCores));
  }
  if (const Val* e = f.Get("freq_ghz")) {
    ReadNumber(*e, &p.freq_ghz, {0, kMaxPlatformFreqGhz, true, false});
  }
  if (const Val* e = f.Get("cost_scale")) {
    ReadNumber(*e, &p.cost_scale, {0, 1000, true, false});
  }
  if (const Val* e = f.Get("time_dilation")) {
    ReadNumber(*e, &p.time_dilation, {1, 1000, false, false});
  }
  if (const Val* e = f.Get("clock_by")) {
    if (ReadEnum(*e, &p.clock_by, ClockByNames(), StringToClockBy) &&
        p.clock_by != ClockBy::kPadding && p.kind != PlatformKind::kCgroup) {
      Error(e->mark, e->path, "kind: cgroup beside it",
            "kind: " + std::string(PlatformKindToString(p.kind)) +
                " (only the real-time platform has CPU quotas or host "
                "clocks)");
    }
  }
  if (const Val* e = f.Get("dispatch")) {
    if (ReadEnum(*e, &p.dispatch, DispatchNames(), StringToDispatch) &&
        p.dispatch != Dispatch::kRunToCompletion &&
        p.kind != PlatformKind::kVirtual) {
      Error(e->mark, e->path, "kind: virtual beside it",
            "kind: " + std::string(PlatformKindToString(p.kind)) +
                " (on the real-time platform the host's scheduler "
                "dispatches)");
    }
  }
  if (const Val* e = f.Get("host_ghz")) {
    ReadNumber(*e, &p.host_ghz, {0, kMaxPlatformFreqGhz, false, false});
  }
}

}  // namespace adse::spec::internal
