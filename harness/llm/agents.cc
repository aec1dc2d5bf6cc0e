#include "harness/llm/agents.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "analysis/diagnosis/remedy.h"
#include "harness/spec/spec_parser.h"
#include "stack/world/world_options.h"

namespace adse::llm {
namespace {

using nlohmann::json;

std::string Excerpt(const std::string& text, size_t n = 120) {
  std::string s = SanitizeText(text, n);
  return s.empty() ? "(empty)" : "'" + s + "'";
}

std::string Trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return "";
  const size_t b = s.find_last_not_of(" \t\r\n");
  return s.substr(a, b - a + 1);
}

// The answer as one JSON object. Reasoning models put a <think>...</think>
// block first; that is dropped. Nothing else is forgiven.
Result<json> ParseObject(const std::string& answer) {
  std::string text = Trim(answer);
  if (text.rfind("<think>", 0) == 0) {
    const size_t end = text.find("</think>");
    if (end != std::string::npos) text = Trim(text.substr(end + 8));
  }
  json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) {
    return Status::InvalidArgument("the answer is not valid JSON: " +
                                   Excerpt(text));
  }
  if (!j.is_object()) {
    return Status::InvalidArgument(
        std::string("the answer must be one JSON object, found a ") +
        j.type_name());
  }
  return j;
}

// InvalidArgument naming the first key of `j` not in `allowed`.
Status CheckKeys(const json& j, const std::vector<std::string>& allowed,
                 const std::string& where) {
  for (const auto& [key, value] : j.items()) {
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      std::string list;
      for (const std::string& a : allowed)
        list += (list.empty() ? "" : ", ") + ("\"" + a + "\"");
      return Status::InvalidArgument(where + " has an unknown key " +
                                     Excerpt(key, 60) +
                                     "; allowed keys: " + list);
    }
  }
  return Status::Ok();
}

Result<std::string> StringField(const json& j, const std::string& key,
                                const std::string& where, bool required) {
  auto it = j.find(key);
  if (it == j.end()) {
    if (required)
      return Status::InvalidArgument(where + " lacks \"" + key + "\"");
    return std::string();
  }
  if (!it->is_string()) {
    return Status::InvalidArgument(where + ".\"" + key + "\" must be a string");
  }
  return it->get<std::string>();
}

Result<bool> BoolField(const json& j, const std::string& key,
                       const std::string& where) {
  auto it = j.find(key);
  if (it == j.end())
    return Status::InvalidArgument(where + " lacks \"" + key + "\"");
  if (!it->is_boolean()) {
    return Status::InvalidArgument(where + ".\"" + key +
                                   "\" must be true or false");
  }
  return it->get<bool>();
}

std::string PointText(const spec::DesignSpace& space,
                      const spec::DesignPoint& p) {
  return spec::FormatPoint(space, p);
}

}  // namespace

std::string SanitizeText(const std::string& text, size_t max_chars) {
  std::string out;
  bool space = false;
  for (unsigned char c : text) {
    if (c == '\n' || c == '\t' || c == '\r' || c == ' ') {
      space = !out.empty();
      continue;
    }
    if (c < 0x20 || c == 0x7f) continue;
    if (space) out += ' ';
    space = false;
    out += static_cast<char>(c);
    if (out.size() >= max_chars) {
      // Do not cut a UTF-8 sequence in half.
      while (!out.empty() &&
             (static_cast<unsigned char>(out.back()) & 0xC0) == 0x80) {
        out.pop_back();
      }
      if (!out.empty() && static_cast<unsigned char>(out.back()) >= 0xC0)
        out.pop_back();
      out += "...";
      break;
    }
  }
  return out;
}

// ---- DSE ------------------------------------------------------------------

