// The campaign's row of a run: an early-stopped (censored) run is a run
// that exists, is infeasible, and whose metrics are never taken for
// measurements.
#include "harness/campaign/evaluation.h"

#include <gtest/gtest.h>

#include <cmath>

#include "harness/spec/spec_parser.h"

namespace adse::campaign {
namespace {

spec::Spec Scenario() {
  spec::ParseOptions options;
  options.check_files = false;
  Result<spec::Spec> spec = spec::ParseSpec(
      "adse: 1\nname: rows\nworld: {map: {generate: parking_lot}}\n"
      "task: {start: {x: 5, y: -1.75}, goal: {x: 60, y: 29.75}}\n"
      "design_space:\n  cores: {bind: platform.cores, values: [1, 4]}\n"
      "objectives: [{minimize: hardware_cost}, {minimize: nav_time_s}]\n"
      "constraints: [nav_time_s <= 60]\n",
      "rows.yaml", ".", options);
  EXPECT_TRUE(spec.ok()) << spec.status().ToString();
  return std::move(spec).value();
}

report::RunReport Report(double cores, double nav_time_s, bool censored) {
  report::RunReport r;
  r.content_key = std::string(64, censored ? 'c' : 'a');
  r.point = {{"cores", cores}};
  r.status = censored ? runfile::kRunInfeasible : runfile::kRunComplete;
  r.termination_reason =
      censored ? "constraint_violated: nav_time_s <= 60" : "goal_reached";
  r.censored = censored;
  r.metrics = {{"nav_time_s", nav_time_s},
               {"ctrl_rate_hz", 3.5},
               {"hardware_cost", cores},
               {"censored", censored ? 1.0 : 0.0}};
  r.feasible = !censored;
  return r;
}

TEST(EvaluationTest, ACensoredRunIsARowWithoutMeasuredMetrics) {
  const EvaluationRow row = RowFromReport(Report(1, 60.05, true));
  EXPECT_EQ(row.status, runfile::kRunComplete);  // its run file exists
  EXPECT_EQ(row.reason, "constraint_violated: nav_time_s <= 60");
  EXPECT_FALSE(row.feasible);
  EXPECT_TRUE(std::isnan(RowMetric(row, "nav_time_s")));
  EXPECT_TRUE(std::isnan(RowMetric(row, "ctrl_rate_hz")));
  EXPECT_EQ(RowMetric(row, "hardware_cost"), 1.0);
  EXPECT_EQ(RowMetric(row, "censored"), 1.0);
  const explore::Observation o = ObservationFromRow(row);
  EXPECT_FALSE(o.failed);
  EXPECT_FALSE(o.feasible);
  EXPECT_EQ(o.metrics.count("nav_time_s"), 0u);
  // Strategies learn which constraint stopped it.
  EXPECT_TRUE(o.censored);
  EXPECT_EQ(o.violated_constraint, "nav_time_s <= 60");
  const explore::Observation measured =
      ObservationFromRow(RowFromReport(Report(4, 45.0, false)));
  EXPECT_FALSE(measured.censored);
  EXPECT_EQ(measured.violated_constraint, "");
}

TEST(EvaluationTest, ACensoredRunIsNeverOnTheFront) {
  const spec::Spec spec = Scenario();
  // The censored run is cheaper and "faster" so far than the measured one.
  const std::vector<EvaluationRow> rows = {
      RowFromReport(Report(1, 60.05, true)),
      RowFromReport(Report(4, 45.0, false))};
  EXPECT_EQ(ParetoFrontOf(spec, rows), std::vector<int>{1});
  EXPECT_FALSE(ParetoEvaluation(spec, rows[0]).feasible);
  const EvaluationRow measured = RowFromReport(Report(4, 45.0, false));
  EXPECT_EQ(RowMetric(measured, "nav_time_s"), 45.0);
  EXPECT_EQ(RowMetric(measured, "censored"), 0.0);
}

}  // namespace
}  // namespace adse::campaign
