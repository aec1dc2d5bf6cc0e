// Pareto front, ranks, hypervolume and search quality on hand-made sets
// with known answers, plus a brute-force cross-check on random sets.
#include "analysis/pareto/pareto.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace adse::analysis {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

Evaluation Eval(std::vector<double> objectives, bool feasible = true,
                double violation = 0.0) {
  Evaluation e;
  e.objectives = std::move(objectives);
  e.feasible = feasible;
  e.violation = violation;
  return e;
}

// A design point named like the reference study's space.
Evaluation At(double cores, double ghz, std::vector<double> objectives,
              bool feasible = true) {
  Evaluation e = Eval(std::move(objectives), feasible, feasible ? 0.0 : 1.0);
  e.point = {{"cores", cores}, {"freq_ghz", ghz}};
  return e;
}

bool Dominates(const std::vector<double>& a, const std::vector<double>& b) {
  bool better = false;
  for (size_t k = 0; k < a.size(); ++k) {
    if (a[k] > b[k]) return false;
    better = better || a[k] < b[k];
  }
  return better;
}

TEST(ParetoFrontTest, TwoObjectivesHandMade) {
  const std::vector<Evaluation> evals = {
      Eval({1, 5}),    Eval({2, 3}), Eval({3, 4}),  // 2 dominated by 1
      Eval({4, 1}),    Eval({5, 5}),                // 4 dominated by all
      Eval({1.5, 4.5})};
  EXPECT_EQ(ParetoFront(evals), (std::vector<int>{0, 1, 3, 5}));
}

TEST(ParetoFrontTest, SameValueInOneObjectiveKeepsOnlyTheBetterOther) {
  // Equal cost, different time: the slower one is dominated (weakly worse
  // in cost, strictly in time).
  const std::vector<Evaluation> evals = {Eval({6, 200}), Eval({6, 170}),
                                         Eval({7.2, 170})};
  EXPECT_EQ(ParetoFront(evals), (std::vector<int>{1}));
}

TEST(ParetoFrontTest, CostsThatDifferOnlyInTheLastBitTie) {
  // 7 cores x 1.8 GHz is 12.6 and 6 x 2.1 is 12.600000000000001: the same
  // price, so only the faster computer is on the front, in 2-D (Kung's
  // algorithm) and in 3-D (non-dominated sorting) alike.
  const double seven_by_1_8 = 7 * 1.8;
  const double six_by_2_1 = 6 * 2.1;
  ASSERT_LT(seven_by_1_8, six_by_2_1);
  EXPECT_EQ(
      ParetoFront({Eval({seven_by_1_8, 173.2}), Eval({six_by_2_1, 163.1})}),
      (std::vector<int>{1}));
  EXPECT_EQ(ParetoFront({Eval({seven_by_1_8, 173.2, -28.4}),
                         Eval({six_by_2_1, 163.1, -28.5})}),
            (std::vector<int>{1}));
  EXPECT_EQ(
      ParetoRanks({Eval({seven_by_1_8, 173.2}), Eval({six_by_2_1, 163.1})}),
      (std::vector<int>{1, 0}));
  EXPECT_TRUE(analysis::Dominates({six_by_2_1, 163.1}, {seven_by_1_8, 173.2}));
  EXPECT_TRUE(WeaklyDominates({six_by_2_1, 1.0}, {seven_by_1_8, 1.0}));
}

TEST(ParetoTieKeyTest, RoundsToTwelveSignificantDigits) {
  EXPECT_EQ(TieKey(7 * 1.8), TieKey(6 * 2.1));
  EXPECT_EQ(TieKey(3 * 1.2), TieKey(2 * 1.8));
  EXPECT_EQ(TieKey(-7 * 1.8), TieKey(-6 * 2.1));
  // A real difference, even in the 10th digit, stays one.
  EXPECT_LT(TieKey(12.6), TieKey(12.600000001));
  EXPECT_LT(TieKey(1e-7), TieKey(1.0000001e-7));
  EXPECT_EQ(TieKey(0.0), 0.0);
  EXPECT_EQ(TieKey(kInf), kInf);
  EXPECT_TRUE(std::isnan(TieKey(kNaN)));
}

