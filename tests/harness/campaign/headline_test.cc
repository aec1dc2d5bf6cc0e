// The answer every command leads with: the cheapest feasible design, the
// computers that tie with it, and the cost-time front they sit on.
#include "harness/campaign/headline.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/spec/spec_parser.h"
#include "tests/harness/testing/grid_campaign.h"

namespace adse::campaign {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

using adse::testing::GridRow;
using adse::testing::GridScenario;

TEST(HeadlineTest, ComputersThatTieWithTheCheapestAreNamedBesideIt) {
  const spec::Spec spec = GridScenario();
  // 4 x 3.0 and 6 x 2.0 GHz-cores cost 12 (a last bit apart as doubles)
  // and arrive in the same time; 8 x 1.5 costs 12 too but is slower.
  const std::vector<EvaluationRow> rows = {
      GridRow(0, 2, 3.0, 70), GridRow(1, 4, 3.0, 47.55),
      GridRow(2, 6, 2.0, 47.55), GridRow(3, 8, 1.5, 50.0),
      GridRow(4, 8, 3.0, 30.0)};
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
  const spec::Spec spec = GridScenario();
  const std::vector<EvaluationRow> rows = {GridRow(0, 4, 3.0, 47.55),
                                           GridRow(1, 6, 2.0, 47.6)};
  const Headline h = ComputeHeadline(spec, rows);
  EXPECT_EQ(h.cheapest, 0);
  EXPECT_TRUE(h.cheapest_ties.empty());
  EXPECT_THAT(h.cost_time_front, ElementsAre(0));
  EXPECT_THAT(HeadlineText(spec, rows, h),
              ::testing::Not(HasSubstr("tied with cheapest")));
}

TEST(HeadlineTest, TiesAboveTheCheapestStayOnTheFrontWithoutBeingCalledTies) {
  const spec::Spec spec = GridScenario();
  const std::vector<EvaluationRow> rows = {GridRow(0, 2, 3.0, 55.0),
                                           GridRow(1, 4, 3.0, 40.0),
                                           GridRow(2, 6, 2.0, 40.0)};
  const Headline h = ComputeHeadline(spec, rows);
  EXPECT_EQ(h.cheapest, 0);
  EXPECT_TRUE(h.cheapest_ties.empty());
  EXPECT_THAT(h.cost_time_front, ElementsAre(0, 1, 2));
}

TEST(HeadlineTest, TheConstraintsInfeasibleDesignsInsideTheLinesFailAreNamed) {
  const spec::Spec spec = GridScenario(
      "[nav_time_s <= 60, deviation_score <= 0.6, ctrl_rate_hz >= 5]");
  std::vector<EvaluationRow> rows = {
      GridRow(0, 2, 3.0, 70), GridRow(1, 4, 3.0, 40), GridRow(2, 6, 2.0, 45),
      GridRow(3, 8, 3.0, 30)};
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
}  // namespace
}  // namespace adse::campaign
