// `exploration.strategy: llm`: a team of LLM agents explores in a fixed
// round — DSE agent (next point) → command agent (the point as connector
// commands) → run → deciphering agent (text and vision) → DSE agent ... —
// until the budget is spent or the DSE agent declares convergence. The
// agents only advise: every answer is parsed strictly and checked; one
// that cannot be used gets one corrective follow-up, after which the
// built-in `agent` strategy proposes that iteration's point instead, and
// the campaign's records say so. Disagreements of the deciphering and
// command agents with the deterministic analysis are recorded; the
// deterministic values are what the campaign uses.
#ifndef ADSE_HARNESS_LLM_LLM_STRATEGY_H_
#define ADSE_HARNESS_LLM_LLM_STRATEGY_H_

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "harness/explore/strategy.h"
#include "harness/llm/exchange_log.h"
#include "harness/spec/spec.h"
#include "stack/base/env.h"
#include "stack/base/status.h"

namespace adse::llm {

// The backend the scenario's `llm` section asks for, wrapped so that every
// exchange is recorded in <record_dir>/llm/exchanges.jsonl (empty: not
// recorded). Exchanges already recorded there are answered from the
// record first, so a resumed campaign re-proposes what it proposed before.
// With `backend: replay` every answer comes from `llm.replay_from`.
Result<std::unique_ptr<RecordingBackend>> OpenBackend(
    const spec::Spec& spec, const std::string& record_dir,
    Env* env = Env::Default());

struct LlmStrategyOptions {
  // A run's RunReport JSON and trajectory picture, by content key.
  std::function<std::string(const std::string& key)> report_path;
  std::function<std::string(const std::string& key)> image_path;
  // Campaign folder for llm/memory.jsonl and llm/events.jsonl; empty:
  // record nothing.
  std::string record_dir;
  // The model backend; required.
  std::unique_ptr<RecordingBackend> backend;
  // Where the records are appended through.
  Env* env = Env::Default();
};

// InvalidArgument when the prompts cannot be loaded or no backend is given.
Result<std::unique_ptr<explore::Strategy>> NewLlmStrategy(
    const spec::Spec& spec, LlmStrategyOptions options);

// What happened in one of the agents' rounds. A new kind needs its token in
// llm_strategy.cc's LlmEventKindTerms.
enum class LlmEventKind {
  // An answer that did not parse or validate (it got a corrective
  // follow-up).
  kRejected,
  // The DSE agent's answers could not be used: the built-in agent proposed
  // the iteration's point.
  kFallback,
  // An agent's reading differed from the deterministic analysis, whose
  // values were used.
  kDisagreement,
  // The DSE agent declared convergence.
  kConverged,
  // The model could not be asked.
  kError,
};

// The token of a kind ("fallback"), as stored in llm/events.jsonl.
const char* LlmEventKindToString(LlmEventKind kind);
// False when `name` is no kind's token; `kind` is then unchanged.
bool StringToLlmEventKind(std::string_view name, LlmEventKind* kind);
// Every token, in enum order.
std::vector<std::string> LlmEventKindNames();

// What happened in the agents' rounds, for reports.
struct LlmEvent {
  int64_t iteration = 0;
  std::string agent;  // dse|command|text|vision
  LlmEventKind kind = LlmEventKind::kRejected;
  std::string detail;
};
std::string EventsPath(const std::string& campaign_folder);
Result<std::vector<LlmEvent>> LoadEvents(const std::string& path);

}  // namespace adse::llm

#endif  // ADSE_HARNESS_LLM_LLM_STRATEGY_H_