Result<DseAnswer> ParseDseAnswer(const std::string& answer,
                                 const spec::DesignSpace& space,
                                 const std::set<spec::DesignPoint>& evaluated) {
  Result<json> parsed = ParseObject(answer);
  if (!parsed.ok()) return parsed.status();
  const json& j = *parsed;
  ADSE_RETURN_IF_ERROR(
      CheckKeys(j, {"point", "rationale", "converged"}, "the answer"));
  DseAnswer out;
  Result<std::string> rationale =
      StringField(j, "rationale", "the answer", true);
  if (!rationale.ok()) return rationale.status();
  out.rationale = SanitizeText(*rationale);
  if (auto c = j.find("converged"); c != j.end()) {
    if (!c->is_boolean()) {
      return Status::InvalidArgument("\"converged\" must be true or false");
    }
    out.converged = c->get<bool>();
  }
  if (out.converged) {
    if (evaluated.empty()) {
      return Status::InvalidArgument(
          "nothing has been evaluated yet, so the search cannot have "
          "converged; "
          "propose a first point");
    }
    return out;
  }
  auto p = j.find("point");
  if (p == j.end() || !p->is_object()) {
    return Status::InvalidArgument(
        "the answer needs \"point\": an object with one value "
        "per design parameter");
  }
  for (const auto& [name, value] : p->items()) {
    if (!space.Find(name)) {
      std::string names;
      for (const std::string& n : space.Names())
        names += (names.empty() ? "" : ", ") + n;
      return Status::InvalidArgument(
          "\"point\" names " + Excerpt(name, 60) +
          ", which is not a design parameter; the parameters are " + names);
    }
    if (!value.is_number()) {
      return Status::InvalidArgument("\"point\".\"" + name +
                                     "\" must be a number, found " +
                                     Excerpt(value.dump(), 60));
    }
    out.point[name] = value.get<double>();
  }
  for (const spec::DesignParameter& param : space.parameters) {
    auto it = out.point.find(param.name);
    if (it == out.point.end()) {
      return Status::InvalidArgument("\"point\" lacks " + param.name +
                                     " (one of " + param.DescribeValues() +
                                     ")");
    }
    const int index = param.IndexOf(it->second);
    if (index < 0) {
      return Status::InvalidArgument(fmt::format(
          "{}={:g} is outside the design space; {} takes one of {}", param.name,
          it->second, param.name, param.DescribeValues()));
    }
    it->second = param.values[index];  // the exact allowed value
  }
  if (evaluated.count(out.point)) {
    return Status::InvalidArgument(
        PointText(space, out.point) +
        " was evaluated already; propose a point that is not "
        "in the evaluated list");
  }
  return out;
}

// ---- Commands ---------------------------------------------------------------

const std::vector<std::string>& TraceRecordOptions() {
  static const std::vector<std::string> kOptions = {
      "callbacks", "topics", "trajectory", "controls", "vehicles"};
  return kOptions;
}

std::string MapDescription(const spec::Spec& spec) {
  const world::MapOptions& m = spec.world.map;
  if (!m.generator.empty()) {
    std::string params;
    for (const auto& [name, value] : m.generator_params) {
      params +=
          fmt::format("{}{}={:g}", params.empty() ? "" : ", ", name, value);
    }
    return "generate " + m.generator +
           (params.empty() ? "" : " (" + params + ")");
  }
  return std::filesystem::path(m.net_path).filename().string();
}

Commands DeriveCommands(const spec::Spec& spec, const spec::DesignPoint& point,
                        uint64_t seed) {
  Commands c;
  c.map = MapDescription(spec);
  c.traffic_seed = static_cast<int64_t>(seed);
  c.weather = world::WeatherToString(spec.world.weather);
  for (const spec::DesignParameter& p : spec.design_space.parameters) {
    auto it = point.find(p.name);
    if (it != point.end()) c.platform[p.bind] = it->second;
  }
  c.record = TraceRecordOptions();
  return c;
}

