#include "harness/llm/llm_strategy.h"

#include <functional>
#include <optional>
#include <set>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "analysis/diagnosis/remedy.h"
#include "harness/llm/agents.h"
#include "harness/llm/jsonl_log.h"
#include "harness/llm/memory.h"
#include "harness/llm/prompts.h"
#include "harness/spec/spec_parser.h"
#include "stack/base/files.h"
#include "stack/base/vocabulary.h"

namespace adse::llm {
namespace {

using nlohmann::json;

// Metrics carried in memory records and step prompts besides objectives.
const char* const kMemoryMetrics[] = {"completed", "nav_time_s", "ctrl_rate_hz",
                                      "hardware_cost", "deviation_score"};
// Longest list of evaluated points written into one prompt.
constexpr size_t kMaxListedPoints = 200;

std::string Place(const world::Location& l) {
  if (l.by_edge)
    return fmt::format("edge {} at {:g} m (lane {})", l.edge, l.pos_m, l.lane);
  return fmt::format("({:g}, {:g}) m", l.x_m, l.y_m);
}

std::string TaskText(const spec::Spec& s) {
  const world::TaskOptions& t = s.task;
  return fmt::format(
      "{} from {} to {} on map {}, speed limit {:g} km/h, abandoned after {:g} "
      "s",
      world::TaskKindToString(t.kind), Place(t.start), Place(t.goal),
      MapDescription(s), t.speed_limit_kmh, t.timeout_s);
}

std::string Lines(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& i : items) out += (out.empty() ? "- " : "\n- ") + i;
  return out.empty() ? "(none)" : out;
}

std::string SpaceText(const spec::DesignSpace& space) {
  std::vector<std::string> lines;
  for (const spec::DesignParameter& p : space.parameters) {
    std::string values;
    for (double v : p.values)
      values += fmt::format("{}{:g}", values.empty() ? "" : ", ", v);
    lines.push_back(fmt::format("{} (sets {}): {}", p.name, p.bind, values));
  }
  return Lines(lines);
}

std::string MetricsText(const std::map<std::string, double>& metrics) {
  std::string out;
  for (const auto& [name, value] : metrics) {
    out += fmt::format("{}{}={:.4g}", out.empty() ? "" : ", ", name, value);
  }
  return out;
}

std::string DiagnosisText(const std::vector<explore::BottleneckHint>& hints) {
  if (hints.empty()) return "no bottleneck found";
  std::string out;
  for (const explore::BottleneckHint& h : hints) {
    out += fmt::format("{}{} {} (deficit {:.0f} %, remedy: {})",
                       out.empty() ? "" : "; ",
                       analysis::FindingKindToString(h.kind), h.node,
                       100.0 * h.severity, h.remedy);
  }
  return out;
}

std::string Join(const std::vector<std::string>& items,
                 const char* sep = "; ") {
  std::string out;
  for (const std::string& i : items) out += (out.empty() ? "" : sep) + i;
  return out;
}

class LlmStrategy : public explore::Strategy {
 public:
  LlmStrategy(const spec::Spec& spec, LlmStrategyOptions options,
              PromptSet prompts, JsonlLog memory_log, JsonlLog events_log,
              std::string system_prompt)
      : spec_(spec),
        options_(std::move(options)),
        prompts_(std::move(prompts)),
        memory_log_(std::move(memory_log)),
        events_log_(std::move(events_log)),
        system_prompt_(std::move(system_prompt)),
        fallback_(explore::NewAgentStrategy(spec)) {
    const uint64_t size = spec.design_space.Size();
    budget_ = std::min<uint64_t>(
        static_cast<uint64_t>(std::max(spec.exploration.budget, 0)), size);
  }

  std::string name() const override { return "llm"; }
  std::string rationale() const override { return rationale_; }
  bool fell_back() const override { return fell_back_; }
  int RoundSize(int /*batch*/) const override { return 1; }
  Status failure() const override { return failure_; }

