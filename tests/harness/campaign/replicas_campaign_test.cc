// End to end: campaigns with harness.replicas on real `adse worker`
// processes — each replica its own seeded run, the point's row their
// median, a run stopped early in every replica, resume that runs only the
// missing replica, and a point whose replicas disagree flagged unstable.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "analysis/runfile/campaign_file.h"
#include "analysis/runfile/run_file.h"
#include "harness/campaign/campaign.h"
#include "harness/campaign/replicas.h"
#include "harness/sim/run_key.h"
#include "harness/spec/spec_parser.h"
#include "stack/base/files.h"
#include "tests/harness/testing/small_scenario.h"
#include "tests/testing/temp_files.h"

namespace adse::campaign {
namespace {
namespace fs = std::filesystem;

const std::string kAdse = std::string(ADSE_BINARY_DIR) + "/bin/adse";

// robotaxi_small.yaml with its design space, constraints and harness
// replaced, written to `dir` (the profile by absolute path).
spec::Spec Scenario(const std::string& dir, const std::string& design_space,
                    const std::string& constraints,
                    const std::string& harness) {
  std::string text = ReadFile(adse::testing::SmallScenarioPath()).value();
  auto replace_line = [&](const std::string& start, const std::string& with) {
    const size_t at = text.find("\n" + start);
    ASSERT_NE(at, std::string::npos) << start;
    const size_t end = text.find('\n', at + 1);
    text.replace(at + 1, end - at - 1, with);
  };
  replace_line("platform:",
               "platform: {kind: virtual, cost_model: counted, profile: " +
                   std::string(ADSE_SOURCE_DIR) +
                   "/scenarios/profiles/autoware-2022.12-i9-12900kf.yaml}");
  const size_t space = text.find("\ndesign_space:");
  const size_t constraints_at = text.find("\nconstraints:");
  text.replace(space + 1, constraints_at - space - 1,
               "design_space:\n" + design_space);
  replace_line("constraints:", "constraints: " + constraints);
  text += "harness: " + harness + "\n";
  const std::string path = dir + "/scenario.yaml";
  EXPECT_TRUE(WriteFileAtomic(path, text).ok());
  Result<spec::Spec> spec = spec::LoadSpec(path);
  EXPECT_TRUE(spec.ok()) << spec.status().ToString() << "\n" << text;
  return std::move(spec).value();
}

CampaignOptions Options(const std::string& out) {
  CampaignOptions o;
  o.output_dir = out;
  o.workers = 2;
  o.use_cache = false;
  o.worker_command = {kAdse, "worker"};
  return o;
}

size_t RunFileCount(const std::string& folder) {
  size_t n = 0;
  for (const auto& e : fs::directory_iterator(folder + "/runs")) {
    n += e.path().extension() == ".h5";
  }
  return n;
}

TEST(ReplicasCampaignTest,
     EachReplicaRunsWithItsOwnSeedAndAResumedCampaignRunsOnlyTheMissingOne) {
  const std::string dir = adse::testing::TestTempDir("adse-replicas");
  // A starved point that every replica stops early, a generous one that
  // reaches the goal in every replica.
  const spec::Spec spec = Scenario(
      dir,
      "  cores:    {bind: platform.cores,    values: [1, 16]}\n"
      "  freq_ghz: {bind: platform.freq_ghz, values: [1.0, 2.1]}\n",
      "[nav_time_s <= 60, ctrl_rate_hz >= 1, completed]", "{replicas: 3}");
  const std::string out = dir + "/campaign";
  CampaignOptions options = Options(out);
  options.strategy = "exhaustive";
  options.budget = 4;
  Result<CampaignSummary> first = RunCampaign(spec, options);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  const std::vector<EvaluationRow>& rows = first->exploration.evaluations;
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(RunFileCount(out), 12u) << "3 runs per point";

  const EvaluationRow* starved = nullptr;
  const EvaluationRow* generous = nullptr;
  for (const EvaluationRow& row : rows) {
    ASSERT_EQ(row.replicas.size(), 3u);
    std::set<uint64_t> seeds;
    for (int r = 0; r < 3; ++r) {
      EXPECT_EQ(row.replicas[r].replica, r);
      EXPECT_EQ(row.replicas[r].seed, sim::ReplicaSeed(spec, r));
      seeds.insert(row.replicas[r].seed);
    }
    EXPECT_EQ(seeds.size(), 3u);
    EXPECT_EQ(row.replicas[0].seed, spec.world.traffic.seed)
        << "replica 0 keeps the scenario's seed";
    if (row.point.at("cores") == 1 && row.point.at("freq_ghz") == 1.0)
      starved = &row;
    if (row.point.at("cores") == 16 && row.point.at("freq_ghz") == 2.1)
      generous = &row;
  }
  ASSERT_NE(starved, nullptr);
  ASSERT_NE(generous, nullptr);

  // Stopped early in every replica: censored, infeasible, stable.
  EXPECT_FALSE(starved->feasible);
  EXPECT_FALSE(starved->unstable);
  EXPECT_EQ(RowMetric(*starved, "censored"), 1.0);
  EXPECT_TRUE(std::isnan(RowMetric(*starved, "nav_time_s")));
  EXPECT_EQ(runfile::ViolatedConstraint(starved->reason), "nav_time_s <= 60");

  // Feasible in every replica; its nav time is the median of three runs
  // that differ (traffic and cost sampling follow the seed).
  EXPECT_TRUE(generous->feasible);
  EXPECT_FALSE(generous->unstable);
  std::vector<double> nav;
  for (const EvaluationRow& run : generous->replicas) {
    nav.push_back(RowMetric(run, "nav_time_s"));
  }
  std::sort(nav.begin(), nav.end());
  EXPECT_LT(nav.front(), nav.back()) << "the replicas' seeds change the run";
  EXPECT_DOUBLE_EQ(RowMetric(*generous, "nav_time_s"), nav[1]);

  // The index keeps every replica; the views show the spread.
  Result<runfile::CampaignIndex> index =
      runfile::ReadCampaignIndex(out + "/campaign.h5");
  ASSERT_TRUE(index.ok()) << index.status().ToString();
  size_t replicas = 0;
  for (const EvaluationRow& row : index->evaluations) {
    replicas += row.replicas.size();
  }
  EXPECT_EQ(replicas, 12u);
  const std::string report = ReadFile(out + "/report.md").value();
  EXPECT_NE(report.find("## Replicas"), std::string::npos);
  EXPECT_NE(report.find("median of 3 runs"), std::string::npos) << report;
  const nlohmann::json summary =
      nlohmann::json::parse(ReadFile(out + "/summary.json").value());
  ASSERT_TRUE(summary.contains("evaluations"));
  bool spread = false;
  for (const auto& e : summary["evaluations"]) {
    EXPECT_EQ(e.at("replicas"), 3);
    if (e.contains("spread") && e["spread"].contains("nav_time_s")) {
      spread = true;
      EXPECT_EQ(e["runs"].size(), 3u);
    }
  }
  EXPECT_TRUE(spread);

  // Resume: one replica's run is lost; only it runs again, and the
  // campaign's answer is the same to the bit.
  const EvaluationRow& lost = generous->replicas[2];
  fs::remove(out + "/runs/" + lost.content_key + ".h5");
  fs::remove(out + "/runs/" + lost.content_key + ".report.json");
  Result<CampaignSummary> second = RunCampaign(spec, options);
  ASSERT_TRUE(second.ok()) << second.status().ToString();
  EXPECT_EQ(second->simulated, 1) << "only the generous point ran again";
  EXPECT_EQ(RunFileCount(out), 12u);
  for (size_t i = 0; i < rows.size(); ++i) {
    const EvaluationRow& again = second->exploration.evaluations[i];
    EXPECT_EQ(again.metrics, rows[i].metrics) << i;
    EXPECT_EQ(again.feasible, rows[i].feasible) << i;
    for (int r = 0; r < 3; ++r) {
      const bool rerun = again.replicas[r].content_key == lost.content_key;
      EXPECT_EQ(again.replicas[r].source, rerun ? "simulated" : "campaign")
          << i << " replica " << r;
    }
  }
}

TEST(ReplicasCampaignTest, APointWhoseReplicasDisagreeIsFlaggedUnstable) {
  const std::string dir = adse::testing::TestTempDir("adse-replicas");
  const std::string cache = dir + "/cache";
  // No early stop: the constraints do not enter the run keys, so a second
  // campaign with another bound reuses the first one's runs.
  const std::string space =
      "  cores:    {bind: platform.cores,    values: [16]}\n"
      "  freq_ghz: {bind: platform.freq_ghz, values: [2.1]}\n";
  const spec::Spec measure =
      Scenario(dir, space, "[completed]", "{replicas: 3, early_stop: false}");
  CampaignOptions options = Options(dir + "/measure");
  options.use_cache = true;
  options.cache_dir = cache;
  Result<CampaignSummary> measured = RunCampaign(measure, options);
  ASSERT_TRUE(measured.ok()) << measured.status().ToString();
  ASSERT_EQ(measured->exploration.evaluations.size(), 1u);
  const EvaluationRow& row = measured->exploration.evaluations[0];
  ASSERT_EQ(row.replicas.size(), 3u);
  EXPECT_FALSE(row.unstable);
  std::vector<double> nav;
  for (const EvaluationRow& run : row.replicas) {
    nav.push_back(RowMetric(run, "nav_time_s"));
  }
  std::sort(nav.begin(), nav.end());
  ASSERT_LT(nav[0], nav[2]) << "the replicas' times must differ";

  // A bound the fastest replica meets and the slowest does not: one or two
  // of the three (the two fastest may tie) meet it.
  const double cut =
      nav[0] < nav[1] ? 0.5 * (nav[0] + nav[1]) : 0.5 * (nav[1] + nav[2]);
  const int meet = nav[0] < nav[1] ? 1 : 2;
  const std::string bound = fmt::format("{:.6f}", cut);
  const spec::Spec strict =
      Scenario(dir, space, "[nav_time_s <= " + bound + ", completed]",
               "{replicas: 3, early_stop: false}");
  options.output_dir = dir + "/strict";
  Result<CampaignSummary> judged = RunCampaign(strict, options);
  ASSERT_TRUE(judged.ok()) << judged.status().ToString();
  EXPECT_EQ(judged->simulated, 0) << "every run comes from the cache";
  const EvaluationRow& point = judged->exploration.evaluations[0];
  EXPECT_TRUE(point.unstable);
  // Feasible when most runs are.
  EXPECT_EQ(point.feasible, meet == 2) << "feasible in " << meet << " of 3";
  const std::string summary =
      fmt::format("unstable: feasible in {} of 3 runs", meet);
  EXPECT_EQ(ReplicaSummary(strict, point), summary);
  const std::string report = ReadFile(dir + "/strict/report.md").value();
  EXPECT_NE(report.find("**" + summary + "**"), std::string::npos) << report;
  Result<runfile::CampaignIndex> index =
      runfile::ReadCampaignIndex(dir + "/strict/campaign.h5");
  ASSERT_TRUE(index.ok());
  EXPECT_TRUE(index->evaluations[0].unstable);
}

TEST(ReplicasCampaignTest, EachPointDrivesEveryCaseAndIsJudgedByItsWorst) {
  const std::string dir = adse::testing::TestTempDir("adse-cases");
  spec::Spec spec = Scenario(
      dir,
      "  cores:    {bind: platform.cores,    values: [16]}\n"
      "  freq_ghz: {bind: platform.freq_ghz, values: [2.1]}\n",
      "[nav_time_s <= 60, ctrl_rate_hz >= 1, completed]", "{replicas: 1}");
  // Two destinations: the scenario's, across the lot, and one on the
  // entrance road.
  std::string text = spec.source_text;
  const size_t goal = text.find("  goal: {x: 10.0, y: 29.75}");
  ASSERT_NE(goal, std::string::npos);
  text.insert(text.find('\n', goal) + 1,
              "  cases:\n"
              "    - {name: across, goal: {x: 10.0, y: 29.75}}\n"
              "    - {name: along, goal: {x: 40.0, y: -1.75}}\n");
  ASSERT_TRUE(WriteFileAtomic(dir + "/scenario.yaml", text).ok());
  Result<spec::Spec> loaded = spec::LoadSpec(dir + "/scenario.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  spec = *loaded;
  const std::string out = dir + "/campaign";
  CampaignOptions options = Options(out);
  options.strategy = "exhaustive";
  options.budget = 1;
  Result<CampaignSummary> first = RunCampaign(spec, options);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  ASSERT_EQ(first->exploration.evaluations.size(), 1u);
  EXPECT_EQ(RunFileCount(out), 2u) << "one run per case";
  const EvaluationRow& row = first->exploration.evaluations[0];
  ASSERT_EQ(row.replicas.size(), 2u);
  const EvaluationRow& across = row.replicas[0];
  const EvaluationRow& along = row.replicas[1];
  EXPECT_EQ(across.task_case, 0);
  EXPECT_EQ(along.task_case, 1);
  EXPECT_NE(across.content_key, along.content_key);
  // Both reach their goals; the point takes the longer drive.
  EXPECT_EQ(across.reason, "goal_reached");
  EXPECT_EQ(along.reason, "goal_reached");
  const double worst =
      std::max(RowMetric(across, "nav_time_s"), RowMetric(along, "nav_time_s"));
  EXPECT_GT(std::fabs(RowMetric(across, "nav_time_s") -
                      RowMetric(along, "nav_time_s")),
            1.0);
  EXPECT_DOUBLE_EQ(RowMetric(row, "nav_time_s"), worst);
  EXPECT_EQ(row.feasible, across.feasible && along.feasible);

  // Each run file names its case; the index and the report keep both.
  Result<runfile::RunData> run =
      runfile::ReadRunFile(out + "/runs/" + along.content_key + ".h5");
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_EQ(run->task_case, "along");
  Result<runfile::CampaignIndex> index =
      runfile::ReadCampaignIndex(out + "/campaign.h5");
  ASSERT_TRUE(index.ok()) << index.status().ToString();
  ASSERT_EQ(index->evaluations[0].replicas.size(), 2u);
  EXPECT_EQ(index->evaluations[0].replicas[1].task_case, 1);
  EXPECT_EQ(index->evaluations[0].task_case, row.task_case);
  const std::string report = ReadFile(out + "/report.md").value();
  EXPECT_NE(report.find("## Cases"), std::string::npos) << report;
  EXPECT_NE(report.find("worst of 2 cases"), std::string::npos) << report;
  EXPECT_NE(report.find("[along](images/" + along.content_key),
            std::string::npos)
      << report;

  // Resumed: nothing runs again, and the row is the same.
  Result<CampaignSummary> second = RunCampaign(spec, options);
  ASSERT_TRUE(second.ok()) << second.status().ToString();
  EXPECT_EQ(second->simulated, 0);
  EXPECT_EQ(second->exploration.evaluations[0].metrics, row.metrics);
}

}  // namespace
}  // namespace adse::campaign