Result<Commands> ParseCommandAnswer(const std::string& answer,
                                    const spec::Spec& spec) {
  Result<json> parsed = ParseObject(answer);
  if (!parsed.ok()) return parsed.status();
  const json& j = *parsed;
  ADSE_RETURN_IF_ERROR(
      CheckKeys(j, {"world", "platform", "tracing"}, "the answer"));
  for (const char* key : {"world", "platform", "tracing"}) {
    if (!j.contains(key) || !j.at(key).is_object()) {
      return Status::InvalidArgument(std::string("the answer needs \"") + key +
                                     "\" as an object");
    }
  }
  Commands c;
  const json& w = j.at("world");
  ADSE_RETURN_IF_ERROR(
      CheckKeys(w, {"map", "traffic_seed", "weather"}, "\"world\""));
  Result<std::string> map = StringField(w, "map", "\"world\"", true);
  if (!map.ok()) return map.status();
  // The map is the scenario's: anything else (a path, a command) is refused.
  const std::string expected_map = MapDescription(spec);
  if (*map != expected_map) {
    return Status::InvalidArgument(
        "\"world\".\"map\" must be the scenario's map \"" + expected_map +
        "\" exactly, found " + Excerpt(*map, 80));
  }
  c.map = *map;
  if (!w.contains("traffic_seed") ||
      !w.at("traffic_seed").is_number_integer()) {
    return Status::InvalidArgument(
        "\"world\".\"traffic_seed\" must be an integer");
  }
  c.traffic_seed = w.at("traffic_seed").get<int64_t>();
  Result<std::string> weather = StringField(w, "weather", "\"world\"", true);
  if (!weather.ok()) return weather.status();
  world::Weather parsed_weather;
  if (!world::StringToWeather(*weather, &parsed_weather)) {
    return Status::InvalidArgument(
        fmt::format("\"world\".\"weather\" must be one of \"{}\", found ",
                    fmt::join(world::WeatherNames(), "\", \"")) +
        Excerpt(*weather, 60));
  }
  c.weather = *weather;

  std::vector<std::string> bindings;
  for (const spec::DesignParameter& p : spec.design_space.parameters)
    bindings.push_back(p.bind);
  const json& pl = j.at("platform");
  ADSE_RETURN_IF_ERROR(CheckKeys(pl, bindings, "\"platform\""));
  for (const auto& [key, value] : pl.items()) {
    if (!value.is_number()) {
      return Status::InvalidArgument("\"platform\".\"" + key +
                                     "\" must be a number");
    }
    c.platform[key] = value.get<double>();
  }

  const json& t = j.at("tracing");
  ADSE_RETURN_IF_ERROR(CheckKeys(t, {"record"}, "\"tracing\""));
  if (!t.contains("record") || !t.at("record").is_array()) {
    return Status::InvalidArgument("\"tracing\".\"record\" must be a list");
  }
  const std::vector<std::string>& options = TraceRecordOptions();
  for (const json& item : t.at("record")) {
    if (!item.is_string() ||
        std::find(options.begin(), options.end(), item.get<std::string>()) ==
            options.end()) {
      std::string list;
      for (const std::string& o : options)
        list += (list.empty() ? "" : ", ") + o;
      return Status::InvalidArgument("\"tracing\".\"record\" may hold only " +
                                     list + "; found " +
                                     Excerpt(item.dump(), 60));
    }
    c.record.push_back(item.get<std::string>());
  }
  return c;
}

std::vector<std::string> CompareCommands(const Commands& agent,
                                         const Commands& derived) {
  std::vector<std::string> out;
  if (agent.traffic_seed != derived.traffic_seed) {
    out.push_back(fmt::format("traffic_seed {} instead of {}",
                              agent.traffic_seed, derived.traffic_seed));
  }
  if (agent.weather != derived.weather) {
    out.push_back("weather " + agent.weather + " instead of " +
                  derived.weather);
  }
  for (const auto& [bind, value] : derived.platform) {
    auto it = agent.platform.find(bind);
    if (it == agent.platform.end()) {
      out.push_back(bind + " missing");
    } else if (std::abs(it->second - value) >
               1e-9 * std::max(1.0, std::abs(value))) {
      out.push_back(
          fmt::format("{}={:g} instead of {:g}", bind, it->second, value));
    }
  }
  for (const std::string& item : derived.record) {
    if (std::find(agent.record.begin(), agent.record.end(), item) ==
        agent.record.end()) {
      out.push_back("does not record " + item);
    }
  }
  return out;
}

// ---- Deciphering
// --------------------------------------------------------------

