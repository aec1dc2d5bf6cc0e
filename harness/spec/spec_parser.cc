#include "harness/spec/spec_parser.h"

#include <fmt/format.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <tuple>
#include <utility>

#include "harness/spec/expression.h"
#include "harness/spec/text_util.h"
#include "stack/base/files.h"

namespace adse::spec {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------
// Vocabulary of the format.

const std::vector<std::string> kTopKeys = {
    "adse",        "name",         "world",   "task",       "stack",
    "platform",    "design_space", "cost",    "objectives", "constraints",
    "exploration", "llm",          "harness", "output"};
const std::vector<std::string> kWorldKeys = {"map", "traffic", "weather",
                                             "step_s"};
const std::vector<std::string> kMapKeys = {"generate", "params", "net",
                                           "polygons"};
const std::vector<std::string> kTrafficKeys = {"seed", "flows",
                                               "parked_occupancy"};
const std::vector<std::string> kFlowKeys = {"from", "to", "vehicles_per_hour"};
const std::vector<std::string> kTaskKeys = {"kind", "start", "goal",
                                            "speed_limit_kmh", "timeout_s"};
const std::vector<std::string> kStartKeys = {"x", "y", "edge", "pos_m", "lane"};
const std::vector<std::string> kGoalKeys = {"x",     "y",    "edge",
                                            "pos_m", "lane", "tolerance_m"};
const std::vector<std::string> kPlatformKeys = {
    "kind",  "reference_ghz", "cost_model", "calibration",
    "cores", "freq_ghz",      "cost_scale"};
const std::vector<std::string> kParameterKeys = {"bind", "range", "values",
                                                 "step"};
const std::vector<std::string> kObjectiveKeys = {"minimize", "maximize"};
const std::vector<std::string> kExplorationKeys = {
    "strategy",   "budget",     "batch",          "seed",
    "start_from", "population", "crossover_rate", "mutation_rate"};
const std::vector<std::string> kLlmKeys = {
    "backend",     "endpoint",  "models",  "prompts",
    "replay_from", "timeout_s", "retries", "api_key_env"};
const std::vector<std::string> kHarnessKeys = {
    "workers",  "cores_per_worker", "memory_mb", "run_timeout_s", "retries",
    "replicas", "isolation",        "executor",  "cache_dir",     "slurm"};
const std::vector<std::string> kSlurmKeys = {
    "partition",     "account",       "nodes",      "cpus",
    "time_limit",    "max_parallel",  "shard_size", "extra_args",
    "signal_lead_s", "run_estimate_s"};

const std::vector<std::string> kWeathers = {"clear", "rain", "fog"};
const std::vector<std::string> kTaskKinds = {"lane_driving", "valet_parking"};
const std::vector<std::string> kGenerators = {"parking_lot", "grid"};
const std::vector<std::string> kPlatformKinds = {"virtual", "cgroup"};
const std::vector<std::string> kCostModels = {"measured", "counted"};
const std::vector<std::string> kStrategies = {"exhaustive", "random", "ga",
                                              "nsga2",      "agent",  "llm"};
const std::vector<std::string> kBackends = {"ollama", "openai", "replay"};
const std::vector<std::string> kLlmRoles = {"dse", "vision", "text", "command",
                                            "interpretation"};
const std::vector<std::string> kIsolations = {"auto", "cgroup", "affinity"};
const std::vector<std::string> kExecutors = {"local", "slurm"};

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

struct GeneratorParam {
  const char* name;
  bool integer;
  double min_value;
  double max_value;
  double default_value;
};

const std::vector<GeneratorParam>& GeneratorParams(const std::string& gen) {
  static const std::vector<GeneratorParam> kParkingLot = {
      {"rows", true, 1, 20, 4},
      {"slots_per_row", true, 1, 60, 12},
      {"aisle_width_m", false, 5, 15, 7.0},
      {"slot_width_m", false, 2.0, 4.0, 2.5},
      {"slot_depth_m", false, 4.0, 7.0, 5.0}};
  static const std::vector<GeneratorParam> kGrid = {
      {"number", true, 2, 12, 3},
      {"length_m", false, 20, 500, 100},
      {"lanes", true, 1, 4, 1}};
  static const std::vector<GeneratorParam> kNone;
  if (gen == "parking_lot") return kParkingLot;
  if (gen == "grid") return kGrid;
  return kNone;
}

constexpr const char* kPlatformCores = "platform.cores";
constexpr const char* kPlatformFreq = "platform.freq_ghz";
constexpr int kMaxPlatformCores = 1024;
constexpr double kMaxFreqGhz = 10.0;

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

const char* WeatherText(world::Weather w) {
  switch (w) {
    case world::Weather::kClear:
      return "clear";
    case world::Weather::kRain:
      return "rain";
    case world::Weather::kFog:
      return "fog";
  }
  return "clear";
}

const char* TaskKindText(world::TaskKind k) {
  return k == world::TaskKind::kValetParking ? "valet_parking" : "lane_driving";
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

// ---------------------------------------------------------------------------
// Pre-scan: bounds the document before yaml-cpp builds any node, so deep
// nesting, alias bombs and huge node counts cost little.

struct LimitExceeded {
  YAML::Mark mark;
  std::string expected;
  std::string found;
};

class LimitScanner : public YAML::EventHandler {
 public:
  void OnDocumentStart(const YAML::Mark&) override { ++documents_; }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t) override { Count(mark); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override {
    Count(mark);
    if (++aliases_ > kMaxYamlAliases) {
      throw LimitExceeded{
          mark, fmt::format("at most {} aliases (*name)", kMaxYamlAliases),
          "more (an alias bomb?)"};
    }
  }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string&) override {
    Count(mark);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&,
                       YAML::anchor_t, YAML::EmitterStyle::value) override {
    Open(mark);
  }
  void OnSequenceEnd() override { --depth_; }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    Open(mark);
  }
  void OnMapEnd() override { --depth_; }

  int documents() const { return documents_; }

 private:
  void Count(const YAML::Mark& mark) {
    if (++nodes_ > kMaxYamlNodes) {
      throw LimitExceeded{mark, fmt::format("at most {} nodes", kMaxYamlNodes),
                          "more"};
    }
  }
  // Throwing here stops yaml-cpp's recursive descent at our depth, long
  // before its own (much larger) guard or the stack.
  void Open(const YAML::Mark& mark) {
    Count(mark);
    if (++depth_ > kMaxYamlDepth) {
      throw LimitExceeded{
          mark, fmt::format("nesting at most {} levels deep", kMaxYamlDepth),
          "deeper nesting"};
    }
  }

  int documents_ = 0;
  int depth_ = 0;
  int nodes_ = 0;
  int aliases_ = 0;
};

// ---------------------------------------------------------------------------
// The reader: walks the node tree along the schema (never generically, so
// shared alias nodes are visited a bounded number of times) and fills Spec.

// A value in the file: its node, where it is, and its field path.
struct Val {
  YAML::Node node;
  YAML::Mark mark;      // of the value (or of the key when the value is empty)
  YAML::Mark key_mark;  // of the key; equals `mark` for list items
  std::string path;
};

// The entries of a map, in file order, by key.
struct Fields {
  std::vector<std::string> order;
  std::map<std::string, Val> by_key;
  const Val* Get(const std::string& key) const {
    auto it = by_key.find(key);
    return it == by_key.end() ? nullptr : &it->second;
  }
};

struct Diagnostic {
  int line = 0;  // 1-based; 0 when unknown
  int column = 0;
  size_t sequence = 0;
  std::string text;
};

struct Bounds {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;

  static Bounds Positive() { return {0, Bounds().hi, true, false}; }
  static Bounds NonNegative() { return {0, Bounds().hi, false, false}; }
  static Bounds Closed(double lo, double hi) { return {lo, hi, false, false}; }