  std::vector<spec::DesignPoint> Ask(int k) override {
    if (k < 1 || converged_ || !failure_.ok() || proposed_ >= budget_)
      return {};
    ++iteration_;
    fell_back_ = false;
    options_.backend->set_iteration(iteration_);

    std::optional<spec::DesignPoint> point;
    std::string proposed_by = "llm";
    const Answer<DseAnswer> answer = Turn<DseAnswer>(
        "dse", DseMessages(),
        [&](const std::string& text) {
          return ParseDseAnswer(text, spec_.design_space, evaluated_);
        },
        "Answer with {\"point\": {<parameter>: <allowed value>, ...}, "
        "\"rationale\": \"...\"}"
        " naming every design parameter once, with a point not evaluated yet; "
        "or with "
        "{\"converged\": true, \"rationale\": \"...\"}.");
    if (!failure_.ok()) return {};
    if (answer.value && answer.value->converged) {
      converged_ = true;
      rationale_ =
          "the DSE agent declared convergence: " + answer.value->rationale;
      Event("dse", LlmEventKind::kConverged, answer.value->rationale);
      return {};
    }
    if (answer.value) {
      point = answer.value->point;
      rationale_ = answer.value->rationale;
    } else {
      Event("dse", LlmEventKind::kFallback,
            "the built-in agent proposes this iteration's point: the DSE "
            "agent " +
                answer.why);
      const std::vector<spec::DesignPoint> fallback = fallback_->Ask(1);
      if (fallback.empty()) return {};
      point = fallback.front();
      proposed_by = "agent";
      fell_back_ = true;
      rationale_ = "fallback to the built-in agent: the DSE agent " +
                   answer.why + ". agent: " + fallback_->rationale();
    }

    CommandTurn(*point);
    ++proposed_;
    evaluated_.insert(*point);
    proposals_[*point] = {iteration_, rationale_, proposed_by};
    return {*point};
  }

  void Tell(const explore::Observation& o) override {
    fallback_->Tell(o);
    evaluated_.insert(o.point);
    MemoryRecord record;
    record.index = static_cast<int64_t>(memory_.size());
    record.iteration = -1;
    if (auto it = proposals_.find(o.point); it != proposals_.end()) {
      record.iteration = it->second.iteration;
      record.rationale = it->second.rationale;
      record.proposed_by = it->second.proposed_by;
    }
    record.point = o.point;
    record.failed = o.failed;
    record.feasible = o.feasible && !o.failed;
    for (const auto& [name, value] : o.metrics) {
      bool wanted = false;
      for (const spec::Objective& obj : spec_.objectives)
        wanted |= obj.metric == name;
      for (const char* m : kMemoryMetrics) wanted |= name == m;
      if (wanted) record.metrics[name] = value;
    }
    record.diagnosis = o.failed ? "" : DiagnosisText(o.bottlenecks);

    last_point_ = spec::FormatPoint(spec_.design_space, o.point);
    if (o.failed) {
      last_result_ =
          "the run failed (crash, timeout or out of memory); no metrics";
      last_report_ = "no trace: the run failed";
    } else {
      last_result_ = std::string(record.feasible ? "feasible" : "infeasible") +
                     "; " + MetricsText(record.metrics);
      last_report_ = "diagnosis: " + DiagnosisText(o.bottlenecks);
      options_.backend->set_iteration(record.iteration);
      if (!o.key.empty()) Decipher(o, &last_report_);
    }
    memory_.push_back(record);
    Record(memory_log_, MemoryLine(record));
  }

 private:
  struct Proposal {
    int64_t iteration = 0;
    std::string rationale;
    std::string proposed_by;
  };

  std::string Model(const std::string& role) const {
    auto it = spec_.llm.models.find(role);
    return it == spec_.llm.models.end() ? "" : it->second;
  }

  std::vector<ChatMessage> DseMessages() const {
    std::vector<std::string> listed;
    for (const spec::DesignPoint& p : evaluated_) {
      if (listed.size() == kMaxListedPoints) {
        listed.push_back(fmt::format("... and {} more",
                                     evaluated_.size() - kMaxListedPoints));
        break;
      }
      listed.push_back(spec::FormatPoint(spec_.design_space, p));
    }
    const bool first = memory_.empty();
    Result<std::string> step = prompts_.Render(
        "dse_step",
        {{"iteration", std::to_string(iteration_)},
         {"remaining", std::to_string(budget_ - proposed_)},
         {"last_point",
          first ? "(none yet: this is the first proposal)" : last_point_},
         {"last_result", first ? "(none)" : last_result_},
         {"last_report", first ? "(none)" : last_report_},
         {"memory", FormatMemory(Curate(memory_, spec_.design_space, {},
                                        ParetoFrontOfMemory(spec_, memory_)))},
         {"evaluated", listed.empty() ? "(none)" : Lines(listed)}});
    return {{"system", system_prompt_, {}},
            {"user", step.ok() ? *step : "", {}}};
  }