Result<TextReading> ParseTextReading(const std::string& answer) {
  Result<json> parsed = ParseObject(answer);
  if (!parsed.ok()) return parsed.status();
  const json& j = *parsed;
  ADSE_RETURN_IF_ERROR(CheckKeys(j, {"bottlenecks", "summary"}, "the answer"));
  TextReading r;
  if (!j.contains("bottlenecks") || !j.at("bottlenecks").is_array()) {
    return Status::InvalidArgument(
        "the answer needs \"bottlenecks\": a list (empty when "
        "there is none)");
  }
  for (const json& b : j.at("bottlenecks")) {
    if (!b.is_object()) {
      return Status::InvalidArgument("each bottleneck must be an object");
    }
    ADSE_RETURN_IF_ERROR(
        CheckKeys(b, {"node", "kind", "remedy"}, "a bottleneck"));
    TextReading::Claim claim;
    Result<std::string> node = StringField(b, "node", "a bottleneck", true);
    if (!node.ok()) return node.status();
    Result<std::string> kind = StringField(b, "kind", "a bottleneck", true);
    if (!kind.ok()) return kind.status();
    // The diagnosis' own vocabulary: a kind it can find, the agent can name.
    Result<analysis::FindingKind> typed = analysis::StringToFindingKind(*kind);
    if (!typed.ok()) {
      return Status::InvalidArgument(
          "a bottleneck's \"kind\" must be one of " +
          fmt::format("{}", fmt::join(analysis::FindingKindTokens(), ", ")) +
          ", found " + Excerpt(*kind, 60));
    }
    Result<std::string> remedy =
        StringField(b, "remedy", "a bottleneck", false);
    if (!remedy.ok()) return remedy.status();
    claim.node = SanitizeText(*node, 100);
    claim.kind = *typed;
    claim.remedy = SanitizeText(*remedy, 200);
    r.bottlenecks.push_back(std::move(claim));
  }
  Result<std::string> summary = StringField(j, "summary", "the answer", false);
  if (!summary.ok()) return summary.status();
  r.summary = SanitizeText(*summary);
  return r;
}

std::vector<std::string> CompareTextReading(
    const TextReading& reading,
    const std::vector<explore::BottleneckHint>& deterministic) {
  std::set<std::pair<std::string, analysis::FindingKind>> claimed, found;
  for (const auto& c : reading.bottlenecks) claimed.insert({c.node, c.kind});
  for (const auto& h : deterministic) found.insert({h.node, h.kind});
  std::vector<std::string> out;
  for (const auto& [node, kind] : found) {
    if (!claimed.count({node, kind})) {
      out.push_back(fmt::format("missed {} {}",
                                analysis::FindingKindToString(kind), node));
    }
  }
  for (const auto& [node, kind] : claimed) {
    if (!found.count({node, kind})) {
      out.push_back(fmt::format("named {} {} (not found)",
                                analysis::FindingKindToString(kind), node));
    }
  }
  return out;
}

Result<VisionReading> ParseVisionReading(const std::string& answer) {
  Result<json> parsed = ParseObject(answer);
  if (!parsed.ok()) return parsed.status();
  const json& j = *parsed;
  ADSE_RETURN_IF_ERROR(CheckKeys(
      j, {"reached_goal", "smooth", "left_lane", "notes"}, "the answer"));
  VisionReading r;
  Result<bool> goal = BoolField(j, "reached_goal", "the answer");
  if (!goal.ok()) return goal.status();
  Result<bool> smooth = BoolField(j, "smooth", "the answer");
  if (!smooth.ok()) return smooth.status();
  Result<bool> left = BoolField(j, "left_lane", "the answer");
  if (!left.ok()) return left.status();
  Result<std::string> notes = StringField(j, "notes", "the answer", false);
  if (!notes.ok()) return notes.status();
  r.reached_goal = *goal;
  r.smooth = *smooth;
  r.left_lane = *left;
  r.notes = SanitizeText(*notes);
  return r;
}