  bool Contains(double v) const {
    if (lo_open ? v <= lo : v < lo) return false;
    if (hi_open ? v >= hi : v > hi) return false;
    return true;
  }
  std::string Describe(const char* noun) const {
    const bool has_lo = std::isfinite(lo);
    const bool has_hi = std::isfinite(hi);
    if (has_lo && has_hi) {
      return fmt::format("{} in {}{}, {}{}", noun, lo_open ? "(" : "[",
                         FormatNumber(lo), FormatNumber(hi),
                         hi_open ? ")" : "]");
    }
    if (has_lo) {
      return fmt::format("{} {} {}", noun,
                         lo_open ? ">" : ">=", FormatNumber(lo));
    }
    if (has_hi) {
      return fmt::format("{} {} {}", noun,
                         hi_open ? "<" : "<=", FormatNumber(hi));
    }
    return noun;
  }
};

std::string Quote(const std::string& text) {
  constexpr size_t kMaxShown = 60;
  std::string shown;
  for (char c : text.substr(0, kMaxShown)) {
    if (c == '\n') {
      shown += "\\n";
    } else if (static_cast<unsigned char>(c) < 0x20) {
      shown += '?';
    } else {
      shown += c;
    }
  }
  if (text.size() > kMaxShown) shown += "...";
  return "'" + shown + "'";
}

std::string Describe(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsScalar()) {
    double number = 0;
    // Numbers read better bare: "found 0", "found 'fast'".
    if (node.Scalar().size() < 32 && ParseNumber(node.Scalar(), &number)) {
      return node.Scalar();
    }
    return Quote(node.Scalar());
  }
  if (node.IsSequence()) {
    return node.size() == 1 ? "a list of 1 item"
                            : fmt::format("a list of {} items", node.size());
  }
  if (node.IsMap()) return "a map";
  return "something else";
}

