// Strategies replayed against recorded exhaustive campaigns: the bundled
// robotaxi study's (tests/data/robotaxi_exhaustive) for the replay itself,
// and the reference study's (tests/data/reference_study) for the built-in
// agent there: the study's LLM agent found 6 true Pareto points with a
// budget of 15 and its GA none; adse's agent finds 8 and the cheapest
// design in most seeds, and more than the GA.
#include "harness/campaign/replay.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "analysis/runfile/campaign_file.h"

#include "tests/harness/testing/recording.h"

namespace adse::campaign {
namespace {

const Recording& Recorded() {
  return adse::testing::RecordingUnderTestData("robotaxi_exhaustive");
}

const Recording& Study() {
  return adse::testing::RecordingUnderTestData("reference_study");
}

TEST(ReplayTest, TheRecordingHoldsTheWholeSpaceWithAFeasibleFront) {
  ASSERT_EQ(Recorded().rows.size(), 280u);
  const adse::testing::Census census = adse::testing::CensusOf(Recorded());
  EXPECT_EQ(census.distinct_points, 280u);
  EXPECT_GT(census.feasible, 100);
  EXPECT_LT(census.feasible, 280) << "starved computers fail the constraints";
}

TEST(ReplayTest,
     AgentFindsTheCheapestDesignAndEightTrueParetoPointsInMostSeeds) {
  // The study's LLM agent found 6 true Pareto points in 15. On adse's
  // recording (run key v23) the agent finds 8 or 9 of the front's 13 and
  // the cheapest design (5 cores at 1.8 GHz) in every seed of 20 (README,
  // "Reproducing the reference study").
  int both = 0;
  for (uint64_t seed = 1; seed <= 8; ++seed) {
    Result<ReplayRun> run = Replay(Study(), "agent", seed, 15);
    ASSERT_TRUE(run.ok()) << run.status().message();
    EXPECT_EQ(run->evaluations, 15);
    EXPECT_EQ(run->missing, 0);
    both += run->found_cheapest_feasible && run->true_pareto_found >= 8;
  }
  EXPECT_GE(both, 7);
}

TEST(ReplayTest, AgentBeatsTheGaBaselineOnTheStudyOverSeeds) {
  double agent = 0, ga = 0;
  constexpr int kSeeds = 8;
  for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
    Result<ReplayRun> a = Replay(Study(), "agent", seed, 15);
    Result<ReplayRun> g = Replay(Study(), "ga", seed, 15);
    ASSERT_TRUE(a.ok() && g.ok());
    EXPECT_GE(a->hypervolume_ratio, 0.94) << "seed " << seed;
    agent += a->true_pareto_found;
    ga += g->true_pareto_found;
  }
  EXPECT_GT(agent / kSeeds, ga / kSeeds + 1.0)
      << "agent " << agent / kSeeds << ", ga " << ga / kSeeds;
}

TEST(ReplayTest, AReplaySaysWhetherItEvaluatedTheCheapestFeasibleDesign) {
  Result<ReplayRun> all = Replay(Recorded(), "exhaustive", 1, 280);
  Result<ReplayRun> two = Replay(Recorded(), "exhaustive", 1, 2);
  ASSERT_TRUE(all.ok() && two.ok());
  EXPECT_TRUE(all->found_cheapest_feasible);
  // Lexicographic order starts at the 1-core corner, which is infeasible.
  EXPECT_FALSE(two->found_cheapest_feasible);
}

TEST(ReplayTest, AReplaySaysWhetherItsRunsLeaveACheaperDesignUntried) {
  // Every design run: nothing cheaper is left, the answer is proven.
  Result<ReplayRun> all = Replay(Recorded(), "exhaustive", 1, 280);
  ASSERT_TRUE(all.ok());
  EXPECT_TRUE(all->cheapest_confirmed);
  EXPECT_EQ(all->cheaper_left_untried, 0);
  // Not found: nothing to confirm.
  Result<ReplayRun> two = Replay(Recorded(), "exhaustive", 1, 2);
  ASSERT_TRUE(two.ok());
  EXPECT_FALSE(two->cheapest_confirmed);
  EXPECT_EQ(two->cheaper_left_untried, -1);
  // The agent's 15 runs find the answer (7 cores at 1.2 GHz) but leave
  // cheaper designs that no failed run of theirs rules out (README,
  // "How sure the cheapest design is").
  Result<ReplayRun> agent = Replay(Recorded(), "agent", 1, 15);
  ASSERT_TRUE(agent.ok());
  EXPECT_TRUE(agent->found_cheapest_feasible);
  EXPECT_FALSE(agent->cheapest_confirmed);
  EXPECT_GT(agent->cheaper_left_untried, 0);
  // Fewer runs would settle them: each untried design has no more capacity
  // than one of those.
  EXPECT_GT(agent->runs_to_settle, 0);
  EXPECT_LE(agent->runs_to_settle, agent->cheaper_left_untried);
  EXPECT_EQ(all->runs_to_settle, 0);
}

TEST(ReplayTest, ReplayIsDeterministicAndAnUnknownStrategyIsAnError) {
  Result<ReplayRun> a = Replay(Recorded(), "nsga2", 3, 15);
  Result<ReplayRun> b = Replay(Recorded(), "nsga2", 3, 15);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->proposals, b->proposals);
  Result<ReplayRun> bad = Replay(Recorded(), "simulated-annealing", 1, 15);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("valid:"), std::string::npos);
}

TEST(ReplayTest, ARecordingWrittenBeforeRoundingReadsItsTimesAndCostsRounded) {
  // The robotaxi recording (2026-11) stores a product of GHz-cores and a
  // sum of 0.05 s steps with their float noise; read as a recording, they
  // are the numbers adse analyze and a new run give.
  Result<runfile::CampaignIndex> raw =
      runfile::ReadCampaignIndex(std::string(ADSE_SOURCE_DIR) +
                                 "/tests/data/robotaxi_exhaustive/campaign.h5");
  ASSERT_TRUE(raw.ok()) << raw.status().message();
  const spec::DesignPoint answer = {
      {"cores", 7}, {"freq_ghz", 1.2}, {"lidar_hz", 7}};
  const spec::DesignPoint six_fast = {
      {"cores", 6}, {"freq_ghz", 2.1}, {"lidar_hz", 7}};
  auto metric = [](const std::vector<EvaluationRow>& rows,
                   const spec::DesignPoint& point, const char* name) {
    for (const EvaluationRow& row : rows) {
      if (row.point == point) return row.metrics.at(name);
    }
    ADD_FAILURE() << "no row for the point";
    return 0.0;
  };
  EXPECT_NE(metric(raw->evaluations, answer, "nav_time_s"), 89.85);
  EXPECT_EQ(metric(Recorded().rows, answer, "nav_time_s"), 89.85);
  EXPECT_NE(metric(raw->evaluations, six_fast, "hardware_cost"), 12.6);
  EXPECT_EQ(metric(Recorded().rows, six_fast, "hardware_cost"), 12.6);
  // A metric no run rounds is read as stored.
  EXPECT_EQ(metric(Recorded().rows, answer, "deviation_score"),
            metric(raw->evaluations, answer, "deviation_score"));
}

TEST(ReplayTest, AMissingOrDamagedRecordingNamesTheFile) {
  Result<Recording> missing = LoadRecording("/nonexistent/campaign");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("/nonexistent/campaign"),
            std::string::npos);
}

}  // namespace
}  // namespace adse::campaign