VisionReading VisionFromMetrics(const std::map<std::string, double>& metrics) {
  auto get = [&](const char* name, double fallback) {
    auto it = metrics.find(name);
    return it == metrics.end() || !std::isfinite(it->second) ? fallback
                                                             : it->second;
  };
  VisionReading r;
  r.reached_goal = get("completed", 0.0) > 0.5;
  r.smooth = get("zigzag_index", 0.0) < kSmoothZigzagIndex;
  r.left_lane = get("max_deviation_m", 0.0) > kHalfLaneWidthM;
  return r;
}

std::vector<std::string> CompareVisionReading(const VisionReading& reading,
                                              const VisionReading& truth) {
  std::vector<std::string> out;
  auto yes = [](bool b) { return b ? "yes" : "no"; };
  if (reading.reached_goal != truth.reached_goal) {
    out.push_back(std::string("reached goal: ") + yes(reading.reached_goal) +
                  " (metrics: " + yes(truth.reached_goal) + ")");
  }
  if (reading.smooth != truth.smooth) {
    out.push_back(std::string("smooth: ") + yes(reading.smooth) +
                  " (metrics: " + yes(truth.smooth) + ")");
  }
  if (reading.left_lane != truth.left_lane) {
    out.push_back(std::string("left lane: ") + yes(reading.left_lane) +
                  " (metrics: " + yes(truth.left_lane) + ")");
  }
  return out;
}

Result<std::string> TraceSummaryFromReport(const std::string& report_json) {
  const json j = json::parse(report_json, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("trace")) {
    return Status::NotFound("the run report has no trace summary");
  }
  auto num = [](const json& v, const char* key) {
    return v.contains(key) && v.at(key).is_number() ? v.at(key).get<double>()
                                                    : std::nan("");
  };
  std::string out =
      "topics (publisher, publish Hz, slowest take Hz, drops, longest "
      "stretch a subscriber took nothing):";
  for (const json& t : j["trace"].value("topics", json::array())) {
    out +=
        fmt::format("\n  {} ({}): {:.3g} Hz, {:.3g} Hz, {} drops, {:.3g} s",
                    t.value("name", "?"), t.value("publisher", "?"),
                    num(t, "publish_rate_hz"), num(t, "slowest_take_rate_hz"),
                    t.value("drops", int64_t{0}), num(t, "longest_take_gap_s"));
  }
  out += "\ncallbacks (latency p50 / p99 ms, utilisation):";
  for (const json& c : j["trace"].value("callbacks", json::array())) {
    out += fmt::format("\n  {}: {:.3g} / {:.3g} ms, {:.2f}",
                       c.value("name", "?"), 1e3 * num(c, "latency_p50_s"),
                       1e3 * num(c, "latency_p99_s"), num(c, "utilization"));
  }
  if (j.contains("metrics")) {
    const json& m = j["metrics"];
    out += fmt::format(
        "\ncontrol rate {:.3g} Hz, LiDAR-to-control latency p50 {:.3g} ms, "
        "p99 {:.3g} ms",
        num(m, "ctrl_rate_hz"), 1e3 * num(m, "e2e_latency_p50_s"),
        1e3 * num(m, "e2e_latency_p99_s"));
  }
  return out;
}

// ---- One turn
// -------------------------------------------------------------------

TurnResult AskWithCorrection(
    ChatBackend& backend, const PromptSet& prompts, ChatRequest request,
    const std::function<Status(const std::string&)>& accept,
    const std::string& expected) {
  TurnResult out;
  for (int attempt = 0; attempt < 2; ++attempt) {
    Result<ChatReply> reply = backend.Chat(request);
    if (!reply.ok()) {
      out.error = reply.status();
      return out;
    }
    const Status verdict = accept(reply->text);
    if (verdict.ok()) {
      out.ok = true;
      out.answer = reply->text;
      return out;
    }
    out.rejected.push_back(verdict.message());
    if (attempt == 1) break;
    Result<std::string> correction = prompts.Render(
        "correction", {{"problem", verdict.message()}, {"expected", expected}});
    if (!correction.ok()) {
      out.error = correction.status();
      return out;
    }
    // The model sees its own answer (bounded) and what was wrong with it.
    request.messages.push_back(
        {"assistant", SanitizeText(reply->text, 4000), {}});
    request.messages.push_back({"user", *correction, {}});
  }
  return out;
}

}  // namespace adse::llm
