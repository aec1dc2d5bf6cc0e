// What a campaign knows of the designs cheaper than its answer, as the
// headline says it, and the runs of the confirm phase that settle them.
#include "harness/campaign/cheaper.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/campaign/headline.h"
#include "harness/spec/design_point.h"
#include "tests/harness/testing/grid_campaign.h"

namespace adse::campaign {
namespace {

using ::testing::HasSubstr;

using adse::testing::GridRow;
using adse::testing::GridScenario;

// "cores=4,freq_ghz=2 settles 4" per pick.
std::vector<std::string> Named(const spec::Spec& spec,
                               const std::vector<SettlePick>& picks) {
  std::vector<std::string> out;
  for (const SettlePick& pick : picks) {
    out.push_back(spec::FormatPoint(spec.design_space, pick.point) +
                  " settles " + std::to_string(pick.settles));
  }
  return out;
}

TEST(CheaperTest,
     DesignsCheaperThanTheAnswerAreRunRuledOutByCapacityOrUntried) {
  const spec::Spec spec = GridScenario();
  const std::vector<EvaluationRow> rows = {
      GridRow(0, 4, 2.0, 70), GridRow(1, 6, 2.0, 45), GridRow(2, 8, 1.5, 50),
      GridRow(3, 2, 3.0, 80)};
  const Headline h = ComputeHeadline(spec, rows);
  ASSERT_EQ(h.cheapest, 1);  // cost 12, as 8 x 1.5 and 4 x 3.0: no cheaper
  const CheaperDesigns& c = h.cheaper;
  ASSERT_TRUE(c.counted);
  // 2 x 1.5, 2 x 2.0, 2 x 3.0, 4 x 1.5, 4 x 2.0 and 6 x 1.5 cost less.
  EXPECT_EQ(c.cheaper, 6);
  EXPECT_EQ(c.run, 2);  // 4 x 2.0 and 2 x 3.0, both too slow
  // 2 x 1.5, 2 x 2.0 and 4 x 1.5 have no more capacity than 4 x 2.0.
  EXPECT_EQ(c.ruled_out, 3);
  EXPECT_EQ(c.untried_count, 1);
  ASSERT_EQ(c.untried.size(), 1u);
  EXPECT_EQ(spec::FormatPoint(spec.design_space, c.untried[0]),
            "cores=6,freq_ghz=1.5");
  EXPECT_DOUBLE_EQ(c.untried_cost[0], 9.0);
  const std::string sentence =
      "6 in the space: 2 run, none feasible; 3 with no more capacity than a "
      "run that failed; 1 untried, cheapest first: cores=6,freq_ghz=1.5 "
      "(cost 9); exploration.confirm_runs (--confirm-runs) runs them after "
      "the budget";
  EXPECT_EQ(c.to_settle_count, 1);  // the one untried: not named twice
  EXPECT_EQ(CheaperText(spec, c), sentence);
  EXPECT_THAT(HeadlineText(spec, rows, h),
              HasSubstr("cheaper designs     " + sentence + "\n"));
  EXPECT_THAT(HeadlineMarkdown(spec, rows, h, "images"),
              HasSubstr("- **Cheaper designs:** " + sentence + ".\n"));
  const nlohmann::json answer = AnswerJson(spec, rows, h);
  const nlohmann::json& cheaper = answer.at("cheaper_designs");
  EXPECT_EQ(cheaper.at("in_space"), 6);
  EXPECT_EQ(cheaper.at("run"), 2);
  EXPECT_EQ(cheaper.at("ruled_out_by_capacity"), 3);
  EXPECT_EQ(cheaper.at("untried_count"), 1);
  EXPECT_EQ(cheaper.at("untried").at(0).at("point"), "cores=6,freq_ghz=1.5");
  EXPECT_DOUBLE_EQ(cheaper.at("untried").at(0).at("hardware_cost"), 9.0);
}

TEST(CheaperTest, OnlyARunShortOfCapacityRulesOutTheDesignsBelowIt) {
  // 2 x 3.0 fails a bound on a knob, not on what it measured: the smaller
  // computers below it are not ruled out by it. A run that crashed says
  // nothing, and its design is not counted as run.
  const spec::Spec spec = GridScenario("[nav_time_s <= 60, cores >= 4]");
  std::vector<EvaluationRow> rows = {
      GridRow(0, 2, 3.0, 40), GridRow(1, 6, 1.5, 45), GridRow(2, 4, 1.5, 80)};
  rows[0].feasible = false;
  rows[2].status = "failed";
  rows[2].metrics.clear();
  const Headline h = ComputeHeadline(spec, rows);
  ASSERT_EQ(h.cheapest, 1);  // cost 9
  const CheaperDesigns& c = h.cheaper;
  EXPECT_EQ(c.cheaper, 5);  // 2 x 1.5, 2 x 2.0, 2 x 3.0, 4 x 1.5, 4 x 2.0
  EXPECT_EQ(c.run, 1);
  EXPECT_EQ(c.ruled_out, 0);
  EXPECT_EQ(c.untried_count, 4);
  // The terminal names three, report.md every one it holds.
  const std::string three =
      "4 untried, cheapest first: cores=2,freq_ghz=1.5 (cost 3), "
      "cores=2,freq_ghz=2 (cost 4), cores=4,freq_ghz=1.5 (cost 6)";
  // 4 x 2.0 has at least the others' capacity: its failure would settle
  // them all.
  EXPECT_EQ(c.to_settle_count, 1);
  const std::string settle =
      "; 1 run settles them (if these fail, every other has no more "
      "capacity than one that failed): cores=4,freq_ghz=2 (cost 8)";
  EXPECT_THAT(CheaperText(spec, c), HasSubstr(three + " and 1 more" + settle));
  EXPECT_THAT(
      HeadlineMarkdown(spec, rows, h, "images"),
      HasSubstr(three + ", cores=4,freq_ghz=2 (cost 8)" + settle +
                "; exploration.confirm_runs (--confirm-runs) runs them after "
                "the budget.\n"));
  const nlohmann::json answer = AnswerJson(spec, rows, h);
  EXPECT_EQ(answer.at("cheaper_designs").at("to_settle_count"), 1);
  EXPECT_EQ(answer.at("cheaper_designs").at("to_settle").at(0).at("point"),
            "cores=4,freq_ghz=2");
}

TEST(CheaperTest, AnExhaustiveCampaignLeavesNoCheaperDesignUntried) {
  const spec::Spec spec = GridScenario();
  std::vector<EvaluationRow> rows;
  int index = 0;
  for (double cores : {2, 4, 6, 8}) {
    for (double ghz : {1.5, 2.0, 3.0}) {
      rows.push_back(GridRow(index++, cores, ghz, 240.0 / (cores * ghz)));
    }
  }
  const Headline h = ComputeHeadline(spec, rows);
  ASSERT_GE(h.cheapest, 0);
  EXPECT_EQ(RowMetric(rows[h.cheapest], kCostMetric), 4.0);  // 60 s
  EXPECT_EQ(CheaperText(spec, h.cheaper),
            "1 in the space: 1 run, none feasible; none untried: the "
            "cheapest feasible design of the space");
  // The cheapest design of the space: nothing costs less.
  rows = {GridRow(0, 2, 1.5, 50)};
  EXPECT_EQ(CheaperText(spec, ComputeHeadline(spec, rows).cheaper),
            "none in the space");
  // Nothing feasible: nothing to be sure of.
  rows = {GridRow(0, 2, 1.5, 90)};
  const Headline none = ComputeHeadline(spec, rows);
  EXPECT_FALSE(none.cheaper.counted);
  EXPECT_EQ(CheaperText(spec, none.cheaper), "");
  EXPECT_TRUE(AnswerJson(spec, rows, none).at("cheaper_designs").is_null());
}

TEST(CheaperTest, ASpaceTooLargeToEnumerateSaysItsCheaperDesignsAreNotCounted) {
  const spec::Spec spec = GridScenario(
      "[nav_time_s <= 60]",
      "  cores: {bind: platform.cores, range: [1, 1001]}\n"
      "  freq_ghz: {bind: platform.freq_ghz, range: [0.1, 10.0], step: 0.1}\n");
  const std::vector<EvaluationRow> rows = {GridRow(0, 4, 2.0, 45)};
  const Headline h = ComputeHeadline(spec, rows);
  ASSERT_EQ(h.cheapest, 0);
  EXPECT_FALSE(h.cheaper.counted);
  EXPECT_EQ(CheaperText(spec, h.cheaper),
            "not counted (a space of 100100 designs, more than the 100000 "
            "adse counts)");
  EXPECT_TRUE(AnswerJson(spec, rows, h).at("cheaper_designs").is_null());
}

TEST(CheaperTest, TheConfirmPhaseRunsFirstTheUntriedDesignThatSettlesTheMost) {
  const spec::Spec spec = GridScenario();
  // 8 x 1.5 (cost 12) is the answer; 2 x 1.5, 2 x 2.0, 2 x 3.0, 4 x 1.5,
  // 4 x 2.0 and 6 x 1.5 cost less and are untried. Of them 2 x 3.0, 4 x 2.0
  // and 6 x 1.5 have no more capable untried design above them; 4 x 2.0
  // has the most below it (2 x 1.5, 2 x 2.0, 4 x 1.5 and itself), the
  // other two three each, the cheaper first.
  std::vector<EvaluationRow> rows = {GridRow(0, 8, 1.5, 50)};
  EXPECT_THAT(Named(spec, SettlePicks(spec, rows, 12.0, 5)),
              ::testing::ElementsAre("cores=4,freq_ghz=2 settles 4",
                                     "cores=2,freq_ghz=3 settles 3",
                                     "cores=6,freq_ghz=1.5 settles 3"));
  EXPECT_THAT(Named(spec, SettlePicks(spec, rows, 12.0, 1)),
              ::testing::ElementsAre("cores=4,freq_ghz=2 settles 4"));
  EXPECT_TRUE(SettlePicks(spec, rows, 12.0, 0).empty());
  EXPECT_EQ(ComputeHeadline(spec, rows).cheaper.to_settle_count, 3);

  // 4 x 2.0 fails: the three below it fail too; the other two settle
  // themselves alone.
  rows.push_back(GridRow(1, 4, 2.0, 70));
  EXPECT_THAT(Named(spec, SettlePicks(spec, rows, 12.0, 5)),
              ::testing::ElementsAre("cores=2,freq_ghz=3 settles 1",
                                     "cores=6,freq_ghz=1.5 settles 1"));
  // A run of 2 x 3.0 that crashed leaves it untried for the headline, but
  // the confirm phase does not propose a point twice.
  rows.push_back(GridRow(2, 2, 3.0, 0));
  rows.back().status = "failed";
  rows.back().metrics.clear();
  rows.back().feasible = false;
  EXPECT_EQ(ComputeHeadline(spec, rows).cheaper.untried_count, 2);
  EXPECT_THAT(Named(spec, SettlePicks(spec, rows, 12.0, 5)),
              ::testing::ElementsAre("cores=6,freq_ghz=1.5 settles 1"));
  // Then nothing is left to run; the crashed design stays untried.
  rows.push_back(GridRow(3, 6, 1.5, 65));
  EXPECT_TRUE(SettlePicks(spec, rows, 12.0, 5).empty());
  EXPECT_THAT(CheaperText(spec, ComputeHeadline(spec, rows).cheaper),
              HasSubstr("1 untried, cheapest first: cores=2,freq_ghz=3"));
  // Had it run and failed, the answer would be the space's cheapest, as
  // far as the capacity order holds.
  rows[2] = GridRow(2, 2, 3.0, 65);
  EXPECT_THAT(CheaperText(spec, ComputeHeadline(spec, rows).cheaper),
              ::testing::EndsWith(
                  "none untried: the cheapest feasible design of the space, "
                  "as far as less capacity never helps"));
}

TEST(CheaperTest, AConfirmPhaseAlreadyAskedForIsNotSuggestedAgain) {
  spec::Spec spec = GridScenario();
  const std::vector<EvaluationRow> rows = {GridRow(0, 8, 1.5, 50)};
  EXPECT_THAT(CheaperText(spec, ComputeHeadline(spec, rows).cheaper),
              HasSubstr("; exploration.confirm_runs (--confirm-runs) runs "
                        "them after the budget"));
  spec.exploration.confirm_runs = 2;
  EXPECT_THAT(CheaperText(spec, ComputeHeadline(spec, rows).cheaper),
              ::testing::Not(HasSubstr("confirm_runs")));
}

}  // namespace
}  // namespace adse::campaign