std::string Join(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

class SpecReader {
 public:
  SpecReader(Spec* spec, bool check_files)
      : spec_(*spec), check_files_(check_files) {}

  void Read(const YAML::Node& root);

  // Diagnostic for a whole-file problem (no node).
  void FileError(const YAML::Mark& mark, const std::string& path,
                 const std::string& expected, const std::string& found) {
    Error(mark, path, expected, found);
  }

  std::vector<Diagnostic> TakeErrors() {
    std::stable_sort(errors_.begin(), errors_.end(),
                     [](const Diagnostic& a, const Diagnostic& b) {
                       return std::tie(a.line, a.column, a.sequence) <
                              std::tie(b.line, b.column, b.sequence);
                     });
    return std::move(errors_);
  }
  bool full() const { return errors_.size() >= kMaxSpecErrors; }
  bool has_errors() const { return !errors_.empty(); }

 private:
  // --- diagnostics ---
  void Error(const YAML::Mark& mark, const std::string& path,
             const std::string& expected, const std::string& found,
             const std::string& suffix = "") {
    if (full()) return;
    Diagnostic d;
    d.line = mark.is_null() ? 1 : mark.line + 1;
    d.column = mark.is_null() ? 1 : mark.column + 1;
    d.sequence = errors_.size();
    d.text = fmt::format("{}:{}:{}: error: {}: expected {}, found {}{}",
                         spec_.source_path, d.line, d.column,
                         path.empty() ? "(top level)" : path, expected, found,
                         suffix);
    errors_.push_back(std::move(d));
  }
  void Error(const Val& v, const std::string& expected,
             const std::string& suffix = "") {
    Error(v.mark, v.path, expected, Describe(v.node), suffix);
  }
  void Missing(const Val& parent, const std::string& key,
               const std::string& expected) {
    Error(parent.key_mark, Join(parent.path, key), expected + " (required)",
          "nothing");
  }
  void Mark(const std::string& path, const YAML::Mark& mark) {
    if (mark.is_null()) return;
    spec_.marks[path] = SourceMark{mark.line + 1, mark.column + 1};
  }

  // --- structure ---
  // Reads a map's entries; reports a non-map, non-scalar keys, duplicate
  // keys and (when `allowed` is given) unknown keys. False when not a map.
  bool ReadFields(const Val& v, const std::vector<std::string>* allowed,
                  Fields* out, const std::string& expected = "a map") {
    if (!v.node.IsMap()) {
      Error(v, expected);
      return false;
    }
    std::map<std::string, int> first_line;
    for (auto it = v.node.begin(); it != v.node.end(); ++it) {
      if (full()) return true;
      const YAML::Node key = it->first;
      const YAML::Node value = it->second;
      if (!key.IsScalar()) {
        Error(key.Mark(), v.path, "plain keys", Describe(key) + " as a key");
        continue;
      }
      const std::string name = key.Scalar();
      const std::string path = Join(v.path, name);
      if (auto seen = first_line.find(name); seen != first_line.end()) {
        Error(key.Mark(), path, "each key once",
              fmt::format("'{}' again (first at line {})", name, seen->second));
        continue;
      }
      first_line[name] = key.Mark().line + 1;
      if (allowed != nullptr &&
          std::find(allowed->begin(), allowed->end(), name) == allowed->end()) {
        Error(key.Mark(), path, "a key among {" + JoinList(*allowed) + "}",
              Quote(name), DidYouMean(name, *allowed));
        continue;
      }
      Val entry;
      entry.node = value;
      entry.key_mark = key.Mark();
      // An empty value (`key:`) has no useful mark of its own.
      entry.mark = value.IsNull() ? key.Mark() : value.Mark();
      entry.path = path;
      Mark(path, key.Mark());
      out->order.push_back(name);
      out->by_key.emplace(name, std::move(entry));
    }
    return true;
  }

  bool ReadList(const Val& v, std::vector<Val>* items,
                const std::string& expected = "a list") {
    if (!v.node.IsSequence()) {
      Error(v, expected);
      return false;
    }
    size_t index = 0;
    for (const YAML::Node& item : v.node) {
      Val entry;
      entry.node = item;
      entry.mark = item.IsNull() ? v.mark : item.Mark();
      entry.key_mark = entry.mark;
      entry.path = fmt::format("{}[{}]", v.path, index++);
      Mark(entry.path, entry.mark);
      items->push_back(std::move(entry));
    }
    return true;
  }

  // --- scalars ---
  bool ReadNumber(const Val& v, double* out, const Bounds& bounds,
                  const char* noun = "a number") {
    double value = 0;
    if (!v.node.IsScalar() || !ParseNumber(v.node.Scalar(), &value) ||
        !bounds.Contains(value)) {
      Error(v, bounds.Describe(noun));
      return false;
    }
    *out = value;
    return true;
  }
  bool ReadInt(const Val& v, int* out, const Bounds& bounds) {
    double value = 0;
    const Bounds limited{std::max(bounds.lo, -1e9), std::min(bounds.hi, 1e9),
                         bounds.lo_open, bounds.hi_open};
    if (!v.node.IsScalar() || !ParseNumber(v.node.Scalar(), &value) ||
        value != std::floor(value) || !limited.Contains(value)) {
      Error(v, bounds.Describe("an integer"));
      return false;
    }
    *out = static_cast<int>(value);
    return true;
  }
  bool ReadSeed(const Val& v, uint64_t* out) {
    const std::string text = v.node.IsScalar() ? v.node.Scalar() : "";
    uint64_t value = 0;
    const auto [end, ec] =
        std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || ec != std::errc() || end != text.data() + text.size()) {
      Error(v, "an integer in [0, 18446744073709551615]");
      return false;
    }
    *out = value;
    return true;
  }
  bool ReadString(const Val& v, std::string* out,
                  const std::string& expected = "a non-empty string") {
    if (!v.node.IsScalar() || v.node.Scalar().empty()) {
      Error(v, expected);
      return false;
    }
    *out = v.node.Scalar();
    return true;
  }
  bool ReadEnum(const Val& v, std::string* out,
                const std::vector<std::string>& options) {
    const std::string expected = "one of " + JoinList(options);
    if (!v.node.IsScalar()) {
      Error(v, expected);
      return false;
    }
    const std::string& text = v.node.Scalar();
    if (std::find(options.begin(), options.end(), text) == options.end()) {
      Error(v, expected, DidYouMean(text, options));
      return false;
    }
    *out = text;
    return true;
  }
  // A path written in the file, made absolute from the file's folder.
  bool ReadPath(const Val& v, std::string* out, const std::string& what) {
    std::string written;
    if (!ReadString(v, &written, what)) return false;
    fs::path path(written);
    if (path.is_relative()) path = fs::path(spec_.base_dir) / path;
    *out = path.lexically_normal().string();
    return true;
  }

  // --- sections ---
  void ReadWorld(const Val& v);
  void ReadMapSource(const Val& v);
  void ReadTraffic(const Val& v);
  void ReadTask(const Val& v);
  void ReadLocation(const Val& v, bool goal, world::Location* location);
  void ReadStack(const Val& v, const std::string& prefix);
  void ReadPlatform(const Val& v);
  void ReadDesignSpace(const Val& v);
  void ReadParameter(const std::string& name, const Val& v,
                     std::map<std::string, std::string>* bound);
  bool CheckBinding(const DesignParameter& p, const Val& at,
                    const std::vector<Val>* items);
  void ReadCost(const Val& v);
  void ReadObjectives(const Val& v);
  void ReadConstraints(const Val& v);
  void ReadExploration(const Val& v);
  void ReadStartFrom(const Val& v);
  void ReadLlm(const Val& v);
  void ReadHarness(const Val& v);
  void ReadSlurm(const Val& v);
  void ReadOutput(const Val* v);
  void ReadExpression(const Val& v, const std::vector<std::string>& names,
                      const std::string& expected);

  Spec& spec_;
  bool check_files_ = true;
  std::vector<Diagnostic> errors_;
  bool space_ok_ = false;
};

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

  const size_t errors_before_space = errors_.size();
  if (const Val* v = f.Get("design_space")) {
    ReadDesignSpace(*v);
  } else {
    Missing(top, "design_space",
            "a map of parameters, e.g. {cores: {bind: platform.cores, "
            "range: [1, 8]}}");
  }
  space_ok_ = errors_.size() == errors_before_space &&
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
    std::string weather;
    if (ReadEnum(*e, &weather, kWeathers)) {
      spec_.world.weather = weather == "rain"  ? world::Weather::kRain
                            : weather == "fog" ? world::Weather::kFog
                                               : world::Weather::kClear;
    }
  }
  if (const Val* e = f.Get("step_s")) {
    ReadNumber(*e, &spec_.world.step_s, {0, 1, true, false});
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
    if (!ReadEnum(*generate, &map.generator, kGenerators)) return;
    const std::vector<GeneratorParam>& table = GeneratorParams(map.generator);
    std::vector<std::string> names;
    for (const GeneratorParam& p : table) {
      names.push_back(p.name);
      map.generator_params[p.name] = p.default_value;
    }
    if (const Val* params = f.Get("params")) {
      Fields pf;
      if (ReadFields(*params, &names, &pf)) {
        for (const GeneratorParam& p : table) {
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
    std::string kind;
    if (ReadEnum(*e, &kind, kTaskKinds)) {
      task.kind = kind == "valet_parking" ? world::TaskKind::kValetParking
                                          : world::TaskKind::kLaneDriving;
    }
  }
  if (const Val* e = f.Get("start")) {
    ReadLocation(*e, false, &task.start);
  } else {
    Missing(v, "start", "a place {x, y} or {edge, pos_m, lane}");
  }
  if (const Val* e = f.Get("goal")) {
    ReadLocation(*e, true, &task.goal);
  } else {
    Missing(v, "goal", "a place {x, y} or {edge, pos_m, lane}");
  }
  if (const Val* e = f.Get("speed_limit_kmh")) {
    ReadNumber(*e, &task.speed_limit_kmh, {0, 300, true, false});
  }
  if (const Val* e = f.Get("timeout_s")) {
    ReadNumber(*e, &task.timeout_s, Bounds::Positive());
  }
}

void SpecReader::ReadLocation(const Val& v, bool goal,
                              world::Location* location) {
  const std::string expected = goal ? "a place {x, y, tolerance_m} or {edge, "
                                      "pos_m, lane, tolerance_m}"
                                    : "a place {x, y} or {edge, pos_m, lane}";
  Fields f;
  if (!ReadFields(v, goal ? &kGoalKeys : &kStartKeys, &f, expected)) return;
  const bool by_xy = f.Get("x") || f.Get("y");
  const bool by_edge = f.Get("edge") || f.Get("pos_m") || f.Get("lane");
  if (by_xy && by_edge) {
    Error(v.key_mark, v.path, "either {x, y} or {edge, pos_m, lane}",
          "both x/y and edge fields");
  } else if (!by_xy && !by_edge) {
    Error(v.key_mark, v.path, "either {x, y} or {edge, pos_m, lane}",
          "neither");
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
    ReadNumber(*e, &spec_.task.goal_tolerance_m, Bounds::Positive());
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
    std::string kind;
    if (ReadEnum(*e, &kind, kPlatformKinds)) {
      p.kind =
          kind == "cgroup" ? PlatformKind::kCgroup : PlatformKind::kVirtual;
    }
  }
  if (const Val* e = f.Get("reference_ghz")) {
    ReadNumber(*e, &p.reference_ghz, {0, kMaxFreqGhz, true, false});
  }
  if (const Val* e = f.Get("cost_model")) {
    std::string model;
    if (ReadEnum(*e, &model, kCostModels)) {
      p.cost_model =
          model == "counted" ? CostModel::kCounted : CostModel::kMeasured;
    }
  }
  if (const Val* e = f.Get("calibration")) {
    if (ReadPath(*e, &p.calibration, "a path to a calibration file")) {
      std::error_code ec;
      if (check_files_ && !fs::is_regular_file(p.calibration, ec)) {
        Error(
            e->mark, e->path, "an existing calibration file",
            Quote(e->node.Scalar()) + " (no such file: " + p.calibration + ")");
      }
    }
  }
  if (const Val* e = f.Get("cores")) {
    ReadInt(*e, &p.cores, Bounds::Closed(1, kMaxPlatformCores));
  }
  if (const Val* e = f.Get("freq_ghz")) {
    ReadNumber(*e, &p.freq_ghz, {0, kMaxFreqGhz, true, false});
  }
  if (const Val* e = f.Get("cost_scale")) {
    ReadNumber(*e, &p.cost_scale, {0, 1000, true, false});
  }
}

void SpecReader::ReadDesignSpace(const Val& v) {
  Fields f;
  if (!ReadFields(v, nullptr, &f,
                  "a map of parameters, e.g. {cores: {bind: platform.cores, "
                  "range: [1, 8]}}")) {
    return;
  }
  if (f.order.empty()) {
    Error(v, "at least one parameter");
    return;
  }
  std::map<std::string, std::string> bound;  // target -> parameter
  for (const std::string& name : f.order) {
    if (full()) return;
    ReadParameter(name, *f.Get(name), &bound);
  }
}

void SpecReader::ReadParameter(const std::string& name, const Val& v,
                               std::map<std::string, std::string>* bound) {
  bool ok = true;
  if (!IsIdentifier(name)) {
    Error(v.key_mark, v.path,
          "a parameter name usable in expressions (letters, digits and '_', "
          "not starting with a digit)",
          Quote(name));
    ok = false;
  } else if (const std::vector<std::string> metrics = MetricNames();
             std::find(metrics.begin(), metrics.end(), name) != metrics.end()) {
    Error(v.key_mark, v.path, "a parameter name that is not a metric name",
          Quote(name));
    ok = false;
  } else if (const auto& reserved = Expression::ReservedNames();
             std::find(reserved.begin(), reserved.end(), name) !=
             reserved.end()) {
    Error(v.key_mark, v.path,
          "a parameter name that is not a built-in function or constant",
          Quote(name));
    ok = false;
  }
  Fields f;
  if (!ReadFields(v, &kParameterKeys, &f,
                  "a map {bind: <target>, range: [lo, hi]} or "
                  "{bind: <target>, values: [...]}")) {
    return;
  }
  DesignParameter p;
  p.name = name;
  const std::vector<std::string> targets = BindTargets();
  if (const Val* e = f.Get("bind")) {
    if (ReadString(*e, &p.bind,
                   "a target: platform.cores, platform.freq_ghz "
                   "or stack.<knob>")) {
      if (std::find(targets.begin(), targets.end(), p.bind) == targets.end()) {
        Error(*e,
              "a target: platform.cores, platform.freq_ghz or stack.<knob> "
              "(knobs are listed in scenarios/README.md)",
              DidYouMean(p.bind, targets));
        ok = false;
      } else if (auto it = bound->find(p.bind); it != bound->end()) {
        Error(*e, "a target no other parameter binds",
              " (already bound by '" + it->second + "')");
        ok = false;
      } else {
        (*bound)[p.bind] = name;
      }
      // `cores` and `freq_ghz` always mean the platform's in expressions.
      if (ok && ((name == "cores" && p.bind != kPlatformCores) ||
                 (name == "freq_ghz" && p.bind != kPlatformFreq))) {
        Error(v.key_mark, v.path,
              std::string("the name '") + name + "' to bind platform." + name +
                  " (it means the platform's value in expressions)",
              Quote(p.bind) + " as its target");
        ok = false;
      }
    } else {
      ok = false;
    }
  } else {
    Missing(v, "bind",
            "a target: platform.cores, platform.freq_ghz or "
            "stack.<knob>");
    ok = false;
  }

  const Val* range = f.Get("range");
  const Val* values = f.Get("values");
  const Val* step = f.Get("step");
  if (range && values) {
    Error(v.key_mark, v.path, "exactly one of 'range' or 'values'", "both");
    return;
  }
  if (!range && !values) {
    Error(v.key_mark, v.path, "exactly one of 'range' or 'values'", "neither");
    return;
  }
  if (step && !range) {
    Error(step->key_mark, step->path, "'step' only together with 'range'",
          "'values'");
    ok = false;
  }
  std::vector<Val> items;
  if (range) {
    std::vector<Val> bounds;
    if (!ReadList(*range, &bounds, "a list [lo, hi]")) return;
    if (bounds.size() != 2) {
      Error(*range, "a list [lo, hi] of two numbers");
      return;
    }
    double lo = 0, hi = 0, by = 1;
    if (!ReadNumber(bounds[0], &lo, {}) || !ReadNumber(bounds[1], &hi, {})) {
      return;
    }
    if (step && !ReadNumber(*step, &by, Bounds::Positive())) return;
    if (lo > hi) {
      Error(range->mark, range->path, "lo <= hi in [lo, hi]",
            fmt::format("[{}, {}] (an inverted range)", FormatNumber(lo),
                        FormatNumber(hi)));
      return;
    }
    const double count = std::floor((hi - lo) / by + 1e-9) + 1;
    if (!(count <= static_cast<double>(kMaxParameterValues))) {
      Error(range->mark, range->path,
            fmt::format("at most {} values", kMaxParameterValues),
            fmt::format("a range of {} values", FormatNumber(count)));
      return;
    }
    for (size_t i = 0; i < static_cast<size_t>(count); ++i) {
      // Multiply rather than accumulate, then round away binary noise so
      // that 0.1 steps give 0.3, not 0.30000000000000004.
      const double raw = lo + static_cast<double>(i) * by;
      double clean = raw;
      ParseNumber(fmt::format("{:.12g}", raw), &clean);
      p.values.push_back(clean);
    }
  } else {
    if (!ReadList(*values, &items, "a list of numbers")) return;
    if (items.empty()) {
      Error(*values, "at least one value");
      return;
    }
    if (items.size() > kMaxParameterValues) {
      Error(*values, fmt::format("at most {} values", kMaxParameterValues));
      return;
    }
    std::map<double, size_t> seen;
    for (const Val& item : items) {
      if (full()) return;
      double value = 0;
      if (!ReadNumber(item, &value, {})) {
        ok = false;
        continue;
      }
      if (seen.count(value)) {
        Error(item, "distinct values", " (a duplicate)");
        ok = false;
        continue;
      }
      seen[value] = p.values.size();
      p.values.push_back(value);
    }
    std::sort(p.values.begin(), p.values.end());
  }
  p.integer = std::all_of(p.values.begin(), p.values.end(),
                          [](double x) { return x == std::floor(x); });
  if (!ok || p.values.empty()) return;
  if (!CheckBinding(p, range ? *range : *values, range ? nullptr : &items)) {
    return;
  }
  spec_.design_space.parameters.push_back(std::move(p));
}

// The values must suit the bound target; reports the first that does not.
bool SpecReader::CheckBinding(const DesignParameter& p, const Val& at,
                              const std::vector<Val>* items) {
  Bounds bounds;
  bool integer = false;
  std::string what;
  if (p.bind == kPlatformCores) {
    bounds = Bounds::Closed(1, kMaxPlatformCores);
    integer = true;
    what = "core counts";
  } else if (p.bind == kPlatformFreq) {
    bounds = {0, kMaxFreqGhz, true, false};
    what = "frequencies, GHz";
  } else if (const KnobInfo* knob = FindStackKnob(p.bind.substr(6))) {
    bounds = Bounds::Closed(knob->min_value, knob->max_value);
    integer = knob->integer;
    what = knob->doc;
  }
  const std::string expected =
      fmt::format("values allowed for {}: {} ({})", p.bind,
                  bounds.Describe(integer ? "integers" : "numbers"), what);
  for (double value : p.values) {
    if (bounds.Contains(value) && (!integer || value == std::floor(value))) {
      continue;
    }
    // Point at the offending list item when there is one.
    const Val* where = &at;
    if (items != nullptr) {
      for (const Val& item : *items) {
        double x = 0;
        if (item.node.IsScalar() && ParseNumber(item.node.Scalar(), &x) &&
            x == value) {
          where = &item;
          break;
        }
      }
    }
    Error(where->mark, where->path, expected, FormatNumber(value));
    return false;
  }
  return true;
}

void SpecReader::ReadExpression(const Val& v,
                                const std::vector<std::string>& names,
                                const std::string& expected) {
  const std::string& text = v.node.Scalar();
  Result<Expression> e = Expression::Parse(text, names);
  if (e.ok()) return;
  const std::string& message = e.status().message();
  // With a broken design space every parameter name looks unknown; only
  // report real syntax problems then.
  if (!space_ok_ && message.rfind("unknown name", 0) == 0) return;
  const size_t suggestion = message.find(" (did you mean");
  if (suggestion != std::string::npos) {
    Error(v.mark, v.path, expected,
          Quote(text) + " with " + message.substr(0, suggestion),
          message.substr(suggestion));
  } else {
    Error(v.mark, v.path, expected, Quote(text) + " with " + message);
  }
}

void SpecReader::ReadCost(const Val& v) {
  if (!ReadString(v, &spec_.cost, "an expression, e.g. cores * freq_ghz")) {
    return;
  }
  ReadExpression(v, CostVariableNames(spec_.design_space),
                 "an expression over design parameters, cores and freq_ghz");
}

void SpecReader::ReadObjectives(const Val& v) {
  std::vector<Val> items;
  const std::string expected =
      "a list of {minimize: <metric>} or {maximize: <metric>}";
  if (!ReadList(v, &items, expected)) return;
  if (items.empty()) {
    Error(v, "at least one objective");
    return;
  }
  const std::vector<std::string> metrics = MetricNames();
  std::set<std::string> seen;
  for (const Val& item : items) {
    if (full()) return;
    Fields f;
    if (!ReadFields(item, &kObjectiveKeys, &f,
                    "a map {minimize: <metric>} or {maximize: <metric>}")) {
      continue;
    }
    if (item.node.size() != 1) {
      Error(item, "exactly one of minimize or maximize");
      continue;
    }
    if (f.order.empty()) continue;  // its key was reported
    const Val& e = *f.Get(f.order[0]);
    Objective objective;
    objective.minimize = f.order[0] == "minimize";
    if (!ReadEnum(e, &objective.metric, metrics)) continue;
    if (!seen.insert(objective.metric).second) {
      Error(e, "each metric in one objective only", " (a duplicate)");
      continue;
    }
    spec_.objectives.push_back(objective);
  }
}

void SpecReader::ReadConstraints(const Val& v) {
  std::vector<Val> items;
  if (!ReadList(v, &items,
                "a list of conditions, e.g. [nav_time_s <= 400, completed]")) {
    return;
  }
  const std::vector<std::string> names =
      ConstraintVariableNames(spec_.design_space);
  for (const Val& item : items) {
    if (full()) return;
    std::string text;
    if (!ReadString(item, &text, "a condition, e.g. nav_time_s <= 400")) {
      continue;
    }
    ReadExpression(item, names,
                   "a condition over metrics and design parameters");
    spec_.constraints.push_back(text);
  }
}

void SpecReader::ReadExploration(const Val& v) {
  Fields f;
  if (!ReadFields(v, &kExplorationKeys, &f)) return;
  ExplorationOptions& x = spec_.exploration;
  if (const Val* e = f.Get("strategy")) ReadEnum(*e, &x.strategy, kStrategies);
  if (const Val* e = f.Get("budget")) {
    ReadInt(*e, &x.budget, Bounds::Closed(1, 1e9));
  }
  if (const Val* e = f.Get("batch")) {
    ReadInt(*e, &x.batch, Bounds::Closed(1, 1e6));
  }
  if (const Val* e = f.Get("seed")) ReadSeed(*e, &x.seed);
  if (const Val* e = f.Get("population")) {
    ReadInt(*e, &x.population, Bounds::Closed(2, 1e6));
  }
  if (const Val* e = f.Get("crossover_rate")) {
    ReadNumber(*e, &x.crossover_rate, Bounds::Closed(0, 1));
  }
  if (const Val* e = f.Get("mutation_rate")) {
    ReadNumber(*e, &x.mutation_rate, Bounds::Closed(0, 1));
  }
  if (const Val* e = f.Get("start_from")) ReadStartFrom(*e);
}

void SpecReader::ReadStartFrom(const Val& v) {
  Fields f;
  if (!ReadFields(v, nullptr, &f,
                  "a design point {<parameter>: <value>, ...}")) {
    return;
  }
  if (!space_ok_) return;  // already reported; nothing to check against
  const DesignSpace& space = spec_.design_space;
  const std::vector<std::string> names = space.Names();
  DesignPoint point;
  for (const std::string& name : f.order) {
    const Val& e = *f.Get(name);
    const DesignParameter* p = space.Find(name);
    if (p == nullptr) {
      Error(e.key_mark, e.path, "a design parameter (" + JoinList(names) + ")",
            Quote(name), DidYouMean(name, names));
      continue;
    }
    double value = 0;
    if (!ReadNumber(e, &value, {})) continue;
    const int index = p->IndexOf(value);
    if (index < 0) {
      Error(e, "one of the values of design_space." + name + ": " +
                   p->DescribeValues() + " (the point must be in the space)");
      continue;
    }
    point[name] = p->values[index];
  }
  std::vector<std::string> missing;
  for (const DesignParameter& p : space.parameters) {
    if (f.Get(p.name) == nullptr) missing.push_back(p.name);
  }
  if (!missing.empty()) {
    Error(v.key_mark, v.path, "a value for every design parameter",
          "no value for " + JoinList(missing));
    return;
  }
  if (point.size() == space.parameters.size()) {
    spec_.exploration.start_from = std::move(point);
  }
}

void SpecReader::ReadLlm(const Val& v) {
  Fields f;
  if (!ReadFields(v, &kLlmKeys, &f)) return;
  LlmOptions& llm = spec_.llm;
  if (const Val* e = f.Get("backend")) ReadEnum(*e, &llm.backend, kBackends);
  if (const Val* e = f.Get("endpoint")) {
    std::string url;
    if (ReadString(*e, &url, "an http:// or https:// URL")) {
      if (url.rfind("http://", 0) == 0 || url.rfind("https://", 0) == 0) {
        llm.endpoint = url;
      } else {
        Error(*e, "an http:// or https:// URL");
      }
    }
  }
  if (const Val* e = f.Get("models")) {
    Fields mf;
    if (ReadFields(*e, &kLlmRoles, &mf, "a map of role -> model name")) {
      for (const std::string& role : mf.order) {
        ReadString(*mf.Get(role), &llm.models[role], "a model name");
      }
    }
  }
  if (const Val* e = f.Get("prompts")) {
    if (ReadPath(*e, &llm.prompts, "a folder of prompt templates")) {
      std::error_code ec;
      if (check_files_ && !fs::is_directory(llm.prompts, ec)) {
        Error(
            e->mark, e->path, "an existing folder of prompt templates",
            Quote(e->node.Scalar()) + " (no such folder: " + llm.prompts + ")");
      }
    }
  }
  if (const Val* e = f.Get("replay_from")) {
    if (ReadPath(*e, &llm.replay_from, "a recorded campaign folder")) {
      std::error_code ec;
      if (check_files_ && !fs::exists(llm.replay_from, ec)) {
        Error(e->mark, e->path, "an existing recorded campaign folder",
              Quote(e->node.Scalar()) + " (no such folder: " + llm.replay_from +
                  ")");
      }
    }
  }
  if (const Val* e = f.Get("timeout_s")) {
    ReadNumber(*e, &llm.timeout_s, Bounds::Positive());
  }
  if (const Val* e = f.Get("retries")) {
    ReadInt(*e, &llm.retries, Bounds::Closed(0, 100));
  }
  if (const Val* e = f.Get("api_key_env")) {
    if (ReadString(*e, &llm.api_key_env, "an environment variable name") &&
        !IsIdentifier(llm.api_key_env)) {
      Error(*e, "an environment variable name (letters, digits, '_')");
    }
  }
  if (llm.backend == "replay" && llm.replay_from.empty() &&
      f.Get("replay_from") == nullptr) {
    const Val* backend = f.Get("backend");
    Error(backend->mark, Join(v.path, "replay_from"),
          "a recorded campaign folder (required by backend: replay)",
          "nothing");
  }
}

void SpecReader::ReadHarness(const Val& v) {
  Fields f;
  if (!ReadFields(v, &kHarnessKeys, &f)) return;
  HarnessOptions& h = spec_.harness;
  if (const Val* e = f.Get("workers")) {
    if (e->node.IsScalar() && e->node.Scalar() == "auto") {
      h.workers = 0;
    } else {
      double value = 0;
      if (!e->node.IsScalar() || !ParseNumber(e->node.Scalar(), &value) ||
          value != std::floor(value) || value < 1 || value > 1e6) {
        Error(*e, "'auto' or an integer >= 1");
      } else {
        h.workers = static_cast<int>(value);
      }
    }
  }
  if (const Val* e = f.Get("cores_per_worker")) {
    ReadInt(*e, &h.cores_per_worker, Bounds::Closed(1, kMaxPlatformCores));
  }
  if (const Val* e = f.Get("memory_mb")) {
    ReadInt(*e, &h.memory_mb, Bounds::Closed(1, 1e9));
  }
  if (const Val* e = f.Get("run_timeout_s")) {
    ReadNumber(*e, &h.run_timeout_s, Bounds::Positive());
  }
  if (const Val* e = f.Get("retries")) {
    ReadInt(*e, &h.retries, Bounds::Closed(0, 100));
  }
  if (const Val* e = f.Get("replicas")) {
    ReadInt(*e, &h.replicas, Bounds::Closed(1, 1000));
  }
  if (const Val* e = f.Get("isolation")) {
    ReadEnum(*e, &h.isolation, kIsolations);
  }
  if (const Val* e = f.Get("executor")) ReadEnum(*e, &h.executor, kExecutors);
  if (const Val* e = f.Get("cache_dir")) {
    ReadPath(*e, &h.cache_dir, "a folder for the result cache");
  }
  if (const Val* e = f.Get("slurm")) ReadSlurm(*e);
}

void SpecReader::ReadSlurm(const Val& v) {
  Fields f;
  if (!ReadFields(v, &kSlurmKeys, &f)) return;
  SlurmOptions& s = spec_.harness.slurm;
  if (const Val* e = f.Get("partition")) {
    ReadString(*e, &s.partition, "a Slurm partition name");
  }
  if (const Val* e = f.Get("account")) {
    ReadString(*e, &s.account, "a Slurm account name");
  }
  if (const Val* e = f.Get("nodes")) {
    ReadInt(*e, &s.nodes, Bounds::Closed(1, 1e6));
  }
  if (const Val* e = f.Get("cpus"))
    ReadInt(*e, &s.cpus, Bounds::Closed(0, 1e7));
  if (const Val* e = f.Get("time_limit")) {
    const std::string expected =
        "a Slurm time limit (M, M:S, H:M:S, D-H, D-H:M or D-H:M:S)";
    std::string limit;
    if (ReadString(*e, &limit, expected)) {
      if (IsSlurmTime(limit)) {
        s.time_limit = limit;
      } else {
        Error(*e, expected);
      }
    }
  }
  if (const Val* e = f.Get("max_parallel")) {
    ReadInt(*e, &s.max_parallel, Bounds::Closed(0, 1e7));
  }
  if (const Val* e = f.Get("shard_size")) {
    ReadInt(*e, &s.shard_size, Bounds::Closed(0, 1e9));
  }
  if (const Val* e = f.Get("signal_lead_s")) {
    ReadInt(*e, &s.signal_lead_s, Bounds::Closed(0, 65535));
  }
  if (const Val* e = f.Get("run_estimate_s")) {
    ReadNumber(*e, &s.run_estimate_s, Bounds::Positive());
  }
  if (const Val* e = f.Get("extra_args")) {
    std::vector<Val> items;
    if (ReadList(*e, &items, "a list of sbatch arguments")) {
      for (const Val& item : items) {
        std::string arg;
        const std::string expected = "an sbatch option, e.g. --qos=long";
        if (!ReadString(item, &arg, expected)) continue;
        // adse sets these itself; one given here would fight it.
        const std::string name = arg.substr(0, arg.find('='));
        if (arg.size() < 2 || arg[0] != '-' ||
            arg.find_first_of("\n\r") != std::string::npos) {
          Error(item, expected + " (one line, starting with '-')");
        } else if (name == "--array" || name == "-a" ||
                   name == "--dependency" || name == "-d" || name == "--wrap" ||
                   name == "--parsable") {
          Error(item, expected + "; " + name + " is set by adse submit itself");
        } else {
          s.extra_args.push_back(arg);
        }
      }
    }
  }
}

void SpecReader::ReadOutput(const Val* v) {
  if (v == nullptr) {
    spec_.output = "results/" + spec_.name;
    return;
  }
  const std::string expected =
      "a folder path, absolute or below the working directory";
  std::string written;
  if (!ReadString(*v, &written, expected)) return;
  const fs::path path(written);
  if (path.is_relative()) {
    const fs::path normal = path.lexically_normal();
    const std::string first =
        normal.empty() ? std::string() : normal.begin()->string();
    if (first == "..") {
      Error(*v, expected, " (the path escapes the working directory)");
      return;
    }
    if (normal.empty() || normal == ".") {
      Error(*v, expected + ", not the working directory itself");
      return;
    }
  }
  spec_.output = written;
}

// ---------------------------------------------------------------------------
// Emitting.

void EmitNumber(YAML::Emitter& out, double value) {
  out << FormatNumber(value);
}

void EmitPoint(YAML::Emitter& out, const DesignPoint& point,
               const DesignSpace& space) {
  out << YAML::Flow << YAML::BeginMap;
  // In the space's order, which is the order users wrote.
  for (const DesignParameter& p : space.parameters) {
    if (auto it = point.find(p.name); it != point.end()) {
      out << YAML::Key << p.name << YAML::Value;
      EmitNumber(out, it->second);
    }
  }
  out << YAML::EndMap;
}

void EmitLocation(YAML::Emitter& out, const world::Location& l,
                  const double* tolerance) {
  out << YAML::Flow << YAML::BeginMap;
  if (l.by_edge) {
    out << YAML::Key << "edge" << YAML::Value << YAML::DoubleQuoted << l.edge;
    out << YAML::Key << "pos_m" << YAML::Value;
    EmitNumber(out, l.pos_m);
    out << YAML::Key << "lane" << YAML::Value << l.lane;
  } else {
    out << YAML::Key << "x" << YAML::Value;
    EmitNumber(out, l.x_m);
    out << YAML::Key << "y" << YAML::Value;
    EmitNumber(out, l.y_m);
  }
  if (tolerance != nullptr) {
    out << YAML::Key << "tolerance_m" << YAML::Value;
    EmitNumber(out, *tolerance);
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
      EmitNumber(out, stack.Get(path));
    } else {
      EmitStack(out, stack, path + ".");
    }
  }
  out << YAML::EndMap;
}

}  // namespace

