// The adse binary as a user runs it: exit codes, messages that cite the
// scenario's lines, and the world check's output folder.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

#include "tests/harness/testing/adse_command.h"

namespace {

namespace fs = std::filesystem;

using adse::testing::Adse;
using adse::testing::CommandRun;

std::string Example() {
  return std::string(ADSE_SOURCE_DIR) + "/scenarios/robotaxi_parking_lot.yaml";
}

// A copy of the robotaxi example with one line replaced.
// Writes scenario text to the temporary folder as adse_cli_<name>.yaml,
// with the bundled calibration and profile beside it (the examples name
// them relative to themselves).
std::string WriteScenario(const std::string& name, const std::string& text) {
  const fs::path path =
      fs::temp_directory_path() / ("adse_cli_" + name + ".yaml");
  std::ofstream(path) << text;
  for (const char* file : {"calibration/reference.json",
                           "profiles/autoware-2022.12-i9-12900kf.yaml"}) {
    const fs::path to = fs::temp_directory_path() / file;
    fs::create_directories(to.parent_path());
    fs::copy_file(std::string(ADSE_SOURCE_DIR) + "/scenarios/" + file, to,
                  fs::copy_options::overwrite_existing);
  }
  return path.string();
}

// The text of the file at `path`.
std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  return std::string((std::istreambuf_iterator<char>(in)),
                     std::istreambuf_iterator<char>());
}

// `text` with its first `from` replaced by `to`; a failure when it has none.
std::string Replaced(std::string text, const std::string& from,
                     const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

std::string Variant(const std::string& name, const std::string& from,
                    const std::string& to) {
  return WriteScenario(name, Replaced(ReadText(Example()), from, to));
}

TEST(CliTest, ValidateReportsTheRobotaxiSpaceOf280Points) {
  const CommandRun run = Adse("validate --quiet " + Example());
  EXPECT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(
      run.out.find(
          "design space: 280 points (cores 28 x freq_ghz 5 x lidar_hz 2)"),
      std::string::npos)
      << run.out;
}

TEST(CliTest, ValidatePrintsAReloadableNormalisedSpec) {
  const CommandRun run =
      Adse("validate --no-world " + Example() + " 2>/dev/null");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const fs::path copy = fs::temp_directory_path() / "adse_cli_normalised.yaml";
  std::ofstream(copy) << run.out;
  const CommandRun again = Adse("validate --quiet --no-world " + copy.string());
  EXPECT_EQ(again.exit_code, 0) << again.out;
  EXPECT_NE(again.out.find("280 points"), std::string::npos);
}

TEST(CliTest, StartOffTheRoadIsReportedAtItsLineWithExitCode2) {
  const std::string file = Variant("offroad", "start: {x: 20.0, y: -1.75}",
                                   "start: {x: 20.0, y: 6.0}");
  const CommandRun run = Adse("validate -q " + file);
  EXPECT_EQ(run.exit_code, 2) << run.out;
  // The start is on line 17 of the example.
  EXPECT_TRUE(std::regex_search(
      run.out,
      std::regex("adse_cli_offroad\\.yaml:17:[0-9]+: error: task\\.start")))
      << run.out;
  EXPECT_NE(run.out.find("off the road network"), std::string::npos) << run.out;
}

TEST(CliTest, UnknownFlowEdgeIsReportedAtItsLine) {
  const std::string file = Variant("flow", "from: W4_E4", "from: E9_W9");
  const CommandRun run = Adse("validate -q " + file);
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_NE(run.out.find("world.traffic.flows[0].from: no edge 'E9_W9'"),
            std::string::npos)
      << run.out;
  EXPECT_TRUE(
      std::regex_search(run.out, std::regex("adse_cli_flow\\.yaml:11:[0-9]+:")))
      << run.out;
}

// The valet example's task.cases with a case's line replaced, written with
// the profile beside it.
std::string ValetVariant(const std::string& name, const std::string& from,
                         const std::string& to) {
  const std::string text = Replaced(
      ReadText(std::string(ADSE_SOURCE_DIR) + "/scenarios/valet_parking.yaml"),
      from, to);
  const fs::path profile = fs::temp_directory_path() /
                           "profiles/autoware-2022.12-i9-12900kf-valet.yaml";
  fs::create_directories(profile.parent_path());
  fs::copy_file(
      std::string(ADSE_SOURCE_DIR) +
          "/scenarios/profiles/autoware-2022.12-i9-12900kf-valet.yaml",
      profile, fs::copy_options::overwrite_existing);
  return WriteScenario(name, text);
}

TEST(CliTest, AnOccupiedSlotInOneCaseIsReportedAtThatCasesLine) {
  const std::string file = ValetVariant(
      "valet_case", "{name: nose_in, goal: {slot: slot_r1_s4, yaw_deg: 90}}",
      "{name: nose_in, goal: {slot: slot_r1_s3, yaw_deg: 90}}");
  const CommandRun run = Adse("validate -q " + file);
  EXPECT_EQ(run.exit_code, 2) << run.out;
  // The nose_in case is on line 27 of the example.
  EXPECT_TRUE(std::regex_search(
      run.out, std::regex("adse_cli_valet_case\\.yaml:27:[0-9]+: error: "
                          "task\\.goal\\.slot: slot 'slot_r1_s3' is occupied")))
      << run.out;
  EXPECT_NE(run.out.find("checking task.cases[1] ('nose_in')"),
            std::string::npos)
      << run.out;
}

TEST(CliTest, ACommandThatRunsOneCaseNeedsItNamed) {
  const std::string valet =
      std::string(ADSE_SOURCE_DIR) + "/scenarios/valet_parking.yaml";
  for (const std::string& command :
       {"simulate " + valet + " -p cores=8,freq_ghz=3.0",
        "world " + valet + " --no-scan", "profile check " + valet,
        "fidelity " + valet + " --points cores=8,freq_ghz=3.0 --runs 1"}) {
    const CommandRun run = Adse(command);
    EXPECT_EQ(run.exit_code, 2) << command << "\n" << run.out;
    EXPECT_NE(run.out.find("has 2 task.cases (backing_in, nose_in); name the "
                           "one to run"),
              std::string::npos)
        << run.out;
  }
  const CommandRun unknown =
      Adse("simulate " + valet + " -p cores=8,freq_ghz=3.0 --case sideways");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.out.find("no case 'sideways' (its cases: backing_in, "
                             "nose_in)"),
            std::string::npos)
      << unknown.out;
  const CommandRun none = Adse("world " + Example() + " --case nose_in");
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_NE(none.out.find("has no task.cases"), std::string::npos) << none.out;
}

