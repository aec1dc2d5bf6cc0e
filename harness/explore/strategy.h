// Exploration strategies: one ask/tell interface over a scenario's design
// space (see the design brief, "Exploration"). A strategy proposes points
// with Ask, the harness evaluates them and reports each back with Tell.
//
// Contract shared by every strategy:
//  - Ask never returns a point already proposed or told, and never more
//    points in total than `exploration.budget` (nor than the space holds).
//  - Every random choice comes from adse::Random seeded from
//    `exploration.seed`: the same spec gives the same proposals.
//  - Each proposed point should get exactly one Tell (failed = true when the
//    run failed); the evolutionary strategies wait for a generation's Tells
//    before proposing the next one, so Ask may return fewer points than
//    asked, or none, until then. Tells of points never proposed (e.g. cached
//    results) are welcome: they count as seen and inform the search.
//  - Nothing throws.
#ifndef ADSE_HARNESS_EXPLORE_STRATEGY_H_
#define ADSE_HARNESS_EXPLORE_STRATEGY_H_

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "analysis/diagnosis/remedy.h"
#include "analysis/pareto/pareto.h"
#include "harness/spec/spec.h"
#include "stack/base/random.h"
#include "stack/base/status.h"

namespace adse::explore {

// A bottleneck found in a run (a summary of analysis/diagnosis's Finding).
struct BottleneckHint {
  analysis::FindingKind kind = analysis::FindingKind::kCpuBound;
  std::string node;       // the node that cannot keep up / is input-limited
  std::string remedy;     // readable text of `remedies`, for prompts
  double severity = 0.0;  // relative deficit
  // What would relieve it, most important first: act on these, not on the
  // text. Empty when the row predates typed remedies. (The initialiser lets
  // the four fields above be brace-initialised without a -Wextra warning.)
  std::vector<analysis::Remedy> remedies = {};
};

// What a strategy is told about an evaluated point.
struct Observation {
  spec::DesignPoint point;
  // nav_time_s, ctrl_rate_hz, hardware_cost, deviation_score, completed, ...
  std::map<std::string, double> metrics;
  bool feasible = false;  // all constraints hold
  bool failed = false;    // the run failed (no metrics)
  // The run was stopped early because `violated_constraint` (as the
  // scenario writes it) could no longer hold: infeasible, its metrics other
  // than hardware_cost withheld, and the constraint's metric known to lie
  // on the violating side of its bound.
  bool censored = false;
  std::string violated_constraint;
  // The run was ended because the car stood held by something traffic
  // would not release (status stalled): censored too, and it would never
  // have arrived, so its nav time lies past any bound on it.
  bool stalled = false;
  // The run's diagnosis, most severe first (empty when healthy or failed).
  std::vector<BottleneckHint> bottlenecks;
  // The run's content key, when it has a run (agents read its report).
  std::string key;
};

class Strategy {
 public:
  virtual ~Strategy() = default;
  // Up to k new points, never one already proposed or evaluated, never
  // beyond the remaining budget.
  virtual std::vector<spec::DesignPoint> Ask(int k) = 0;
  virtual void Tell(const Observation& observation) = 0;
  virtual std::string name() const = 0;
  // A short written reason for the last Ask (for the report), may be empty.
  virtual std::string rationale() const { return {}; }
  // Whether the last Ask did not go as the strategy meant (the llm
  // strategy's built-in agent standing in for its model): progress output
  // shows that round's rationale even under a progress bar.
  virtual bool fell_back() const { return false; }
  // Whether proposals depend on what Tell reported. A non-adaptive
  // strategy (exhaustive, random) may be asked whenever a worker is free;
  // an adaptive one is asked in rounds of RoundSize points whose Tells all
  // arrive, in proposal order, before the next Ask, so that a campaign
  // proposes the same points however fast its runs finish.
  virtual bool adaptive() const { return true; }
  // Points per round for an adaptive strategy, given exploration.batch
  // (GA / NSGA-II: a generation).
  virtual int RoundSize(int batch) const { return batch < 1 ? 1 : batch; }
  // Why the strategy cannot go on (e.g. an llm replay was asked something
  // never recorded): it then proposes nothing more, and the campaign stops
  // with this error, keeping what was evaluated. Ok otherwise.
  virtual Status failure() const { return Status::Ok(); }
};

struct StrategyContext {
  // Design space, objectives, exploration options (seed, budget,
  // population, rates, start_from). Must outlive the strategy.
  const spec::Spec* spec = nullptr;
};

// The names CreateStrategy accepts: spec::StrategyNames() without "llm"
// (which harness/llm builds), in the same order.
const std::vector<std::string>& StrategyNames();

// Factory keyed by one of StrategyNames(). An
// unknown name, a missing spec or an empty design space gives
// InvalidArgument (the first listing the valid names).
Result<std::unique_ptr<Strategy>> CreateStrategy(
    const std::string& name, const StrategyContext& context);

// ---------------------------------------------------------------------------
// Building blocks shared by the strategies (and usable by others, e.g. the
// agent strategies). `spec` must be non-null with a non-empty design space
// whose parameters all have values; CreateStrategy checks that.

// A point as one value index per parameter, in file order.
using Genes = std::vector<int>;

// The design space as a mixed-radix grid. Index order is lexicographic over
// the parameters in file order (the first parameter varies slowest).
class SpaceGrid {
 public:
  explicit SpaceGrid(const spec::DesignSpace& space);