// ---------------------------------------------------------------------------
// Public API.

std::vector<std::string> CostVariableNames(const DesignSpace& space) {
  std::vector<std::string> names = space.Names();
  for (const char* n : {"cores", "freq_ghz"}) {
    if (std::find(names.begin(), names.end(), n) == names.end()) {
      names.push_back(n);
    }
  }
  return names;
}

std::vector<std::string> ConstraintVariableNames(const DesignSpace& space) {
  std::vector<std::string> names = MetricNames();
  for (const std::string& n : space.Names()) names.push_back(n);
  return names;
}

Result<Spec> ParseSpec(std::string_view text, const std::string& file_name,
                       const std::string& base_dir,
                       const ParseOptions& options) {
  Spec spec;
  spec.source_path = file_name;
  std::error_code ec;
  spec.base_dir =
      fs::absolute(base_dir.empty() ? fs::path(".") : fs::path(base_dir), ec)
          .lexically_normal()
          .string();
  if (spec.base_dir.size() > 1 && spec.base_dir.back() == '/') {
    spec.base_dir.pop_back();
  }
  if (text.size() > kMaxSpecBytes) {
    return Status::InvalidArgument(
        fmt::format("{}:1:1: error: (file): expected at most {} bytes, found "
                    "{} bytes",
                    file_name, kMaxSpecBytes, text.size()));
  }
  spec.source_text = std::string(text);
  spec.name = NameFromFile(file_name);
  SpecReader reader(&spec, options.check_files);

  // Scan events first: limits are enforced before any node exists.
  try {
    std::istringstream in(spec.source_text);
    YAML::Parser parser(in);
    LimitScanner scanner;
    parser.HandleNextDocument(scanner);
    if (parser.HandleNextDocument(scanner) && scanner.documents() > 1) {
      return Status::InvalidArgument(fmt::format(
          "{}:1:1: error: (file): expected one YAML document, found several "
          "('---' separators)",
          file_name));
    }
  } catch (const LimitExceeded& e) {
    reader.FileError(e.mark, "(file)", e.expected, e.found);
  } catch (const YAML::Exception& e) {
    const YAML::Mark mark = e.mark;
    return Status::InvalidArgument(fmt::format(
        "{}:{}:{}: error: (file): expected valid YAML, found a syntax error: "
        "{}",
        file_name, mark.is_null() ? 1 : mark.line + 1,
        mark.is_null() ? 1 : mark.column + 1, e.msg));
  } catch (const std::exception& e) {
    return Status::InvalidArgument(
        fmt::format("{}:1:1: error: (file): expected valid YAML, found {}",
                    file_name, e.what()));
  }

  if (!reader.has_errors()) {
    try {
      const YAML::Node root = YAML::Load(spec.source_text);
      reader.Read(root);
    } catch (const YAML::Exception& e) {
      const YAML::Mark mark = e.mark;
      reader.FileError(mark, "(file)", "valid YAML",
                       std::string("a syntax error: ") + e.msg);
    } catch (const std::exception& e) {
      reader.FileError(YAML::Mark(), "(file)", "a readable scenario", e.what());
    }
  }

  std::vector<Diagnostic> errors = reader.TakeErrors();
  if (errors.empty()) return spec;
  std::string message;
  for (const Diagnostic& d : errors) {
    if (!message.empty()) message += '\n';
    message += d.text;
  }
  if (errors.size() >= static_cast<size_t>(kMaxSpecErrors)) {
    message += fmt::format("\n{}: note: stopped after {} errors", file_name,
                           kMaxSpecErrors);
  }
  return Status::InvalidArgument(message);
}

