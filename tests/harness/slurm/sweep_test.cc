// A planned sweep's shard and index without Slurm: `adse shard --local`
// runs one shard's points in local workers, `adse index` builds the views
// from what exists and says what is missing, and a scenario edited after
// planning is refused.
#include "harness/slurm/sweep.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "harness/sim/run_key.h"
#include "harness/slurm/records.h"
#include "harness/spec/spec_parser.h"
#include "tests/harness/slurm/testing/adse_commands.h"

namespace adse::slurm::testing {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

// The plan adse submit would write for these points, one per shard.
void WritePlan(const std::string& scenario, const std::string& campaign,
               const std::vector<std::string>& points) {
  Result<spec::Spec> spec = spec::LoadSpec(scenario);
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  SweepPlan plan;
  plan.scenario = scenario;
  plan.strategy = "exhaustive";
  plan.budget = static_cast<int>(points.size());
  plan.shard_size = 1;
  plan.use_cache = false;
  for (const std::string& text : points) {
    Result<spec::DesignPoint> point =
        spec::ParsePoint(spec->design_space, text);
    ASSERT_TRUE(point.ok());
    Result<std::string> key =
        sim::RunKey(*spec, *point, spec->world.traffic.seed);
    ASSERT_TRUE(key.ok());
    plan.points.push_back(
        {static_cast<int64_t>(plan.points.size()), text, *key, {*key}});
  }
  ASSERT_TRUE(WriteSweepPlan(campaign, plan).ok());
}

TEST(SweepTest, ALocalShardRunsItsPointsAndTheIndexNamesWhatIsMissing) {
  const TestFolder folder("sweep-local");
  const std::string scenario = SmallScenarioIn(
      folder.path(), "{strategy: exhaustive, budget: 2}", "{memory_mb: 2048}");
  const std::string campaign = folder.path() + "/campaign";
  WritePlan(scenario, campaign,
            {"cores=16,freq_ghz=2.1,lidar_hz=7",
             "cores=16,freq_ghz=2.1,lidar_hz=14"});

  AdseRun run = Adse({"shard", campaign, "--task", "1", "--local"});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("cores=16,freq_ghz=2.1,lidar_hz=14"));
  EXPECT_THAT(run.output, HasSubstr("1 of 1 points have a result"));
  // Run again: nothing to simulate.
  run = Adse({"shard", campaign, "--task", "1", "--local"});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("(0 simulated, 1 reused, 0 failed)"));
  run = Adse({"shard", campaign, "--task", "2", "--local"});
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("--task: expected a shard of"));

  run = Adse({"index", campaign});
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_THAT(run.output, HasSubstr("1 planned point(s) have no result"));
  const json summary =
      json::parse(ReadFile(campaign + "/summary.json").value());
  EXPECT_EQ(summary["complete"], false);
  EXPECT_EQ(summary["unfinished"], 1);
  ASSERT_EQ(summary["evaluations"].size(), 1u);
  EXPECT_EQ(summary["evaluations"][0]["source"], "simulated");
  EXPECT_EQ(summary["evaluations"][0]["iteration"], 1) << "shard 1";
  EXPECT_THAT(ReadFile(campaign + "/report.md").value(),
              HasSubstr("incomplete: 1 planned point(s) have no result yet"));
  run = Adse({"status", campaign, "--json"});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const json st = json::parse(run.output);
  EXPECT_EQ(st["kind"], "sweep");
  EXPECT_EQ(st["counts"],
            json({{"done", 1}, {"failed", 0}, {"running", 0}, {"pending", 1}}));

  // The scenario edited after planning: its keys no longer match.
  std::string text = ReadFile(scenario).value();
  text.replace(text.find("seed: 3"), 7, "seed: 4");
  std::ofstream(scenario) << text;
  run = Adse({"shard", campaign, "--task", "0", "--local"});
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("changed since adse submit planned"));
  run = Adse({"index", campaign});
  EXPECT_EQ(run.exit_code, 2) << run.output;
}

}  // namespace
}  // namespace adse::slurm::testing