  void CommandTurn(const spec::DesignPoint& point) {
    const Commands derived =
        DeriveCommands(spec_, point, spec_.world.traffic.seed);
    std::string bindings;
    for (const spec::DesignParameter& p : spec_.design_space.parameters) {
      bindings += (bindings.empty() ? "" : ", ") + p.name + " -> " + p.bind;
    }
    Result<std::string> prompt = prompts_.Render(
        "command",
        {{"point", spec::FormatPoint(spec_.design_space, point)},
         {"bindings", bindings},
         {"world",
          fmt::format("map \"{}\", traffic seed {}, weather {}", derived.map,
                      derived.traffic_seed, derived.weather)},
         {"tracing_options", Join(TraceRecordOptions(), ", ")}});
    const Answer<Commands> commands = Turn<Commands>(
        "command", {{"user", prompt.ok() ? *prompt : "", {}}},
        [&](const std::string& text) {
          return ParseCommandAnswer(text, spec_);
        },
        "Answer with {\"world\": {\"map\", \"traffic_seed\", \"weather\"}, "
        "\"platform\": "
        "{<binding>: <value>}, \"tracing\": {\"record\": [...]}} and no other "
        "keys.");
    if (!failure_.ok()) return;
    if (!commands.value) {
      Event("command", LlmEventKind::kError,
            "the command agent " + commands.why +
                "; the commands derived from the point are used");
      return;
    }
    const std::vector<std::string> diffs =
        CompareCommands(*commands.value, derived);
    if (!diffs.empty()) {
      Event("command", LlmEventKind::kDisagreement,
            Join(diffs) + "; the commands derived from the point are used");
    }
  }

  // The deciphering agent's two parts; their readings are compared with
  // the deterministic analysis, which is what `report` keeps.
  void Decipher(const explore::Observation& o, std::string* report) {
    const std::string point = spec::FormatPoint(spec_.design_space, o.point);
    Result<std::string> report_json =
        ReadFile(options_.report_path(o.key), 16u << 20);
    Result<std::string> trace = report_json.ok()
                                    ? TraceSummaryFromReport(*report_json)
                                    : Result<std::string>(report_json.status());
    if (trace.ok()) {
      Result<std::string> prompt = prompts_.Render(
          "decipher_text", {{"point", point}, {"trace_summary", *trace}});
      const Answer<TextReading> reading = Turn<TextReading>(
          "text", {{"user", prompt.ok() ? *prompt : "", {}}}, ParseTextReading,
          "Answer with {\"bottlenecks\": [{\"node\", \"kind\", \"remedy\"}], "
          "\"summary\"}.");
      if (!failure_.ok()) return;
      if (reading.value) {
        const std::vector<std::string> diffs =
            CompareTextReading(*reading.value, o.bottlenecks);
        if (!diffs.empty()) {
          Event("text", LlmEventKind::kDisagreement,
                Join(diffs) + "; the deterministic diagnosis is kept");
          *report += "\ntext agent (disagrees, not used): " + Join(diffs);
        } else if (!reading.value->summary.empty()) {
          *report += "\ntext agent (agrees): " + reading.value->summary;
        }
      } else {
        Event("text", LlmEventKind::kError, "the text agent " + reading.why);
      }
    }

    Result<std::string> png = ReadFile(options_.image_path(o.key), 32u << 20);
    if (!png.ok()) return;
    Result<std::string> prompt = prompts_.Render(
        "decipher_vision",
        {{"point", point},
         {"legend",
          "The picture has its own legend (lanes, ideal path, trajectory, "
          "other "
          "vehicles, start, goal) and corner coordinates in metres."}});
    const Answer<VisionReading> reading = Turn<VisionReading>(
        "vision", {{"user", prompt.ok() ? *prompt : "", {*png}}},
        ParseVisionReading,
        "Answer with {\"reached_goal\": bool, \"smooth\": bool, \"left_lane\": "
        "bool, "
        "\"notes\": \"...\"}.");
    if (!failure_.ok()) return;
    if (reading.value) {
      const VisionReading truth = VisionFromMetrics(o.metrics);
      const std::vector<std::string> diffs =
          CompareVisionReading(*reading.value, truth);
      if (!diffs.empty()) {
        Event("vision", LlmEventKind::kDisagreement,
              Join(diffs) + "; the metrics are kept");
        *report += "\nvision agent (disagrees with the metrics, not used): " +
                   Join(diffs);
      } else if (!reading.value->notes.empty()) {
        *report += "\nvision agent (agrees): " + reading.value->notes;
      }
    } else {
      Event("vision", LlmEventKind::kError, "the vision agent " + reading.why);
    }
  }