TEST(ParetoFrontTest, InfeasiblePointsNeverBeatFeasibleOnes) {
  // The infeasible (0, 0) would dominate everything.
  const std::vector<Evaluation> evals = {Eval({0, 0}, false, 5.0), Eval({1, 5}),
                                         Eval({3, 2}), Eval({4, 4})};
  EXPECT_EQ(ParetoFront(evals), (std::vector<int>{1, 2}));
}

TEST(ParetoFrontTest, DuplicatesAreAllKeptInAscendingOrder) {
  const std::vector<Evaluation> evals = {
      Eval({2, 2}), Eval({1, 3}), Eval({2, 2}), Eval({3, 3}), Eval({1, 3})};
  EXPECT_EQ(ParetoFront(evals), (std::vector<int>{0, 1, 2, 4}));
  // Same answer regardless of the order pagmo's sort visits ties in.
  std::vector<Evaluation> reversed(evals.rbegin(), evals.rend());
  EXPECT_EQ(ParetoFront(reversed), (std::vector<int>{0, 2, 3, 4}));
}

TEST(ParetoFrontTest, AllInfeasibleGivesTheLeastViolatingNonDominated) {
  const std::vector<Evaluation> evals = {
      Eval({1, 1}, false, 3.0), Eval({5, 5}, false, 0.5),
      Eval({6, 4}, false, 0.5), Eval({7, 7}, false, 0.5),  // dominated
      Eval({0, 0}, false, 2.0), Eval({9, 1}, false, 0.5 + 1e-15)};
  EXPECT_EQ(ParetoFront(evals), (std::vector<int>{1, 2, 5}));
}

TEST(ParetoFrontTest, AllInfeasibleWithOneLeastViolating) {
  const std::vector<Evaluation> evals = {Eval({1, 1}, false, 3.0),
                                         Eval({5, 5}, false, 0.25),
                                         Eval({0, 0}, false, kNaN)};
  EXPECT_EQ(ParetoFront(evals), (std::vector<int>{1}));
}

TEST(ParetoFrontTest, ThreeObjectives) {
  const std::vector<Evaluation> evals = {
      Eval({1, 2, 3}), Eval({3, 2, 1}),
      Eval({2, 2, 2}), Eval({2, 3, 3}),  // dominated by 0
      Eval({3, 3, 3}),                   // dominated by 0, 1, 2
      Eval({1, 2, 3})};
  EXPECT_EQ(ParetoFront(evals), (std::vector<int>{0, 1, 2, 5}));
}

TEST(ParetoFrontTest, OneObjectiveKeepsTheMinima) {
  const std::vector<Evaluation> evals = {Eval({3}), Eval({1}), Eval({2}),
                                         Eval({1})};
  EXPECT_EQ(ParetoFront(evals), (std::vector<int>{1, 3}));
}

TEST(ParetoFrontTest, EmptyAndSingle) {
  EXPECT_TRUE(ParetoFront({}).empty());
  EXPECT_EQ(ParetoFront({Eval({1, 2})}), (std::vector<int>{0}));
  EXPECT_EQ(ParetoFront({Eval({1, 2}, false, 1.0)}), (std::vector<int>{0}));
}

TEST(ParetoFrontTest, UnusableEvaluationsAreNeverOnTheFront) {
  const std::vector<Evaluation> evals = {Eval({0, kNaN}),  // NaN objective
                                         Eval({0}),  // wrong objective count
                                         Eval({2, 2}), Eval({1, 3}),
                                         Eval({kInf, 0})};
  EXPECT_EQ(ParetoFront(evals), (std::vector<int>{2, 3, 4}));
}

TEST(ParetoRanksTest, LayersFeasibleThenInfeasibleThenUnusable) {
  const std::vector<Evaluation> evals = {
      Eval({1, 4}),              // 0: front
      Eval({2, 5}),              // 1: dominated by 0 -> 1
      Eval({3, 6}),              // 2: -> 2
      Eval({4, 1}),              // 3: front
      Eval({0, 0}, false, 1.0),  // 4: first infeasible level -> 3
      Eval({1, 1}, false, 1.0),  // 5: dominated within its level -> 4
      Eval({0, 0}, false, 2.0),  // 6: next level -> 5
      Eval({0, kNaN}),           // 7: unusable -> 6
  };
  EXPECT_EQ(ParetoRanks(evals), (std::vector<int>{0, 1, 2, 0, 3, 4, 5, 6}));
}