  size_t dimensions() const { return counts_.size(); }
  int count(size_t dimension) const { return counts_[dimension]; }
  // Number of points; meaningful only when !saturated().
  uint64_t size() const { return size_; }
  // The point count does not fit in 64 bits (minus one).
  bool saturated() const { return saturated_; }

  spec::DesignPoint ToPoint(const Genes& genes) const;
  // nullopt when a parameter is missing or its value is not allowed.
  std::optional<Genes> FromPoint(const spec::DesignPoint& point) const;
  // Mixed-radix index <-> genes (only when !saturated()).
  Genes Decode(uint64_t index) const;
  uint64_t Encode(const Genes& genes) const;
  // A uniformly random point (possibly seen already).
  Genes RandomGenes(Random& random) const;

 private:
  const spec::DesignSpace* space_;
  std::vector<int> counts_;
  uint64_t size_ = 1;
  bool saturated_ = false;
};

// Draws points uniformly without replacement (a lazy Fisher-Yates shuffle
// over the grid index, so memory grows with draws, not with the space) and
// skips points in a caller's `seen` set.
class UnseenSampler {
 public:
  UnseenSampler(const SpaceGrid* grid, uint64_t seed);
  // A point not in `seen` and not drawn before; nullopt when none is left
  // (for a saturated space: when many random draws all hit seen points).
  std::optional<Genes> Next(const std::set<Genes>& seen);

 private:
  const SpaceGrid* grid_;
  Random random_;
  uint64_t remaining_;
  std::unordered_map<uint64_t, uint64_t> swapped_;
};

// The spec's objectives in minimisation form (maximised ones negated), in
// spec order; NaN for a missing metric and for every objective of a failed
// run.
std::vector<double> MinimizationObjectives(const spec::Spec& spec,
                                           const Observation& observation);

// How badly an observation misses the constraints: 0 when feasible,
// otherwise the number of spec constraints that do not hold (at least 1,
// since `feasible` is authoritative); +inf for a failed run.
double ConstraintViolation(const spec::Spec& spec,
                           const Observation& observation);

// The observation as analysis/pareto takes it: objectives in minimisation
// form, feasibility and violation. A run without a usable value of an
// objective still takes part, infeasible and ranked behind every placed one.
analysis::Evaluation ParetoEvaluationOf(const spec::Spec& spec,
                                        const Observation& observation);

// The constraint-aware Pareto front of `observations` (indices, ascending):
// the one computation behind every front adse shows — campaigns, replay,
// analysis, status — and the LLM agents' memory.
std::vector<int> ParetoFrontOf(const spec::Spec& spec,
                               const std::vector<Observation>& observations);

// The individual strategies (CreateStrategy is the checked entry point).
std::unique_ptr<Strategy> NewExhaustiveStrategy(const spec::Spec& spec);
std::unique_ptr<Strategy> NewRandomStrategy(const spec::Spec& spec);
std::unique_ptr<Strategy> NewGeneticStrategy(const spec::Spec& spec);
std::unique_ptr<Strategy> NewNsga2Strategy(const spec::Spec& spec);
// The built-in reasoning strategy (agent.cc): a Ceres-fitted surrogate of
// the metrics, constraint- and bottleneck-guided proposals with a rationale.
std::unique_ptr<Strategy> NewAgentStrategy(const spec::Spec& spec);

}  // namespace adse::explore

#endif  // ADSE_HARNESS_EXPLORE_STRATEGY_H_