  template <typename T>
  struct Answer {
    std::optional<T> value;
    std::string why;  // when there is none: "could not ask its model (...)"
  };

  // One agent's turn: the request, strict parsing with one corrective
  // follow-up, rejected answers recorded. A replay asked something never
  // recorded stops the strategy (failure_): going on with the built-in
  // agent would quietly make a different campaign than the recorded one.
  template <typename T>
  Answer<T> Turn(const std::string& agent, std::vector<ChatMessage> messages,
                 const std::function<Result<T>(const std::string&)>& parse,
                 const std::string& expected) {
    const ChatRequest request{agent, Model(agent), std::move(messages), true};
    Answer<T> out;
    const TurnResult turn = AskWithCorrection(
        *options_.backend, prompts_, request,
        [&](const std::string& text) {
          Result<T> parsed = parse(text);
          if (parsed.ok()) out.value = std::move(parsed).value();
          return parsed.status();
        },
        expected);
    for (const std::string& why : turn.rejected)
      Event(agent, LlmEventKind::kRejected, why);
    if (turn.ok) return out;
    if (turn.error.code() == Status::Code::kNotFound && failure_.ok()) {
      failure_ = turn.error;
      Event(agent, LlmEventKind::kError, turn.error.message());
    }
    out.why = turn.error.ok()
                  ? "gave answers that could not be used (" +
                        turn.rejected.back() + ")"
                  : "could not ask its model (" + turn.error.message() + ")";
    return out;
  }

  void Event(const std::string& agent, LlmEventKind kind,
             const std::string& detail) {
    const json j = {{"iteration", iteration_},
                    {"agent", agent},
                    {"kind", LlmEventKindToString(kind)},
                    {"detail", SanitizeText(detail, 1000)}};
    Record(events_log_, j.dump(-1, ' ', false, json::error_handler_t::replace));
  }

  // Records are advisory: a write that fails is said once on stderr, and
  // the exploration goes on.
  void Record(JsonlLog& log, const std::string& line) {
    Status s = log.Append(line);
    if (!s.ok() && !record_error_shown_) {
      record_error_shown_ = true;
      std::fprintf(stderr, "adse: llm records: %s\n", s.ToString().c_str());
    }
  }

  const spec::Spec& spec_;
  LlmStrategyOptions options_;
  PromptSet prompts_;
  JsonlLog memory_log_;
  JsonlLog events_log_;
  std::string system_prompt_;
  std::unique_ptr<explore::Strategy> fallback_;
  uint64_t budget_ = 0;
  uint64_t proposed_ = 0;
  int64_t iteration_ = -1;
  bool converged_ = false;
  bool fell_back_ = false;  // the last Ask's point is the built-in agent's
  bool record_error_shown_ = false;
  Status failure_;
  std::string rationale_;
  std::set<spec::DesignPoint> evaluated_;
  std::map<spec::DesignPoint, Proposal> proposals_;
  std::vector<MemoryRecord> memory_;
  std::string last_point_, last_result_, last_report_;
};

}  // namespace

