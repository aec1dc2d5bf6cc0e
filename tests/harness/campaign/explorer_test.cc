// The exploration loop against an in-memory evaluator whose results come
// back in a scrambled order: what a strategy proposes must not depend on
// how fast runs finish, or on how many run at once.
#include "harness/campaign/explorer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "harness/campaign/headline.h"
#include "harness/spec/spec_parser.h"
#include "stack/base/random.h"

namespace adse::campaign {
namespace {

spec::Spec Space(const std::string& strategy, int budget, int batch = 1) {
  Result<spec::Spec> spec = spec::ParseSpec(R"(adse: 1
world: {map: {generate: parking_lot}}
task: {start: {x: 0, y: 0}, goal: {x: 80, y: 40}}
design_space:
  cores:    {bind: platform.cores,    range: [1, 16]}
  freq_ghz: {bind: platform.freq_ghz, values: [1.0, 1.5, 2.0]}
constraints: [nav_time_s <= 60, completed]
objectives: [{minimize: hardware_cost}, {minimize: nav_time_s}]
)",
                                            "space.yaml", "");
  EXPECT_TRUE(spec.ok()) << spec.status().message();
  spec->exploration.strategy = strategy;
  spec->exploration.budget = budget;
  spec->exploration.batch = batch;
  return *spec;
}

// Metrics from a formula; completes up to `capacity` evaluations at once,
// returning them in a seeded random order, some of them as failures.
class FormulaEvaluator : public Evaluator {
 public:
  FormulaEvaluator(int capacity, uint64_t seed)
      : capacity_(capacity), random_(seed) {}
  int capacity() const override { return capacity_; }
  void Start(const EvalRequest& r) override {
    const double cores = r.point.at("cores"), ghz = r.point.at("freq_ghz");
    EvaluationRow row;
    row.index = r.index;
    row.iteration = r.iteration;
    row.point = r.point;
    row.content_key = spec::FormatPoint({}, r.point);
    if (static_cast<int>(cores) % 7 == 3) {
      row.status = "failed";
    } else {
      row.status = "complete";
      const double nav = 20 + 120 / (std::min(cores, 8.0) * ghz);
      row.metrics = {{"nav_time_s", nav},
                     {"hardware_cost", cores * ghz},
                     {"completed", 1}};
      row.feasible = nav <= 60;
    }
    row.bottlenecks_json = "[]";
    pending_.push_back(row);
    ++started_;
    max_outstanding_ = std::max(max_outstanding_, outstanding());
  }
  int outstanding() const override { return static_cast<int>(pending_.size()); }
  std::vector<EvaluationRow> Wait() override {
    // Finish a random non-empty subset, in random order.
    std::vector<EvaluationRow> done;
    const size_t n = 1 + random_.Below(pending_.size());
    for (size_t i = 0; i < n; ++i) {
      const size_t pick = random_.Below(pending_.size());
      done.push_back(pending_[pick]);
      pending_.erase(pending_.begin() + static_cast<long>(pick));
    }
    return done;
  }
  bool interrupted() const override { return started_ >= interrupt_after_; }

