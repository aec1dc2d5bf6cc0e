#include "harness/llm/interpret.h"

#include <algorithm>
#include <map>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "harness/llm/agents.h"
#include "harness/spec/spec.h"

namespace adse::llm {
namespace {

// The robotaxi example's small variant: a complete scenario to imitate.
const char kExample[] = R"(adse: 1
name: robotaxi-small
world:
  map: {generate: parking_lot, params: {rows: 2, slots_per_row: 8}}
  traffic: {seed: 3, flows: [{from: E2_W2, to: W0_E0, vehicles_per_hour: 60}], parked_occupancy: 0.5}
task:
  start: {x: 8.0, y: -1.75}
  goal: {x: 10.0, y: 29.75}
  speed_limit_kmh: 30
  timeout_s: 300
platform: {kind: virtual, reference_ghz: 2.1, cost_model: counted, cost_scale: 30}
design_space:
  cores:    {bind: platform.cores,      values: [1, 4, 16]}
  freq_ghz: {bind: platform.freq_ghz,   values: [1.0, 2.1]}
  lidar_hz: {bind: stack.lidar.rate_hz, values: [7, 14]}
objectives: [{minimize: hardware_cost}, {minimize: nav_time_s}]
constraints: [nav_time_s <= 60, completed]
exploration: {strategy: agent, budget: 12})";

const char kMaps[] =
    "- {generate: parking_lot, params: {rows: R, slots_per_row: S}}: a parking "
    "lot with R "
    "rows of S slots (aisles run along y; lanes are 3.5 m wide; with rows: 2 "
    "and "
    "slots_per_row: 8 the drive from (8.0, -1.75) to (10.0, 29.75) is valid)\n"
    "- {generate: grid, params: {number: N, length_m: L, lanes: K}}: a town "
    "grid of N by N "
    "junctions L metres apart, K lanes per direction\n"
    "- {net: <path to a SUMO .net.xml>}: an existing SUMO network";

std::string StripFence(std::string text) {
  const size_t a = text.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return "";
  text = text.substr(a);
  if (text.rfind("```", 0) == 0) {
    const size_t first_newline = text.find('\n');
    const size_t close = text.rfind("```");
    if (first_newline != std::string::npos && close > first_newline) {
      text = text.substr(first_newline + 1, close - first_newline - 1);
    }
  }
  return text;
}

}  // namespace

const std::vector<std::string>& InterpretableSections() {
  static const std::vector<std::string> kSections = {
      "adse",         "name", "world",      "task",        "platform",
      "design_space", "cost", "objectives", "constraints", "exploration"};
  return kSections;
}

const std::vector<std::pair<std::string, std::string>>& InterpretDefaults() {
  static const std::vector<std::pair<std::string, std::string>> kDefaults = {
      {"design_space",
       "{cores: {bind: platform.cores, values: [1, 2, 4, 8, 16]}, "
       "freq_ghz: {bind: platform.freq_ghz, values: [1.0, 1.5, 2.1]}, "
       "lidar_hz: {bind: stack.lidar.rate_hz, values: [7, 14]}}"},
      {"objectives", "[{minimize: hardware_cost}, {minimize: nav_time_s}]"},
      {"constraints", "[completed]"},
  };
  return kDefaults;
}

Result<InterpretResult> Interpret(const std::string& request,
                                  ChatBackend& backend,
                                  const PromptSet& prompts,
                                  const InterpretOptions& options) {
  if (!options.validate) return Status::Internal("interpret: no validator");
  std::string metrics;
  for (const spec::MetricInfo& m : spec::KnownMetrics()) {
    metrics += (metrics.empty() ? "- " : "\n- ") + m.name + ": " + m.doc;
  }
  std::string defaults;
  for (const auto& [section, yaml] : InterpretDefaults()) {
    defaults += "\n  " + section + ": " + yaml;
  }
  Result<std::string> prompt =
      prompts.Render("interpret", {{"request", request},
                                   {"maps", kMaps},
                                   {"metrics", metrics},
                                   {"defaults", defaults},
                                   {"example", kExample}});
  if (!prompt.ok()) return prompt.status();

  ChatRequest chat;
  chat.agent = "interpretation";
  chat.model = options.model;
  chat.json = false;  // the answer is YAML
  chat.messages = {{"user", *prompt, {}}};

  InterpretResult out;
  std::string last_problem;
  for (int round = 0; round <= options.max_corrections; ++round) {
    Result<ChatReply> reply = backend.Chat(chat);
    if (!reply.ok()) return reply.status();
    ++out.answers;
    const std::string answer = StripFence(reply->text);

    // Keep what a model may choose; fill in what it left out.
    std::string problem;
    std::string yaml;
    std::vector<std::string> filled, dropped;
    try {
      YAML::Node root = YAML::Load(answer);
      if (!root.IsMap()) {
        problem = "the answer is not a YAML mapping of scenario sections";
      } else {
        YAML::Node kept(YAML::NodeType::Map);
        std::map<std::string, int> line_of;  // each section once
        for (const auto& item : root) {
          const std::string key = item.first.as<std::string>();
          const int line = item.first.Mark().line + 1;
          if (auto [seen, first] = line_of.emplace(key, line); !first) {
            problem = fmt::format(
                "the answer gives the section '{}' twice (lines {} and {}); "
                "give each section once",
                key, seen->second, line);
            break;
          }
          const auto& allowed = InterpretableSections();
          if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
            dropped.push_back(key);
          } else {
            kept[key] = item.second;
          }
        }
        for (const auto& [section, text] : InterpretDefaults()) {
          if (problem.empty() && !kept[section]) {
            kept[section] = YAML::Load(text);
            filled.push_back(section + ": " + text);
          }
        }
        YAML::Emitter emitter;
        emitter << kept;
        if (problem.empty()) yaml = std::string(emitter.c_str()) + "\n";
      }
    } catch (const YAML::Exception& e) {
      problem = std::string("the answer is not valid YAML: ") + e.what();
    }
    if (problem.empty()) {
      const Status valid = options.validate(yaml);
      if (valid.ok()) {
        out.yaml = yaml;
        out.defaults = filled;
        out.dropped = dropped;
        return out;
      }
      problem = "adse's validator reports:\n" + valid.message();
    }
    out.rejected.push_back(problem);
    last_problem = problem;
    if (round == options.max_corrections) break;
    Result<std::string> correction = prompts.Render(
        "correction",
        {{"problem", problem},
         {"expected",
          "Answer with the whole corrected scenario file, as YAML only."}});
    if (!correction.ok()) return correction.status();
    chat.messages.push_back({"assistant", answer.substr(0, 20000), {}});
    chat.messages.push_back({"user", *correction, {}});
  }
  return Status::InvalidArgument(
      "the interpretation agent gave no valid scenario in " +
      std::to_string(out.answers) + " answers (" +
      std::to_string(options.max_corrections) +
      " corrections); the last problem:\n" + last_problem);
}

}  // namespace adse::llm
