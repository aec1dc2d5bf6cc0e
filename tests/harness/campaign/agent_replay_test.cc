// The built-in agent replayed over every recording and landscape in
// tests/data at a budget of 15 over 20 seeds (issue 16's measure): what it
// finds of the true front, its hypervolume next to random search's, and in
// how many seeds it evaluates the cheapest feasible design. Thresholds sit
// a little below the values measured when this test was written (README,
// "Strategies"); where they fall short of the targets, the README
// says so.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "harness/campaign/replay.h"
#include "tests/harness/testing/recording.h"

namespace adse::campaign {
namespace {

constexpr int kSeeds = 20;
constexpr int kBudget = 15;

struct Outcome {
  double median_true_pareto = 0.0;
  double median_hypervolume = 0.0;
  int cheapest_found = 0;  // seeds
};

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

Outcome ReplayOver(const Recording& recording, const std::string& data,
                   const std::string& strategy) {
  std::vector<double> found, volume;
  Outcome outcome;
  for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
    Result<ReplayRun> run = Replay(recording, strategy, seed, kBudget);
    EXPECT_TRUE(run.ok()) << data << ": " << run.status().message();
    if (!run.ok()) return outcome;
    EXPECT_EQ(run->missing, 0) << data;
    found.push_back(run->true_pareto_found);
    volume.push_back(run->hypervolume_ratio);
    outcome.cheapest_found += run->found_cheapest_feasible ? 1 : 0;
  }
  outcome.median_true_pareto = Median(found);
  outcome.median_hypervolume = Median(volume);
  return outcome;
}

struct Expected {
  double true_pareto;  // median at least
  double hypervolume;  // median at least
  int cheapest_found;  // seeds at least
  // How far the median hypervolume may fall below random search's: to
  // rounding, except where the README says the agent falls short.
  double below_random = 0.005;
};

void ExpectAgentOn(const Recording& recording, const std::string& data,
                   const Expected& expected) {
  const Outcome agent = ReplayOver(recording, data, "agent");
  const Outcome random = ReplayOver(recording, data, "random");
  EXPECT_GE(agent.median_true_pareto, expected.true_pareto) << data;
  EXPECT_GE(agent.median_hypervolume, expected.hypervolume) << data;
  EXPECT_GE(agent.cheapest_found, expected.cheapest_found) << data;
  // Never below random search's median hypervolume (to rounding).
  EXPECT_GE(agent.median_hypervolume,
            random.median_hypervolume - expected.below_random)
      << data << ": random search's median " << random.median_hypervolume;
}

void ExpectAgentOn(const std::string& data, const Expected& expected) {
  ExpectAgentOn(adse::testing::RecordingUnderTestData(data), data, expected);
}

TEST(AgentReplayTest, OnTheRecordedRobotaxiCampaign) {
  // Measured on the recording at run key v24 (recorded again on 2026-12-06
  // with how far each stopped run got; 256 Monte Carlo samples): a median
  // of 8 of the 72 true Pareto points, a median hypervolume ratio of 0.868,
  // the cheapest design (7 cores at 1.2 GHz, cost 8.4, 89.85 s against the
  // 90 s bound) in 18 of 20 seeds (README, "Strategies"; before the agent
  // read how far stopped runs got 7, 0.883 and 4).
  ExpectAgentOn("robotaxi_exhaustive", {7, 0.86, 17});
}

TEST(AgentReplayTest, OnTheRobotaxiCampaignWithTwoObjectives) {
  // Issue 16's targets are for two objectives: the same recording scored
  // on cost and nav time alone, whose front holds 14 of the 280 points.
  // Measured: a median of 3 true Pareto points, a median hypervolume
  // ratio of 0.872, 0.007 below random search's (every seed keeps to the
  // 1.0-1.5 GHz columns after 4 cores at 2.1 GHz stop 87 % of the way,
  // while the front lies at 2.1 GHz), the cheapest design in 20 of 20
  // seeds (before the agent read how far stopped runs got 5, 0.947 and
  // 10; docs/agent_development.md, "How far a stopped run got").
  Recording recording =
      adse::testing::RecordingUnderTestData("robotaxi_exhaustive");
  ASSERT_TRUE(KeepObjectives({"hardware_cost", "nav_time_s"}, &recording).ok());
  ExpectAgentOn(recording, "robotaxi_exhaustive (cost, nav time)",
                {3, 0.86, 19, /*below_random=*/0.01});
}

TEST(AgentReplayTest, OnTheRobotaxiLotDrivenTheOtherWay) {
  // Recorded 2026-12-06 (tests/data/robotaxi_return_exhaustive): a median
  // of 6 of the 13 true Pareto points, a median hypervolume ratio of
  // 0.967 (random search 0.879), the cheapest design in 20 of 20 seeds.
  ExpectAgentOn("robotaxi_return_exhaustive", {5, 0.95, 19});
}

TEST(AgentReplayTest, OnTheRilsaSignalRoute) {
  // Recorded 2026-12-06 (tests/data/rilsa_exhaustive): all 3 true Pareto
  // points, a hypervolume ratio of 1.000 (random search 0.843) and the
  // cheapest design in every seed.
  ExpectAgentOn("rilsa_exhaustive", {3, 0.99, 19});
}

TEST(AgentReplayTest, OnTheReferenceStudyWhereStarvedRunsAreStoppedEarly) {
  // Measured on the recording at run key v24 (2026-12-05): a median of 9
  // of the 13 true Pareto points (the study's LLM agent found 6), a median
  // hypervolume ratio of 0.994, the cheapest design (5 cores at 1.8 GHz)
  // in 20 of 20 seeds (README, "Strategies"; at v23 9, 0.985 and 20).
  ExpectAgentOn("reference_study", {8, 0.98, 19});
}

TEST(AgentReplayTest, OnALandscapeThatSaturates) {
  ExpectAgentOn("landscapes/saturating", {7, 0.99, 19});
}

TEST(AgentReplayTest, OnALandscapeCutByATimeBoundWithCensoredRuns) {
  ExpectAgentOn("landscapes/constraint_cut", {8, 0.99, 19});
}

TEST(AgentReplayTest, OnANoisyLandscape) {
  ExpectAgentOn("landscapes/noisy", {3, 0.94, 19});
}

TEST(AgentReplayTest, OnALandscapePricedByAnotherCostExpression) {
  ExpectAgentOn("landscapes/other_cost", {7, 0.98, 19});
}

TEST(AgentReplayTest, OnALandscapeWithAKnobThatDoesNothing) {
  ExpectAgentOn("landscapes/dead_knob", {7, 0.99, 19});
}

TEST(AgentReplayTest, OnAFourDimensionalLandscape) {
  ExpectAgentOn("landscapes/four_d", {3, 0.97, 19});
}

}  // namespace
}  // namespace adse::campaign
