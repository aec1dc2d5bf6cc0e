// NormalizedYaml: the whole spec, defaults filled in, in the v1 format.
// Each section is a table of fields (key, when present, how written), so
// adding a field to the format is one row here beside its reader.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <functional>
#include <string>
#include <vector>

#include "harness/spec/spec_parser.h"
#include "harness/spec/text_util.h"
#include "harness/spec/types.h"
#include "stack/config/stack_config.h"

namespace adse::spec {
namespace {

// Lists longer than this are written as their range when they are one.
constexpr size_t kLongList = 64;

template <typename T>
struct Field {
  const char* key;
  // How the value is written; the spec gives context (e.g. the design
  // space's order for a point).
  std::function<void(YAML::Emitter&, const T&, const Spec&)> emit;
  // Whether the field is written at all; null: always.
  std::function<bool(const T&)> present = nullptr;
};

// The fields' keys and values, inside a map the caller opened.
template <typename T>
void EmitEntries(YAML::Emitter& out, const T& value, const Spec& spec,
                 const std::vector<Field<T>>& fields) {
  for (const Field<T>& f : fields) {
    if (f.present && !f.present(value)) continue;
    out << YAML::Key << f.key << YAML::Value;
    f.emit(out, value, spec);
  }
}

template <typename T>
void EmitFields(YAML::Emitter& out, const T& value, const Spec& spec,
                const std::vector<Field<T>>& fields) {
  out << YAML::BeginMap;
  EmitEntries(out, value, spec, fields);
  out << YAML::EndMap;
}

// Field makers for the common shapes.
template <typename T>
Field<T> Number(const char* key, double T::*member) {
  return {key, [member](YAML::Emitter& out, const T& v, const Spec&) {
            out << FormatNumber(v.*member);
          }};
}
template <typename T, typename I>
Field<T> Integer(const char* key, I T::*member) {
  return {key, [member](YAML::Emitter& out, const T& v, const Spec&) {
            out << std::to_string(v.*member);
          }};
}
template <typename T>
Field<T> Boolean(const char* key, bool T::*member) {
  return {key, [member](YAML::Emitter& out, const T& v, const Spec&) {
            out << (v.*member ? "true" : "false");
          }};
}
template <typename T>
Field<T> Plain(const char* key, std::string T::*member) {
  return {key, [member](YAML::Emitter& out, const T& v, const Spec&) {
            out << v.*member;
          }};
}
// Quoted: paths, ids and free text that could read as another type.
template <typename T>
Field<T> Quoted(const char* key, std::string T::*member) {
  return {key, [member](YAML::Emitter& out, const T& v, const Spec&) {
            out << YAML::DoubleQuoted << v.*member;
          }};
}
template <typename T>
Field<T> QuotedIfSet(const char* key, std::string T::*member) {
  Field<T> f = Quoted(key, member);
  f.present = [member](const T& v) { return !(v.*member).empty(); };
  return f;
}
template <typename T>
Field<T> QuotedList(const char* key, std::vector<std::string> T::*member) {
  return {key, [member](YAML::Emitter& out, const T& v, const Spec&) {
            out << YAML::Flow << YAML::BeginSeq;
            for (const std::string& s : v.*member)
              out << YAML::DoubleQuoted << s;
            out << YAML::EndSeq;
          }};
}

void EmitPoint(YAML::Emitter& out, const DesignPoint& point,
               const DesignSpace& space) {
  out << YAML::Flow << YAML::BeginMap;
  // In the space's order, which is the order users wrote.
  for (const DesignParameter& p : space.parameters) {
    if (auto it = point.find(p.name); it != point.end()) {
      out << YAML::Key << p.name << YAML::Value << FormatNumber(it->second);
    }
  }
  out << YAML::EndMap;
}

void EmitLocation(YAML::Emitter& out, const world::Location& l,
                  const world::TaskOptions* goal_of) {
  out << YAML::Flow << YAML::BeginMap;
  if (!l.slot.empty()) {
    out << YAML::Key << "slot" << YAML::Value << YAML::DoubleQuoted << l.slot;
  } else if (l.by_edge) {
    out << YAML::Key << "edge" << YAML::Value << YAML::DoubleQuoted << l.edge;
    out << YAML::Key << "pos_m" << YAML::Value << FormatNumber(l.pos_m);
    out << YAML::Key << "lane" << YAML::Value << l.lane;
  } else {
    out << YAML::Key << "x" << YAML::Value << FormatNumber(l.x_m);
    out << YAML::Key << "y" << YAML::Value << FormatNumber(l.y_m);
  }
  if (l.has_yaw) {
    out << YAML::Key << "yaw_deg" << YAML::Value << FormatNumber(l.yaw_deg);
  }
  if (goal_of != nullptr) {
    out << YAML::Key << "tolerance_m" << YAML::Value
        << FormatNumber(goal_of->goal_tolerance_m);
    // Only a parked pose has a heading to hold: lane-driving scenarios
    // normalise (and key their runs) as before.
    if (goal_of->kind == world::TaskKind::kValetParking) {
      out << YAML::Key << "yaw_tolerance_deg" << YAML::Value
          << FormatNumber(goal_of->goal_yaw_tolerance_deg);
    }
  }
  out << YAML::EndMap;
}

// Knob paths as nested maps ("lidar.rate_hz" -> lidar: {rate_hz: ...}), in
// StackKnobs() order.
void EmitStack(YAML::Emitter& out, const StackConfig& stack,
               const std::string& prefix) {
  std::vector<std::string> segments;
  for (const KnobInfo& knob : StackKnobs()) {
    if (knob.path.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = knob.path.substr(prefix.size());
    const std::string segment = rest.substr(0, rest.find('.'));
    if (std::find(segments.begin(), segments.end(), segment) ==
        segments.end()) {
      segments.push_back(segment);
    }
  }
  out << YAML::BeginMap;
  for (const std::string& segment : segments) {
    const std::string path = prefix + segment;
    out << YAML::Key << segment << YAML::Value;
    if (FindStackKnob(path) != nullptr) {
      out << FormatNumber(stack.Get(path));
    } else {
      EmitStack(out, stack, path + ".");
    }
  }
  out << YAML::EndMap;
}

void EmitMap(YAML::Emitter& out, const world::MapOptions& map) {
  out << YAML::Flow << YAML::BeginMap;
  if (!map.generator.empty()) {
    out << YAML::Key << "generate" << YAML::Value << map.generator;
    out << YAML::Key << "params" << YAML::Value << YAML::Flow << YAML::BeginMap;
    if (const auto* params = world::MapGeneratorParams(map.generator)) {
      for (const world::MapGeneratorParam& p : *params) {
        out << YAML::Key << p.name << YAML::Value
            << FormatNumber(world::MapGeneratorParamValue(map, p.name));
      }
    }
    out << YAML::EndMap;
  } else {
    out << YAML::Key << "net" << YAML::Value << YAML::DoubleQuoted
        << map.net_path;
  }
  if (!map.polygons_path.empty()) {
    out << YAML::Key << "polygons" << YAML::Value << YAML::DoubleQuoted
        << map.polygons_path;
  }
  out << YAML::EndMap;
}

using world::TaskOptions;
using world::TrafficOptions;
using world::WorldOptions;

const std::vector<Field<TrafficOptions>>& TrafficFields() {
  static const std::vector<Field<TrafficOptions>> kFields = {
      Integer("seed", &TrafficOptions::seed),
      {"flows",
       [](YAML::Emitter& out, const TrafficOptions& t, const Spec&) {
         out << YAML::BeginSeq;
         for (const world::Flow& flow : t.flows) {
           out << YAML::Flow << YAML::BeginMap;
           out << YAML::Key << "from" << YAML::Value << YAML::DoubleQuoted
               << flow.from_edge;
           out << YAML::Key << "to" << YAML::Value << YAML::DoubleQuoted
               << flow.to_edge;
           out << YAML::Key << "vehicles_per_hour" << YAML::Value
               << FormatNumber(flow.vehicles_per_hour);
           out << YAML::EndMap;
         }
         out << YAML::EndSeq;
       }},
      Number("parked_occupancy", &TrafficOptions::parked_occupancy),
      Number("signal_program_switch_s",
             &TrafficOptions::signal_program_switch_s),
      {"parked_slots",
       [](YAML::Emitter& out, const TrafficOptions& t, const Spec&) {
         out << YAML::Flow << YAML::BeginSeq;
         for (const std::string& name : t.parked_slots) out << name;
         out << YAML::EndSeq;
       },
       [](const TrafficOptions& t) { return !t.parked_slots.empty(); }},
      {"stopped_vehicles",
       [](YAML::Emitter& out, const TrafficOptions& t, const Spec&) {
         out << YAML::BeginSeq;
         for (const world::Location& l : t.stopped_vehicles) {
           EmitLocation(out, l, nullptr);
         }
         out << YAML::EndSeq;
       },
       [](const TrafficOptions& t) { return !t.stopped_vehicles.empty(); }}};
  return kFields;
}

const std::vector<Field<WorldOptions>>& WorldFields() {
  static const std::vector<Field<WorldOptions>> kFields = {
      {"map", [](YAML::Emitter& out, const WorldOptions& w,
                 const Spec&) { EmitMap(out, w.map); }},
      {"traffic",
       [](YAML::Emitter& out, const WorldOptions& w, const Spec& spec) {
         EmitFields(out, w.traffic, spec, TrafficFields());
       }},
      {"weather",
       [](YAML::Emitter& out, const WorldOptions& w, const Spec&) {
         out << world::WeatherToString(w.weather);
       }},
      Number("step_s", &WorldOptions::step_s)};
  return kFields;
}

const std::vector<Field<TaskOptions>>& TaskFields() {
  static const std::vector<Field<TaskOptions>> kFields = {
      {"kind", [](YAML::Emitter& out, const TaskOptions& t,
                  const Spec&) { out << world::TaskKindToString(t.kind); }},
      {"start", [](YAML::Emitter& out, const TaskOptions& t,
                   const Spec&) { EmitLocation(out, t.start, nullptr); }},
      {"via",
       [](YAML::Emitter& out, const TaskOptions& t, const Spec&) {
         out << YAML::Flow << YAML::BeginSeq;
         for (const world::Location& l : t.via) EmitLocation(out, l, nullptr);
         out << YAML::EndSeq;
       },
       [](const TaskOptions& t) { return !t.via.empty(); }},
      {"goal", [](YAML::Emitter& out, const TaskOptions& t,
                  const Spec&) { EmitLocation(out, t.goal, &t); }},
      Number("speed_limit_kmh", &TaskOptions::speed_limit_kmh),
      Number("timeout_s", &TaskOptions::timeout_s),
      Number("stall_timeout_s", &TaskOptions::stall_timeout_s),
      Number("traffic_stall_timeout_s", &TaskOptions::traffic_stall_timeout_s)};
  return kFields;
}

// The task's fields, then its cases, each with its places in full.
void EmitTask(YAML::Emitter& out, const Spec& spec) {
  out << YAML::BeginMap;
  EmitEntries(out, spec.task, spec, TaskFields());
  if (!spec.cases.empty()) {
    out << YAML::Key << "cases" << YAML::Value << YAML::BeginSeq;
    for (const TaskCase& c : spec.cases) {
      out << YAML::BeginMap;
      out << YAML::Key << "name" << YAML::Value << c.name;
      out << YAML::Key << "start" << YAML::Value;
      EmitLocation(out, c.task.start, nullptr);
      if (!c.task.via.empty() || !spec.task.via.empty()) {
        out << YAML::Key << "via" << YAML::Value << YAML::Flow
            << YAML::BeginSeq;
        for (const world::Location& l : c.task.via) {
          EmitLocation(out, l, nullptr);
        }
        out << YAML::EndSeq;
      }
      out << YAML::Key << "goal" << YAML::Value;
      EmitLocation(out, c.task.goal, &c.task);
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
  out << YAML::EndMap;
}

const std::vector<Field<PlatformOptions>>& PlatformFields() {
  static const std::vector<Field<PlatformOptions>> kFields = {
      {"kind", [](YAML::Emitter& out, const PlatformOptions& p,
                  const Spec&) { out << PlatformKindToString(p.kind); }},
      Number("reference_ghz", &PlatformOptions::reference_ghz),
      {"cost_model",
       [](YAML::Emitter& out, const PlatformOptions& p, const Spec&) {
         out << CostModelToString(p.cost_model);
       }},
      QuotedIfSet("calibration", &PlatformOptions::calibration),
      QuotedIfSet("profile", &PlatformOptions::profile),
      Integer("cores", &PlatformOptions::cores),
      Number("freq_ghz", &PlatformOptions::freq_ghz),
      Number("cost_scale", &PlatformOptions::cost_scale),
      // Written when not the default, so that the normalised text of
      // scenarios from before it stays as it was.
      {"dispatch",
       [](YAML::Emitter& out, const PlatformOptions& p, const Spec&) {
         out << DispatchToString(p.dispatch);
       },
       [](const PlatformOptions& p) {
         return p.dispatch != Dispatch::kRunToCompletion;
       }},
      [] {
        // Only the real-time platform has a clock to slow.
        Field<PlatformOptions> f =
            Number("time_dilation", &PlatformOptions::time_dilation);
        f.present = [](const PlatformOptions& p) {
          return p.kind == PlatformKind::kCgroup;
        };
        return f;
      }(),
      {"clock_by",
       [](YAML::Emitter& out, const PlatformOptions& p, const Spec&) {
         out << ClockByToString(p.clock_by);
       },
       [](const PlatformOptions& p) {
         return p.kind == PlatformKind::kCgroup;
       }},
      [] {
        Field<PlatformOptions> f =
            Number("host_ghz", &PlatformOptions::host_ghz);
        f.present = [](const PlatformOptions& p) {
          return p.clock_by == ClockBy::kQuota;
        };
        return f;
      }()};
  return kFields;
}

const std::vector<Field<ExplorationOptions>>& ExplorationFields() {
  using X = ExplorationOptions;
  static const std::vector<Field<X>> kFields = {
      Plain("strategy", &X::strategy),
      Integer("budget", &X::budget),
      Integer("confirm_runs", &X::confirm_runs),
      Integer("batch", &X::batch),
      Integer("seed", &X::seed),
      {"start_from",
       [](YAML::Emitter& out, const X& x, const Spec& spec) {
         EmitPoint(out, x.start_from, spec.design_space);
       },
       [](const X& x) { return !x.start_from.empty(); }},
      // Written only when set, so that scenarios without it keep their
      // normalised text.
      [] {
        Field<X> f = Integer("initial_points", &X::initial_points);
        f.present = [](const X& x) { return x.initial_points != 0; };
        return f;
      }(),
      Integer("population", &X::population),
      Number("crossover_rate", &X::crossover_rate),
      Number("mutation_rate", &X::mutation_rate)};
  return kFields;
}

const std::vector<Field<LlmOptions>>& LlmFields() {
  static const std::vector<Field<LlmOptions>> kFields = {
      Plain("backend", &LlmOptions::backend),
      Quoted("endpoint", &LlmOptions::endpoint),
      {"models",
       [](YAML::Emitter& out, const LlmOptions& l, const Spec&) {
         out << YAML::BeginMap;
         for (const std::string& role : LlmRoleNames()) {
           if (auto it = l.models.find(role); it != l.models.end()) {
             out << YAML::Key << role << YAML::Value << YAML::DoubleQuoted
                 << it->second;
           }
         }
         out << YAML::EndMap;
       }},
      QuotedIfSet("prompts", &LlmOptions::prompts),
      QuotedIfSet("replay_from", &LlmOptions::replay_from),
      Number("timeout_s", &LlmOptions::timeout_s),
      Integer("retries", &LlmOptions::retries),
      Plain("api_key_env", &LlmOptions::api_key_env)};
  return kFields;
}

const std::vector<Field<SlurmOptions>>& SlurmFields() {
  using S = SlurmOptions;
  static const std::vector<Field<S>> kFields = {
      QuotedIfSet("partition", &S::partition),
      QuotedIfSet("account", &S::account),
      Integer("nodes", &S::nodes),
      Integer("cpus", &S::cpus),
      Quoted("time_limit", &S::time_limit),
      Integer("max_parallel", &S::max_parallel),
      Integer("shard_size", &S::shard_size),
      Integer("signal_lead_s", &S::signal_lead_s),
      Number("run_estimate_s", &S::run_estimate_s),
      QuotedList("extra_args", &S::extra_args)};
  return kFields;
}

const std::vector<Field<HarnessOptions>>& HarnessFields() {
  using H = HarnessOptions;
  static const std::vector<Field<H>> kFields = {
      {"workers",
       [](YAML::Emitter& out, const H& h, const Spec&) {
         out << (h.workers > 0 ? std::to_string(h.workers) : "auto");
       }},
      Integer("cores_per_worker", &H::cores_per_worker),
      Integer("memory_mb", &H::memory_mb),
      Number("run_timeout_s", &H::run_timeout_s),
      Integer("retries", &H::retries),
      Integer("replicas", &H::replicas),
      Boolean("early_stop", &H::early_stop),
      Plain("isolation", &H::isolation),
      Plain("executor", &H::executor),
      QuotedIfSet("cache_dir", &H::cache_dir),
      {"slurm", [](YAML::Emitter& out, const H& h, const Spec& spec) {
         EmitFields(out, h.slurm, spec, SlurmFields());
       }}};
  return kFields;
}

// The top level: one field per section, in the order of the format.
const std::vector<Field<Spec>>& SpecFields() {
  static const std::vector<Field<Spec>> kFields = {
      Integer("adse", &Spec::version),
      Quoted("name", &Spec::name),
      {"world",
       [](YAML::Emitter& out, const Spec& s, const Spec&) {
         EmitFields(out, s.world, s, WorldFields());
       }},
      {"task", [](YAML::Emitter& out, const Spec& s,
                  const Spec&) { EmitTask(out, s); }},
      {"stack", [](YAML::Emitter& out, const Spec& s,
                   const Spec&) { EmitStack(out, s.stack, ""); }},
      {"platform",
       [](YAML::Emitter& out, const Spec& s, const Spec&) {
         EmitFields(out, s.platform, s, PlatformFields());
       }},
      {"design_space",
       [](YAML::Emitter& out, const Spec& s, const Spec&) {
         out << YAML::BeginMap;
         for (const DesignParameter& d : s.design_space.parameters) {
           out << YAML::Key << d.name << YAML::Value << YAML::Flow
               << YAML::BeginMap;
           out << YAML::Key << "bind" << YAML::Value << d.bind;
           if (d.role != DefaultKnobRole(d.bind)) {
             out << YAML::Key << "role" << YAML::Value
                 << KnobRoleToString(d.role);
           }
           // A long regular list is written back as the range it came
           // from, so the normalised text stays within kMaxSpecBytes.
           std::string lo, hi, step;
           if (d.values.size() > kLongList &&
               RangeOf(d.values, &lo, &hi, &step)) {
             out << YAML::Key << "range" << YAML::Value << YAML::Flow
                 << YAML::BeginSeq << lo << hi << YAML::EndSeq;
             out << YAML::Key << "step" << YAML::Value << step;
             out << YAML::EndMap;
             continue;
           }
           out << YAML::Key << "values" << YAML::Value << YAML::Flow
               << YAML::BeginSeq;
           for (double value : d.values) out << FormatNumber(value);
           out << YAML::EndSeq << YAML::EndMap;
         }
         out << YAML::EndMap;
       }},
      Quoted("cost", &Spec::cost),
      {"objectives",
       [](YAML::Emitter& out, const Spec& s, const Spec&) {
         out << YAML::Flow << YAML::BeginSeq;
         for (const Objective& o : s.objectives) {
           out << YAML::Flow << YAML::BeginMap << YAML::Key
               << (o.minimize ? "minimize" : "maximize") << YAML::Value
               << o.metric << YAML::EndMap;
         }
         out << YAML::EndSeq;
       }},
      QuotedList("constraints", &Spec::constraints),
      {"exploration",
       [](YAML::Emitter& out, const Spec& s, const Spec&) {
         EmitFields(out, s.exploration, s, ExplorationFields());
       }},
      {"llm", [](YAML::Emitter& out, const Spec& s,
                 const Spec&) { EmitFields(out, s.llm, s, LlmFields()); }},
      {"harness",
       [](YAML::Emitter& out, const Spec& s, const Spec&) {
         EmitFields(out, s.harness, s, HarnessFields());
       }},
      Quoted("output", &Spec::output)};
  return kFields;
}

}  // namespace

std::string NormalizedYaml(const Spec& spec) {
  YAML::Emitter out;
  EmitFields(out, spec, spec, SpecFields());
  return std::string(out.c_str()) + "\n";
}

}  // namespace adse::spec