TEST(ParetoRanksTest, NoFeasibleStartsAtZero) {
  const std::vector<Evaluation> evals = {Eval({2, 2}, false, 0.5),
                                         Eval({1, 1}, false, 0.5),
                                         Eval({0, 0}, false, 4.0)};
  EXPECT_EQ(ParetoRanks(evals), (std::vector<int>{1, 0, 2}));
  EXPECT_TRUE(ParetoRanks({}).empty());
}

TEST(ParetoRanksTest, RandomSetsAgreeWithBruteForce) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> value(0, 9);  // ties on purpose
  std::bernoulli_distribution feasible(0.7);
  for (int trial = 0; trial < 50; ++trial) {
    const size_t m = 2 + trial % 3;
    std::vector<Evaluation> evals(5 + trial);
    for (Evaluation& e : evals) {
      for (size_t k = 0; k < m; ++k) e.objectives.push_back(value(rng));
      e.feasible = trial % 10 != 0 && feasible(rng);  // some all-infeasible
      e.violation = e.feasible ? 0.0 : value(rng) % 3;
    }
    bool any_feasible = false;
    double least = kInf;
    for (const Evaluation& e : evals) {
      any_feasible = any_feasible || e.feasible;
      if (!e.feasible) least = std::min(least, e.violation);
    }
    std::vector<int> expected;
    for (size_t i = 0; i < evals.size(); ++i) {
      const bool candidate =
          any_feasible ? evals[i].feasible : evals[i].violation == least;
      if (!candidate) continue;
      bool dominated = false;
      for (size_t j = 0; j < evals.size(); ++j) {
        const bool rival =
            any_feasible ? evals[j].feasible : evals[j].violation == least;
        dominated = dominated || (rival && Dominates(evals[j].objectives,
                                                     evals[i].objectives));
      }
      if (!dominated) expected.push_back(static_cast<int>(i));
    }
    const std::vector<int> front = ParetoFront(evals);
    EXPECT_EQ(front, expected) << "trial " << trial;
    const std::vector<int> ranks = ParetoRanks(evals);
    std::vector<int> rank_zero;
    for (size_t i = 0; i < ranks.size(); ++i) {
      if (ranks[i] == 0) rank_zero.push_back(static_cast<int>(i));
    }
    EXPECT_EQ(rank_zero, front) << "trial " << trial;
    // A dominating feasible point always ranks strictly better.
    for (size_t i = 0; i < evals.size(); ++i) {
      for (size_t j = 0; j < evals.size(); ++j) {
        if (evals[i].feasible && evals[j].feasible &&
            Dominates(evals[i].objectives, evals[j].objectives)) {
          EXPECT_LT(ranks[i], ranks[j]);
        }
        if (evals[i].feasible && !evals[j].feasible) {
          EXPECT_LT(ranks[i], ranks[j]);
        }
      }
    }
  }
}

TEST(ParetoHypervolumeTest, StaircaseHasItsExactArea) {
  // Boxes [1,4]x[3,4], [2,4]x[2,4], [3,4]x[1,4]: union 1 + 2 + 3 = 6.
  std::vector<Evaluation> evals = {Eval({1, 3}), Eval({2, 2}), Eval({3, 1})};
  EXPECT_DOUBLE_EQ(Hypervolume(evals, {4, 4}), 6.0);
  // Dominated, duplicate, infeasible and out-of-bounds points add nothing.
  evals.push_back(Eval({2.5, 2.5}));
  evals.push_back(Eval({2, 2}));
  evals.push_back(Eval({0, 0}, false, 1.0));
  evals.push_back(Eval({0.5, 10}));  // on the front, beyond the reference
  evals.push_back(Eval({4, 0.5}));   // on the reference boundary
  EXPECT_DOUBLE_EQ(Hypervolume(evals, {4, 4}), 6.0);
}

TEST(ParetoHypervolumeTest, ThreeObjectives) {
  EXPECT_DOUBLE_EQ(Hypervolume({Eval({1, 1, 1})}, {2, 3, 4}), 6.0);
  // 2 + 4 - overlap [2,3]^3 = 5.
  EXPECT_DOUBLE_EQ(Hypervolume({Eval({1, 2, 2}), Eval({2, 1, 1})}, {3, 3, 3}),
                   5.0);
}