Result<std::unique_ptr<RecordingBackend>> OpenBackend(
    const spec::Spec& spec, const std::string& record_dir, Env* env) {
  const std::string own = record_dir.empty() ? "" : ExchangesPath(record_dir);
  // With a live model, a resumed campaign first hears again what its
  // models said before.
  const std::string replay =
      spec.llm.backend == "replay" ? ExchangesPath(spec.llm.replay_from) : own;
  return OpenRecordingBackend(spec.llm, replay, own, spec.Where("llm"), env);
}

Result<std::unique_ptr<explore::Strategy>> NewLlmStrategy(
    const spec::Spec& spec, LlmStrategyOptions options) {
  if (!options.backend)
    return Status::InvalidArgument("llm strategy: no model backend");
  if (!options.report_path || !options.image_path) {
    return Status::InvalidArgument("llm strategy: no way to find run reports");
  }
  if (spec.design_space.parameters.empty()) {
    return Status::InvalidArgument(
        spec.Where("design_space") +
        "design_space: the llm strategy needs a design space");
  }
  Result<PromptSet> prompts = PromptSet::Load(spec.llm.prompts);
  if (!prompts.ok()) return prompts.status();
  const std::string dir = options.record_dir;
  Result<JsonlLog> memory =
      JsonlLog::Open(dir.empty() ? "" : MemoryPath(dir), options.env);
  if (!memory.ok()) return memory.status();
  Result<JsonlLog> events =
      JsonlLog::Open(dir.empty() ? "" : EventsPath(dir), options.env);
  if (!events.ok()) return events.status();

  std::vector<std::string> objectives, constraints;
  for (const spec::Objective& o : spec.objectives) {
    objectives.push_back((o.minimize ? "minimize " : "maximize ") + o.metric);
  }
  for (const std::string& c : spec.constraints) constraints.push_back(c);
  Result<std::string> system = prompts->Render(
      "dse_system", {{"scenario_name", spec.name},
                     {"task", TaskText(spec)},
                     {"objectives", Lines(objectives)},
                     {"constraints", Lines(constraints)},
                     {"cost", spec.cost},
                     {"design_space", SpaceText(spec.design_space)},
                     {"budget", std::to_string(spec.exploration.budget)}});
  if (!system.ok()) return system.status();
  return std::unique_ptr<explore::Strategy>(new LlmStrategy(
      spec, std::move(options), std::move(*prompts), std::move(*memory),
      std::move(*events), std::move(*system)));
}

namespace {
const std::vector<Term<LlmEventKind>>& LlmEventKindTerms() {
  static const std::vector<Term<LlmEventKind>> kTerms = {
      {LlmEventKind::kRejected, "rejected"},
      {LlmEventKind::kFallback, "fallback"},
      {LlmEventKind::kDisagreement, "disagreement"},
      {LlmEventKind::kConverged, "converged"},
      {LlmEventKind::kError, "error"},
  };
  return kTerms;
}
}  // namespace

const char* LlmEventKindToString(LlmEventKind kind) {
  return NameOf(LlmEventKindTerms(), kind);
}
bool StringToLlmEventKind(std::string_view name, LlmEventKind* kind) {
  return ValueOf(LlmEventKindTerms(), name, kind);
}
std::vector<std::string> LlmEventKindNames() {
  return NamesOf(LlmEventKindTerms());
}

std::string EventsPath(const std::string& campaign_folder) {
  return campaign_folder + "/llm/events.jsonl";
}

Result<std::vector<LlmEvent>> LoadEvents(const std::string& path) {
  std::vector<LlmEvent> events;
  ADSE_RETURN_IF_ERROR(
      ReadJsonLines(path, "an llm event", [&](const std::string& line) {
        const json j = json::parse(line);
        const std::string token = j.at("kind").get<std::string>();
        LlmEventKind kind = LlmEventKind::kRejected;
        if (!StringToLlmEventKind(token, &kind)) {
          throw std::invalid_argument(
              UnknownTermMessage("event kind", token, LlmEventKindNames()));
        }
        events.push_back({j.at("iteration").get<int64_t>(),
                          j.at("agent").get<std::string>(), kind,
                          j.at("detail").get<std::string>()});
      }));
  return events;
}

}  // namespace adse::llm
