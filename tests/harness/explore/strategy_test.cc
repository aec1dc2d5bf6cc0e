// The strategy contract (no repeats, budget, allowed values, determinism)
// for every strategy, exhaustive coverage, and a weak improvement check for
// the evolutionary ones, on a synthetic objective instead of simulations.
#include "harness/explore/strategy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "harness/spec/spec_parser.h"

namespace adse::explore {
namespace {

// 16 x 5 x 2 = 160 points.
spec::Spec MakeSpec(const std::string& exploration) {
  const std::string text = R"(adse: 1
world: {map: {generate: grid}}
task: {start: {edge: E0}, goal: {edge: E5, pos_m: 20, lane: 1}}
design_space:
  cores:    {bind: platform.cores,      range: [1, 16]}
  freq_ghz: {bind: platform.freq_ghz,   values: [1.0, 1.2, 1.5, 1.8, 2.1]}
  lidar_hz: {bind: stack.lidar.rate_hz, values: [7, 14]}
objectives: [{minimize: hardware_cost}, {minimize: nav_time_s}]
constraints: [nav_time_s <= 40]
exploration: )" + exploration +
                           "\n";
  Result<spec::Spec> spec = spec::ParseSpec(text, "t.yaml", "");
  EXPECT_TRUE(spec.ok()) << spec.status().message();
  return spec.ok() ? *spec : spec::Spec();
}

// nav = 100/cores + 10/freq, cost = cores * freq, feasible if nav <= 40.
Observation Evaluate(const spec::DesignPoint& point) {
  Observation observation;
  observation.point = point;
  const double cores = point.at("cores");
  const double freq = point.at("freq_ghz");
  const double nav = 100.0 / cores + 10.0 / freq;
  observation.metrics["nav_time_s"] = nav;
  observation.metrics["hardware_cost"] = cores * freq;
  observation.metrics["completed"] = 1;
  observation.feasible = nav <= 40.0;
  return observation;
}

std::unique_ptr<Strategy> Create(const std::string& name,
                                 const spec::Spec& spec) {
  Result<std::unique_ptr<Strategy>> strategy =
      CreateStrategy(name, StrategyContext{&spec});
  EXPECT_TRUE(strategy.ok()) << strategy.status().message();
  return strategy.ok() ? std::move(*strategy) : nullptr;
}

// Runs ask/tell rounds of `batch` points until the strategy proposes
// nothing twice in a row; returns every proposal in order.
std::vector<spec::DesignPoint> Drive(Strategy& strategy, int batch) {
  std::vector<spec::DesignPoint> all;
  for (int round = 0; round < 10000; ++round) {
    std::vector<spec::DesignPoint> points = strategy.Ask(batch);
    EXPECT_LE(static_cast<int>(points.size()), batch);
    if (points.empty()) break;  // every proposal is told, so this is final
    for (const spec::DesignPoint& point : points) {
      all.push_back(point);
      strategy.Tell(Evaluate(point));
    }
  }
  return all;
}

class StrategyContractTest : public ::testing::TestWithParam<std::string> {};

TEST_P(StrategyContractTest, NoRepeatsWithinBudgetAndAllowedValues) {
  const spec::Spec spec = MakeSpec("{budget: 60, seed: 3, population: 8}");
  std::unique_ptr<Strategy> strategy = Create(GetParam(), spec);
  ASSERT_NE(strategy, nullptr);
  EXPECT_EQ(strategy->name(), GetParam());
  const std::vector<spec::DesignPoint> points = Drive(*strategy, 3);
  EXPECT_EQ(points.size(), 60u);  // 60 < 160: the budget is used fully
  std::set<spec::DesignPoint> distinct(points.begin(), points.end());
  EXPECT_EQ(distinct.size(), points.size());
  for (const spec::DesignPoint& point : points) {
    EXPECT_TRUE(spec.design_space.Check(point).ok())
        << spec.design_space.Check(point).message();
  }
  EXPECT_TRUE(strategy->Ask(5).empty());
  EXPECT_FALSE(strategy->rationale().empty());
}

TEST_P(StrategyContractTest, BudgetLargerThanSpaceCoversItOnce) {
  const spec::Spec spec = MakeSpec("{budget: 500, seed: 5, population: 6}");
  std::unique_ptr<Strategy> strategy = Create(GetParam(), spec);
  ASSERT_NE(strategy, nullptr);
  const std::vector<spec::DesignPoint> points = Drive(*strategy, 4);
  std::set<spec::DesignPoint> distinct(points.begin(), points.end());
  EXPECT_EQ(distinct.size(), points.size());
  EXPECT_EQ(points.size(), spec.design_space.Size());
}

TEST_P(StrategyContractTest, SameSeedSameSequenceOtherSeedDiffers) {
  const spec::Spec a = MakeSpec("{budget: 40, seed: 11}");
  const spec::Spec b = MakeSpec("{budget: 40, seed: 12}");
  std::unique_ptr<Strategy> first = Create(GetParam(), a);
  std::unique_ptr<Strategy> again = Create(GetParam(), a);
  std::unique_ptr<Strategy> other = Create(GetParam(), b);
  ASSERT_TRUE(first && again && other);
  const auto p1 = Drive(*first, 2);
  const auto p2 = Drive(*again, 2);
  const auto p3 = Drive(*other, 2);
  EXPECT_EQ(p1, p2);
  if (GetParam() == "exhaustive") {
    EXPECT_EQ(p1, p3);
  } else {
    EXPECT_NE(p1, p3);
  }
}

TEST_P(StrategyContractTest, ToldPointsAreNeverProposed) {
  const spec::Spec spec = MakeSpec("{budget: 500, seed: 2}");
  std::unique_ptr<Strategy> strategy = Create(GetParam(), spec);
  ASSERT_NE(strategy, nullptr);
  // Cached results for every point with 4 cores, told before any Ask.
  std::set<spec::DesignPoint> told;
  for (double freq : {1.0, 1.2, 1.5, 1.8, 2.1}) {
    for (double lidar : {7.0, 14.0}) {
      spec::DesignPoint point{
          {"cores", 4}, {"freq_ghz", freq}, {"lidar_hz", lidar}};
      told.insert(point);
      strategy->Tell(Evaluate(point));
    }
  }
  for (const spec::DesignPoint& point : Drive(*strategy, 5)) {
    EXPECT_EQ(told.count(point), 0u);
  }
}

INSTANTIATE_TEST_SUITE_P(AllStrategies, StrategyContractTest,
                         ::testing::Values("exhaustive", "random", "ga",
                                           "nsga2"));

TEST(ExhaustiveTest, LexicographicOrderFromStartWrappingAround) {
  const spec::Spec spec = MakeSpec(
      "{budget: 1000, start_from: {cores: 16, freq_ghz: 2.1, lidar_hz: 7}}");
  std::unique_ptr<Strategy> strategy = Create("exhaustive", spec);
  ASSERT_NE(strategy, nullptr);
  const std::vector<spec::DesignPoint> points = Drive(*strategy, 7);
  ASSERT_EQ(points.size(), 160u);
  EXPECT_EQ(points[0], (spec::DesignPoint{
                           {"cores", 16}, {"freq_ghz", 2.1}, {"lidar_hz", 7}}));
  EXPECT_EQ(
      points[1],
      (spec::DesignPoint{{"cores", 16}, {"freq_ghz", 2.1}, {"lidar_hz", 14}}));
  EXPECT_EQ(points[2], (spec::DesignPoint{
                           {"cores", 1}, {"freq_ghz", 1.0}, {"lidar_hz", 7}}));
  EXPECT_EQ(points[3], (spec::DesignPoint{
                           {"cores", 1}, {"freq_ghz", 1.0}, {"lidar_hz", 14}}));
  EXPECT_EQ(points[4], (spec::DesignPoint{
                           {"cores", 1}, {"freq_ghz", 1.2}, {"lidar_hz", 7}}));
  EXPECT_EQ(
      points.back(),
      (spec::DesignPoint{{"cores", 16}, {"freq_ghz", 1.8}, {"lidar_hz", 14}}));
}

TEST(EvolutionaryTest, GenerationWaitsForItsTells) {
  const spec::Spec spec = MakeSpec("{budget: 30, population: 4}");
  std::unique_ptr<Strategy> strategy = Create("ga", spec);
  ASSERT_NE(strategy, nullptr);
  const std::vector<spec::DesignPoint> initial = strategy->Ask(10);
  EXPECT_EQ(initial.size(), 4u);  // one population, not ten
  EXPECT_TRUE(strategy->Ask(1).empty());
  for (size_t i = 0; i + 1 < initial.size(); ++i) {
    strategy->Tell(Evaluate(initial[i]));
  }
  EXPECT_TRUE(strategy->Ask(1).empty());
  Observation failed;
  failed.point = initial.back();
  failed.failed = true;
  strategy->Tell(failed);
  EXPECT_EQ(strategy->Ask(10).size(), 4u);
}

// Sum of the two objectives normalised over the whole space's ranges.
double Quality(const Observation& o) {
  const double nav = o.metrics.at("nav_time_s");
  const double cost = o.metrics.at("hardware_cost");
  const double nav_lo = 100.0 / 16 + 10.0 / 2.1;
  const double nav_hi = 110.0;
  return (nav - nav_lo) / (nav_hi - nav_lo) + (cost - 1.0) / (33.6 - 1.0);
}

class EvolutionaryImprovesTest : public ::testing::TestWithParam<std::string> {
};

TEST_P(EvolutionaryImprovesTest, LaterFeasiblePointsBeatTheInitialOnes) {
  // Averaged over seeds so one unlucky draw does not decide.
  double initial_sum = 0.0;
  double later_sum = 0.0;
  for (int seed = 1; seed <= 5; ++seed) {
    const spec::Spec spec = MakeSpec(
        "{budget: 30, population: 8, seed: " + std::to_string(seed) + "}");
    std::unique_ptr<Strategy> strategy = Create(GetParam(), spec);
    ASSERT_NE(strategy, nullptr);
    const std::vector<spec::DesignPoint> points = Drive(*strategy, 8);
    ASSERT_EQ(points.size(), 30u);
    double initial = 0.0, later = 0.0;
    int n_initial = 0, n_later = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      const Observation o = Evaluate(points[i]);
      if (!o.feasible) continue;
      if (i < 8) {
        initial += Quality(o);
        ++n_initial;
      } else {
        later += Quality(o);
        ++n_later;
      }
    }
    ASSERT_GT(n_later, 0);
    if (n_initial == 0) continue;  // nothing feasible to beat
    initial_sum += initial / n_initial;
    later_sum += later / n_later;
  }
  EXPECT_LT(later_sum, initial_sum);
}

