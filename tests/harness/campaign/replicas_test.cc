// A point's replicas folded into its row: medians with runs stopped early
// ranked beyond their bound, majority feasibility, the unstable flag, the
// representative run, and the spread the views show.
#include "harness/campaign/replicas.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "analysis/runfile/run_data.h"
#include "harness/campaign/headline.h"
#include "harness/spec/spec_parser.h"
#include "tests/harness/testing/lot_scenario.h"

namespace adse::campaign {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

spec::Spec Scenario() {
  return adse::testing::LotScenario(
      "replicas",
      "design_space:\n  cores: {bind: platform.cores, values: [1, 4]}\n"
      "objectives: [{minimize: hardware_cost}, {minimize: nav_time_s}]\n"
      "constraints: [nav_time_s <= 60, ctrl_rate_hz >= 1]\n"
      "harness: {replicas: 3}\n");
}

// A run that reached the goal in `nav_time_s` at 4 cores.
EvaluationRow Reached(int replica, double nav_time_s,
                      double ctrl_rate_hz = 5.0) {
  EvaluationRow row;
  row.index = 7;
  row.iteration = 2;
  row.replica = replica;
  row.content_key = std::string(64, static_cast<char>('a' + replica));
  row.seed = 100 + static_cast<uint64_t>(replica);
  row.status = "complete";
  row.reason = "goal_reached";
  row.source = "simulated";
  row.attempts = 1;
  row.wall_s = 2.0;
  row.point = {{"cores", 4}};
  row.metrics = {{"nav_time_s", nav_time_s},
                 {"ctrl_rate_hz", ctrl_rate_hz},
                 {"hardware_cost", 4},
                 {"completed", 1},
                 {"censored", 0}};
  row.feasible = nav_time_s <= 60 && ctrl_rate_hz >= 1;
  row.bottlenecks_json = "[]";
  return row;
}

// A run stopped early on `constraint`: only cost and censoring are known.
EvaluationRow Stopped(int replica, const std::string& constraint) {
  EvaluationRow row = Reached(replica, 0);
  row.reason = std::string(runfile::kConstraintViolatedPrefix) + constraint;
  row.metrics = {{"hardware_cost", 4}, {"censored", 1}};
  row.feasible = false;
  return row;
}

EvaluationRow Failed(int replica) {
  EvaluationRow row = Reached(replica, 0);
  row.status = "failed";
  row.reason = "crashed: killed by signal 11";
  row.metrics.clear();
  row.feasible = false;
  return row;
}

TEST(ReplicasTest, OneRunIsItsOwnRow) {
  const EvaluationRow run = Reached(0, 42.0);
  const EvaluationRow row = AggregateReplicas(Scenario(), {run});
  EXPECT_EQ(row.content_key, run.content_key);
  EXPECT_EQ(row.metrics, run.metrics);
  EXPECT_TRUE(row.replicas.empty());
  EXPECT_FALSE(row.unstable);
  EXPECT_EQ(ReplicaSummary(Scenario(), row), "1 run");
  EXPECT_FALSE(SpreadOf(Scenario(), row, "nav_time_s"));
}

TEST(ReplicasTest, MetricsAreTheMedianAndTheRunsAreKept) {
  const EvaluationRow row = AggregateReplicas(
      Scenario(),
      {Reached(0, 50.0, 4.0), Reached(1, 40.0, 6.0), Reached(2, 45.0, 5.0)});
  EXPECT_EQ(row.status, "complete");
  EXPECT_DOUBLE_EQ(row.metrics.at("nav_time_s"), 45.0);
  EXPECT_DOUBLE_EQ(row.metrics.at("ctrl_rate_hz"), 5.0);
  EXPECT_DOUBLE_EQ(row.metrics.at("censored"), 0.0);
  EXPECT_TRUE(row.feasible);
  EXPECT_FALSE(row.unstable);
  ASSERT_EQ(row.replicas.size(), 3u);
  EXPECT_EQ(row.replicas[1].replica, 1);
  EXPECT_EQ(row.index, 7);
  EXPECT_EQ(row.iteration, 2);
  EXPECT_EQ(row.attempts, 3);
  EXPECT_DOUBLE_EQ(row.wall_s, 6.0);
  EXPECT_EQ(row.content_key, row.replicas[0].content_key);
  EXPECT_EQ(ReplicaSummary(Scenario(), row), "3 runs");

  const std::optional<MetricSpread> nav =
      SpreadOf(Scenario(), row, "nav_time_s");
  ASSERT_TRUE(nav);
  EXPECT_DOUBLE_EQ(nav->min, 40.0);
  EXPECT_DOUBLE_EQ(nav->max, 50.0);
  EXPECT_DOUBLE_EQ(nav->q1, 42.5);
  EXPECT_DOUBLE_EQ(nav->q3, 47.5);
  EXPECT_EQ(nav->measured, 3);
  EXPECT_EQ(nav->censored, 0);
}

TEST(ReplicasTest, AnEvenNumberOfRunsTakesTheMeanOfTheMiddleTwo) {
  spec::Spec spec = Scenario();
  spec.harness.replicas = 4;
  const EvaluationRow row = AggregateReplicas(
      spec,
      {Reached(0, 50.0), Reached(1, 40.0), Reached(2, 44.0), Reached(3, 46.0)});
  EXPECT_DOUBLE_EQ(row.metrics.at("nav_time_s"), 45.0);
}

TEST(ReplicasTest, ARunStoppedEarlyRanksBeyondTheBoundItBroke) {
  // Two runs made it, one was stopped past 60 s: the median is the slower
  // of the two, not their mean, and the point is unstable.
  const EvaluationRow row = AggregateReplicas(
      Scenario(),
      {Reached(0, 50.0), Stopped(1, "nav_time_s <= 60"), Reached(2, 40.0)});
  EXPECT_DOUBLE_EQ(row.metrics.at("nav_time_s"), 50.0);
  EXPECT_TRUE(row.feasible);
  EXPECT_TRUE(row.unstable);
  EXPECT_DOUBLE_EQ(row.metrics.at("censored"), 0.0);
  EXPECT_EQ(row.reason, "goal_reached");
  EXPECT_EQ(ReplicaSummary(Scenario(), row),
            "unstable: feasible in 2 of 3 runs");
  const std::optional<MetricSpread> nav =
      SpreadOf(Scenario(), row, "nav_time_s");
  ASSERT_TRUE(nav);
  EXPECT_EQ(nav->max, kInf);
  EXPECT_EQ(nav->measured, 2);
  EXPECT_EQ(nav->censored, 1);
  EXPECT_EQ(nav->q3, kInf);

  // A rate floor: the stopped run ranks below every measured rate.
  const EvaluationRow slow = AggregateReplicas(
      Scenario(), {Reached(0, 50.0, 3.0), Stopped(1, "ctrl_rate_hz >= 1"),
                   Reached(2, 40.0, 2.0)});
  EXPECT_DOUBLE_EQ(slow.metrics.at("ctrl_rate_hz"), 2.0);
  EXPECT_EQ(SpreadOf(Scenario(), slow, "ctrl_rate_hz")->min, -kInf);
}

TEST(ReplicasTest, AMajorityStoppedEarlyMakesTheRowCensored) {
  const EvaluationRow row = AggregateReplicas(
      Scenario(), {Reached(0, 55.0), Stopped(1, "nav_time_s <= 60"),
                   Stopped(2, "nav_time_s <= 60")});
  EXPECT_FALSE(row.feasible);
  EXPECT_TRUE(row.unstable);
  EXPECT_EQ(row.metrics.count("nav_time_s"), 0u);
  EXPECT_DOUBLE_EQ(row.metrics.at("censored"), 1.0);
  EXPECT_DOUBLE_EQ(row.metrics.at("hardware_cost"), 4.0);
  // The representative is a stopped run: its reason names the constraint.
  EXPECT_EQ(runfile::ViolatedConstraint(row.reason), "nav_time_s <= 60");
  EXPECT_EQ(row.content_key, row.replicas[1].content_key);

  // Every run stopped: no run measured the time at all.
  const EvaluationRow all =
      AggregateReplicas(Scenario(), {Stopped(0, "nav_time_s <= 60"),
                                     Stopped(1, "nav_time_s <= 60"),
                                     Stopped(2, "nav_time_s <= 60")});
  EXPECT_FALSE(all.feasible);
  EXPECT_FALSE(all.unstable);
  EXPECT_DOUBLE_EQ(all.metrics.at("censored"), 1.0);
}

TEST(ReplicasTest, FailedRunsCountAgainstFeasibilityButNotStability) {
  const EvaluationRow row = AggregateReplicas(
      Scenario(), {Failed(0), Reached(1, 50.0), Reached(2, 40.0)});
  EXPECT_EQ(row.status, "complete");
  EXPECT_TRUE(row.feasible);  // 2 of 3
  EXPECT_FALSE(row.unstable);
  EXPECT_DOUBLE_EQ(row.metrics.at("nav_time_s"), 45.0);
  EXPECT_EQ(row.content_key, row.replicas[1].content_key);
  EXPECT_EQ(ReplicaSummary(Scenario(), row), "3 runs, 1 failed");

  const EvaluationRow half =
      AggregateReplicas(Scenario(), {Failed(0), Failed(1), Reached(2, 40.0)});
  EXPECT_FALSE(half.feasible);  // 1 of 3 is no majority

  const EvaluationRow none =
      AggregateReplicas(Scenario(), {Failed(0), Failed(1), Failed(2)});
  EXPECT_EQ(none.status, "failed");
  EXPECT_FALSE(none.feasible);
  EXPECT_TRUE(none.metrics.empty());
  EXPECT_EQ(none.reason, "crashed: killed by signal 11");
}

// Case `task_case`'s run: as Reached, with a deviation (a metric no
// objective or constraint judges).
EvaluationRow CaseRun(int task_case, int replica, double nav_time_s,
                      double ctrl_rate_hz, double deviation_m) {
  EvaluationRow row = Reached(replica, nav_time_s, ctrl_rate_hz);
  row.task_case = task_case;
  row.content_key =
      std::string(64, static_cast<char>('k' + 3 * task_case + replica));
  row.metrics["max_deviation_m"] = deviation_m;
  return row;
}

TEST(CasesTest, APointIsTheWorstOfItsCasesWithEveryRunKept) {
  spec::Spec spec = Scenario();
  spec.harness.replicas = 1;
  // Given in any order: folded case by case.
  const EvaluationRow row = AggregatePoint(
      spec, {CaseRun(1, 0, 55.0, 3.0, 0.4), CaseRun(0, 0, 40.0, 6.0, 0.2)});
  EXPECT_EQ(row.status, "complete");
  EXPECT_TRUE(row.feasible);
  // Judged metrics: the worst (nav time minimised, control rate bounded
  // from below); the others: the mean.
  EXPECT_DOUBLE_EQ(row.metrics.at("nav_time_s"), 55.0);
  EXPECT_DOUBLE_EQ(row.metrics.at("ctrl_rate_hz"), 3.0);
  EXPECT_DOUBLE_EQ(row.metrics.at("max_deviation_m"), 0.3);
  EXPECT_DOUBLE_EQ(row.metrics.at("hardware_cost"), 4.0);
  EXPECT_DOUBLE_EQ(row.metrics.at("censored"), 0.0);
  // The representative: the case worst in the first objective that differs
  // (nav time; the cost is the same).
  EXPECT_EQ(row.task_case, 1);
  EXPECT_EQ(row.content_key, CaseRun(1, 0, 0, 0, 0).content_key);
  ASSERT_EQ(row.replicas.size(), 2u);
  EXPECT_EQ(row.replicas[0].task_case, 0);
  EXPECT_EQ(row.replicas[1].task_case, 1);
  EXPECT_EQ(row.attempts, 2);
  EXPECT_EQ(CaseCountOf(row), 2);
  EXPECT_EQ(ReplicaSummary(Scenario(), row), "2 cases");
  // A spread across cases would mix two tasks.
  EXPECT_FALSE(SpreadOf(spec, row, "nav_time_s"));
}

TEST(CasesTest, OneInfeasibleCaseMakesThePointInfeasibleAndStandsForIt) {
  spec::Spec spec = Scenario();
  spec.harness.replicas = 1;
  EvaluationRow stopped = Stopped(0, "nav_time_s <= 60");
  stopped.task_case = 1;
  const EvaluationRow row =
      AggregatePoint(spec, {CaseRun(0, 0, 40.0, 6.0, 0.2), stopped});
  EXPECT_EQ(row.status, "complete");
  EXPECT_FALSE(row.feasible);
  // Stopped beyond the bound: the worst nav time is unknown, the row
  // censored, and its reason the stopped case's.
  EXPECT_EQ(row.metrics.count("nav_time_s"), 0u);
  EXPECT_DOUBLE_EQ(row.metrics.at("censored"), 1.0);
  EXPECT_EQ(row.task_case, 1);
  EXPECT_EQ(row.reason, stopped.reason);

  // A case that failed makes the point fail.
  EvaluationRow failed = Failed(0);
  failed.task_case = 1;
  const EvaluationRow broken =
      AggregatePoint(spec, {CaseRun(0, 0, 40.0, 6.0, 0.2), failed});
  EXPECT_EQ(broken.status, "failed");
  EXPECT_FALSE(broken.feasible);
  EXPECT_EQ(broken.reason, failed.reason);
  EXPECT_TRUE(broken.metrics.empty());
  EXPECT_EQ(ReplicaSummary(Scenario(), broken), "2 cases, 1 failed");
}

TEST(CasesTest, TheCaseFailingMostConstraintsStandsForAnInfeasiblePoint) {
  spec::Spec spec = Scenario();
  spec.harness.replicas = 1;
  // Case 0 is too slow; case 1 too slow and its control too: case 1's run
  // explains both failures of the point.
  EvaluationRow slow = CaseRun(0, 0, 70.0, 6.0, 0.2);
  EvaluationRow starved = CaseRun(1, 0, 65.0, 0.5, 0.2);
  starved.reason = "parked_out_of_tolerance";
  const EvaluationRow row = AggregatePoint(spec, {slow, starved});
  EXPECT_FALSE(row.feasible);
  EXPECT_EQ(row.task_case, 1);
  EXPECT_EQ(row.reason, "parked_out_of_tolerance");
  EXPECT_DOUBLE_EQ(row.metrics.at("nav_time_s"), 70.0);
  EXPECT_DOUBLE_EQ(row.metrics.at("ctrl_rate_hz"), 0.5);

  // Equal failures: the first case.
  const EvaluationRow equal =
      AggregatePoint(spec, {slow, CaseRun(1, 0, 80.0, 6.0, 0.2)});
  EXPECT_EQ(equal.task_case, 0);
}

TEST(CasesTest, ACountThatMustBeZeroIsFoldedToItsWorstNotItsMean) {
  spec::Spec spec = Scenario();
  spec.harness.replicas = 1;
  spec.constraints.push_back("obstacle_collisions == 0");
  EvaluationRow clean = CaseRun(0, 0, 40.0, 6.0, 0.2);
  clean.metrics["obstacle_collisions"] = 0;
  EvaluationRow touched = CaseRun(1, 0, 45.0, 6.0, 0.2);
  touched.metrics["obstacle_collisions"] = 1;
  touched.feasible = false;
  const EvaluationRow row = AggregatePoint(spec, {clean, touched});
  EXPECT_FALSE(row.feasible);
  EXPECT_DOUBLE_EQ(row.metrics.at("obstacle_collisions"), 1.0);
  EXPECT_EQ(row.task_case, 1);
}

TEST(CasesTest, EachCasesReplicasAreFoldedBeforeTheCases) {
  // Three replicas per case: medians 45 and 52, the point 52.
  const EvaluationRow row = AggregatePoint(
      Scenario(),
      {CaseRun(0, 0, 50.0, 4.0, 0.1), CaseRun(0, 1, 40.0, 6.0, 0.1),
       CaseRun(0, 2, 45.0, 5.0, 0.1), CaseRun(1, 0, 52.0, 5.0, 0.3),
       CaseRun(1, 1, 58.0, 5.0, 0.3), CaseRun(1, 2, 51.0, 5.0, 0.3)});
  EXPECT_DOUBLE_EQ(row.metrics.at("nav_time_s"), 52.0);
  EXPECT_DOUBLE_EQ(row.metrics.at("ctrl_rate_hz"), 5.0);
  EXPECT_DOUBLE_EQ(row.metrics.at("max_deviation_m"), 0.2);
  EXPECT_TRUE(row.feasible);
  ASSERT_EQ(row.replicas.size(), 6u);
  EXPECT_EQ(ReplicaSummary(Scenario(), row), "2 cases x 3 runs");
}

TEST(CasesTest, ACaseWhoseRunsDisagreeIsNamed) {
  spec::Spec spec = Scenario();
  spec.cases = {{"backing_in", spec.task}, {"nose_in", spec.task}};
  // backing_in holds in all three runs, nose_in in two: 70 s breaks the
  // 60 s bound.
  const EvaluationRow row = AggregatePoint(
      spec, {CaseRun(0, 0, 50.0, 4.0, 0.1), CaseRun(0, 1, 40.0, 6.0, 0.1),
             CaseRun(0, 2, 45.0, 5.0, 0.1), CaseRun(1, 0, 52.0, 5.0, 0.3),
             CaseRun(1, 1, 70.0, 5.0, 0.3), CaseRun(1, 2, 51.0, 5.0, 0.3)});
  EXPECT_TRUE(row.feasible);
  EXPECT_TRUE(row.unstable);
  EXPECT_EQ(Instability(spec, row),
            "unstable: nose_in feasible in 2 of 3 runs");
  EXPECT_EQ(ReplicaSummary(spec, row),
            "2 cases x 3 runs, unstable: nose_in feasible in 2 of 3 runs");
  // The headline says how sure its design is once, case by case.
  const std::string headline =
      HeadlineText(spec, {row}, ComputeHeadline(spec, {row}));
  EXPECT_NE(headline.find("(worst of 2 cases, each the median of 3 runs, "
                          "unstable: nose_in feasible in 2 of 3 runs)"),
            std::string::npos)
      << headline;
  const EvaluationRow stable = AggregatePoint(
      spec, {CaseRun(0, 0, 50.0, 4.0, 0.1), CaseRun(1, 0, 52.0, 5.0, 0.3)});
  EXPECT_EQ(Instability(spec, stable), "");
}

}  // namespace
}  // namespace adse::campaign
