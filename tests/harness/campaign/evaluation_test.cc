// The campaign's row of a run: an early-stopped (censored) run is a run
// that exists, is infeasible, and whose metrics are never taken for
// measurements.
#include "harness/campaign/evaluation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/spec/spec_parser.h"
#include "tests/harness/testing/lot_scenario.h"
#include "tests/harness/testing/recording.h"

namespace adse::campaign {
namespace {

spec::Spec Scenario() {
  return adse::testing::LotScenario(
      "rows",
      "design_space:\n  cores: {bind: platform.cores, values: [1, 4]}\n"
      "objectives: [{minimize: hardware_cost}, {minimize: nav_time_s}]\n"
      "constraints: [nav_time_s <= 60]\n");
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

TEST(EvaluationTest, ACensoredRunKeepsHowFarItGot) {
  report::RunReport stopped = Report(1, 60.05, true);
  stopped.metrics["driven_fraction"] = 0.4;
  stopped.metrics["deviation_score"] = 0.03;
  const EvaluationRow row = RowFromReport(stopped);
  EXPECT_EQ(RowMetric(row, "driven_fraction"), 0.4);
  EXPECT_TRUE(std::isnan(RowMetric(row, "deviation_score")));
  EXPECT_EQ(ObservationFromRow(row).metrics.at("driven_fraction"), 0.4);
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

using analysis::Remedy;
using analysis::RemedyKind;

// A starved run's report with one finding of each kind.
report::RunReport ReportWithFindings() {
  report::RunReport r = Report(2, 50.0, false);
  report::FindingSummary cpu;
  cpu.kind = analysis::FindingKind::kCpuBound;
  cpu.node = "lidar_driver";
  cpu.topics = {"/sensing/lidar/points_raw"};
  cpu.rates_hz = {{"deficit", 0.4}};
  cpu.remedies = {{RemedyKind::kMoreCores, "lidar_driver"},
                  {RemedyKind::kLowerSensorRate, "/sensing/lidar/points_raw"}};
  cpu.remedy = analysis::RemediesText(cpu.remedies);
  report::FindingSummary frequency;
  frequency.kind = analysis::FindingKind::kFrequencyBound;
  frequency.node = "planner";
  frequency.topics = {"/objects"};
  frequency.rates_hz = {{"deficit", 0.3}};
  frequency.remedies = {
      {RemedyKind::kRaisePublisherRate, "/objects", "euclidean_cluster"},
      {RemedyKind::kRelieveNode, "euclidean_cluster"}};
  frequency.remedy = analysis::RemediesText(frequency.remedies);
  r.findings = {cpu, frequency};
  return r;
}

TEST(EvaluationTest, TypedRemediesGoFromTheReportToTheStrategy) {
  const report::RunReport r = ReportWithFindings();
  const nlohmann::json j = report::ToJson(r);
  EXPECT_EQ(j["findings"][0]["remedies"],
            nlohmann::json::parse(
                R"([{"kind":"more_cores","target":"lidar_driver"},
                    {"kind":"lower_sensor_rate",
                     "target":"/sensing/lidar/points_raw"}])"));
  EXPECT_EQ(j["findings"][0]["remedy"], "more cores; lower sensor rate");
  EXPECT_EQ(j["findings"][1]["remedies"][0],
            nlohmann::json::parse(
                R"({"kind":"raise_publisher_rate","target":"/objects",
                    "publisher":"euclidean_cluster"})"));

  // As a worker leaves it next to its run, and as the index stores it.
  Result<EvaluationRow> row = RowFromReportJson(j.dump(1), "x.report.json");
  ASSERT_TRUE(row.ok()) << row.status().ToString();
  const nlohmann::json bottlenecks =
      nlohmann::json::parse(row->bottlenecks_json);
  ASSERT_EQ(bottlenecks.size(), 2u);
  EXPECT_EQ(bottlenecks[0]["remedies"], j["findings"][0]["remedies"]);
  EXPECT_EQ(bottlenecks[1]["remedies"], j["findings"][1]["remedies"]);
  EXPECT_EQ(bottlenecks[0]["remedy"], "more cores; lower sensor rate");
  EXPECT_EQ(RowFromReport(r).bottlenecks_json, row->bottlenecks_json);

  const explore::Observation o = ObservationFromRow(*row);
  ASSERT_EQ(o.bottlenecks.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(o.bottlenecks[i].kind, r.findings[i].kind);
    EXPECT_EQ(o.bottlenecks[i].node, r.findings[i].node);
    EXPECT_EQ(o.bottlenecks[i].remedies, r.findings[i].remedies);
    EXPECT_EQ(o.bottlenecks[i].remedy, r.findings[i].remedy);
  }
  EXPECT_EQ(o.bottlenecks[1].remedy,
            "raise the rate of /objects's publisher (euclidean_cluster); "
            "relieve euclidean_cluster (cpu_bound)");
}

TEST(EvaluationTest, AReportWithAnUnknownRemedyKindIsRefusedNamingIt) {
  nlohmann::json j = report::ToJson(ReportWithFindings());
  j["findings"][1]["remedies"][1]["kind"] = "buy_a_faster_car";
  Result<EvaluationRow> row = RowFromReportJson(j.dump(), "x.report.json");
  ASSERT_FALSE(row.ok());
  EXPECT_EQ(row.status().code(), Status::Code::kCorruption);
  const std::string& message = row.status().message();
  EXPECT_NE(message.find("x.report.json"), std::string::npos) << message;
  EXPECT_NE(message.find("finding 1 (frequency_bound planner)"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("unknown remedy kind 'buy_a_faster_car'"),
            std::string::npos)
      << message;

  j = report::ToJson(ReportWithFindings());
  j["findings"][0]["remedies"][0].erase("target");
  row = RowFromReportJson(j.dump(), "x.report.json");
  ASSERT_FALSE(row.ok());
  EXPECT_NE(row.status().message().find("remedy 0 has no string"),
            std::string::npos)
      << row.status().message();
}

TEST(EvaluationTest, AReportWhoseFindingHasAnUnknownKindIsRefused) {
  nlohmann::json j = report::ToJson(ReportWithFindings());
  j["findings"][1]["kind"] = "memory_bound";
  Result<EvaluationRow> row = RowFromReportJson(j.dump(), "x.report.json");
  ASSERT_FALSE(row.ok());
  EXPECT_EQ(row.status().code(), Status::Code::kCorruption);
  EXPECT_NE(row.status().message().find(
                "x.report.json: finding 1: unknown bottleneck kind "
                "'memory_bound'; valid kinds: cpu_bound"),
            std::string::npos)
      << row.status().message();
  j["findings"][1].erase("kind");
  EXPECT_FALSE(RowFromReportJson(j.dump(), "x.report.json").ok());
}

TEST(EvaluationTest, AReportWithoutTypedRemediesIsRefused) {
  nlohmann::json j = report::ToJson(ReportWithFindings());
  j["findings"][0].erase("remedies");
  Result<EvaluationRow> row = RowFromReportJson(j.dump(), "x.report.json");
  ASSERT_FALSE(row.ok());
  EXPECT_NE(row.status().message().find(
                "x.report.json: finding 0 has no typed remedies"),
            std::string::npos)
      << row.status().message();
  // A healthy run's report has no finding to miss them.
  j["findings"] = nlohmann::json::array();
  EXPECT_TRUE(RowFromReportJson(j.dump(), "x.report.json").ok());
}

// An older adse's report lacks what rows now carry (localization_lost_s
// since version 4, starved_input findings since 5, topics' longest take
// gaps since 6, the driven fraction since 7): the campaign analyses its
// run again instead.
TEST(EvaluationTest, AReportOfAnOlderVersionIsStale) {
  nlohmann::json j = report::ToJson(ReportWithFindings());
  ASSERT_TRUE(RowFromReportJson(j.dump(), "new.report.json").ok());
  for (const nlohmann::json& version :
       {nlohmann::json(report::kReportVersion - 1), nlohmann::json("5"),
        nlohmann::json()}) {
    j["report_version"] = version;
    Result<EvaluationRow> row = RowFromReportJson(j.dump(), "old.report.json");
    ASSERT_FALSE(row.ok()) << version;
    EXPECT_EQ(row.status().code(), Status::Code::kCorruption);
    EXPECT_NE(row.status().message().find(
                  "old.report.json: a report older than report_version 7"),
              std::string::npos)
        << row.status().message();
  }
  j.erase("report_version");
  EXPECT_FALSE(RowFromReportJson(j.dump(), "old.report.json").ok());
}

TEST(EvaluationTest, AnIndexRowWithoutTypedRemediesKeepsItsText) {
  EvaluationRow row = RowFromReport(Report(2, 50.0, false));
  row.bottlenecks_json =
      R"([{"kind":"cpu_bound","node":"ekf_localizer","remedy":"more cores",)"
      R"("severity":0.3},)"
      R"({"kind":"cpu_bound","node":"x","remedy":"more cores",)"
      R"("remedies":[{"kind":"warp_drive","target":"x"}],"severity":0.2}])";
  const explore::Observation o = ObservationFromRow(row);
  ASSERT_EQ(o.bottlenecks.size(), 2u);
  for (const explore::BottleneckHint& hint : o.bottlenecks) {
    EXPECT_EQ(hint.remedy, "more cores");
    EXPECT_TRUE(hint.remedies.empty()) << hint.node;
  }
}

TEST(EvaluationTest, AnIndexRowsHintOfAnUnknownKindIsLeftOut) {
  EvaluationRow row = RowFromReport(Report(2, 50.0, false));
  row.bottlenecks_json =
      R"([{"kind":"memory_bound","node":"a","remedy":"more memory"},)"
      R"({"kind":"frequency_bound","node":"b","remedy":"more cores"}])";
  const explore::Observation o = ObservationFromRow(row);
  ASSERT_EQ(o.bottlenecks.size(), 1u);
  EXPECT_EQ(o.bottlenecks[0].node, "b");
  EXPECT_EQ(o.bottlenecks[0].kind, analysis::FindingKind::kFrequencyBound);
}

// tests/data/migrate_remedies.py gave the recordings their typed remedies:
// they must say what the recorded text says.
TEST(EvaluationTest, TheRecordedCampaignsCarryTypedRemediesThatReadAsText) {
  for (const char* name : {"robotaxi_exhaustive", "reference_study"}) {
    const Recording& recording = adse::testing::RecordingUnderTestData(name);
    ASSERT_EQ(recording.rows.size(), 280u) << name;
    std::set<std::string> kinds;
    int hints = 0;
    for (const EvaluationRow& row : recording.rows) {
      for (const explore::BottleneckHint& hint :
           ObservationFromRow(row).bottlenecks) {
        ++hints;
        ASSERT_FALSE(hint.remedies.empty()) << name << " " << hint.node;
        EXPECT_EQ(analysis::RemediesText(hint.remedies), hint.remedy)
            << name << " " << hint.node;
        for (const Remedy& remedy : hint.remedies) {
          kinds.insert(analysis::RemedyKindToString(remedy.kind));
          if (remedy.kind == RemedyKind::kLowerSensorRate) {
            EXPECT_EQ(remedy.target.rfind("/sensing/", 0), 0u) << remedy;
          } else {
            EXPECT_EQ(remedy.target, hint.node) << remedy;
          }
        }
      }
    }
    EXPECT_GT(hints, 0) << name;
    EXPECT_EQ(kinds, (std::set<std::string>{"higher_frequency", "more_cores",
                                            "lower_sensor_rate"}))
        << name;
  }
}

}  // namespace
}  // namespace adse::campaign
