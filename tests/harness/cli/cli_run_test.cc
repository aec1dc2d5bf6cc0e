// `adse run`, `adse explore --replay`, `adse analyze` of a campaign and
// the worker, as a user runs them: progress, answers that agree, bad flags.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

#include "tests/harness/cli/example_files.h"
#include "tests/harness/testing/adse_command.h"
#include "tests/harness/testing/small_scenario.h"
#include "tests/testing/temp_files.h"

namespace {

namespace fs = std::filesystem;

using adse::testing::Adse;
using adse::testing::CommandRun;
using adse::testing::ReadText;
using adse::testing::Replaced;
using adse::testing::SmallScenarioPath;
using adse::testing::WriteScenario;

TEST(CliRunTest, ExploreReplayPrintsADistributionPerStrategy) {
  const CommandRun run =
      Adse("explore --replay " + std::string(ADSE_SOURCE_DIR) +
           "/tests/data/robotaxi_exhaustive --strategy agent,ga --seeds 3");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("280 recorded evaluations, budget 15, seeds 1..3"),
            std::string::npos)
      << run.out;
  // The recording's own answer leads, from the same front as adse run's:
  // the true cheapest feasible design of the 280-point space.
  EXPECT_NE(run.out.find("cheapest feasible   cores=7,freq_ghz=1.2,lidar_hz=7"
                         "  cost 8.4,"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("| cheapest feasible found | cheapest confirmed (no "
                         "cheaper design left untried) |"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("| agent |"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("| ga |"), std::string::npos) << run.out;
  const CommandRun bad = Adse("explore --replay /nonexistent/campaign");
  EXPECT_EQ(bad.exit_code, 2) << bad.out;
  EXPECT_NE(bad.out.find("/nonexistent/campaign"), std::string::npos)
      << bad.out;
  // An unknown strategy is refused before any of the replay's table.
  const CommandRun unknown =
      Adse("explore --replay " + std::string(ADSE_SOURCE_DIR) +
           "/tests/data/robotaxi_exhaustive --strategy agent,nope");
  EXPECT_EQ(unknown.exit_code, 2) << unknown.out;
  EXPECT_NE(unknown.out.find("nope"), std::string::npos) << unknown.out;
  EXPECT_EQ(unknown.out.find("| strategy |"), std::string::npos) << unknown.out;
  EXPECT_EQ(unknown.out.find("replay of"), std::string::npos) << unknown.out;
  // So is a strategy that cannot replay (llm without recorded exchanges),
  // even after one that could.
  const CommandRun llm =
      Adse("explore --replay " + std::string(ADSE_SOURCE_DIR) +
           "/tests/data/robotaxi_exhaustive --strategy random,llm --seeds 1");
  EXPECT_NE(llm.exit_code, 0) << llm.out;
  EXPECT_NE(llm.out.find("--strategy llm"), std::string::npos) << llm.out;
  EXPECT_EQ(llm.out.find("| strategy |"), std::string::npos) << llm.out;
  EXPECT_EQ(llm.out.find("| random |"), std::string::npos) << llm.out;
  // A strategy named twice, and seeds that would run past 2^64 - 1.
  const std::string replay = "explore --replay " +
                             std::string(ADSE_SOURCE_DIR) +
                             "/tests/data/robotaxi_exhaustive ";
  const CommandRun twice = Adse(replay + "--strategy agent,agent");
  EXPECT_EQ(twice.exit_code, 2) << twice.out;
  EXPECT_NE(twice.out.find("'agent' given twice"), std::string::npos)
      << twice.out;
  const CommandRun wrapped =
      Adse(replay + "--seeds 100 --first-seed 18446744073709551615");
  EXPECT_EQ(wrapped.exit_code, 2) << wrapped.out;
  EXPECT_NE(wrapped.out.find("the seeds run past"), std::string::npos)
      << wrapped.out;
}

TEST(CliRunTest,
     ExploreReplayWithInitialPointsSeedsTheAgentsSecondAndThirdRuns) {
  const std::string replay = "explore --replay " +
                             std::string(ADSE_SOURCE_DIR) +
                             "/tests/data/landscapes/saturating --strategy "
                             "agent --seeds 2 --budget 4 --json";
  const CommandRun seeded = Adse(replay + " --initial-points 2");
  ASSERT_EQ(seeded.exit_code, 0) << seeded.out;
  const nlohmann::json out = nlohmann::json::parse(seeded.out);
  EXPECT_EQ(out["initial_points"], 2);
  const nlohmann::json& runs = out["strategies"]["agent"]["runs"];
  ASSERT_EQ(runs.size(), 2u);
  for (const nlohmann::json& run : runs) {
    const nlohmann::json& rounds = run["iterations"];
    ASSERT_EQ(rounds.size(), 4u) << seeded.out;
    EXPECT_NE(rounds[1]["rationale"].get<std::string>().find(
                  "Initial design, point 1 of 2"),
              std::string::npos)
        << seeded.out;
    EXPECT_NE(rounds[2]["rationale"].get<std::string>().find(
                  "Initial design, point 2 of 2"),
              std::string::npos)
        << seeded.out;
    EXPECT_EQ(rounds[3]["rationale"].get<std::string>().find("Initial design"),
              std::string::npos)
        << seeded.out;
  }
  // The same start, then each seed's own draws.
  EXPECT_EQ(runs[0]["proposals"][0], runs[1]["proposals"][0]);
  EXPECT_NE(runs[0]["proposals"][1], runs[1]["proposals"][1]);
  // Without it, the recording's own (none).
  const CommandRun plain = Adse(replay);
  ASSERT_EQ(plain.exit_code, 0) << plain.out;
  EXPECT_EQ(nlohmann::json::parse(plain.out)["initial_points"], 0);
  const CommandRun negative = Adse(replay + " --initial-points -1");
  EXPECT_EQ(negative.exit_code, 2) << negative.out;
  EXPECT_NE(negative.out.find("--initial-points"), std::string::npos)
      << negative.out;
}

TEST(CliRunTest, ExploreReplayWithTwoOfTheObjectivesScoresAgainstTheirFront) {
  const std::string replay = "explore --replay " +
                             std::string(ADSE_SOURCE_DIR) +
                             "/tests/data/robotaxi_exhaustive --strategy "
                             "random --seeds 1 --json";
  const CommandRun all = Adse(replay);
  ASSERT_EQ(all.exit_code, 0) << all.out;
  const nlohmann::json four = nlohmann::json::parse(all.out);
  EXPECT_EQ(four["objectives"].size(), 4u) << all.out;
  const CommandRun two =
      Adse(replay + " --objectives nav_time_s,hardware_cost");
  ASSERT_EQ(two.exit_code, 0) << two.out;
  const nlohmann::json out = nlohmann::json::parse(two.out);
  // The scenario's order is kept; the true front is the 2-D one: 14 of
  // the 280 points, against 72 over all four objectives.
  EXPECT_EQ(out["objectives"],
            nlohmann::json::array({"hardware_cost", "nav_time_s"}));
  EXPECT_EQ(out["strategies"]["random"]["true_front_size"], 14) << two.out;
  EXPECT_EQ(four["strategies"]["random"]["true_front_size"], 72) << all.out;
  // Whether each seed's runs confirm the answer: random search's one seed
  // found no cheapest design, so it has nothing to confirm.
  EXPECT_EQ(four["strategies"]["random"]["seeds_that_confirmed_cheapest"], 0);
  EXPECT_EQ(four["strategies"]["random"]["runs"][0]["cheapest_confirmed"],
            false);
  EXPECT_TRUE(
      four["strategies"]["random"]["runs"][0]["cheaper_left_untried"].is_null())
      << all.out;
  EXPECT_TRUE(four["answer"]["cheaper_designs"].is_object()) << all.out;
  // With confirm runs after the budget, the seed settles the designs
  // cheaper than its answer: it finds the recording's and confirms it.
  const CommandRun confirm = Adse(replay + " --confirm-runs 10");
  ASSERT_EQ(confirm.exit_code, 0) << confirm.out;
  const nlohmann::json confirmed = nlohmann::json::parse(confirm.out);
  EXPECT_EQ(confirmed["confirm_runs"], 10);
  const nlohmann::json& seed = confirmed["strategies"]["random"]["runs"][0];
  EXPECT_GT(seed["confirm_evaluations"], 0) << confirm.out;
  EXPECT_EQ(seed["evaluations"], 15 + seed["confirm_evaluations"].get<int>());
  EXPECT_EQ(seed["found_cheapest_feasible"], true) << confirm.out;
  EXPECT_EQ(seed["cheapest_confirmed"], true) << confirm.out;
  // The table says what they cost.
  std::string table = replay + " --confirm-runs 10";
  table.erase(table.find(" --json"), 7);
  const CommandRun text = Adse(table);
  ASSERT_EQ(text.exit_code, 0) << text.out;
  EXPECT_NE(text.out.find("budget 15 and up to 10 confirm runs"),
            std::string::npos)
      << text.out;
  EXPECT_NE(
      text.out.find("1 of 1 seeds after a median of " +
                    std::to_string(seed["confirm_evaluations"].get<int>()) +
                    " confirm runs of at most 10"),
      std::string::npos)
      << text.out;
  const CommandRun negative = Adse(replay + " --confirm-runs -1");
  EXPECT_EQ(negative.exit_code, 2) << negative.out;
  EXPECT_NE(negative.out.find("--confirm-runs"), std::string::npos)
      << negative.out;

  const CommandRun unknown = Adse(replay + " --objectives nav_time,cost");
  EXPECT_EQ(unknown.exit_code, 2) << unknown.out;
  EXPECT_NE(unknown.out.find("--objectives: 'nav_time' is not an objective "
                             "of the recorded scenario (its objectives: "
                             "hardware_cost, nav_time_s, deviation_score, "
                             "ctrl_rate_hz)"),
            std::string::npos)
      << unknown.out;
  const CommandRun one = Adse(replay + " --objectives nav_time_s");
  EXPECT_EQ(one.exit_code, 2) << one.out;
  EXPECT_NE(one.out.find("two objectives at least"), std::string::npos)
      << one.out;
}

TEST(CliRunTest, ExploreReplayWithRationaleShowsEachRoundAndWhy) {
  const std::string replay =
      "explore --replay " + std::string(ADSE_SOURCE_DIR) +
      "/tests/data/landscapes/saturating --strategy agent,random --seeds 2 "
      "--budget 4";
  const CommandRun text = Adse(replay + " --rationale");
  ASSERT_EQ(text.exit_code, 0) << text.out;
  for (const char* seed :
       {"agent seed 1:", "agent seed 2:", "random seed 1:", "random seed 2:"}) {
    EXPECT_NE(text.out.find(seed), std::string::npos) << seed << text.out;
  }
  // The agent's first round has nothing to model; later ones explain the
  // model's prediction. Random search says how it drew.
  EXPECT_NE(text.out.find("  iteration 0: cores="), std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("<- No usable run to model yet"), std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("<- Last ("), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("<- random: 1 point(s) drawn uniformly"),
            std::string::npos)
      << text.out;

  // Where some of the model's samples never arrive (a 4-D space's coarse
  // voxels on 3 cores at 2.1 GHz, in seed 1's twelfth round), the
  // rationale says so instead of printing "inf".
  const CommandRun four_d =
      Adse("explore --replay " + std::string(ADSE_SOURCE_DIR) +
           "/tests/data/landscapes/four_d --strategy agent --seeds 1 "
           "--rationale");
  ASSERT_EQ(four_d.exit_code, 0) << four_d.out;
  EXPECT_NE(four_d.out.find("nav_time_s unbounded in some of the model's "
                            "samples"),
            std::string::npos)
      << four_d.out;
  EXPECT_FALSE(std::regex_search(four_d.out, std::regex(R"(\binf\b)")))
      << four_d.out;

  // The same rounds in JSON: one entry per round, its points in proposal
  // order, together the run's proposals.
  const CommandRun json = Adse(replay + " --json");
  ASSERT_EQ(json.exit_code, 0) << json.out;
  const nlohmann::json out = nlohmann::json::parse(json.out);
  for (const char* name : {"agent", "random"}) {
    SCOPED_TRACE(name);
    const nlohmann::json& runs = out["strategies"][name]["runs"];
    ASSERT_EQ(runs.size(), 2u);
    for (const nlohmann::json& run : runs) {
      nlohmann::json points = nlohmann::json::array();
      for (const nlohmann::json& iteration : run["iterations"]) {
        for (const nlohmann::json& point : iteration["points"]) {
          points.push_back(point);
        }
        EXPECT_FALSE(iteration["rationale"].get<std::string>().empty());
      }
      EXPECT_EQ(points, run["proposals"]);
      EXPECT_EQ(points.size(), 4u);
    }
  }
}

TEST(CliRunTest, RunRejectsBadFlagsAndUnsupportedSettingsByName) {
  const CommandRun isolation =
      Adse("run " + SmallScenarioPath() + " --isolation containers");
  EXPECT_EQ(isolation.exit_code, 2) << isolation.out;
  EXPECT_NE(isolation.out.find("--isolation"), std::string::npos)
      << isolation.out;
  // A file where the campaign folder, or a folder above it, goes.
  const fs::path file = adse::testing::TestScratch() / "adse_cli_run_file";
  std::ofstream(file) << "not a folder\n";
  for (const fs::path& out : {file, file / "campaign"}) {
    const CommandRun run =
        Adse("run " + SmallScenarioPath() + " -o " + out.string());
    EXPECT_EQ(run.exit_code, 2) << run.out;
    EXPECT_NE(run.out.find("-o " + out.string() + ": " + file.string() +
                           " is a file, not a folder"),
              std::string::npos)
        << run.out;
  }
  EXPECT_EQ(ReadText(file.string()), "not a folder\n");
}

TEST(CliRunTest, RunWithReplicasRunsEachPointOncePerReplicaAndShowsTheSpread) {
  const std::string file = WriteScenario(
      "replicas", ReadText(SmallScenarioPath()) + "harness: {replicas: 2}\n");
  const fs::path out = adse::testing::TestScratch() / "adse_cli_replicas";
  fs::remove_all(out);
  const CommandRun run =
      Adse("run " + file + " --budget 1 --no-cache -o " + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  size_t runs = 0;
  for (const auto& e : fs::directory_iterator(out / "runs")) {
    runs += e.path().extension() == ".h5";
  }
  EXPECT_EQ(runs, 2u) << "one run file per replica";
  const std::string md = ReadText((out / "report.md").string());
  EXPECT_NE(md.find("## Replicas"), std::string::npos) << md;
  EXPECT_NE(md.find("| 2 runs |"), std::string::npos) << md;
  // adse status counts runs: both replicas are done, none pending.
  const CommandRun status = Adse("status " + out.string() + " --json");
  ASSERT_EQ(status.exit_code, 0) << status.out;
  EXPECT_NE(status.out.find("\"done\": 2"), std::string::npos) << status.out;
  EXPECT_NE(status.out.find("\"pending\": 0"), std::string::npos) << status.out;
  EXPECT_NE(status.out.find("\"total\": 2"), std::string::npos) << status.out;
}

TEST(CliRunTest, ARunNeverWritesIntoAFolderThatIsNoCampaigns) {
  const fs::path dir = adse::testing::TestScratch() / "adse_cli_user_folder";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "report.md") << "my notes\n";
  const std::string run = "run " + SmallScenarioPath() + " --budget 1 -q -o ";
  const CommandRun into = Adse(run + dir.string());
  EXPECT_EQ(into.exit_code, 2) << into.out;
  EXPECT_NE(
      into.out.find("is no campaign's folder (no campaign.h5) and holds " +
                    (dir / "report.md").string()),
      std::string::npos)
      << into.out;
  // A log the shell opened for the run is no obstacle.
  fs::create_directories(dir / "logged");
  std::ofstream(dir / "logged" / "run.log") << "";
  EXPECT_EQ(Adse(run + (dir / "logged").string()).exit_code, 0);
  EXPECT_EQ(ReadText((dir / "logged" / "run.log").string()), "");
  // Nor into the current folder, unless it is a campaign's.
  const fs::path cwd = fs::current_path();
  fs::current_path(dir);
  const CommandRun here = Adse(run + ".");
  fs::current_path(cwd);
  EXPECT_EQ(here.exit_code, 2) << here.out;
  EXPECT_EQ(ReadText((dir / "report.md").string()), "my notes\n");
  EXPECT_FALSE(fs::exists(dir / "campaign.h5"));
  fs::remove(dir / "report.md");
  ASSERT_EQ(Adse(run + (dir / "c").string()).exit_code, 0);
  fs::current_path(dir / "c");
  const CommandRun resumed = Adse(run + ".");
  fs::current_path(cwd);
  EXPECT_EQ(resumed.exit_code, 0) << resumed.out;
  fs::remove_all(dir);
}

TEST(CliRunTest, ADamagedRunFileIsRunAgainWhenTheCampaignResumes) {
  const fs::path out = adse::testing::TestScratch() / "adse_cli_damaged_run";
  fs::remove_all(out);
  const std::string run = "run " + SmallScenarioPath() +
                          " --budget 1 --strategy exhaustive --no-cache -o " +
                          out.string();
  ASSERT_EQ(Adse(run).exit_code, 0);
  fs::path file;
  for (const auto& e : fs::directory_iterator(out / "runs")) {
    if (e.path().extension() == ".h5") file = e.path();
  }
  ASSERT_FALSE(file.empty());
  // Cut in half: its report.json, left by the worker, still says it ran.
  const std::string whole = ReadText(file.string());
  std::ofstream(file, std::ios::binary | std::ios::trunc)
      << whole.substr(0, whole.size() / 2);
  const CommandRun resumed = Adse(run);
  EXPECT_EQ(resumed.exit_code, 0) << resumed.out;
  EXPECT_NE(resumed.out.find(file.string() + " is unusable"), std::string::npos)
      << resumed.out;
  EXPECT_NE(resumed.out.find("1 simulated"), std::string::npos) << resumed.out;
  EXPECT_EQ(ReadText(file.string()).size(), whole.size());
  fs::remove_all(out);
}

TEST(CliRunTest, ARunIntoAnotherScenariosFolderWarnsAndStatusCountsItsOwnRuns) {
  const fs::path out = adse::testing::TestScratch() / "adse_cli_two_scenarios";
  fs::remove_all(out);
  const CommandRun first = Adse("run " + SmallScenarioPath() +
                                " --budget 1 --no-cache -o " + out.string());
  ASSERT_EQ(first.exit_code, 0) << first.out;
  EXPECT_EQ(first.out.find("warning"), std::string::npos) << first.out;
  // Another scenario (another name, another first point) into the same
  // folder.
  const std::string other = WriteScenario(
      "other_name", Replaced(Replaced(ReadText(SmallScenarioPath()),
                                      "values: [1, 4, 16]", "values: [16]"),
                             "name: robotaxi-small", "name: other-small"));
  const CommandRun second =
      Adse("run " + other + " --budget 1 --no-cache -o " + out.string());
  ASSERT_EQ(second.exit_code, 0) << second.out;
  EXPECT_NE(second.out.find("warning: " + out.string() +
                            " holds the campaign of another scenario, "
                            "'robotaxi-small'"),
            std::string::npos)
      << second.out;
  const CommandRun status = Adse("status " + out.string());
  ASSERT_EQ(status.exit_code, 0) << status.out;
  EXPECT_NE(status.out.find("runs: 1 done, 0 failed, 0 running, 0 pending "
                            "(of 1)"),
            std::string::npos)
      << status.out;
  EXPECT_NE(status.out.find("runs/ also holds 1 run file(s) that no "
                            "evaluation of this campaign uses"),
            std::string::npos)
      << status.out;
  EXPECT_NE(status.out.find("answer (campaign.h5):"), std::string::npos)
      << status.out;
  // The same scenario with a smaller budget than the folder's views hold.
  const std::string wide =
      "run " + other + " --budget 2 --no-cache -o " + out.string();
  ASSERT_EQ(Adse(wide).exit_code, 0);
  // Confirm runs come on top of the budget: two evaluations are no more
  // than one with one confirm run.
  const CommandRun confirming = Adse("run " + other +
                                     " --budget 1 --confirm-runs 1 --no-cache "
                                     "-o " +
                                     out.string());
  ASSERT_EQ(confirming.exit_code, 0) << confirming.out;
  EXPECT_EQ(confirming.out.find("warning:"), std::string::npos)
      << confirming.out;
  const CommandRun wider = Adse(wide);
  ASSERT_EQ(wider.exit_code, 0) << wider.out;
  const CommandRun smaller =
      Adse("run " + other + " --budget 1 --no-cache -o " + out.string());
  ASSERT_EQ(smaller.exit_code, 0) << smaller.out;
  EXPECT_NE(smaller.out.find("warning: " + out.string() +
                             " holds 2 evaluations, more than this "
                             "campaign's budget of 1"),
            std::string::npos)
      << smaller.out;
}

TEST(CliRunTest, AnInfeasiblePointsProgressLineNamesTheConstraintItBroke) {
  // No run meets a 1 ms latency; no early stop ends a run for it either,
  // so the run reaches the goal and is still infeasible. One point,
  // generous enough to reach the goal.
  const std::string file = WriteScenario(
      "latency_bound",
      Replaced(Replaced(ReadText(SmallScenarioPath()),
                        "constraints: [nav_time_s <= 60, ctrl_rate_hz >= 1, "
                        "completed]",
                        "constraints: [nav_time_s <= 60, e2e_latency_p50_s <= "
                        "0.001, completed]"),
               "values: [1, 4, 16]", "values: [16]"));
  const fs::path out = adse::testing::TestScratch() / "adse_cli_latency_bound";
  fs::remove_all(out);
  const CommandRun run =
      Adse("run " + file + " --budget 1 --no-cache -o " + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find(": goal_reached, nav "), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("infeasible: e2e_latency_p50_s <= 0.001 (simulated"),
            std::string::npos)
      << run.out;
}

TEST(CliRunTest,
     AnLlmCampaignWithItsServerDownSaysSoAndFinishesWithTheBuiltInAgent) {
  // Port 9 (discard): nothing listens there.
  const std::string file = WriteScenario(
      "llm_down", ReadText(SmallScenarioPath()) +
                      "llm: {endpoint: \"http://127.0.0.1:9\", retries: 0}\n");
  const std::string out =
      (adse::testing::TestScratch() / "adse_cli_llm_down").string();
  fs::remove_all(out);
  const CommandRun run =
      Adse("run " + file + " --strategy llm --budget 1 -o " + out);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("fallback to the built-in agent"), std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("cannot reach http://127.0.0.1:9/api/chat"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("ollama serve"), std::string::npos) << run.out;
  EXPECT_TRUE(fs::exists(out + "/llm/exchanges.jsonl"));
}

// The front as printed: the "Pareto front over" line and its indented rows.
std::string FrontSection(const std::string& out) {
  size_t at = out.find("Pareto front over");
  if (at == std::string::npos) return "";
  std::string section;
  do {
    const size_t end = out.find('\n', at);
    section += out.substr(at, end - at) + "\n";
    at = end + 1;
  } while (at < out.size() && out.compare(at, 2, "  ") == 0);
  return section;
}

TEST(CliRunTest, AnOldCampaignsNavTimeReadsTheSameInItsAnalysisAndItsReplay) {
  // The robotaxi recording's index predates the nav time's rounding
  // (89.84999999999704 s stored). Its analysis keeps every row as the
  // index recorded it (no run file is here) and its replay reads the
  // index: both say 89.85 s, as a new run would.
  const fs::path dir = adse::testing::TestScratch() / "adse_cli_old_index";
  fs::remove_all(dir);
  fs::create_directories(dir / "runs");
  fs::copy_file(std::string(ADSE_SOURCE_DIR) +
                    "/tests/data/robotaxi_exhaustive/campaign.h5",
                dir / "campaign.h5");
  const CommandRun analyze = Adse("analyze " + dir.string());
  EXPECT_EQ(analyze.exit_code, 2) << analyze.out;  // no run file to read
  EXPECT_NE(analyze.out.find("280 kept as campaign.h5 recorded them"),
            std::string::npos)
      << analyze.out;
  const nlohmann::json summary = nlohmann::json::parse(
      ReadText((dir / "analysis" / "v1" / "summary.json").string()));
  const CommandRun replay =
      Adse("explore --replay " + dir.string() + " --strategy random --json");
  ASSERT_EQ(replay.exit_code, 0) << replay.out;
  const nlohmann::json replayed = nlohmann::json::parse(replay.out);
  for (const nlohmann::json* answer : {&summary, &replayed}) {
    const nlohmann::json& cheapest = (*answer)["answer"]["cheapest_feasible"];
    EXPECT_EQ(cheapest["metrics"]["nav_time_s"].get<double>(), 89.85)
        << cheapest.dump();
  }
}

TEST(CliRunTest, AnalyzeOfACampaignFromAnotherFolderGivesTheSameAnswerAsRun) {
  const fs::path out = adse::testing::TestScratch() / "adse_cli_one_answer";
  fs::remove_all(out);
  const CommandRun run = Adse("run " + SmallScenarioPath() +
                              " --budget 7 --no-cache -q -o " + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  ASSERT_NE(run.out.find("cheapest feasible"), std::string::npos) << run.out;
  ASSERT_FALSE(FrontSection(run.out).empty()) << run.out;
  // From "/", the scenario's relative paths do not resolve; the stored
  // scenario still decides objectives and constraints.
  const fs::path here = fs::current_path();
  fs::current_path("/");
  const CommandRun analyze = Adse("analyze " + out.string());
  fs::current_path(here);
  ASSERT_EQ(analyze.exit_code, 0) << analyze.out;
  EXPECT_EQ(FrontSection(analyze.out), FrontSection(run.out)) << analyze.out;
  const size_t cheapest = run.out.find("cheapest feasible");
  const std::string cheapest_line =
      run.out.substr(cheapest, run.out.find('\n', cheapest) - cheapest);
  EXPECT_NE(analyze.out.find(cheapest_line), std::string::npos)
      << cheapest_line << "\n"
      << analyze.out;
  // adse status tells the same answer, from the same front.
  const CommandRun status = Adse("status " + out.string());
  ASSERT_EQ(status.exit_code, 0) << status.out;
  EXPECT_NE(status.out.find(cheapest_line), std::string::npos) << status.out;
  EXPECT_EQ(FrontSection(status.out), FrontSection(run.out)) << status.out;
  EXPECT_TRUE(fs::exists(out / "analysis" / "v1" / "pareto.png"));
  EXPECT_TRUE(fs::exists(out / "analysis" / "v1" / "report.md"));
  EXPECT_FALSE(fs::exists(out / "runs" / "analysis"));
  // How the runs were got, as the campaign said it.
  const std::regex got("[0-9]+ simulated, [0-9]+ reused");
  std::smatch campaign_got, analysis_got;
  const std::string campaign_md = ReadText((out / "report.md").string());
  const std::string analysis_md =
      ReadText((out / "analysis" / "v1" / "report.md").string());
  ASSERT_TRUE(std::regex_search(campaign_md, campaign_got, got));
  ASSERT_TRUE(std::regex_search(analysis_md, analysis_got, got));
  EXPECT_EQ(campaign_got.str(), "7 simulated, 0 reused");
  EXPECT_EQ(analysis_got.str(), campaign_got.str());
  ASSERT_EQ(Adse("analyze " + out.string() +
                 " --threshold frequency_bound_fraction=0.8")
                .exit_code,
            0);
  const CommandRun diff =
      Adse("analyze --diff " + (out / "analysis" / "v1").string() + " " +
           (out / "analysis" / "v2").string());
  EXPECT_EQ(diff.exit_code, 0) << diff.out;
  EXPECT_NE(diff.out.find("of 7 points changed"), std::string::npos)
      << diff.out;
  // Points read as everywhere else, one line each, no JSON.
  EXPECT_TRUE(
      std::regex_search(diff.out, std::regex("\n  cores=[0-9]+,freq_ghz=[0-9.]+"
                                             ",lidar_hz=[0-9]+: ")) ||
      diff.out.find("0 of 7 points changed") != std::string::npos)
      << diff.out;
  EXPECT_EQ(diff.out.find("{\""), std::string::npos) << diff.out;
  // A campaign's runs/ folder stands for the campaign, as in analyze.
  const CommandRun same =
      Adse("analyze --diff " + (out / "runs").string() + "/ " + out.string());
  EXPECT_EQ(same.exit_code, 0) << same.out;
  EXPECT_NE(same.out.find("0 of 7 points changed"), std::string::npos)
      << same.out;
  // Its runs/ folder stands for the campaign: the same answer, written
  // beside the others, nothing among the run files.
  const CommandRun runs = Adse("analyze " + (out / "runs").string() + "/");
  ASSERT_EQ(runs.exit_code, 0) << runs.out;
  EXPECT_EQ(FrontSection(runs.out), FrontSection(run.out)) << runs.out;
  EXPECT_TRUE(fs::exists(out / "analysis" / "v3" / "report.md"));
  EXPECT_FALSE(fs::exists(out / "runs" / "analysis"));

  // The analysis says how the campaign ended, as its own views do: its
  // budget (the run's --budget 7, not the scenario's 12), a stop, or that
  // nothing records whether it finished.
  auto analysed = [&](const std::string& version) {
    return nlohmann::json::parse(
        ReadText((out / "analysis" / version / "summary.json").string()));
  };
  EXPECT_EQ(analysed("v3")["budget"], 7);
  EXPECT_TRUE(analysed("v3")["complete"].get<bool>());
  nlohmann::json own =
      nlohmann::json::parse(ReadText((out / "summary.json").string()));
  own["interrupted_by_signal"] = 2;
  own["complete"] = false;
  std::ofstream(out / "summary.json") << own.dump(2);
  ASSERT_EQ(Adse("analyze " + out.string()).exit_code, 0);
  EXPECT_FALSE(analysed("v4")["complete"].get<bool>());
  EXPECT_NE(ReadText((out / "analysis" / "v4" / "report.md").string())
                .find("stopped early by signal 2"),
            std::string::npos);
  fs::remove(out / "summary.json");
  ASSERT_EQ(Adse("analyze " + out.string()).exit_code, 0);
  EXPECT_FALSE(analysed("v5")["complete"].get<bool>());
  EXPECT_NE(ReadText((out / "analysis" / "v5" / "report.md").string())
                .find("whether the campaign finished is not recorded"),
            std::string::npos);
  // Each version's pictures are named where they are, not where they were
  // written.
  for (const auto& e :
       fs::directory_iterator(out / "analysis" / "v5" / "reports")) {
    const nlohmann::json report =
        nlohmann::json::parse(ReadText(e.path().string()));
    EXPECT_EQ(report["images"]["trajectory"].get<std::string>().rfind(
                  (out / "analysis" / "v5" / "images").string(), 0),
              0u)
        << report["images"];
  }
  for (const auto& e : fs::directory_iterator(out / "analysis")) {
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos);
  }

  // Thresholds: decimal numbers in range, a window that holds something;
  // those given are recorded in each report.
  for (const char* bad : {"min_messages=1.5", "min_messages=0x10",
                          "start_s=50 --threshold end_s=20"}) {
    const CommandRun refused =
        Adse("analyze " + out.string() + " --threshold " + bad);
    EXPECT_EQ(refused.exit_code, 2) << bad << "\n" << refused.out;
  }
  EXPECT_FALSE(fs::exists(out / "analysis" / "v6"));
  const CommandRun late =
      Adse("analyze " + out.string() + " --threshold start_s=100000");
  ASSERT_EQ(late.exit_code, 0) << late.out;
  EXPECT_NE(late.out.find("warning: 7 runs of 7 end before the diagnosis' "
                          "window starts (--threshold start_s=100000)"),
            std::string::npos)
      << late.out;
  for (const auto& e :
       fs::directory_iterator(out / "analysis" / "v6" / "reports")) {
    const nlohmann::json report =
        nlohmann::json::parse(ReadText(e.path().string()));
    EXPECT_EQ(report["diagnosis"]["thresholds"]["start_s"], 100000.0);
    EXPECT_EQ(report["diagnosis"]["window_s"], 0.0);
    EXPECT_TRUE(report["findings"].empty());
  }

  // adse status takes the campaign's runs/ for the campaign, as analyze
  // does, and says a folder that is not there is not there.
  const CommandRun of_runs = Adse("status " + (out / "runs").string());
  ASSERT_EQ(of_runs.exit_code, 0) << of_runs.out;
  EXPECT_EQ(FrontSection(of_runs.out), FrontSection(run.out)) << of_runs.out;
  const CommandRun nowhere = Adse("status " + (out / "nowhere").string());
  EXPECT_EQ(nowhere.exit_code, 2) << nowhere.out;
  EXPECT_NE(nowhere.out.find("nowhere: no such folder"), std::string::npos)
      << nowhere.out;
  // A campaign.h5 cut short makes the views unreadable, not complete.
  {
    const std::string index = ReadText((out / "campaign.h5").string());
    std::ofstream(out / "campaign.h5", std::ios::binary | std::ios::trunc)
        << index.substr(0, index.size() / 2);
  }
  const CommandRun damaged = Adse("status " + out.string());
  EXPECT_EQ(damaged.exit_code, 0) << damaged.out;
  EXPECT_NE(damaged.out.find("views: unreadable in"), std::string::npos)
      << damaged.out;
  EXPECT_NE(damaged.out.find("campaign.h5"), std::string::npos) << damaged.out;
  EXPECT_EQ(damaged.out.find("views: complete"), std::string::npos)
      << damaged.out;
}

TEST(CliRunTest, AnalyzeOfACampaignWithCasesFoldsEveryCaseAsRunDid) {
  // The small scenario at one point, with two destinations.
  std::string text = ReadText(SmallScenarioPath());
  const std::string goal = "  goal: {x: 10.0, y: 29.75}\n";
  const size_t at = text.find(goal);
  ASSERT_NE(at, std::string::npos);
  text.insert(at + goal.size(),
              "  cases:\n"
              "    - {name: across, goal: {x: 10.0, y: 29.75}}\n"
              "    - {name: along, goal: {x: 40.0, y: -1.75}}\n");
  const std::string scenario = WriteScenario("cases", text);
  const fs::path out = adse::testing::TestScratch() / "adse_cli_cases";
  fs::remove_all(out);
  const CommandRun run = Adse(
      "run " + scenario +
      " --budget 1 --strategy exhaustive -q --no-cache -o " + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const CommandRun analyze = Adse("analyze " + out.string());
  ASSERT_EQ(analyze.exit_code, 0) << analyze.out;
  EXPECT_NE(analyze.out.find("2 runs analysed"), std::string::npos)
      << analyze.out;
  EXPECT_EQ(FrontSection(analyze.out), FrontSection(run.out)) << analyze.out;
  EXPECT_NE(FrontSection(analyze.out).find("(1 of 1 evaluation"),
            std::string::npos)
      << analyze.out;
}

TEST(CliRunTest, AnalyzeWithAReferenceDrawsTheStudysFigureOrRefusesClearly) {
  const fs::path out = adse::testing::TestScratch() / "adse_cli_study_figure";
  fs::remove_all(out);
  ASSERT_EQ(
      Adse("run " + SmallScenarioPath() + " --budget 3 -q -o " + out.string())
          .exit_code,
      0);
  // The reference: the same scenario's exhaustive sweep.
  const fs::path recording =
      adse::testing::TestScratch() / "adse_cli_study_ref";
  fs::remove_all(recording);
  ASSERT_EQ(Adse("run " + SmallScenarioPath() +
                 " --strategy exhaustive -q -o " + recording.string())
                .exit_code,
            0);
  const CommandRun ok =
      Adse("analyze " + out.string() + " --reference " + recording.string());
  ASSERT_EQ(ok.exit_code, 0) << ok.out;
  EXPECT_NE(ok.out.find("in the study's form over"), std::string::npos)
      << ok.out;
  EXPECT_TRUE(fs::exists(out / "analysis" / "v1" / "pareto.png"));
  // Another scenario's study: exit 2 naming both, nothing written.
  const CommandRun other =
      Adse("analyze " + out.string() + " --reference " +
           std::string(ADSE_SOURCE_DIR) + "/tests/data/reference_study");
  EXPECT_EQ(other.exit_code, 2) << other.out;
  EXPECT_NE(other.out.find("of scenario 'reference-study', not of "
                           "'robotaxi-small'"),
            std::string::npos)
      << other.out;
  EXPECT_FALSE(fs::exists(out / "analysis" / "v2"));
  // A reference that is no campaign: exit 2, named, nothing written.
  const CommandRun missing =
      Adse("analyze " + out.string() + " --reference /nonexistent/ref");
  EXPECT_EQ(missing.exit_code, 2) << missing.out;
  EXPECT_NE(missing.out.find("--reference"), std::string::npos) << missing.out;
  EXPECT_NE(missing.out.find("/nonexistent/ref"), std::string::npos)
      << missing.out;
  EXPECT_FALSE(fs::exists(out / "analysis" / "v2"));
  // The figure is a campaign's: a run file with --reference is refused.
  const CommandRun file = Adse("analyze " + (out / "campaign.h5").string() +
                               " --reference " + recording.string());
  EXPECT_EQ(file.exit_code, 2) << file.out;
  EXPECT_NE(file.out.find("not a campaign folder"), std::string::npos)
      << file.out;
}

TEST(CliRunTest, WorkersRunTheCampaignsOwnAdseWhenItsFileIsReplaced) {
  // A copy of adse starts a two-point campaign, one worker; once it has
  // started, its file is replaced by another program (as a rebuild does).
  // The second point's worker still runs the campaign's adse; by the
  // file's path it ran the other program and failed.
  const fs::path dir = adse::testing::TestScratch() / "adse_cli_replaced";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path copy = dir / "adse";
  fs::copy_file(std::string(ADSE_BINARY_DIR) + "/bin/adse", copy);
  const fs::path out = dir / "campaign";
  const std::string script =
      copy.string() + " run " + SmallScenarioPath() +
      " --strategy exhaustive --budget 2 --workers 1 --no-cache -o " +
      out.string() + " > " + (dir / "run.log").string() +
      " 2>&1 & pid=$!; "
      "while [ ! -d " +
      out.string() +
      " ]; do sleep 0.05; done; "
      "rm " +
      copy.string() + "; printf '#!/bin/sh\\nexit 3\\n' > " + copy.string() +
      "; chmod +x " + copy.string() + "; wait $pid";
  const int status = std::system(script.c_str());
  const std::string log = ReadText((dir / "run.log").string());
  ASSERT_TRUE(WIFEXITED(status)) << log;
  EXPECT_EQ(WEXITSTATUS(status), 0) << log;
  size_t runs = 0;
  for (const auto& e : fs::directory_iterator(out / "runs")) {
    runs += e.path().extension() == ".h5";
  }
  EXPECT_EQ(runs, 2u) << log;
  const CommandRun done = Adse("status " + out.string() + " --json");
  EXPECT_NE(done.out.find("\"done\": 2"), std::string::npos) << done.out;
}

TEST(CliRunTest, WorkerRefusesAScenarioThatChangedUnderItsCampaign) {
  const std::string out =
      (adse::testing::TestScratch() / "adse_cli_worker.h5").string();
  const CommandRun run = Adse("worker " + SmallScenarioPath() +
                              " --point cores=4,freq_ghz=2.1,lidar_hz=14 -o " +
                              out + " --expect-key " + std::string(64, '0'));
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_NE(run.out.find("changed since the campaign started"),
            std::string::npos)
      << run.out;
  EXPECT_FALSE(fs::exists(out));
}

TEST(CliRunTest, WorkerLeavesItsAnalysisBesideTheRunFileWhenAsked) {
  const fs::path dir = adse::testing::TestScratch() / "adse_cli_worker_report";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string out = (dir / "run.h5").string();
  const std::string report = (dir / "run.report.json").string();
  const CommandRun run = Adse("worker " + SmallScenarioPath() +
                              " --point cores=4,freq_ghz=2.1,lidar_hz=14 -o " +
                              out + " --report " + report);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  ASSERT_TRUE(fs::exists(out));
  std::ifstream in(report);
  ASSERT_TRUE(in) << "no " << report;
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j.value("content_key", "").size(), 64u);
  ASSERT_TRUE(j.contains("metrics"));
  EXPECT_TRUE(j["metrics"].contains("nav_time_s"));
  EXPECT_TRUE(j["metrics"].contains("deviation_score"));
  EXPECT_TRUE(j.contains("findings"));
}

}  // namespace