INSTANTIATE_TEST_SUITE_P(GaAndNsga2, EvolutionaryImprovesTest,
                         ::testing::Values("ga", "nsga2"));

TEST(CreateStrategyTest, UnknownNameListsValidOnes) {
  const spec::Spec spec = MakeSpec("{budget: 5}");
  Result<std::unique_ptr<Strategy>> strategy =
      CreateStrategy("simulated_annealing", StrategyContext{&spec});
  ASSERT_FALSE(strategy.ok());
  EXPECT_EQ(strategy.status().code(), Status::Code::kInvalidArgument);
  for (const char* name : {"exhaustive", "random", "ga", "nsga2"}) {
    EXPECT_NE(strategy.status().message().find(name), std::string::npos);
  }
}

TEST(CreateStrategyTest, MissingSpecIsAnError) {
  EXPECT_FALSE(CreateStrategy("random", StrategyContext{}).ok());
}

TEST(SpaceGridTest, EncodeDecodeRoundTrip) {
  const spec::Spec spec = MakeSpec("{budget: 5}");
  SpaceGrid grid(spec.design_space);
  ASSERT_EQ(grid.size(), 160u);
  for (uint64_t i = 0; i < grid.size(); ++i) {
    EXPECT_EQ(grid.Encode(grid.Decode(i)), i);
    std::optional<Genes> back = grid.FromPoint(grid.ToPoint(grid.Decode(i)));
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(*back, grid.Decode(i));
  }
  EXPECT_FALSE(grid.FromPoint({{"cores", 3}, {"freq_ghz", 1.1}}).has_value());
}

}  // namespace
}  // namespace adse::explore
