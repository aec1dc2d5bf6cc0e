// The analysis of real runs of the small robotaxi scenario: the starved
// computer is diagnosed CPU-bound at its localization/perception nodes, the
// generous one is not, and both get a deviation score. And what a report
// says about a car that stood.
#include "harness/report/run_report.h"

#include <gtest/gtest.h>

#include <gmock/gmock.h>

#include <nlohmann/json.hpp>

#include "harness/sim/simulator.h"
#include "harness/spec/spec_parser.h"
#include "tests/harness/testing/small_scenario.h"

namespace adse::report {
namespace {

using adse::testing::SmallScenario;
using runfile::StopSample;

RunReport Analyse(double cores, double ghz, double hz) {
  Result<runfile::RunData> run = sim::SimulatePoint(
      SmallScenario(), adse::testing::SmallPoint(cores, ghz, hz));
  EXPECT_TRUE(run.ok()) << run.status().ToString();
  Result<RunReport> report = AnalyzeRun(*run, "memory", AnalyzeOptions{});
  EXPECT_TRUE(report.ok()) << report.status().ToString();
  return std::move(report).value();
}

bool HasCpuBoundAt(const RunReport& r, const std::vector<std::string>& nodes) {
  for (const FindingSummary& f : r.findings) {
    if (f.kind != analysis::FindingKind::kCpuBound) continue;
    for (const std::string& n : nodes) {
      if (f.node == n) return true;
    }
  }
  return false;
}

const std::vector<std::string> kLocalizationAndPerception = {
    "lidar_driver",  "voxel_filter",      "ndt_scan_matcher",
    "ground_filter", "euclidean_cluster", "multi_object_tracker",
    "ekf_localizer"};

TEST(RunReportTest,
     StarvedComputerIsDiagnosedCpuBoundAtLocalizationOrPerception) {
  const RunReport r = Analyse(1, 1.0, 14);
  EXPECT_TRUE(HasCpuBoundAt(r, kLocalizationAndPerception))
      << ToJson(r).dump(2);
  for (const FindingSummary& f : r.findings) {
    EXPECT_FALSE(f.message.empty());
    EXPECT_FALSE(f.remedy.empty());
    EXPECT_FALSE(f.rates_hz.empty()) << "a finding carries its evidence";
    // The typed remedies are what the text says, about this finding.
    ASSERT_FALSE(f.remedies.empty()) << f.node;
    EXPECT_EQ(analysis::RemediesText(f.remedies), f.remedy);
    if (f.kind == analysis::FindingKind::kCpuBound) {
      EXPECT_EQ(f.remedies[0].target, f.node);
    }
  }
  // The JSON carries them beside the text.
  const nlohmann::json j = ToJson(r);
  ASSERT_FALSE(j["findings"].empty());
  for (const nlohmann::json& f : j["findings"]) {
    ASSERT_TRUE(f.contains("remedies")) << f.dump();
    Result<std::vector<analysis::Remedy>> remedies =
        RemediesFromJson(f["remedies"]);
    ASSERT_TRUE(remedies.ok()) << remedies.status().ToString();
    EXPECT_EQ(analysis::RemediesText(*remedies),
              f["remedy"].get<std::string>());
  }
  EXPECT_FALSE(r.feasible);
}

TEST(RunReportTest,
     GenerousComputerKeepsUpWithTheScansAndDrivesCloseToThePath) {
  const RunReport r = Analyse(16, 2.1, 7);
  // No node falls behind: with Autoware's measured costs a node busy with
  // a 40 ms scan skips some of the 50 Hz poses it keeps last-1, but it
  // takes a fresh one for each of its outputs, which is all it needs.
  for (const FindingSummary& f : r.findings) {
    EXPECT_NE(f.kind, analysis::FindingKind::kCpuBound) << ToJson(r).dump(2);
  }
  EXPECT_TRUE(r.feasible) << ToJson(r).dump(2);
  EXPECT_TRUE(r.deviation_complete);
  // A tracking controller on a good pose stays well within half a lane.
  EXPECT_LT(r.metrics.at("deviation_score"), 0.3);
  EXPECT_GE(r.metrics.at("deviation_score"), 0.0);
  EXPECT_LT(r.metrics.at("max_deviation_m"), 1.5);
  // The stored scenario names its calibration by a relative path that does
  // not resolve where the run is re-analysed; constraints still evaluate.
  EXPECT_EQ(r.constraints_error, "");
  ASSERT_EQ(r.constraints.size(), 3u);
  for (const ConstraintStatus& c : r.constraints)
    EXPECT_TRUE(c.satisfied) << c.expression;
  // The planner said why its trajectories stop, one reason per trajectory,
  // and a car that reaches the goal does not stand for long.
  EXPECT_TRUE(r.standing.has_reasons);
  EXPECT_LT(r.standing.standing_s, 5.0) << ToJson(r).dump(2);
  const nlohmann::json j = ToJson(r);
  EXPECT_TRUE(j["metrics"].contains("zigzag_index"));
  EXPECT_EQ(j["point"]["cores"], 16.0);
}

// 60 s: drives 10 s, then stands behind track 7 (map structure) for 40 s
// and 10 s more with localization lost.
runfile::RunData StoodRun() {
  runfile::RunData run;
  run.status = runfile::kRunComplete;
  run.termination_reason = "timeout";
  for (int i = 0; i <= 600; ++i) {
    const double t = 0.1 * i;
    run.ego.push_back({t, t < 10 ? t : 10.0, 0, 0, t < 10 ? 1.0 : 0.0, 0, 0});
    StopSample stop{t, t - 0.05, StopReason::kNone, -1, -1, -1, 0};
    if (t >= 10 && t < 50)
      stop = {t, t - 0.05, StopReason::kObstacle, 0.0, 7, 3.3, 1};
    if (t >= 50) {
      stop = {t, t - 0.05, StopReason::kLocalizationLost, 0.0, -1, -1, 0};
    }
    run.stop_reasons.push_back(stop);
  }
  return run;
}

TEST(RunReportTest, NamesTheDominantStopReasonAndHowLongTheCarStood) {
  Result<RunReport> r = AnalyzeRun(StoodRun(), "memory", AnalyzeOptions{});
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_NEAR(r->standing.standing_s, 50.0, 1e-6);
  ASSERT_EQ(r->standing.by_reason.size(), 2u);
  EXPECT_EQ(r->standing.by_reason[0].reason, StopReason::kObstacle);
  const std::string text = FormatSummary(*r);
  EXPECT_THAT(text, ::testing::HasSubstr(
                        "stood       50.0 s, mostly for obstacle (track 7, "
                        "static structure, 3.3 m ahead): 40.0 s\n"));
  EXPECT_THAT(text, ::testing::HasSubstr("also localization_lost: 10.0 s\n"));
  const nlohmann::json j = ToJson(*r);
  EXPECT_EQ(j["report_version"], 7);
  EXPECT_EQ(j["standing"]["standing_s"], 50.0);
  ASSERT_EQ(j["standing"]["by_reason"].size(), 2u);
  const nlohmann::json& dominant = j["standing"]["by_reason"][0];
  EXPECT_EQ(dominant["reason"], "obstacle");
  EXPECT_EQ(dominant["track_id"], 7);
  EXPECT_EQ(dominant["static_structure"], true);
  EXPECT_EQ(dominant["obstacle_gap_m"], 3.3);
  EXPECT_EQ(j["standing"]["by_reason"][1]["reason"], "localization_lost");
  EXPECT_FALSE(j["standing"]["by_reason"][1].contains("track_id"));
}

TEST(RunReportTest, AStalledRunSaysWhatHeldTheCarAndIsCensored) {
  runfile::RunData run = StoodRun();
  run.status = runfile::kRunStalled;
  run.termination_reason = "stalled: obstacle";
  Result<RunReport> r = AnalyzeRun(run, "memory", AnalyzeOptions{});
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_TRUE(r->censored);
  EXPECT_FALSE(r->feasible);
  EXPECT_EQ(r->metrics.at("censored"), 1.0);
  const std::string text = FormatSummary(*r);
  EXPECT_THAT(text, ::testing::HasSubstr(
                        "ended       stalled: the car stood still until 60 s, "
                        "held by obstacle (task.stall_timeout_s on map "
                        "structure, task.traffic_stall_timeout_s behind a "
                        "road user)\n"));
  EXPECT_THAT(text, ::testing::HasSubstr("nav_time_s is a lower bound"));
  EXPECT_EQ(ToJson(*r)["status"], "stalled");
}

TEST(RunReportTest, AStoppedRunSaysHowFarAlongItsRouteItGot) {
  runfile::RunData run = StoodRun();  // drives 10 m, then stands
  run.status = runfile::kRunInfeasible;
  run.termination_reason = "constraint_violated: nav_time_s <= 60";
  for (int i = 0; i <= 40; ++i) run.ideal_path.push_back({i * 1.0, i * 1.0, 0});
  Result<RunReport> r = AnalyzeRun(run, "memory", AnalyzeOptions{});
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_TRUE(r->censored);
  // 10 m of a 40 m route: a quarter, as the metric the campaign keeps.
  EXPECT_NEAR(r->metrics.at("driven_fraction"), 0.25, 0.01);
  EXPECT_NEAR(ToJson(*r)["metrics"]["driven_fraction"].get<double>(), 0.25,
              0.01);
}

TEST(RunReportTest, AnObjectBesideTheCarIsSaidToBeBesideIt) {
  analysis::StandingTime t;
  t.reason = StopReason::kObstacle;
  t.standing_s = 33.6;
  t.track_id = 37;
  t.obstacle_gap_m = -8.8;
  EXPECT_EQ(DescribeStanding(t),
            "obstacle (track 37, beside the car, 8.8 m behind its front): "
            "33.6 s");
}

TEST(RunReportTest, AWaitForALaneChangeNamesTheCarWithoutItsGap) {
  analysis::StandingTime t;
  t.reason = StopReason::kLaneChange;
  t.standing_s = 19.1;
  t.track_id = 122;
  t.obstacle_gap_m = -4.2;
  EXPECT_EQ(DescribeStanding(t),
            "lane_change (track 122, beside the car in the target lane): "
            "19.1 s");
  // A car behind is not "ahead": the gap has no direction.
  t.obstacle_gap_m = 20.0;
  EXPECT_EQ(DescribeStanding(t),
            "lane_change (track 122, 20.0 m away in the target lane): 19.1 s");
}

TEST(RunReportTest, AnOldRunFilesCostIsReadWithoutItsFloatNoise) {
  runfile::RunData run = StoodRun();
  run.metrics["hardware_cost"] = 7 * 2.1;  // as runs stored it before
  ASSERT_NE(run.metrics["hardware_cost"], 14.7);
  Result<RunReport> r = AnalyzeRun(run, "memory", AnalyzeOptions{});
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->metrics.at("hardware_cost"), 14.7);
}

TEST(RunReportTest, AnOldRunFileSaysItHasNoStopReasons) {
  runfile::RunData run = StoodRun();
  run.stop_reasons.clear();
  Result<RunReport> r = AnalyzeRun(run, "memory", AnalyzeOptions{});
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_THAT(FormatSummary(*r),
              ::testing::HasSubstr("stood       50.0 s (no stop reasons "
                                   "recorded in this run file)\n"));
  EXPECT_EQ(ToJson(*r)["standing"]["has_reasons"], false);
}

TEST(RunReportTest, UnknownThresholdIsAnError) {
  runfile::RunData empty;
  AnalyzeOptions options;
  options.thresholds["no_such_threshold"] = 1.0;
  Result<RunReport> r = AnalyzeRun(empty, "memory", options);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("no_such_threshold"), std::string::npos);
}

}  // namespace
}  // namespace adse::report