TEST(ParetoHypervolumeTest, OneObjective) {
  EXPECT_DOUBLE_EQ(Hypervolume({Eval({3}), Eval({1.5})}, {4}), 2.5);
}

TEST(ParetoHypervolumeTest, NothingFeasibleOrNothingInsideIsZero) {
  EXPECT_EQ(Hypervolume({}, {1, 1}), 0.0);
  EXPECT_EQ(Hypervolume({Eval({0, 0}, false, 1.0)}, {1, 1}), 0.0);
  EXPECT_EQ(Hypervolume({Eval({2, 0})}, {1, 1}), 0.0);
  EXPECT_EQ(Hypervolume({Eval({kInf, 0})}, {1, 1}), 0.0);
}

TEST(ParetoHypervolumeTest, BareVectorsGiveTheSameVolume) {
  const std::vector<std::vector<double>> points = {
      {1, 3}, {2, 2}, {3, 1}, {2.5, 2.5}, {2, 2}, {0.5, 10}, {4, 0.5}};
  EXPECT_DOUBLE_EQ(PointsHypervolume(points, {4, 4}), 6.0);
  EXPECT_DOUBLE_EQ(PointsHypervolume({{1, 2, 2}, {2, 1, 1}}, {3, 3, 3}), 5.0);
  EXPECT_DOUBLE_EQ(PointsHypervolume({{3}, {1.5}}, {4}), 2.5);
  EXPECT_EQ(PointsHypervolume({}, {1, 1}), 0.0);
  EXPECT_EQ(PointsHypervolume({{kNaN, 0}}, {1, 1}), 0.0);
  EXPECT_EQ(PointsHypervolume({{0, 0}}, {1}), 0.0);  // size mismatch
  EXPECT_EQ(PointsHypervolume({{0, 0}}, {1, kInf}), 0.0);
}

TEST(ParetoDominanceTest, StrictAndWeak) {
  EXPECT_TRUE(analysis::Dominates({1, 2}, {1, 3}));
  EXPECT_FALSE(analysis::Dominates({1, 2}, {1, 2}));
  EXPECT_FALSE(analysis::Dominates({1, 4}, {2, 3}));
  EXPECT_TRUE(WeaklyDominates({1, 2}, {1, 2}));
  EXPECT_TRUE(WeaklyDominates({0, 2}, {1, 2}));
  EXPECT_FALSE(WeaklyDominates({1, 3}, {1, 2}));
}

TEST(ParetoHypervolumeTest, BadReferenceIsNaN) {
  const std::vector<Evaluation> evals = {Eval({1, 1})};
  EXPECT_TRUE(std::isnan(Hypervolume(evals, {2})));
  EXPECT_TRUE(std::isnan(Hypervolume(evals, {2, kNaN})));
  EXPECT_TRUE(std::isnan(Hypervolume(evals, {2, kInf})));
}

TEST(ParetoReferenceTest, WorstFeasibleValuePlusMargin) {
  const std::vector<Evaluation> evals = {Eval({2, 100}), Eval({5, 40}),
                                         Eval({50, 500}, false, 1.0),
                                         Eval({3, kInf})};
  const std::vector<double> r = ReferencePoint(evals);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_DOUBLE_EQ(r[0], 5.5);
  EXPECT_DOUBLE_EQ(r[1], 110.0);  // +inf is not a usable worst value
  EXPECT_EQ(ReferencePoint(evals, 0.0), (std::vector<double>{5, 100}));
}

TEST(ParetoReferenceTest, ZerosAndNegatedObjectives) {
  // A maximised objective enters negated: worst -10 moves out to -9.
  const std::vector<Evaluation> evals = {Eval({0, -10}), Eval({-1, -20})};
  const std::vector<double> r = ReferencePoint(evals, 0.1);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_DOUBLE_EQ(r[0], 0.1);
  EXPECT_DOUBLE_EQ(r[1], -9.0);
  EXPECT_GT(Hypervolume(evals, r), 0.0);
}

TEST(ParetoReferenceTest, EmptyWithoutFeasiblePoints) {
  EXPECT_TRUE(ReferencePoint({}).empty());
  EXPECT_TRUE(ReferencePoint({Eval({1, 1}, false, 1.0)}).empty());
  EXPECT_TRUE(ReferencePoint({Eval({1, kInf})}).empty());
}