Result<Spec> LoadSpec(const std::string& path) {
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) {
    const auto size = fs::file_size(path, ec);
    if (!ec && size > kMaxSpecBytes) {
      return Status::InvalidArgument(fmt::format(
          "{}:1:1: error: (file): expected a scenario of at most {} bytes, "
          "found {} bytes",
          path, kMaxSpecBytes, size));
    }
  }
  Result<std::string> text = ReadFile(path, kMaxSpecBytes);
  if (!text.ok()) return text.status();
  const fs::path dir = fs::absolute(path, ec).parent_path();
  return ParseSpec(*text, path, dir.string());
}

std::string NormalizedYaml(const Spec& spec) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "adse" << YAML::Value << spec.version;
  out << YAML::Key << "name" << YAML::Value << YAML::DoubleQuoted << spec.name;

  // world
  const world::WorldOptions& w = spec.world;
  out << YAML::Key << "world" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "map" << YAML::Value << YAML::Flow << YAML::BeginMap;
  if (!w.map.generator.empty()) {
    out << YAML::Key << "generate" << YAML::Value << w.map.generator;
    out << YAML::Key << "params" << YAML::Value << YAML::Flow << YAML::BeginMap;
    for (const GeneratorParam& p : GeneratorParams(w.map.generator)) {
      auto it = w.map.generator_params.find(p.name);
      out << YAML::Key << p.name << YAML::Value;
      EmitNumber(out, it != w.map.generator_params.end() ? it->second
                                                         : p.default_value);
    }
    out << YAML::EndMap;
  } else {
    out << YAML::Key << "net" << YAML::Value << YAML::DoubleQuoted
        << w.map.net_path;
  }
  if (!w.map.polygons_path.empty()) {
    out << YAML::Key << "polygons" << YAML::Value << YAML::DoubleQuoted
        << w.map.polygons_path;
  }
  out << YAML::EndMap;
  out << YAML::Key << "traffic" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "seed" << YAML::Value << std::to_string(w.traffic.seed);
  out << YAML::Key << "flows" << YAML::Value << YAML::BeginSeq;
  for (const world::Flow& flow : w.traffic.flows) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "from" << YAML::Value << YAML::DoubleQuoted
        << flow.from_edge;
    out << YAML::Key << "to" << YAML::Value << YAML::DoubleQuoted
        << flow.to_edge;
    out << YAML::Key << "vehicles_per_hour" << YAML::Value;
    EmitNumber(out, flow.vehicles_per_hour);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::Key << "parked_occupancy" << YAML::Value;
  EmitNumber(out, w.traffic.parked_occupancy);
  out << YAML::EndMap;
  out << YAML::Key << "weather" << YAML::Value << WeatherText(w.weather);
  out << YAML::Key << "step_s" << YAML::Value;
  EmitNumber(out, w.step_s);
  out << YAML::EndMap;

  // task
  const world::TaskOptions& t = spec.task;
  out << YAML::Key << "task" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "kind" << YAML::Value << TaskKindText(t.kind);
  out << YAML::Key << "start" << YAML::Value;
  EmitLocation(out, t.start, nullptr);
  out << YAML::Key << "goal" << YAML::Value;
  EmitLocation(out, t.goal, &t.goal_tolerance_m);
  out << YAML::Key << "speed_limit_kmh" << YAML::Value;
  EmitNumber(out, t.speed_limit_kmh);
  out << YAML::Key << "timeout_s" << YAML::Value;
  EmitNumber(out, t.timeout_s);
  out << YAML::EndMap;

  out << YAML::Key << "stack" << YAML::Value;
  EmitStack(out, spec.stack, "");

  // platform
  const PlatformOptions& p = spec.platform;
  out << YAML::Key << "platform" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "kind" << YAML::Value
      << (p.kind == PlatformKind::kCgroup ? "cgroup" : "virtual");
  out << YAML::Key << "reference_ghz" << YAML::Value;
  EmitNumber(out, p.reference_ghz);
  out << YAML::Key << "cost_model" << YAML::Value
      << (p.cost_model == CostModel::kCounted ? "counted" : "measured");
  if (!p.calibration.empty()) {
    out << YAML::Key << "calibration" << YAML::Value << YAML::DoubleQuoted
        << p.calibration;
  }
  out << YAML::Key << "cores" << YAML::Value << p.cores;
  out << YAML::Key << "freq_ghz" << YAML::Value;
  EmitNumber(out, p.freq_ghz);
  out << YAML::Key << "cost_scale" << YAML::Value;
  EmitNumber(out, p.cost_scale);
  out << YAML::EndMap;

  out << YAML::Key << "design_space" << YAML::Value << YAML::BeginMap;
  for (const DesignParameter& d : spec.design_space.parameters) {
    out << YAML::Key << d.name << YAML::Value << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "bind" << YAML::Value << d.bind;
    out << YAML::Key << "values" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (double value : d.values) EmitNumber(out, value);
    out << YAML::EndSeq << YAML::EndMap;
  }
  out << YAML::EndMap;

  out << YAML::Key << "cost" << YAML::Value << YAML::DoubleQuoted << spec.cost;
  out << YAML::Key << "objectives" << YAML::Value << YAML::Flow
      << YAML::BeginSeq;
  for (const Objective& o : spec.objectives) {
    out << YAML::Flow << YAML::BeginMap << YAML::Key
        << (o.minimize ? "minimize" : "maximize") << YAML::Value << o.metric
        << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::Key << "constraints" << YAML::Value << YAML::Flow
      << YAML::BeginSeq;
  for (const std::string& c : spec.constraints) out << YAML::DoubleQuoted << c;
  out << YAML::EndSeq;

  // exploration
  const ExplorationOptions& x = spec.exploration;
  out << YAML::Key << "exploration" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "strategy" << YAML::Value << x.strategy;
  out << YAML::Key << "budget" << YAML::Value << x.budget;
  out << YAML::Key << "batch" << YAML::Value << x.batch;
  out << YAML::Key << "seed" << YAML::Value << std::to_string(x.seed);
  if (!x.start_from.empty()) {
    out << YAML::Key << "start_from" << YAML::Value;
    EmitPoint(out, x.start_from, spec.design_space);
  }
  out << YAML::Key << "population" << YAML::Value << x.population;
  out << YAML::Key << "crossover_rate" << YAML::Value;
  EmitNumber(out, x.crossover_rate);
  out << YAML::Key << "mutation_rate" << YAML::Value;
  EmitNumber(out, x.mutation_rate);
  out << YAML::EndMap;

  // llm
  const LlmOptions& l = spec.llm;
  out << YAML::Key << "llm" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "backend" << YAML::Value << l.backend;
  out << YAML::Key << "endpoint" << YAML::Value << YAML::DoubleQuoted
      << l.endpoint;
  out << YAML::Key << "models" << YAML::Value << YAML::BeginMap;
  for (const std::string& role : kLlmRoles) {
    if (auto it = l.models.find(role); it != l.models.end()) {
      out << YAML::Key << role << YAML::Value << YAML::DoubleQuoted
          << it->second;
    }
  }
  out << YAML::EndMap;
  if (!l.prompts.empty()) {
    out << YAML::Key << "prompts" << YAML::Value << YAML::DoubleQuoted
        << l.prompts;
  }
  if (!l.replay_from.empty()) {
    out << YAML::Key << "replay_from" << YAML::Value << YAML::DoubleQuoted
        << l.replay_from;
  }
  out << YAML::Key << "timeout_s" << YAML::Value;
  EmitNumber(out, l.timeout_s);
  out << YAML::Key << "retries" << YAML::Value << l.retries;
  out << YAML::Key << "api_key_env" << YAML::Value << l.api_key_env;
  out << YAML::EndMap;

  // harness
  const HarnessOptions& h = spec.harness;
  out << YAML::Key << "harness" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "workers" << YAML::Value;
  if (h.workers > 0) {
    out << h.workers;
  } else {
    out << "auto";
  }
  out << YAML::Key << "cores_per_worker" << YAML::Value << h.cores_per_worker;
  out << YAML::Key << "memory_mb" << YAML::Value << h.memory_mb;
  out << YAML::Key << "run_timeout_s" << YAML::Value;
  EmitNumber(out, h.run_timeout_s);
  out << YAML::Key << "retries" << YAML::Value << h.retries;
  out << YAML::Key << "replicas" << YAML::Value << h.replicas;
  out << YAML::Key << "isolation" << YAML::Value << h.isolation;
  out << YAML::Key << "executor" << YAML::Value << h.executor;
  if (!h.cache_dir.empty()) {
    out << YAML::Key << "cache_dir" << YAML::Value << YAML::DoubleQuoted
        << h.cache_dir;
  }
  const SlurmOptions& s = h.slurm;
  out << YAML::Key << "slurm" << YAML::Value << YAML::BeginMap;
  if (!s.partition.empty()) {
    out << YAML::Key << "partition" << YAML::Value << YAML::DoubleQuoted
        << s.partition;
  }
  if (!s.account.empty()) {
    out << YAML::Key << "account" << YAML::Value << YAML::DoubleQuoted
        << s.account;
  }
  out << YAML::Key << "nodes" << YAML::Value << s.nodes;
  out << YAML::Key << "cpus" << YAML::Value << s.cpus;
  out << YAML::Key << "time_limit" << YAML::Value << YAML::DoubleQuoted
      << s.time_limit;
  out << YAML::Key << "max_parallel" << YAML::Value << s.max_parallel;
  out << YAML::Key << "shard_size" << YAML::Value << s.shard_size;
  out << YAML::Key << "signal_lead_s" << YAML::Value << s.signal_lead_s;
  out << YAML::Key << "run_estimate_s" << YAML::Value;
  EmitNumber(out, s.run_estimate_s);
  out << YAML::Key << "extra_args" << YAML::Value << YAML::Flow
      << YAML::BeginSeq;
  for (const std::string& arg : s.extra_args) {
    out << YAML::DoubleQuoted << arg;
  }
  out << YAML::EndSeq;
  out << YAML::EndMap;
  out << YAML::EndMap;

  out << YAML::Key << "output" << YAML::Value << YAML::DoubleQuoted
      << spec.output;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

std::string FormatPoint(const DesignSpace& space, const DesignPoint& point) {
  std::string text;
  auto add = [&text](const std::string& name, double value) {
    text += fmt::format("{}{}={}", text.empty() ? "" : ",", name, value);
  };
  for (const DesignParameter& p : space.parameters) {
    auto it = point.find(p.name);
    if (it != point.end()) add(p.name, it->second);
  }
  for (const auto& [name, value] : point) {
    if (space.Find(name) == nullptr) add(name, value);
  }
  return text;
}

Result<DesignPoint> ParsePoint(const DesignSpace& space,
                               std::string_view text) {
  std::vector<std::string> errors;
  DesignPoint point;
  const std::vector<std::string> names = space.Names();
  auto trim = [](std::string_view s) {
    const size_t b = s.find_first_not_of(" \t");
    if (b == std::string_view::npos) return std::string_view();
    const size_t e = s.find_last_not_of(" \t");
    return s.substr(b, e - b + 1);
  };
  if (trim(text).empty()) {
    return Status::InvalidArgument(
        "expected name=value pairs separated by ',' (parameters: " +
        JoinList(names) + "), found nothing");
  }
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find(',', start);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view item = trim(text.substr(start, end - start));
    start = end + 1;
    const size_t eq = item.find('=');
    if (eq == std::string_view::npos) {
      errors.push_back("expected name=value, found '" + std::string(item) +
                       "'");
      continue;
    }
    const std::string name(trim(item.substr(0, eq)));
    const std::string value_text(trim(item.substr(eq + 1)));
    const DesignParameter* p = space.Find(name);
    if (p == nullptr) {
      errors.push_back("unknown parameter '" + name + "'; parameters: " +
                       JoinList(names) + DidYouMean(name, names));
      continue;
    }
    if (point.count(name)) {
      errors.push_back(name + ": expected one value, found it twice");
      continue;
    }
    double value = 0;
    if (!ParseNumber(value_text, &value)) {
      errors.push_back(name + ": expected a number, found '" + value_text +
                       "'");
      continue;
    }
    const int index = p->IndexOf(value);
    if (index < 0) {
      errors.push_back(name + ": expected one of " + p->DescribeValues() +
                       ", found " + value_text);
      continue;
    }
    point[name] = p->values[index];
  }
  std::vector<std::string> missing;
  for (const DesignParameter& p : space.parameters) {
    if (!point.count(p.name)) {
      bool mentioned = false;  // already reported with a bad value
      for (const std::string& e : errors) {
        if (e.rfind(p.name + ":", 0) == 0) mentioned = true;
      }
      if (!mentioned) missing.push_back(p.name);
    }
  }
  if (!missing.empty()) {
    errors.push_back("missing parameter" +
                     std::string(missing.size() > 1 ? "s: " : ": ") +
                     JoinList(missing));
  }
  if (errors.empty()) return point;
  std::string message;
  for (const std::string& e : errors) {
    if (!message.empty()) message += '\n';
    message += e;
  }
  return Status::InvalidArgument(message);
}

