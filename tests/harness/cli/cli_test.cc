// The adse binary as a user runs it: exit codes, messages that cite the
// scenario's lines, the world check's output folder, single runs and their
// analysis (the fidelity check: cli_fidelity_test.cc).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

#include "stack/base/files.h"
#include "tests/harness/cli/example_files.h"
#include "tests/harness/testing/adse_command.h"
#include "tests/harness/testing/small_scenario.h"
#include "tests/testing/temp_files.h"

namespace {

namespace fs = std::filesystem;

using adse::testing::Adse;
using adse::testing::CommandRun;
using adse::testing::Example;
using adse::testing::ReadText;
using adse::testing::Replaced;
using adse::testing::SmallScenarioPath;
using adse::testing::Variant;
using adse::testing::WriteScenario;

TEST(CliTest, ValidateReportsTheRobotaxiSpaceOf280Points) {
  const CommandRun run = Adse("validate --quiet " + Example());
  EXPECT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(
      run.out.find(
          "design space: 280 points (cores 28 x freq_ghz 5 x lidar_hz 2)"),
      std::string::npos)
      << run.out;
}

TEST(CliTest, ValidateSaysTheSizeOfASpaceBeyondSixtyFourBits) {
  // 1024 x 99,991 x 99,501 x 49,001 x 99,001 x 19,001 points, about 9e26.
  const std::string scenario = WriteScenario(
      "big_space",
      Replaced(ReadText(SmallScenarioPath()),
               "  cores:    {bind: platform.cores,      values: [1, 4, 16]}\n"
               "  freq_ghz: {bind: platform.freq_ghz,   values: [1.0, 2.1]}\n"
               "  lidar_hz: {bind: stack.lidar.rate_hz, values: [7, 14]}\n",
               "  cores: {bind: platform.cores, range: [1, 1024]}\n"
               "  freq_ghz: {bind: platform.freq_ghz, range: [0.0001, 10], "
               "step: 0.0001}\n"
               "  lidar_hz: {bind: stack.lidar.rate_hz, range: [0.5, 100], "
               "step: 0.001}\n"
               "  a: {bind: stack.localization.voxel_leaf_m, range: [0.1, 5], "
               "step: 0.0001}\n"
               "  b: {bind: stack.odometry.rate_hz, range: [1, 100], "
               "step: 0.001}\n"
               "  c: {bind: stack.lidar.horizontal_resolution_deg, range: "
               "[0.1, 2], step: 0.0001}\n"));
  const CommandRun run = Adse("validate --quiet --no-world " + scenario);
  EXPECT_EQ(run.exit_code, 0) << run.out;
  EXPECT_TRUE(std::regex_search(
      run.out, std::regex("design space: about [0-9.]+e\\+26 points")))
      << run.out;
}

TEST(CliTest, ValidatePrintsAReloadableNormalisedSpec) {
  const CommandRun run =
      Adse("validate --no-world " + Example() + " 2>/dev/null");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const fs::path copy =
      adse::testing::TestScratch() / "adse_cli_normalised.yaml";
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

TEST(CliTest, AGoalOnTheStartIsReportedAtItsLine) {
  const std::string file =
      Variant("goal_on_start", "goal: {x: 15.0, y: 63.75, tolerance_m: 2.0}",
              "goal: {x: 21.0, y: -1.75, tolerance_m: 2.0}");
  const CommandRun run = Adse("validate -q " + file);
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_TRUE(std::regex_search(
      run.out, std::regex("adse_cli_goal_on_start\\.yaml:18:[0-9]+: error: "
                          "task\\.goal: expected a goal farther along the "
                          "road from the start than its tolerance_m \\(2 "
                          "m\\), found one 1\\.[0-9]+ m from it")))
      << run.out;
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

// The valet example's task.cases with a case's line replaced.
std::string ValetVariant(const std::string& name, const std::string& from,
                         const std::string& to) {
  return WriteScenario(name, Replaced(ReadText(std::string(ADSE_SOURCE_DIR) +
                                               "/scenarios/valet_parking.yaml"),
                                      from, to));
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

TEST(CliTest, ACostThatIsNotFiniteAtSomePointIsRefusedBeforeAnythingRuns) {
  const std::string file =
      Variant("cost", "cost: cores * freq_ghz", "cost: 10 / (cores - 3)");
  const fs::path out = adse::testing::TestScratch() / "adse_cli_cost_out";
  fs::remove_all(out);
  for (const std::string& command :
       {"validate -q --no-world " + file,
        "run --budget 2 -o " + out.string() + " " + file}) {
    const CommandRun run = Adse(command);
    EXPECT_EQ(run.exit_code, 2) << command << "\n" << run.out;
    EXPECT_TRUE(std::regex_search(
        run.out, std::regex("adse_cli_cost\\.yaml:[0-9]+:[0-9]+: error: cost: "
                            "expected a finite cost at every design point, "
                            "found '10 / \\(cores - 3\\)' = inf at "
                            "cores=3,freq_ghz=1,lidar_hz=7")))
        << command << "\n"
        << run.out;
  }
  EXPECT_FALSE(fs::exists(out));
}

TEST(CliTest, AKnobThatCannotActInTheScenarioIsRefusedAtItsLine) {
  const std::string file =
      Variant("dead_knob", "  lidar_hz: {bind: stack.lidar.rate_hz",
              "  lidar_hz: {bind: stack.parking.rate_hz");
  const CommandRun run = Adse("validate -q --no-world " + file);
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_TRUE(std::regex_search(
      run.out,
      std::regex("adse_cli_dead_knob\\.yaml:32:[0-9]+: error: "
                 "design_space\\.lidar_hz: binds stack\\.parking\\.rate_hz, "
                 "which acts only in valet_parking tasks, and task\\.kind is "
                 "lane_driving; every point would drive alike")))
      << run.out;
}

TEST(CliTest, MisspelledKeyGetsADidYouMeanAndNothingIsWritten) {
  const std::string file = Variant("typo", "weather: clear", "wether: clear");
  const fs::path out = adse::testing::TestScratch() / "adse_cli_typo_out";
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
  const CommandRun missing = Adse("validate /nonexistent/scenario.yaml");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.out.find("/nonexistent/scenario.yaml"), std::string::npos)
      << missing.out;
  const CommandRun help = Adse("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("validate"), std::string::npos);
}

TEST(CliTest, ANumberOutOfItsRangeIsRefusedSayingWhatIsExpected) {
  const CommandRun scans = Adse("world " + Example() + " --save-scans -3");
  EXPECT_EQ(scans.exit_code, 2);
  EXPECT_NE(scans.out.find("--save-scans: expected a whole number from 0 to "
                           "2147483647, found '-3'"),
            std::string::npos)
      << scans.out;
  // Read as the scenario reads numbers: 1e3 is a thousand, 2.5 no count.
  const CommandRun budgets =
      Adse("explore --replay " + std::string(ADSE_SOURCE_DIR) +
           "/tests/data/landscapes/saturating --strategy random --seeds 1 "
           "--budget 1e1 --json");
  ASSERT_EQ(budgets.exit_code, 0) << budgets.out;
  EXPECT_EQ(nlohmann::json::parse(budgets.out)["budget"], 10) << budgets.out;
  const CommandRun half =
      Adse("explore --replay " + std::string(ADSE_SOURCE_DIR) +
           "/tests/data/landscapes/saturating --budget 2.5");
  EXPECT_EQ(half.exit_code, 2) << half.out;
  EXPECT_NE(half.out.find("--budget: expected a whole number from 1 to "
                          "1000000000, found '2.5'"),
            std::string::npos)
      << half.out;
  // More workers than CPUs is said of the flag, before any run.
  const fs::path crowded = adse::testing::TestScratch() / "crowded";
  fs::remove_all(crowded);
  const CommandRun workers =
      Adse("run " + Example() + " --workers 100000 -o " + crowded.string());
  EXPECT_EQ(workers.exit_code, 2) << workers.out;
  EXPECT_NE(workers.out.find("--workers 100000: 100000 workers x 1 cores per "
                             "worker need 100000 cores"),
            std::string::npos)
      << workers.out;
  EXPECT_FALSE(fs::exists(crowded / "campaign.h5"));
  // So is a worker wider than the machine, of the field that asked.
  const CommandRun wide =
      Adse("run " +
           Variant("wide", "cores_per_worker: 1", "cores_per_worker: 1024") +
           " -o " + crowded.string());
  EXPECT_EQ(wide.exit_code, 2) << wide.out;
  EXPECT_NE(wide.out.find("harness.cores_per_worker: 1 workers x 1024 cores "
                          "per worker need 1024 cores"),
            std::string::npos)
      << wide.out;
  EXPECT_FALSE(fs::exists(crowded / "campaign.h5"));
  // A budget on the command line has the scenario's bounds: a campaign of
  // no evaluations is refused, not written.
  const fs::path out = adse::testing::TestScratch() / "budget_zero";
  fs::remove_all(out);
  const CommandRun budget =
      Adse("run " + Example() + " --budget 0 -o " + out.string());
  EXPECT_EQ(budget.exit_code, 2);
  EXPECT_NE(budget.out.find("--budget"), std::string::npos) << budget.out;
  EXPECT_FALSE(fs::exists(out));
  const CommandRun timeout = Adse("interpret request --timeout 0");
  EXPECT_EQ(timeout.exit_code, 2);
  EXPECT_NE(timeout.out.find("expected a finite number above 0, found '0'"),
            std::string::npos)
      << timeout.out;
  // CLI11 took "-1" for the largest seed.
  const CommandRun seed = Adse("simulate " + Example() + " --seed -1");
  EXPECT_EQ(seed.exit_code, 2);
  EXPECT_NE(seed.out.find("--seed: expected a whole number from 0 to "
                          "18446744073709551615, found '-1'"),
            std::string::npos)
      << seed.out;
  // CLI11's own positive-number check named the largest double.
  EXPECT_EQ(budget.out.find("179769313486"), std::string::npos) << budget.out;
  EXPECT_EQ(timeout.out.find("179769313486"), std::string::npos) << timeout.out;
}

TEST(CliTest, WorldFollowIdealReachesTheGoalAndWritesWhatItSaw) {
  const fs::path out = adse::testing::TestScratch() / "adse_cli_world_check";
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

// The private path a writer of `path` on this host that is gone would
// have left: TemporaryPathFor's, with the pid of a reaped child.
std::string AbandonedTemporaryOf(const fs::path& path) {
  const std::string own = adse::TemporaryPathFor(path.string());
  const pid_t gone = ::fork();
  if (gone == 0) ::_exit(0);
  ::waitpid(gone, nullptr, 0);
  return own.substr(0, own.rfind('.') + 1) + std::to_string(gone);
}

TEST(CliTest, WorldFollowIdealNeverReplacesWhatItDidNotWrite) {
  const fs::path dir = adse::testing::TestScratch() / "adse_cli_world_others";
  fs::remove_all(dir);
  fs::create_directories(dir / "results");
  std::ofstream(dir / "results" / "precious.txt") << "keep me\n";
  std::ofstream(dir / "scenario.yaml") << "keep me too\n";
  const std::string world = "world " + Example() + " --follow-ideal -o ";
  const CommandRun folder = Adse(world + (dir / "results").string());
  EXPECT_EQ(folder.exit_code, 2) << folder.out;
  EXPECT_NE(folder.out.find((dir / "results" / "precious.txt").string() +
                            ", which this command does not write"),
            std::string::npos)
      << folder.out;
  const CommandRun file = Adse(world + (dir / "scenario.yaml").string());
  EXPECT_EQ(file.exit_code, 2) << file.out;
  EXPECT_NE(file.out.find("a file is there"), std::string::npos) << file.out;
  // The current folder (here a scratch one) is never the output.
  const fs::path cwd = fs::current_path();
  fs::current_path(dir);
  const CommandRun here = Adse(world + ".");
  fs::current_path(cwd);
  EXPECT_EQ(here.exit_code, 2) << here.out;
  EXPECT_NE(here.out.find("the current folder or one above it"),
            std::string::npos)
      << here.out;
  EXPECT_EQ(ReadText((dir / "results" / "precious.txt").string()), "keep me\n");
  EXPECT_EQ(ReadText((dir / "scenario.yaml").string()), "keep me too\n");
  // What a check killed on its way left (its private folder, named for
  // this host and a process that is gone) goes with the next check.
  fs::create_directories(AbandonedTemporaryOf(dir / "check") + "/scans");
  // An earlier check is replaced by the new one.
  const CommandRun first =
      Adse(world + (dir / "check").string() + " --no-scan");
  ASSERT_EQ(first.exit_code, 0) << first.out;
  const CommandRun again =
      Adse(world + (dir / "check").string() + " --no-scan");
  EXPECT_EQ(again.exit_code, 0) << again.out;
  EXPECT_TRUE(fs::exists(dir / "check" / "summary.json"));
  for (const auto& e : fs::directory_iterator(dir)) {
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos)
        << e.path();
  }
  fs::remove_all(dir);
}

TEST(CliTest, SimulateAndCalibrateNeverOverwriteWhatIsNotTheirs) {
  const fs::path dir = adse::testing::TestScratch() / "adse_cli_simulate_out";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "mine.yaml") << "keep me\n";
  const std::string simulate = "simulate " + SmallScenarioPath() +
                               " --point cores=16,freq_ghz=2.1,lidar_hz=7 -q ";
  const CommandRun yaml = Adse(simulate + "-o " + (dir / "mine.yaml").string());
  EXPECT_EQ(yaml.exit_code, 2) << yaml.out;
  EXPECT_NE(yaml.out.find("a file that is not a run file is there"),
            std::string::npos)
      << yaml.out;
  const CommandRun calibrate = Adse("calibrate " + SmallScenarioPath() +
                                    " -p cores=16,freq_ghz=2.1,lidar_hz=7 -o " +
                                    (dir / "mine.yaml").string());
  EXPECT_EQ(calibrate.exit_code, 2) << calibrate.out;
  EXPECT_NE(calibrate.out.find("a file that is not a calibration (adse "
                               "calibrate's JSON) is there"),
            std::string::npos)
      << calibrate.out;
  EXPECT_EQ(calibrate.out.find("calibration run"), std::string::npos)
      << calibrate.out;
  EXPECT_EQ(ReadText((dir / "mine.yaml").string()), "keep me\n");
  const CommandRun under =
      Adse(simulate + "-o " + (dir / "mine.yaml" / "run.h5").string());
  EXPECT_EQ(under.exit_code, 2) << under.out;
  EXPECT_NE(under.out.find("mine.yaml is a file, not a folder"),
            std::string::npos)
      << under.out;
  // A campaign's index, or a place among its runs, is no run file's to
  // take.
  const fs::path campaign = dir / "camp";
  ASSERT_EQ(Adse("run " + SmallScenarioPath() +
                 " --budget 1 --strategy exhaustive -q -o " + campaign.string())
                .exit_code,
            0);
  const std::string index_before =
      ReadText((campaign / "campaign.h5").string());
  const CommandRun over_index =
      Adse(simulate + "-o " + (campaign / "campaign.h5").string());
  EXPECT_EQ(over_index.exit_code, 2) << over_index.out;
  EXPECT_NE(over_index.out.find("a file that is not a run file is there"),
            std::string::npos)
      << over_index.out;
  EXPECT_EQ(ReadText((campaign / "campaign.h5").string()), index_before);
  const CommandRun among_runs =
      Adse(simulate + "-o " + (campaign / "runs" / "mine.h5").string());
  EXPECT_EQ(among_runs.exit_code, 2) << among_runs.out;
  EXPECT_NE(among_runs.out.find("a campaign's runs/ folder holds its runs"),
            std::string::npos)
      << among_runs.out;
  // A seed of its own gets a file of its own by default.
  const std::string scenario = WriteScenario(
      "simulate_seeds",
      Replaced(ReadText(SmallScenarioPath()), "output: results/robotaxi-small",
               "output: " + (dir / "campaign").string()));
  const CommandRun seeded =
      Adse("simulate " + scenario +
           " --point cores=16,freq_ghz=2.1,lidar_hz=7 -q --seed 5");
  ASSERT_EQ(seeded.exit_code, 0) << seeded.out;
  EXPECT_TRUE(fs::exists(dir / "campaign" / "simulate" /
                         "cores-16_freq_ghz-2.1_lidar_hz-7_seed5.h5"))
      << seeded.out;
  fs::remove_all(dir);
}

// Runs adse with `args` while `folder` is read-only: a read-only tmpfs
// over it in a mount namespace of the command's own for root (who writes
// through permission bits), its permission bits for anyone else.
CommandRun AdseWithReadOnly(const fs::path& folder, const std::string& args) {
  if (::geteuid() != 0) {
    fs::permissions(folder, fs::perms::owner_read | fs::perms::owner_exec);
    CommandRun run = Adse(args);
    fs::permissions(folder, fs::perms::owner_all);
    return run;
  }
  const std::string inner = "mount -t tmpfs -o ro adse-ro " + folder.string() +
                            " && " + ADSE_BINARY_DIR + "/bin/adse " + args;
  FILE* pipe = ::popen(("unshare -m sh -c '" + inner + "' 2>&1").c_str(), "r");
  std::string out;
  char buffer[4096];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) {
    out.append(buffer, n);
  }
  const int status = ::pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

TEST(CliTest, AFolderItCannotWriteInIsRefusedBeforeAnyWork) {
  const fs::path dir = adse::testing::TestScratch() / "adse_cli_read_only";
  fs::remove_all(dir);
  fs::create_directories(dir / "locked");
  const fs::path locked = dir / "locked";
  const std::string point = " --point cores=16,freq_ghz=2.1,lidar_hz=7 -q ";
  struct Case {
    std::string args;
    std::string named;  // the flag or field the message names
  };
  const Case cases[] = {
      {"simulate " + SmallScenarioPath() + point + "-o " +
           (locked / "run.h5").string(),
       "-o " + (locked / "run.h5").string()},
      {"simulate " + SmallScenarioPath() + point + "-o " +
           (locked / "sub" / "run.h5").string(),
       "-o "},
      {"run " + SmallScenarioPath() + " --budget 1 -q -o " +
           (locked / "camp").string(),
       "-o "},
      {"run " + SmallScenarioPath() + " --budget 1 -q -o " +
           (dir / "camp").string() + " --cache-dir " +
           (locked / "cache").string(),
       "--cache-dir "},
      {"world " + SmallScenarioPath() + " --follow-ideal --no-scan -o " +
           (locked / "w").string(),
       "-o "},
  };
  for (const Case& c : cases) {
    const CommandRun run = AdseWithReadOnly(locked, c.args);
    EXPECT_EQ(run.exit_code, 2) << c.args << "\n" << run.out;
    EXPECT_NE(run.out.find(c.named), std::string::npos) << run.out;
    EXPECT_NE(run.out.find(": cannot write in " + locked.string()),
              std::string::npos)
        << run.out;
    // Said before any simulation: no run's progress or result.
    EXPECT_EQ(run.out.find("nav_time_s"), std::string::npos) << run.out;
  }
  EXPECT_FALSE(fs::exists(dir / "camp"));
  fs::remove_all(dir);
}

TEST(CliTest, SimulateWritesARunFileThatPassesTheSchemaCheck) {
  const fs::path out = adse::testing::TestScratch() / "adse_cli_simulate.h5";
  fs::remove(out);
  const CommandRun run =
      Adse("simulate " + SmallScenarioPath() +
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

  // A damaged block inside a table passes the schema's checks of the
  // file's structure, not the read of the table's checksums.
  const fs::path damaged = adse::testing::TestScratch() / "adse_cli_damaged.h5";
  fs::copy_file(out, damaged, fs::copy_options::overwrite_existing);
  const fs::path offset_file =
      adse::testing::TestScratch() / "adse_cli_damaged.offset";
  const std::string find_chunk =
      "/usr/bin/python3 -c \"import h5py; print(h5py.File('" +
      damaged.string() +
      "', 'r')['/trace/callbacks'].id.get_chunk_info(0).byte_offset)\" > " +
      offset_file.string() + " 2>/dev/null";
  if (std::system(find_chunk.c_str()) != 0) {
    GTEST_SKIP() << "no /usr/bin/python3 with h5py to find a chunk";
  }
  long offset = -1;
  std::ifstream(offset_file) >> offset;
  ASSERT_GT(offset, 0);
  {
    std::fstream file(damaged, std::ios::in | std::ios::out | std::ios::binary);
    file.seekp(offset + 100);
    file << std::string(64, '\xff');
  }
  const CommandRun broken = Adse("schema check " + damaged.string());
  EXPECT_EQ(broken.exit_code, 2) << broken.out;
  EXPECT_EQ(broken.out.find(": ok"), std::string::npos) << broken.out;
  EXPECT_NE(broken.out.find(damaged.string() + ": /trace/callbacks: reading"),
            std::string::npos)
      << broken.out;
}

TEST(CliTest, SimulateRejectsAPointOutsideTheSpace) {
  const CommandRun run = Adse("simulate " + SmallScenarioPath() +
                              " --point cores=3,freq_ghz=2.1,lidar_hz=7");
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_NE(run.out.find("cores"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("1, 4, 16"), std::string::npos) << run.out;
  const CommandRun unknown = Adse("simulate " + SmallScenarioPath() +
                                  " --point cores=4,freq_ghz=2.1,lidar=7");
  EXPECT_EQ(unknown.exit_code, 2) << unknown.out;
  EXPECT_NE(unknown.out.find("lidar"), std::string::npos) << unknown.out;
}

TEST(CliTest, SchemaCheckRejectsAFileThatIsNotARunFile) {
  const fs::path bogus = adse::testing::TestScratch() / "adse_cli_bogus.h5";
  std::ofstream(bogus) << "not hdf5\n";
  const CommandRun run = Adse("schema check " + bogus.string());
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_NE(run.out.find("adse_cli_bogus.h5"), std::string::npos) << run.out;
}

TEST(CliTest, AnalyzeReanalysesAFolderSkipsBrokenFilesAndDiffsVersions) {
  const fs::path dir = adse::testing::TestScratch() / "adse_cli_analyze";
  fs::remove_all(dir);
  fs::create_directories(dir / "runs");
  const CommandRun sim =
      Adse("simulate " + SmallScenarioPath() +
           " --point cores=16,freq_ghz=2.1,lidar_hz=7 -q -o " +
           (dir / "runs" / "a.h5").string());
  ASSERT_EQ(sim.exit_code, 0) << sim.out;
  std::ofstream(dir / "runs" / "broken.h5") << "truncated";
  const CommandRun first = Adse("analyze " + dir.string());
  EXPECT_EQ(first.exit_code, 2) << first.out;  // one file could not be read
  const std::string broken = (dir / "runs" / "broken.h5").string();
  EXPECT_NE(first.out.find("skipped " + broken +
                           ": not an HDF5 file (no HDF5 signature)"),
            std::string::npos)
      << first.out;
  EXPECT_NE(first.out.find("1 run analysed"), std::string::npos) << first.out;
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
  EXPECT_NE(bad.out.find("--threshold nonsense=1: unknown diagnosis "
                         "threshold 'nonsense'"),
            std::string::npos)
      << bad.out;
  EXPECT_FALSE(fs::exists(dir / "analysis" / "v3"));
  // An analysis killed on its way leaves no version that looks complete:
  // every vN there has its summary.
  const std::string killed =
      std::string(ADSE_BINARY_DIR) + "/bin/adse analyze " + dir.string() +
      " > /dev/null 2>&1 & sleep 0.3; kill -9 $! 2>/dev/null; wait";
  ASSERT_NE(std::system(killed.c_str()), -1);
  for (const auto& e : fs::directory_iterator(dir / "analysis")) {
    const std::string name = e.path().filename().string();
    if (name.find(".tmp.") != std::string::npos) continue;
    EXPECT_TRUE(fs::exists(e.path() / "summary.json")) << name;
  }
  // What it left (here also one planted, of a process that is gone) goes
  // with the next analysis.
  fs::create_directories(AbandonedTemporaryOf(dir / "analysis" / "v9") +
                         "/reports");
  // (Exit 2: the folder's broken file is still skipped.)
  ASSERT_EQ(Adse("analyze " + dir.string()).exit_code, 2);
  for (const auto& e : fs::directory_iterator(dir / "analysis")) {
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos)
        << e.path();
  }
  // Run files outside a campaign: no analysis folder either.
  const CommandRun loose = Adse("analyze " + (dir / "runs").string() +
                                "/a.h5 --threshold frequency_bound_fraction=7");
  EXPECT_EQ(loose.exit_code, 2) << loose.out;
  EXPECT_NE(loose.out.find("out of range"), std::string::npos) << loose.out;
  EXPECT_FALSE(fs::exists(dir / "runs" / "a.analysis"));
}

TEST(CliTest, AnalyzeOneRunPrintsDeviationAndDiagnosis) {
  const fs::path run = adse::testing::TestScratch() / "adse_cli_analyze_one.h5";
  fs::remove_all(adse::testing::TestScratch() /
                 "adse_cli_analyze_one.analysis");
  ASSERT_EQ(
      Adse("simulate " + SmallScenarioPath() +
           " --point cores=1,freq_ghz=1.0,lidar_hz=14 -q -o " + run.string())
          .exit_code,
      0);
  const CommandRun r = Adse("analyze " + run.string());
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("deviation_score"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("diagnosis   cpu_bound"), std::string::npos) << r.out;
  // A run file named otherwise keeps its whole name.
  const fs::path other =
      adse::testing::TestScratch() / "adse_cli_analyze_run_a";
  fs::remove_all(adse::testing::TestScratch() /
                 "adse_cli_analyze_run_a.analysis");
  fs::copy_file(run, other, fs::copy_options::overwrite_existing);
  ASSERT_EQ(Adse("analyze " + other.string()).exit_code, 0);
  EXPECT_TRUE(fs::exists(adse::testing::TestScratch() /
                         "adse_cli_analyze_run_a.analysis" / "v1" /
                         "report.json"));
}

TEST(CliTest, AnalyzeDiffRefusesASummaryItCannotRead) {
  const fs::path dir = adse::testing::TestScratch() / "adse_cli_diff_malformed";
  fs::remove_all(dir);
  for (const auto& [name, text] :
       {std::pair{"a", R"({"evaluations": [{"point": {"cores": 1}}]})"},
        std::pair{"b", R"({"evaluations": [1]})"},
        std::pair{"c", R"({"evaluations": [], "pareto_front": {}})"}}) {
    fs::create_directories(dir / name);
    std::ofstream(dir / name / "summary.json") << text;
  }
  const CommandRun b = Adse("analyze --diff " + (dir / "a").string() + " " +
                            (dir / "b").string());
  EXPECT_EQ(b.exit_code, 2) << b.out;
  EXPECT_NE(b.out.find((dir / "b" / "summary.json").string() +
                       ": evaluations[0]: expected an object with a point"),
            std::string::npos)
      << b.out;
  const CommandRun c = Adse("analyze --diff " + (dir / "a").string() + " " +
                            (dir / "c").string());
  EXPECT_EQ(c.exit_code, 2) << c.out;
  EXPECT_NE(c.out.find("pareto_front: expected a list of evaluations"),
            std::string::npos)
      << c.out;
  fs::remove_all(dir);
}

}  // namespace
