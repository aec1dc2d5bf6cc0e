// The exploration loop: asks a strategy for points, hands them to an
// Evaluator (live worker processes, or recorded results for replay), and
// tells the strategy what came back — in an order that depends only on the
// results, never on how fast runs finish. So a campaign started again
// re-creates its strategy from the seed, replays the recorded history
// (finished runs are found by content key, not run again) and then
// proposes what the uninterrupted campaign would have proposed.
#ifndef ADSE_HARNESS_CAMPAIGN_EXPLORER_H_
#define ADSE_HARNESS_CAMPAIGN_EXPLORER_H_

#include <cstdint>
#include <string>
#include <vector>

#include "harness/campaign/evaluation.h"
#include "harness/explore/strategy.h"
#include "harness/spec/spec.h"

namespace adse::campaign {

struct EvalRequest {
  int64_t index = 0;      // evaluation number, in proposal order
  int64_t iteration = 0;  // round that proposed it
  spec::DesignPoint point;
};

// Evaluates points; may run several at once.
class Evaluator {
 public:
  virtual ~Evaluator() = default;
  // How many evaluations can run at once.
  virtual int capacity() const = 0;
  // Accepts a request (queueing it when every slot is busy). A known
  // result (recorded, cached) may complete at once.
  virtual void Start(const EvalRequest& request) = 0;
  // Evaluations started and not yet returned by Wait.
  virtual int outstanding() const = 0;
  // Blocks until at least one evaluation has completed (or an interrupt
  // arrived) and returns the completed rows, each with index and
  // iteration set. Returns nothing only when interrupted() or nothing is
  // outstanding.
  virtual std::vector<EvaluationRow> Wait() = 0;
  // A stop was requested (Ctrl-C, SIGTERM): the loop proposes nothing more.
  virtual bool interrupted() const = 0;
};

// Told of the loop's progress (for progress bars and logs).
class ExplorerListener {
 public:
  virtual ~ExplorerListener() = default;
  // `fell_back`: explore::Strategy::fell_back() of the strategy that
  // proposed them (false for the confirm phase).
  virtual void OnProposed(const runfile::IterationRow& /*iteration*/,
                          const std::vector<spec::DesignPoint>& /*points*/,
                          bool /*fell_back*/) {}
  virtual void OnEvaluated(const EvaluationRow& /*row*/) {}
};

struct ExplorationResult {
  std::vector<EvaluationRow> evaluations;         // by index
  std::vector<runfile::IterationRow> iterations;  // by iteration
  bool interrupted = false;
  // An interrupt came before the confirm phase ended (it may have had
  // runs left to propose even when the strategy's budget was spent).
  bool confirm_cut = false;
};

// The iterations of the confirm phase carry this strategy name.
inline constexpr char kConfirmPhase[] = "confirm";

// How many of `result`'s evaluations the confirm phase proposed.
int ConfirmEvaluations(const ExplorationResult& result);

// Runs `strategy` to the end of its budget (or an interrupt), then the
// confirm phase when exploration.confirm_runs > 0: rounds of up to
// exploration.batch SettlePicks (campaign/cheaper.h) of the runs so far,
// until nothing cheaper than the cheapest feasible design is left untried
// or the confirm runs are spent. Non-adaptive strategies are asked
// whenever a slot is free; adaptive ones round by round, their Tells in
// proposal order. Each iteration row lists the content keys of the points
// it proposed (known once they are evaluated).
ExplorationResult Explore(const spec::Spec& spec, explore::Strategy& strategy,
                          Evaluator& evaluator,
                          ExplorerListener* listener = nullptr);

}  // namespace adse::campaign

#endif  // ADSE_HARNESS_CAMPAIGN_EXPLORER_H_
