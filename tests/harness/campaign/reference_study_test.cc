// The recorded exhaustive campaign of scenarios/reference_study.yaml
// (tests/data/reference_study) has the reference study's shape: its
// constraints cut the space, the starved corner fails them, and the time a
// computer needs falls with its capacity.
#include <gtest/gtest.h>

#include <cmath>

#include "harness/campaign/evaluation.h"
#include "harness/campaign/headline.h"
#include "harness/campaign/replay.h"
#include "tests/harness/testing/recording.h"

namespace adse::campaign {
namespace {

const Recording& Recorded() {
  return adse::testing::RecordingUnderTestData("reference_study");
}

const EvaluationRow* At(double cores, double freq_ghz, double lidar_hz) {
  for (const EvaluationRow& row : Recorded().rows) {
    if (row.point.at("cores") == cores &&
        std::abs(row.point.at("freq_ghz") - freq_ghz) < 1e-9 &&
        row.point.at("lidar_hz") == lidar_hz) {
      return &row;
    }
  }
  return nullptr;
}

TEST(ReferenceStudyTest, TheRecordingHoldsTheWholeSpaceAndItsConstraintsCutIt) {
  ASSERT_EQ(Recorded().rows.size(), 280u);
  for (const EvaluationRow& row : Recorded().rows)
    EXPECT_EQ(row.status, "complete") << row.reason;
  const adse::testing::Census census = adse::testing::CensusOf(Recorded());
  EXPECT_EQ(census.distinct_points, 280u);
  // Issue 14 asks for 30 % to 80 % feasible; the 838 m route was chosen
  // for it (77.1 % feasible at run key v24, 76.1 % at v23, 75.4 % at v18,
  // 71.4 % at v17, 77.9 % at v16; the 661 m route before left 80.7 % at
  // v11).
  EXPECT_GE(census.feasible, 0.30 * 280);
  EXPECT_LE(census.feasible, 0.80 * 280);
  // Every infeasible run is cut short: at the 400 s bound or stalled.
  int stopped_at_bound = 0;
  for (const EvaluationRow& row : Recorded().rows) {
    if (row.feasible) continue;
    EXPECT_EQ(RowMetric(row, "censored"), 1.0) << row.reason;
    stopped_at_bound +=
        row.reason == "constraint_violated: nav_time_s <= 400" ? 1 : 0;
  }
  EXPECT_GE(stopped_at_bound, 40);
}

TEST(ReferenceStudyTest, TheStarvedCornerIsStoppedEarlyAtTheNavTimeBound) {
  for (double lidar_hz : {7.0, 14.0}) {
    const EvaluationRow* starved = At(1, 1.0, lidar_hz);
    ASSERT_NE(starved, nullptr);
    EXPECT_FALSE(starved->feasible);
    EXPECT_EQ(starved->reason, "constraint_violated: nav_time_s <= 400");
    EXPECT_EQ(RowMetric(*starved, "censored"), 1.0);
    EXPECT_TRUE(std::isnan(RowMetric(*starved, "nav_time_s")));
  }
}

TEST(ReferenceStudyTest, TheStudysFourPointsOrderAsInTheStudy) {
  const EvaluationRow* slow = At(4, 1.2, 14);
  const EvaluationRow* mid = At(6, 1.5, 7);
  const EvaluationRow* fast = At(18, 1.8, 7);
  const EvaluationRow* wide = At(23, 1.5, 7);
  ASSERT_TRUE(slow && mid && fast && wide);
  // As in the study: (4, 1.2, 14) fails the 400 s bound, the other three
  // drive within it, and more capacity is faster.
  EXPECT_FALSE(slow->feasible);
  EXPECT_TRUE(mid->feasible && fast->feasible && wide->feasible);
  EXPECT_GT(RowMetric(*mid, "nav_time_s"), RowMetric(*fast, "nav_time_s"));
  EXPECT_GT(RowMetric(*mid, "nav_time_s"), RowMetric(*wide, "nav_time_s"));
  // The route was chosen so that the fast point takes the study's 165 s
  // (174.65 s at run key v24, 174.75 s at v23, 177.1 s at v17 and v18,
  // 169.3 s at v16); the censored (4, 1.2, 14) ran past 400 s, at least 2.2
  // times that (5.3 times run to its end, README).
  EXPECT_NEAR(RowMetric(*fast, "nav_time_s"), 165.0, 15.0);
  EXPECT_LT(RowMetric(*fast, "nav_time_s"), 400.0 / 2.2);
  EXPECT_LT(RowMetric(*mid, "ctrl_rate_hz"),
            RowMetric(*fast, "ctrl_rate_hz") + 1e-9);
}

TEST(ReferenceStudyTest,
     TheAnswerListsTheFrontCheapestFirstAndTiesEqualPrices) {
  const Headline answer = ComputeHeadline(Recorded().spec, Recorded().rows);
  ASSERT_GE(answer.cheapest, 0);
  // Two feasible designs cost 9: 5 x 1.8 and 6 x 1.5, 15 s slower. The
  // answer is the faster, and the slower is not on the front.
  const EvaluationRow* five = At(5, 1.8, 7);
  const EvaluationRow* six_slow = At(6, 1.5, 7);
  ASSERT_TRUE(five && six_slow && five->feasible && six_slow->feasible);
  ASSERT_GT(RowMetric(*six_slow, "nav_time_s"), RowMetric(*five, "nav_time_s"));
  EXPECT_EQ(answer.cheapest, five - Recorded().rows.data());
  // 7 x 1.8 is a last bit cheaper than 6 x 2.1 and 13 s slower: the same
  // price, so it is not on the front either.
  const EvaluationRow* seven = At(7, 1.8, 7);
  const EvaluationRow* six = At(6, 2.1, 7);
  ASSERT_TRUE(seven && six && seven->feasible && six->feasible);
  ASSERT_GT(RowMetric(*seven, "nav_time_s"), RowMetric(*six, "nav_time_s"));
  for (int i : answer.front) {
    EXPECT_NE(&Recorded().rows[i], seven);
    EXPECT_NE(&Recorded().rows[i], six_slow);
  }
  EXPECT_EQ(answer.front.size(), answer.cost_time_front.size());
  // As printed: cheapest first, each line faster than the one before.
  const std::vector<int> listed = CheapestFirst(Recorded().rows, answer.front);
  ASSERT_EQ(listed.size(), answer.front.size());
  for (size_t k = 1; k < listed.size(); ++k) {
    const EvaluationRow& before = Recorded().rows[listed[k - 1]];
    const EvaluationRow& row = Recorded().rows[listed[k]];
    EXPECT_LT(RowMetric(before, "hardware_cost"),
              RowMetric(row, "hardware_cost"));
    EXPECT_GT(RowMetric(before, "nav_time_s"), RowMetric(row, "nav_time_s"));
  }
  const std::string text =
      HeadlineText(Recorded().spec, Recorded().rows, answer);
  EXPECT_LT(text.find("cores=5,freq_ghz=1.8,lidar_hz=7      cost"),
            text.find("cores=5,freq_ghz=2.1,lidar_hz=7"));
}

}  // namespace
}  // namespace adse::campaign
