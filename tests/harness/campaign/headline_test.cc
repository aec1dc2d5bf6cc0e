// The answer every command leads with: the cheapest feasible design, the
// computers that tie with it, and the cost-time front they sit on.
#include "harness/campaign/headline.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/spec/spec_parser.h"

namespace adse::campaign {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr char kGrid[] =
    "  cores: {bind: platform.cores, values: [2, 4, 6, 8]}\n"
    "  freq_ghz: {bind: platform.freq_ghz, values: [1.5, 2.0, 3.0]}\n";

// `constraints` as the scenario writes them; `space` the design space's
// lines.
spec::Spec Scenario(const std::string& constraints = "[nav_time_s <= 60]",
                    const std::string& space = kGrid) {
  spec::ParseOptions options;
  options.check_files = false;
  Result<spec::Spec> spec = spec::ParseSpec(
      "adse: 1\nname: ties\nworld: {map: {generate: parking_lot}}\n"
      "task: {start: {x: 5, y: -1.75}, goal: {x: 60, y: 29.75}}\n"
      "design_space:\n" +
          space +
          "cost: cores * freq_ghz\n"
          "objectives: [{minimize: hardware_cost}, {minimize: nav_time_s}]\n"
          "constraints: " +
          constraints + "\n",
      "ties.yaml", ".", options);
  EXPECT_TRUE(spec.ok()) << spec.status().ToString();
  return std::move(spec).value();
}

EvaluationRow Row(int index, double cores, double freq_ghz, double nav_time_s) {
  EvaluationRow row;
  row.index = index;
  row.content_key = std::string(64, static_cast<char>('a' + index));
  row.status = "complete";
  row.reason = "goal_reached";
  row.source = "simulated";
  row.attempts = 1;
  row.point = {{"cores", cores}, {"freq_ghz", freq_ghz}};
  row.metrics = {{"nav_time_s", nav_time_s},
                 {"hardware_cost", cores * freq_ghz},
                 {"ctrl_rate_hz", 10},
                 {"completed", 1}};
  row.feasible = nav_time_s <= 60;
  row.bottlenecks_json = "[]";
  return row;
}

TEST(HeadlineTest, ComputersThatTieWithTheCheapestAreNamedBesideIt) {
  const spec::Spec spec = Scenario();
  // 4 x 3.0 and 6 x 2.0 GHz-cores cost 12 (a last bit apart as doubles)
  // and arrive in the same time; 8 x 1.5 costs 12 too but is slower.
  const std::vector<EvaluationRow> rows = {
      Row(0, 2, 3.0, 70), Row(1, 4, 3.0, 47.55), Row(2, 6, 2.0, 47.55),
      Row(3, 8, 1.5, 50.0), Row(4, 8, 3.0, 30.0)};
  const Headline h = ComputeHeadline(spec, rows);
  EXPECT_EQ(h.cheapest, 1);
  EXPECT_THAT(h.cheapest_ties, ElementsAre(2));
  EXPECT_THAT(h.cost_time_front, ElementsAre(1, 2, 4));
  // The front over both objectives holds the tie too: one answer.
  EXPECT_THAT(CheapestFirst(rows, h.front), ElementsAre(1, 2, 4));
  const std::string text = HeadlineText(spec, rows, h);
  EXPECT_THAT(text, HasSubstr("cheapest feasible   cores=4,freq_ghz=3"));
  EXPECT_THAT(text, HasSubstr("tied with cheapest  cores=6,freq_ghz=2"));
  EXPECT_THAT(HeadlineMarkdown(spec, rows, h, "images"),
              HasSubstr("- **Tied with cheapest:** `cores=6,freq_ghz=2`"));
}

TEST(HeadlineTest, ADesignAsCheapButSlowerIsNoTie) {
  const spec::Spec spec = Scenario();
  const std::vector<EvaluationRow> rows = {Row(0, 4, 3.0, 47.55),
                                           Row(1, 6, 2.0, 47.6)};
  const Headline h = ComputeHeadline(spec, rows);
  EXPECT_EQ(h.cheapest, 0);
  EXPECT_TRUE(h.cheapest_ties.empty());
  EXPECT_THAT(h.cost_time_front, ElementsAre(0));
  EXPECT_THAT(HeadlineText(spec, rows, h),
              ::testing::Not(HasSubstr("tied with cheapest")));
}

TEST(HeadlineTest, TiesAboveTheCheapestStayOnTheFrontWithoutBeingCalledTies) {
  const spec::Spec spec = Scenario();
  const std::vector<EvaluationRow> rows = {
      Row(0, 2, 3.0, 55.0), Row(1, 4, 3.0, 40.0), Row(2, 6, 2.0, 40.0)};
  const Headline h = ComputeHeadline(spec, rows);
  EXPECT_EQ(h.cheapest, 0);
  EXPECT_TRUE(h.cheapest_ties.empty());
  EXPECT_THAT(h.cost_time_front, ElementsAre(0, 1, 2));
}

TEST(HeadlineTest, TheConstraintsInfeasibleDesignsInsideTheLinesFailAreNamed) {
  const spec::Spec spec =
      Scenario("[nav_time_s <= 60, deviation_score <= 0.6, ctrl_rate_hz >= 5]");
  std::vector<EvaluationRow> rows = {Row(0, 2, 3.0, 70), Row(1, 4, 3.0, 40),
                                     Row(2, 6, 2.0, 45), Row(3, 8, 3.0, 30)};
  for (EvaluationRow& row : rows) row.metrics["deviation_score"] = 0.1;
  // Too slow, and straying: the time bound shows why.
  rows[0].metrics["deviation_score"] = 0.9;
  rows[0].feasible = false;
  // Inside the time bound, infeasible by the deviation alone.
  rows[1].metrics["deviation_score"] = 0.7;
  rows[1].feasible = false;
  EXPECT_THAT(UndrawnFailures(spec, rows),
              ElementsAre("deviation_score <= 0.6"));
  // And one by the control rate too: both, in the scenario's order.
  rows[2].metrics["ctrl_rate_hz"] = 2;
  rows[2].feasible = false;
  EXPECT_THAT(UndrawnFailures(spec, rows),
              ElementsAre("deviation_score <= 0.6", "ctrl_rate_hz >= 5"));
  // Every infeasible design beyond a line: nothing to name.
  rows[1].feasible = rows[2].feasible = true;
  rows[1].metrics["deviation_score"] = 0.1;
  rows[2].metrics["ctrl_rate_hz"] = 10;
  EXPECT_TRUE(UndrawnFailures(spec, rows).empty());
}

// Costs over the grid (cores x GHz): 2 cores 3, 4, 6; 4 cores 6, 8, 12;
// 6 cores 9, 12, 18; 8 cores 12, 16, 24.
TEST(HeadlineTest,
     DesignsCheaperThanTheAnswerAreRunRuledOutByCapacityOrUntried) {
  const spec::Spec spec = Scenario();
  const std::vector<EvaluationRow> rows = {
      Row(0, 4, 2.0, 70), Row(1, 6, 2.0, 45), Row(2, 8, 1.5, 50),
      Row(3, 2, 3.0, 80)};
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
      "(cost 9)";
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

TEST(HeadlineTest, OnlyARunShortOfCapacityRulesOutTheDesignsBelowIt) {
  // 2 x 3.0 fails a bound on a knob, not on what it measured: the smaller
  // computers below it are not ruled out by it. A run that crashed says
  // nothing, and its design is not counted as run.
  const spec::Spec spec = Scenario("[nav_time_s <= 60, cores >= 4]");
  std::vector<EvaluationRow> rows = {Row(0, 2, 3.0, 40), Row(1, 6, 1.5, 45),
                                     Row(2, 4, 1.5, 80)};
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
      HasSubstr(three + ", cores=4,freq_ghz=2 (cost 8)" + settle + ".\n"));
  const nlohmann::json answer = AnswerJson(spec, rows, h);
  EXPECT_EQ(answer.at("cheaper_designs").at("to_settle_count"), 1);
  EXPECT_EQ(answer.at("cheaper_designs").at("to_settle").at(0).at("point"),
            "cores=4,freq_ghz=2");
}

TEST(HeadlineTest, AnExhaustiveCampaignLeavesNoCheaperDesignUntried) {
  const spec::Spec spec = Scenario();
  std::vector<EvaluationRow> rows;
  int index = 0;
  for (double cores : {2, 4, 6, 8}) {
    for (double ghz : {1.5, 2.0, 3.0}) {
      rows.push_back(Row(index++, cores, ghz, 240.0 / (cores * ghz)));
    }
  }
  const Headline h = ComputeHeadline(spec, rows);
  ASSERT_GE(h.cheapest, 0);
  EXPECT_EQ(RowMetric(rows[h.cheapest], kCostMetric), 4.0);  // 60 s
  EXPECT_EQ(CheaperText(spec, h.cheaper),
            "1 in the space: 1 run, none feasible; none untried");
  // The cheapest design of the space: nothing costs less.
  rows = {Row(0, 2, 1.5, 50)};
  EXPECT_EQ(CheaperText(spec, ComputeHeadline(spec, rows).cheaper),
            "none in the space");
  // Nothing feasible: nothing to be sure of.
  rows = {Row(0, 2, 1.5, 90)};
  const Headline none = ComputeHeadline(spec, rows);
  EXPECT_FALSE(none.cheaper.counted);
  EXPECT_EQ(CheaperText(spec, none.cheaper), "");
  EXPECT_TRUE(AnswerJson(spec, rows, none).at("cheaper_designs").is_null());
}

TEST(HeadlineTest,
     ASpaceTooLargeToEnumerateSaysItsCheaperDesignsAreNotCounted) {
  const spec::Spec spec = Scenario(
      "[nav_time_s <= 60]",
      "  cores: {bind: platform.cores, range: [1, 1001]}\n"
      "  freq_ghz: {bind: platform.freq_ghz, range: [0.1, 10.0], step: 0.1}\n");
  const std::vector<EvaluationRow> rows = {Row(0, 4, 2.0, 45)};
  const Headline h = ComputeHeadline(spec, rows);
  ASSERT_EQ(h.cheapest, 0);
  EXPECT_FALSE(h.cheaper.counted);
  EXPECT_EQ(CheaperText(spec, h.cheaper),
            "not counted (a space of 100100 designs, more than the 100000 "
            "adse counts)");
  EXPECT_TRUE(AnswerJson(spec, rows, h).at("cheaper_designs").is_null());
}

}  // namespace
}  // namespace adse::campaign