namespace {

// Variable values for expressions: the point plus the platform's cores and
// frequency (from the point when bound).
std::map<std::string, double> PointVariables(const Spec& spec,
                                             const DesignPoint& point) {
  std::map<std::string, double> vars(point.begin(), point.end());
  const DesignSpace& space = spec.design_space;
  const DesignParameter* cores = space.FindByBind(kPlatformCores);
  const DesignParameter* freq = space.FindByBind(kPlatformFreq);
  vars["cores"] = cores ? point.at(cores->name) : spec.platform.cores;
  vars["freq_ghz"] = freq ? point.at(freq->name) : spec.platform.freq_ghz;
  return vars;
}

}  // namespace

Result<double> EvaluateCost(const Spec& spec, const DesignPoint& point) {
  ADSE_RETURN_IF_ERROR(spec.design_space.Check(point));
  Result<Expression> cost =
      Expression::Parse(spec.cost, CostVariableNames(spec.design_space));
  if (!cost.ok()) {
    return Status::InvalidArgument("cost: " + cost.status().message());
  }
  Result<double> value = cost->TryEvaluate(PointVariables(spec, point));
  if (!value.ok()) return value.status();
  if (!std::isfinite(*value)) {
    return Status::InvalidArgument("cost: '" + spec.cost +
                                   "' is not finite at this point");
  }
  return *value;
}