// An exhaustive "campaign" over cores x GHz with cost = cores * GHz and a
// time that falls with compute, plus a constraint on time.
std::vector<Evaluation> Campaign() {
  std::vector<Evaluation> evals;
  for (int cores = 1; cores <= 8; ++cores) {
    for (double ghz : {1.0, 1.5, 2.0}) {
      const double cost = cores * ghz;
      const double time_s = 1200.0 / (cores * std::sqrt(ghz)) + 20.0 * ghz;
      evals.push_back(At(cores, ghz, {cost, time_s}, time_s <= 400.0));
    }
  }
  return evals;
}

TEST(ParetoSearchQualityTest, SubsetFindsKOfN) {
  const std::vector<Evaluation> reference = Campaign();
  const std::vector<int> front = ParetoFront(reference);
  ASSERT_GE(front.size(), 4u);
  for (int i : front) ASSERT_TRUE(reference[i].feasible);

  // Everything: all found, same volume.
  SearchQuality all = CompareToReference(reference, reference);
  EXPECT_EQ(all.true_front_size, static_cast<int>(front.size()));
  EXPECT_EQ(all.true_pareto_points_found, all.true_front_size);
  EXPECT_DOUBLE_EQ(all.hypervolume_ratio, 1.0);

  // Two front points, one dominated point and one infeasible point.
  std::vector<Evaluation> found = {reference[front[0]], reference[front[2]]};
  int dominated = -1, infeasible = -1;
  for (size_t i = 0; i < reference.size(); ++i) {
    const bool on_front = std::find(front.begin(), front.end(),
                                    static_cast<int>(i)) != front.end();
    if (reference[i].feasible && !on_front) dominated = static_cast<int>(i);
    if (!reference[i].feasible) infeasible = static_cast<int>(i);
  }
  ASSERT_GE(dominated, 0);
  ASSERT_GE(infeasible, 0);
  found.push_back(reference[dominated]);
  found.push_back(reference[infeasible]);
  const SearchQuality some = CompareToReference(found, reference);
  EXPECT_EQ(some.true_pareto_points_found, 2);
  EXPECT_EQ(some.true_front_size, static_cast<int>(front.size()));
  EXPECT_GT(some.hypervolume_ratio, 0.0);
  EXPECT_LT(some.hypervolume_ratio, 1.0);

  // Exactly the found volume over the reference volume.
  const std::vector<double> r = ReferencePoint(reference);
  EXPECT_DOUBLE_EQ(some.hypervolume_ratio,
                   Hypervolume(found, r) / Hypervolume(reference, r));

  // Nothing found.
  const SearchQuality none = CompareToReference({}, reference);
  EXPECT_EQ(none.true_pareto_points_found, 0);
  EXPECT_EQ(none.hypervolume_ratio, 0.0);
}

TEST(ParetoSearchQualityTest, MatchesByDesignPointWithinTolerance) {
  const std::vector<Evaluation> reference = {
      At(4, 1.5, {6, 300}), At(8, 1.0, {8, 200}), At(8, 1.0, {8, 200}),
      At(2, 1.0, {2, 900}, /*feasible=*/false)};
  // Re-evaluated with noise, design values off by float rounding.
  std::vector<Evaluation> found = {At(4, 1.5 + 1e-12, {6, 310})};
  const SearchQuality q = CompareToReference(found, reference);
  EXPECT_EQ(q.true_front_size, 2);  // the duplicate point counts once
  EXPECT_EQ(q.true_pareto_points_found, 1);

  found[0].point["freq_ghz"] = 1.5001;
  EXPECT_EQ(CompareToReference(found, reference).true_pareto_points_found, 0);
  found[0].point = {{"cores", 4}};
  EXPECT_EQ(CompareToReference(found, reference).true_pareto_points_found, 0);
}

TEST(ParetoSearchQualityTest, ReferenceWithoutFeasiblePoints) {
  const std::vector<Evaluation> reference = {At(1, 1, {1, 900}, false),
                                             At(2, 1, {2, 800}, false)};
  const SearchQuality q = CompareToReference(reference, reference);
  EXPECT_EQ(q.true_front_size, 0);
  EXPECT_EQ(q.true_pareto_points_found, 0);
  EXPECT_EQ(q.hypervolume_ratio, 0.0);
}

}  // namespace
}  // namespace adse::analysis