  int capacity_;
  Random random_;
  std::vector<EvaluationRow> pending_;
  int started_ = 0;
  int max_outstanding_ = 0;
  int interrupt_after_ = 1 << 30;
};

std::vector<spec::DesignPoint> Proposals(const ExplorationResult& r) {
  std::vector<spec::DesignPoint> points;
  for (const EvaluationRow& row : r.evaluations) points.push_back(row.point);
  return points;
}

ExplorationResult RunWith(const spec::Spec& spec, int capacity,
                          uint64_t order_seed) {
  Result<std::unique_ptr<explore::Strategy>> strategy =
      explore::CreateStrategy(spec.exploration.strategy, {&spec});
  EXPECT_TRUE(strategy.ok()) << strategy.status().message();
  FormulaEvaluator evaluator(capacity, order_seed);
  ExplorationResult r = Explore(spec, **strategy, evaluator);
  EXPECT_LE(evaluator.max_outstanding_,
            std::max(capacity, (*strategy)->RoundSize(spec.exploration.batch)));
  return r;
}

class ExplorerTest : public ::testing::TestWithParam<std::string> {};

TEST_P(ExplorerTest, ProposalsDoNotDependOnCompletionOrderOrParallelism) {
  const spec::Spec spec = Space(GetParam(), 14, 2);
  const ExplorationResult serial = RunWith(spec, 1, 1);
  ASSERT_EQ(serial.evaluations.size(), 14u);
  for (uint64_t order_seed : {2u, 3u}) {
    for (int capacity : {2, 3}) {
      const ExplorationResult parallel = RunWith(spec, capacity, order_seed);
      std::vector<spec::DesignPoint> a = Proposals(serial),
                                     b = Proposals(parallel);
      if (!explore::CreateStrategy(GetParam(), {&spec}).value()->adaptive()) {
        // Non-adaptive strategies may interleave differently; the set holds.
        std::sort(a.begin(), a.end());
        std::sort(b.begin(), b.end());
      }
      EXPECT_EQ(a, b) << GetParam() << " capacity " << capacity << " order "
                      << order_seed;
    }
  }
}

TEST_P(ExplorerTest, NeverRepeatsAPointAndRespectsTheBudget) {
  const spec::Spec spec = Space(GetParam(), 20, 3);
  const ExplorationResult r = RunWith(spec, 3, 7);
  EXPECT_EQ(r.evaluations.size(), 20u);
  std::set<spec::DesignPoint> seen;
  for (const EvaluationRow& row : r.evaluations) {
    EXPECT_TRUE(seen.insert(row.point).second)
        << spec::FormatPoint(spec.design_space, row.point);
  }
  // Every evaluation belongs to a recorded iteration that lists its key.
  size_t keys = 0;
  for (const runfile::IterationRow& it : r.iterations)
    keys += it.content_keys.size();
  EXPECT_EQ(keys, r.evaluations.size());
}

INSTANTIATE_TEST_SUITE_P(AllStrategies, ExplorerTest,
                         ::testing::ValuesIn(explore::StrategyNames()));

TEST(ExplorerInterruptTest, AnInterruptStopsProposing) {
  const spec::Spec spec = Space("random", 30);
  auto strategy = explore::CreateStrategy("random", {&spec}).value();
  FormulaEvaluator evaluator(2, 1);
  evaluator.interrupt_after_ = 5;
  const ExplorationResult r = Explore(spec, *strategy, evaluator);
  EXPECT_TRUE(r.interrupted);
  EXPECT_LE(evaluator.started_, 6);
  EXPECT_LT(r.evaluations.size(), 30u);
}

// The evaluations of the confirm phase's iterations.
std::vector<EvaluationRow> ConfirmRows(const ExplorationResult& r) {
  std::set<int64_t> confirming;
  for (const runfile::IterationRow& it : r.iterations) {
    if (it.strategy == kConfirmPhase) confirming.insert(it.iteration);
  }
  std::vector<EvaluationRow> rows;
  for (const EvaluationRow& row : r.evaluations) {
    if (confirming.count(row.iteration) > 0) rows.push_back(row);
  }
  return rows;
}

TEST(ExplorerConfirmTest,
     TheConfirmPhaseRunsCheaperDesignsUntilNoneIsLeftUntriedWhateverTheOrder) {
  spec::Spec spec = Space("random", 4, 2);
  const ExplorationResult plain = RunWith(spec, 1, 1);
  // The budget's runs found a feasible design, but not the cheapest (2
  // cores at 1.5 GHz, cost 3): the phase has work to do.
  const Headline before = ComputeHeadline(spec, plain.evaluations);
  ASSERT_GE(before.cheapest, 0);
  ASSERT_GT(RowMetric(plain.evaluations[before.cheapest], kCostMetric), 3.0);
  ASSERT_GT(before.cheaper.untried_count, 0);
  EXPECT_TRUE(ConfirmRows(plain).empty());

  spec.exploration.confirm_runs = 40;
  const ExplorationResult confirmed = RunWith(spec, 1, 1);
  EXPECT_FALSE(confirmed.confirm_cut);
  // The strategy's runs are the same; the phase's come after them.
  ASSERT_GT(confirmed.evaluations.size(), plain.evaluations.size());
  for (size_t i = 0; i < plain.evaluations.size(); ++i) {
    EXPECT_EQ(confirmed.evaluations[i].point, plain.evaluations[i].point);
  }
  const std::vector<EvaluationRow> phase = ConfirmRows(confirmed);
  EXPECT_EQ(phase.size(),
            confirmed.evaluations.size() - plain.evaluations.size());
  EXPECT_LT(phase.size(), 40u) << "it ends once nothing cheaper is untried";
  std::set<spec::DesignPoint> seen;
  for (const EvaluationRow& row : confirmed.evaluations) {
    EXPECT_TRUE(seen.insert(row.point).second) << "proposed twice";
  }
  const Headline after = ComputeHeadline(spec, confirmed.evaluations);
  ASSERT_GE(after.cheapest, 0);
  EXPECT_DOUBLE_EQ(
      RowMetric(confirmed.evaluations[after.cheapest], kCostMetric), 3.0);
  EXPECT_EQ(after.cheaper.untried_count, 0);
  // As the strategy's, the phase's picks do not depend on how fast runs
  // finish or how many run at once.
  for (int capacity : {2, 3}) {
    const ExplorationResult other = RunWith(spec, capacity, 5);
    EXPECT_EQ(Proposals(other), Proposals(confirmed)) << capacity;
  }
  // Fewer confirm runs than it would take: the phase stops at them.
  spec.exploration.confirm_runs = 1;
  EXPECT_EQ(ConfirmRows(RunWith(spec, 1, 1)).size(), 1u);
}

TEST(ExplorerConfirmTest, AnInterruptCutsTheConfirmPhase) {
  spec::Spec spec = Space("random", 4);
  spec.exploration.confirm_runs = 40;
  auto strategy = explore::CreateStrategy("random", {&spec}).value();
  FormulaEvaluator evaluator(1, 1);
  evaluator.interrupt_after_ = 5;  // the phase's first run
  const ExplorationResult r = Explore(spec, *strategy, evaluator);
  EXPECT_TRUE(r.interrupted);
  EXPECT_TRUE(r.confirm_cut);
  EXPECT_LE(r.evaluations.size(), 5u);
}

}  // namespace
}  // namespace adse::campaign