Result<bool> EvaluateConstraint(const Spec& spec, const std::string& constraint,
                                const std::map<std::string, double>& metrics,
                                const DesignPoint& point) {
  Result<Expression> e =
      Expression::Parse(constraint, ConstraintVariableNames(spec.design_space));
  if (!e.ok()) {
    return Status::InvalidArgument("constraint '" + constraint +
                                   "': " + e.status().message());
  }
  std::map<std::string, double> vars = metrics;
  for (const auto& [name, value] : point) vars[name] = value;
  Result<double> value = e->TryEvaluate(vars);
  if (!value.ok()) return value.status();
  // NaN (a metric without a value, e.g. nav_time_s of a failed run) never
  // satisfies a constraint.
  return std::isfinite(*value) && *value != 0.0;
}

Result<PointConfig> ApplyPoint(const Spec& spec, const DesignPoint& point) {
  ADSE_RETURN_IF_ERROR(spec.design_space.Check(point));
  PointConfig config{spec.platform, spec.stack};
  for (const DesignParameter& p : spec.design_space.parameters) {
    const double value = point.at(p.name);
    if (p.bind == kPlatformCores) {
      config.platform.cores = static_cast<int>(std::lround(value));
    } else if (p.bind == kPlatformFreq) {
      config.platform.freq_ghz = value;
    } else if (p.bind.rfind("stack.", 0) == 0) {
      ADSE_RETURN_IF_ERROR(config.stack.Set(p.bind.substr(6), value));
    } else {
      return Status::InvalidArgument(p.name + ": unknown target " + p.bind);
    }
  }
  return config;
}

}  // namespace adse::spec