TEST(CliTest, MisspelledKeyGetsADidYouMeanAndNothingIsWritten) {
  const std::string file = Variant("typo", "weather: clear", "wether: clear");
  const fs::path out = fs::temp_directory_path() / "adse_cli_typo_out";
  fs::remove_all(out);
  const CommandRun run =
      Adse("world " + file + " --follow-ideal -o " + out.string());
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_NE(run.out.find("did you mean 'weather'"), std::string::npos)
      << run.out;
  EXPECT_FALSE(fs::exists(out));
}

TEST(CliTest, BadFlagsAndMissingFilesExitWith2) {
  EXPECT_EQ(Adse("validate").exit_code, 2);
  EXPECT_EQ(Adse("world " + Example() + " --save-scans -3").exit_code, 2);
  const CommandRun missing = Adse("validate /nonexistent/scenario.yaml");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.out.find("/nonexistent/scenario.yaml"), std::string::npos)
      << missing.out;
  const CommandRun help = Adse("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("validate"), std::string::npos);
}

TEST(CliTest, WorldFollowIdealReachesTheGoalAndWritesWhatItSaw) {
  const fs::path out = fs::temp_directory_path() / "adse_cli_world_check";
  fs::remove_all(out);
  const CommandRun run =
      Adse("world " + Example() + " --follow-ideal --json --save-scans 50 -o " +
           out.string());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  std::ifstream summary_file(out / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_TRUE(summary["reached_goal"].get<bool>());
  EXPECT_EQ(summary["collisions"].get<int>(), 0);
  // Within 1 m (issue 17); the lot's right-angle corners are cut by about
  // 0.4 m.
  EXPECT_LT(summary["max_lateral_error_m"].get<double>(), 0.5);
  EXPECT_EQ(summary["red_light_wait_s"].get<double>(), 0.0);  // no signals
  // 168 m of path at 30 km/h with four slow corners.
  EXPECT_NEAR(summary["time_s"].get<double>(), 27.0, 6.0);
  // Scans at the scenario's 10 Hz.
  EXPECT_NEAR(summary["scans"].get<int>(), summary["time_s"].get<double>() * 10,
              2);
  EXPECT_TRUE(fs::exists(out / "trajectory.csv"));
  EXPECT_TRUE(fs::exists(out / "ideal_path.csv"));
  EXPECT_TRUE(fs::exists(out / "scans" / "scan_00000.pcd"));
  EXPECT_TRUE(fs::exists(out / "scans" / "scan_00050.pcd"));
  EXPECT_FALSE(fs::exists(out / "scans" / "scan_00010.pcd"));
}

std::string Small() {
  return std::string(ADSE_SOURCE_DIR) + "/scenarios/robotaxi_small.yaml";
}

TEST(CliTest, SimulateWritesARunFileThatPassesTheSchemaCheck) {
  const fs::path out = fs::temp_directory_path() / "adse_cli_simulate.h5";
  fs::remove(out);
  const CommandRun run =
      Adse("simulate " + Small() +
           " --point cores=16,freq_ghz=2.1,lidar_hz=7 --json -q -o " +
           out.string() + " 2>/dev/null");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const nlohmann::json doc = nlohmann::json::parse(run.out);
  EXPECT_EQ(doc["termination_reason"], "goal_reached");
  EXPECT_EQ(doc["metrics"]["completed"].get<double>(), 1.0);
  EXPECT_NEAR(doc["metrics"]["hardware_cost"].get<double>(), 16 * 2.1, 1e-9);
  EXPECT_GT(doc["timing_s"]["simulated"].get<double>(), 10.0);
  ASSERT_TRUE(fs::exists(out));
  const CommandRun check = Adse("schema check " + out.string());
  EXPECT_EQ(check.exit_code, 0) << check.out;
  EXPECT_NE(check.out.find(": ok"), std::string::npos) << check.out;
}

TEST(CliTest, SimulateRejectsAPointOutsideTheSpace) {
  const CommandRun run =
      Adse("simulate " + Small() + " --point cores=3,freq_ghz=2.1,lidar_hz=7");
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_NE(run.out.find("cores"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("1, 4, 16"), std::string::npos) << run.out;
  const CommandRun unknown =
      Adse("simulate " + Small() + " --point cores=4,freq_ghz=2.1,lidar=7");
  EXPECT_EQ(unknown.exit_code, 2) << unknown.out;
  EXPECT_NE(unknown.out.find("lidar"), std::string::npos) << unknown.out;
}

TEST(CliTest, SchemaCheckRejectsAFileThatIsNotARunFile) {
  const fs::path bogus = fs::temp_directory_path() / "adse_cli_bogus.h5";
  std::ofstream(bogus) << "not hdf5\n";
  const CommandRun run = Adse("schema check " + bogus.string());
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_NE(run.out.find("adse_cli_bogus.h5"), std::string::npos) << run.out;
}

TEST(CliTest, AnalyzeReanalysesAFolderSkipsBrokenFilesAndDiffsVersions) {
  const fs::path dir = fs::temp_directory_path() / "adse_cli_analyze";
  fs::remove_all(dir);
  fs::create_directories(dir / "runs");
  const CommandRun sim =
      Adse("simulate " + Small() +
           " --point cores=16,freq_ghz=2.1,lidar_hz=7 -q -o " +
           (dir / "runs" / "a.h5").string());
  ASSERT_EQ(sim.exit_code, 0) << sim.out;
  std::ofstream(dir / "runs" / "broken.h5") << "truncated";
  const CommandRun first = Adse("analyze " + dir.string());
  EXPECT_EQ(first.exit_code, 2) << first.out;  // one file could not be read
  EXPECT_NE(first.out.find("skipped " + (dir / "runs" / "broken.h5").string()),
            std::string::npos)
      << first.out;
  EXPECT_NE(first.out.find("1 runs analysed"), std::string::npos) << first.out;
  ASSERT_TRUE(fs::exists(dir / "analysis" / "v1" / "summary.json"));
  EXPECT_TRUE(fs::exists(dir / "analysis" / "v1" / "pareto.png"));
  EXPECT_TRUE(fs::exists(dir / "analysis" / "v1" / "report.md"));
  // Per-run reports and pictures go into the version, never beside the runs.
  int reports = 0;
  for (const auto& entry :
       fs::directory_iterator(dir / "analysis" / "v1" / "reports")) {
    ++reports;
    const std::string key = entry.path().stem().string();
    EXPECT_TRUE(fs::exists(dir / "analysis" / "v1" / "images" / key /
                           "trajectory.png"));
  }
  EXPECT_EQ(reports, 1);
  EXPECT_FALSE(fs::exists(dir / "runs" / "a.analysis"));
  // Raw data is never rewritten; a second analysis is a new version.
  const auto raw_time = fs::last_write_time(dir / "runs" / "a.h5");
  Adse("analyze " + dir.string() + " --threshold frequency_bound_fraction=0.5");
  EXPECT_EQ(fs::last_write_time(dir / "runs" / "a.h5"), raw_time);
  ASSERT_TRUE(fs::exists(dir / "analysis" / "v2" / "summary.json"));
  const CommandRun diff =
      Adse("analyze --diff " + (dir / "analysis" / "v1").string() + " " +
           (dir / "analysis" / "v2").string());
  EXPECT_EQ(diff.exit_code, 0) << diff.out;
  EXPECT_NE(diff.out.find("0 of 1 points changed"), std::string::npos)
      << diff.out;
  const CommandRun bad =
      Adse("analyze " + dir.string() + " --threshold nonsense=1");
  EXPECT_EQ(bad.exit_code, 2) << bad.out;
  EXPECT_NE(bad.out.find("nonsense"), std::string::npos) << bad.out;
}

TEST(CliTest, AnalyzeOneRunPrintsDeviationAndDiagnosis) {
  const fs::path run = fs::temp_directory_path() / "adse_cli_analyze_one.h5";
  fs::remove_all(fs::temp_directory_path() / "adse_cli_analyze_one.analysis");
  ASSERT_EQ(
      Adse("simulate " + Small() +
           " --point cores=1,freq_ghz=1.0,lidar_hz=14 -q -o " + run.string())
          .exit_code,
      0);
  const CommandRun r = Adse("analyze " + run.string());
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("deviation_score"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("diagnosis   cpu_bound"), std::string::npos) << r.out;
}

}  // namespace

namespace {

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
  EXPECT_NE(run.out.find("cheapest feasible   cores=6,freq_ghz=1.5,lidar_hz=7"
                         "  cost 9,"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("| agent |"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("| ga |"), std::string::npos) << run.out;
  const CommandRun bad = Adse("explore --replay /nonexistent/campaign");
  EXPECT_EQ(bad.exit_code, 2) << bad.out;
  EXPECT_NE(bad.out.find("/nonexistent/campaign"), std::string::npos)
      << bad.out;
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
  // the 280 points, against 69 over all four objectives.
  EXPECT_EQ(out["objectives"],
            nlohmann::json::array({"hardware_cost", "nav_time_s"}));
  EXPECT_EQ(out["strategies"]["random"]["true_front_size"], 14) << two.out;
  EXPECT_EQ(four["strategies"]["random"]["true_front_size"], 69) << all.out;

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
      Adse("run " + Small() + " --isolation containers");
  EXPECT_EQ(isolation.exit_code, 2) << isolation.out;
  EXPECT_NE(isolation.out.find("--isolation"), std::string::npos)
      << isolation.out;
}

TEST(CliTest, FidelityComparesTheVirtualPlatformWithARealTimeRun) {
  const std::string file = WriteScenario(
      "fidelity", Replaced(ReadText(std::string(ADSE_SOURCE_DIR) +
                                    "/scenarios/fidelity_small.yaml"),
                           "timeout_s: 30", "timeout_s: 4"));
  const fs::path out = fs::temp_directory_path() / "adse_cli_fidelity";
  fs::remove_all(out);
  const CommandRun run = Adse(
      "fidelity " + file +
      " --points cores=1,freq_ghz=2.1,lidar_hz=7 --runs 1 -o " + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("virtual (run_to_completion) vs real-time (median "
                         "of 1 run; cgroup v"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("ctrl_rate_hz"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("callback p50 latency"), std::string::npos);
  // How each run ended leads (4 s: neither reaches the goal).
  EXPECT_NE(run.out.find("  ended: virtual timeout; real-time timeout\n"),
            std::string::npos)
      << run.out;
  std::ifstream json_in(out / "fidelity.json");
  const nlohmann::json json = nlohmann::json::parse(json_in, nullptr, false);
  ASSERT_FALSE(json.is_discarded());
  EXPECT_EQ(json["points"][0]["ended"]["virtual"], "timeout");
  EXPECT_EQ(json["points"][0]["ended"]["realtime"].size(), 1u);
  for (const char* name : {"fidelity.txt", "fidelity.json", "fidelity-1.png",
                           "runs/1-virtual.h5", "runs/1-realtime-1.h5"}) {
    EXPECT_TRUE(fs::is_regular_file(out / name)) << name;
  }
  // Both dispatches against the same real-time run: a table, a picture and
  // a virtual run file each, and how often each met the targets.
  const fs::path both = out / "both";
  const CommandRun two =
      Adse("fidelity " + file +
           " --points cores=1,freq_ghz=2.1,lidar_hz=7 --runs 1 --dispatch "
           "run_to_completion,processor_sharing -o " +
           both.string());
  ASSERT_EQ(two.exit_code, 0) << two.out;
  EXPECT_NE(two.out.find("virtual (processor_sharing) vs real-time"),
            std::string::npos)
      << two.out;
  EXPECT_NE(two.out.find("dispatch "), std::string::npos) << two.out;
  EXPECT_NE(two.out.find("\nprocessor_sharing "), std::string::npos) << two.out;
  std::ifstream both_in(both / "fidelity.json");
  const nlohmann::json both_json =
      nlohmann::json::parse(both_in, nullptr, false);
  ASSERT_FALSE(both_json.is_discarded());
  ASSERT_EQ(both_json["points"].size(), 2u);
  EXPECT_EQ(both_json["points"][0]["dispatch"], "run_to_completion");
  EXPECT_EQ(both_json["points"][1]["dispatch"], "processor_sharing");
  // On one core the two dispatches are the same model.
  EXPECT_EQ(both_json["points"][0]["metrics"],
            both_json["points"][1]["metrics"]);
  for (const char* name :
       {"fidelity-1-run_to_completion.png", "fidelity-1-processor_sharing.png",
        "runs/1-virtual-run_to_completion.h5",
        "runs/1-virtual-processor_sharing.h5", "runs/1-realtime-1.h5"}) {
    EXPECT_TRUE(fs::is_regular_file(both / name)) << name;
  }
  const CommandRun bad_dispatch =
      Adse("fidelity " + file +
           " --points cores=1,freq_ghz=2.1,lidar_hz=7 --dispatch shared");
  EXPECT_EQ(bad_dispatch.exit_code, 2) << bad_dispatch.out;
  EXPECT_NE(bad_dispatch.out.find("--dispatch"), std::string::npos)
      << bad_dispatch.out;
  // A point outside the space, and no runs, are bad input.
  const CommandRun outside =
      Adse("fidelity " + file +
           " --points cores=3,freq_ghz=2.1,lidar_hz=7 -o " + out.string());
  EXPECT_EQ(outside.exit_code, 2) << outside.out;
  EXPECT_NE(outside.out.find("cores"), std::string::npos) << outside.out;
  const CommandRun none =
      Adse("fidelity " + file +
           " --points cores=1,freq_ghz=2.1,lidar_hz=7 --runs 0");
  EXPECT_EQ(none.exit_code, 2) << none.out;
  EXPECT_NE(none.out.find("--runs"), std::string::npos) << none.out;
}

TEST(CliRunTest, RunWithReplicasRunsEachPointOncePerReplicaAndShowsTheSpread) {
  const std::string file =
      WriteScenario("replicas", ReadText(Small()) + "harness: {replicas: 2}\n");
  const fs::path out = fs::temp_directory_path() / "adse_cli_replicas";
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

TEST(CliRunTest, AnInfeasiblePointsProgressLineNamesTheConstraintItBroke) {
  // No run meets a 1 ms latency; no early stop ends a run for it either,
  // so the run reaches the goal and is still infeasible. One point,
  // generous enough to reach the goal.
  const std::string file = WriteScenario(
      "latency_bound",
      Replaced(Replaced(ReadText(Small()),
                        "constraints: [nav_time_s <= 60, ctrl_rate_hz >= 1, "
                        "completed]",
                        "constraints: [nav_time_s <= 60, e2e_latency_p50_s <= "
                        "0.001, completed]"),
               "values: [1, 4, 16]", "values: [16]"));
  const fs::path out = fs::temp_directory_path() / "adse_cli_latency_bound";
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
      "llm_down", ReadText(Small()) +
                      "llm: {endpoint: \"http://127.0.0.1:9\", retries: 0}\n");
  const std::string out =
      (fs::temp_directory_path() / "adse_cli_llm_down").string();
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

TEST(CliRunTest, AnalyzeOfACampaignFromAnotherFolderGivesTheSameAnswerAsRun) {
  const fs::path out = fs::temp_directory_path() / "adse_cli_one_answer";
  fs::remove_all(out);
  const CommandRun run =
      Adse("run " + Small() + " --budget 7 -q -o " + out.string());
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
  // Its runs/ folder stands for the campaign: the same answer, written
  // beside the others, nothing among the run files.
  const CommandRun runs = Adse("analyze " + (out / "runs").string() + "/");
  ASSERT_EQ(runs.exit_code, 0) << runs.out;
  EXPECT_EQ(FrontSection(runs.out), FrontSection(run.out)) << runs.out;
  EXPECT_TRUE(fs::exists(out / "analysis" / "v3" / "report.md"));
  EXPECT_FALSE(fs::exists(out / "runs" / "analysis"));
}

TEST(CliRunTest, AnalyzeOfACampaignWithCasesFoldsEveryCaseAsRunDid) {
  // The small scenario at one point, with two destinations.
  std::string text = ReadText(Small());
  const std::string goal = "  goal: {x: 10.0, y: 29.75}\n";
  const size_t at = text.find(goal);
  ASSERT_NE(at, std::string::npos);
  text.insert(at + goal.size(),
              "  cases:\n"
              "    - {name: across, goal: {x: 10.0, y: 29.75}}\n"
              "    - {name: along, goal: {x: 40.0, y: -1.75}}\n");
  const std::string scenario = WriteScenario("cases", text);
  const fs::path out = fs::temp_directory_path() / "adse_cli_cases";
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
  EXPECT_NE(FrontSection(analyze.out).find("1 of 1 evaluations"),
            std::string::npos)
      << analyze.out;
}

TEST(CliRunTest, AnalyzeWithAReferenceDrawsTheStudysFigureOrRefusesClearly) {
  const fs::path out = fs::temp_directory_path() / "adse_cli_study_figure";
  fs::remove_all(out);
  ASSERT_EQ(
      Adse("run " + Small() + " --budget 3 -q -o " + out.string()).exit_code,
      0);
  const std::string recording =
      std::string(ADSE_SOURCE_DIR) + "/tests/data/reference_study";
  const CommandRun ok =
      Adse("analyze " + out.string() + " --reference " + recording);
  ASSERT_EQ(ok.exit_code, 0) << ok.out;
  EXPECT_NE(ok.out.find("in the study's form over"), std::string::npos)
      << ok.out;
  EXPECT_TRUE(fs::exists(out / "analysis" / "v1" / "pareto.png"));
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
                               " --reference " + recording);
  EXPECT_EQ(file.exit_code, 2) << file.out;
  EXPECT_NE(file.out.find("not a campaign folder"), std::string::npos)
      << file.out;
}

TEST(CliRunTest, WorkersRunTheCampaignsOwnAdseWhenItsFileIsReplaced) {
  // A copy of adse starts a two-point campaign, one worker; once it has
  // started, its file is replaced by another program (as a rebuild does).
  // The second point's worker still runs the campaign's adse; by the
  // file's path it ran the other program and failed.
  const fs::path dir = fs::temp_directory_path() / "adse_cli_replaced";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path copy = dir / "adse";
  fs::copy_file(std::string(ADSE_BINARY_DIR) + "/bin/adse", copy);
  const fs::path out = dir / "campaign";
  const std::string script =
      copy.string() + " run " + Small() +
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
      (fs::temp_directory_path() / "adse_cli_worker.h5").string();
  const CommandRun run = Adse("worker " + Small() +
                              " --point cores=4,freq_ghz=2.1,lidar_hz=14 -o " +
                              out + " --expect-key " + std::string(64, '0'));
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_NE(run.out.find("changed since the campaign started"),
            std::string::npos)
      << run.out;
  EXPECT_FALSE(fs::exists(out));
}

TEST(CliRunTest, WorkerLeavesItsAnalysisBesideTheRunFileWhenAsked) {
  const fs::path dir = fs::temp_directory_path() / "adse_cli_worker_report";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string out = (dir / "run.h5").string();
  const std::string report = (dir / "run.report.json").string();
  const CommandRun run = Adse("worker " + Small() +
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

// `adse profile`: the bundled profile is what importing the trimmed CARET
// report with the bundled mapping writes; bad input is exit 2 with the file
// and field named, and nothing written.
std::string TrimmedCaret() {
  return std::string(ADSE_SOURCE_DIR) +
         "/tests/data/caret-autoware-2022.12-trimmed";
}
std::string BundledMapping() {
  return std::string(ADSE_SOURCE_DIR) +
         "/scenarios/profiles/autoware-2022.12-mapping.yaml";
}

TEST(CliProfileTest, ImportWritesTheProfileAndShowPrintsItsTotalLoad) {
  const fs::path out = fs::temp_directory_path() / "adse_cli_profile.yaml";
  fs::remove(out);
  const CommandRun import =
      Adse("profile import --caret " + TrimmedCaret() + " --map " +
           BundledMapping() + " -o " + out.string());
  ASSERT_EQ(import.exit_code, 0) << import.out;
  // Every callback of the stack graph, from the CARET callbacks mapped.
  EXPECT_NE(import.out.find("wrote " + out.string() +
                            ": profile 'autoware-2022.12-i9-12900kf', 30 "
                            "callbacks from 34 CARET callbacks; total load"),
            std::string::npos)
      << import.out;
  const CommandRun show = Adse("profile show " + out.string());
  ASSERT_EQ(show.exit_code, 0) << show.out;
  EXPECT_TRUE(std::regex_search(
      show.out, std::regex("total load at 4\\.9 GHz: [0-9]+\\.[0-9]{2} cores "
                           "busy")))
      << show.out;
  EXPECT_NE(show.out.find("ndt_scan_matcher/points"), std::string::npos);
  const CommandRun bundled =
      Adse("profile show " + std::string(ADSE_SOURCE_DIR) +
           "/scenarios/profiles/autoware-2022.12-i9-12900kf.yaml");
  EXPECT_EQ(bundled.out, show.out);
}

TEST(CliProfileTest, ImportOfBadInputExitsWith2AndWritesNothing) {
  const fs::path out = fs::temp_directory_path() / "adse_cli_bad_profile.yaml";
  fs::remove(out);
  const CommandRun missing =
      Adse("profile import --caret /nonexistent/caret --map " +
           BundledMapping() + " -o " + out.string());
  EXPECT_EQ(missing.exit_code, 2) << missing.out;
  EXPECT_NE(missing.out.find("/nonexistent/caret: error: --caret: expected a "
                             "CARET report folder"),
            std::string::npos)
      << missing.out;
  EXPECT_FALSE(fs::exists(out));

  const fs::path mapping = fs::temp_directory_path() / "adse_cli_mapping.yaml";
  std::ofstream(mapping) << Replaced(ReadText(BundledMapping()),
                                     "top/velodyne_convert_node/callback_0",
                                     "top/velodyne/callback_0");
  const CommandRun unknown =
      Adse("profile import --caret " + TrimmedCaret() + " --map " +
           mapping.string() + " -o " + out.string());
  EXPECT_EQ(unknown.exit_code, 2) << unknown.out;
  EXPECT_TRUE(std::regex_search(
      unknown.out,
      std::regex("adse_cli_mapping\\.yaml:[0-9]+:[0-9]+: error: "
                 "callbacks\\.lidar_driver/points_raw\\.sources\\[0\\]")))
      << unknown.out;
  EXPECT_NE(unknown.out.find("did you mean "
                             "'/sensing/lidar/top/velodyne_convert_node/"
                             "callback_0'"),
            std::string::npos)
      << unknown.out;
  EXPECT_FALSE(fs::exists(out));

  EXPECT_EQ(Adse("profile import --caret " + TrimmedCaret()).exit_code, 2);
  const CommandRun show = Adse("profile show /nonexistent/profile.yaml");
  EXPECT_EQ(show.exit_code, 2) << show.out;
  EXPECT_NE(show.out.find("/nonexistent/profile.yaml"), std::string::npos);
}

TEST(CliProfileTest, CheckComparesTheChainsOnTheReferenceMachine) {
  const fs::path out = fs::temp_directory_path() / "adse_cli_profile_check";
  fs::remove_all(out);
  const CommandRun check =
      Adse("profile check " + Small() + " -o " + out.string());
  ASSERT_EQ(check.exit_code, 0) << check.out;
  for (const char* file : {"run.h5", "check.txt", "check.png"}) {
    EXPECT_TRUE(fs::is_regular_file(out / file)) << file;
  }
  EXPECT_NE(check.out.find("16 cores at 4.9 GHz, LiDAR 10 Hz"),
            std::string::npos)
      << check.out;
  // The sensing chain against Autoware's 85.1 ms, with its verdict.
  EXPECT_TRUE(std::regex_search(
      check.out, std::regex("\nsensing +[0-9]+ +[0-9.]+ +[0-9.]+ +85\\.12 "
                            "+116\\.72 +[-+][0-9]+ %  within 15 %: ")))
      << check.out;
  EXPECT_NE(check.out.find("lidar_driver/points_raw"), std::string::npos);
  // The bundled profile's reference_units were measured on this scenario:
  // a change to the stack that moves them (NDT's iterations) must measure
  // them again, or the profile charges off its source.
  const size_t units = check.out.find("\nwork units per invocation");
  ASSERT_NE(units, std::string::npos) << check.out;
  EXPECT_NE(check.out.find("\nndt_scan_matcher/points ", units),
            std::string::npos);
  EXPECT_EQ(check.out.find("  beyond 5 %", units), std::string::npos)
      << check.out;

  // A scenario with task.cases checks the case it is told to drive.
  const fs::path parked = fs::temp_directory_path() / "adse_cli_check_case";
  fs::remove_all(parked);
  const CommandRun nose_in = Adse(
      "profile check " + std::string(ADSE_SOURCE_DIR) +
      "/scenarios/valet_parking.yaml --case nose_in -o " + parked.string());
  ASSERT_EQ(nose_in.exit_code, 0) << nose_in.out;
  EXPECT_NE(nose_in.out.find(", case nose_in: goal_reached"), std::string::npos)
      << nose_in.out;
  EXPECT_TRUE(fs::is_regular_file(parked / "run.h5"));

  // A scenario without a profile has nothing to check.
  const std::string calibrated =
      Variant("no_profile",
              "platform: {kind: virtual, cost_model: counted, profile: "
              "profiles/autoware-2022.12-i9-12900kf.yaml}",
              "platform: {kind: virtual, cost_model: counted, calibration: "
              "calibration/reference.json}");
  const CommandRun none = Adse("profile check " + calibrated);
  EXPECT_EQ(none.exit_code, 2) << none.out;
  EXPECT_NE(none.out.find("platform.profile: expected a cost profile to "
                          "check, found none"),
            std::string::npos)
      << none.out;
}

}  // namespace
