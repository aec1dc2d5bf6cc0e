// The LLM agents' answers as data: strict parsing and validation of what
// each role may say, the deterministic values they are checked against,
// and one exchange with a corrective follow-up. Models only advise: an
// answer that fails these checks changes nothing.
#ifndef ADSE_HARNESS_LLM_AGENTS_H_
#define ADSE_HARNESS_LLM_AGENTS_H_

#include <cstdint>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "analysis/diagnosis/remedy.h"
#include "harness/explore/strategy.h"
#include "harness/llm/chat.h"
#include "harness/llm/prompts.h"
#include "harness/spec/spec.h"
#include "stack/base/status.h"

namespace adse::llm {

// ---- DSE agent -------------------------------------------------------------
struct DseAnswer {
  spec::DesignPoint point;  // empty when converged
  std::string rationale;
  bool converged = false;
};
// {"point": {...}, "rationale": "...", "converged": false} or
// {"converged": true, "rationale": "..."}. InvalidArgument (the message is
// what the model is told) for anything else: not one JSON object, unknown
// keys, a parameter missing or not in the space, a value not allowed, a
// point in `evaluated`, convergence before anything was evaluated.
Result<DseAnswer> ParseDseAnswer(const std::string& answer,
                                 const spec::DesignSpace& space,
                                 const std::set<spec::DesignPoint>& evaluated);

// ---- Command agent
// -----------------------------------------------------------
struct Commands {
  std::string map;  // MapDescription of the scenario
  int64_t traffic_seed = 0;
  std::string weather;                     // clear|rain|fog
  std::map<std::string, double> platform;  // binding -> value
  std::vector<std::string> record;         // tracing: what to record
};
// What the tracer can record (every item is recorded in any case: the
// analysis needs all of them).
const std::vector<std::string>& TraceRecordOptions();
// "generate parking_lot (rows=2, slots_per_row=8)" or the net file's name.
std::string MapDescription(const spec::Spec& spec);
// The commands the harness derives from the point itself.
Commands DeriveCommands(const spec::Spec& spec, const spec::DesignPoint& point,
                        uint64_t seed);
// Schema check: exactly the keys world{map,traffic_seed,weather},
// platform{<binding>: number}, tracing{record: [...]}; strings only from
// the allowed sets, the map equal to the scenario's (so no path or shell
// text passes).
Result<Commands> ParseCommandAnswer(const std::string& answer,
                                    const spec::Spec& spec);
// Differences from the derived commands, one sentence each (empty: agree).
std::vector<std::string> CompareCommands(const Commands& agent,
                                         const Commands& derived);

// ---- Deciphering agent
// -------------------------------------------------------
struct TextReading {
  struct Claim {
    std::string node;
    analysis::FindingKind kind = analysis::FindingKind::kCpuBound;
    std::string remedy;
  };
  std::vector<Claim> bottlenecks;
  std::string summary;
};
Result<TextReading> ParseTextReading(const std::string& answer);
// Disagreements with the deterministic diagnosis (by node and kind).
std::vector<std::string> CompareTextReading(
    const TextReading& reading,
    const std::vector<explore::BottleneckHint>& deterministic);

struct VisionReading {
  bool reached_goal = false;
  bool smooth = false;
  bool left_lane = false;
  std::string notes;
};
Result<VisionReading> ParseVisionReading(const std::string& answer);
// The same three judgements from the run's metrics: reached_goal =
// completed; smooth = zigzag_index < kSmoothZigzagIndex; left_lane =
// max_deviation_m > kHalfLaneWidthM.
inline constexpr double kSmoothZigzagIndex = 0.35;  // a weave under ~6 s
inline constexpr double kHalfLaneWidthM = 1.75;
VisionReading VisionFromMetrics(const std::map<std::string, double>& metrics);
std::vector<std::string> CompareVisionReading(
    const VisionReading& reading, const VisionReading& deterministic);

// The trace summary the text part reads, from a RunReport JSON text (its
// "trace" and "metrics"); NotFound when the report has no trace.
Result<std::string> TraceSummaryFromReport(const std::string& report_json);

// ---- One turn
// -----------------------------------------------------------------
struct TurnResult {
  bool ok = false;
  std::string answer;                 // the accepted answer
  std::vector<std::string> rejected;  // why each rejected answer was refused
  Status error;                       // the backend's error, if it failed
};
// Sends `request`; when `accept` refuses the answer, sends one corrective
// follow-up (the correction template with the problem and `expected`) and
// tries the second answer. Never more than two requests.
TurnResult AskWithCorrection(
    ChatBackend& backend, const PromptSet& prompts, ChatRequest request,
    const std::function<Status(const std::string&)>& accept,
    const std::string& expected);

// Free text from a model, made safe to show in reports: control characters
// dropped, whitespace collapsed, at most `max_chars`.
std::string SanitizeText(const std::string& text, size_t max_chars = 500);

}  // namespace adse::llm

#endif  // ADSE_HARNESS_LLM_AGENTS_H_
