// `adse fidelity` as a user runs it: the points it refuses before any run,
// the comparison of the virtual platform with a real-time run and what it
// writes, and what it keeps when a point fails or cannot be written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "analysis/runfile/run_file.h"
#include "tests/harness/cli/example_files.h"
#include "tests/harness/testing/adse_command.h"
#include "tests/testing/temp_files.h"

namespace {

namespace fs = std::filesystem;

using adse::testing::Adse;
using adse::testing::CommandRun;
using adse::testing::ReadText;
using adse::testing::Replaced;
using adse::testing::WriteScenario;

TEST(CliFidelityTest, FidelityRefusesAPointItCannotRunInRealTimeBeforeAnyRun) {
  // A second point with more cores (1024) than a host this test runs on
  // gives the process, and a scenario without a cost profile: exit 2 before the
  // first point's runs, nothing written.
  const fs::path out =
      adse::testing::TestScratch() / "adse_cli_fidelity_refused";
  fs::remove_all(out);
  const std::string small =
      WriteScenario("fidelity_many_cores",
                    Replaced(ReadText(std::string(ADSE_SOURCE_DIR) +
                                      "/scenarios/fidelity_small.yaml"),
                             "values: [1, 2]}", "values: [1, 2, 1024]}"));
  const CommandRun cores =
      Adse("fidelity " + small +
           " --points cores=1,freq_ghz=2.1,lidar_hz=7 "
           "cores=1024,freq_ghz=2.1,lidar_hz=7 --runs 1 -o " +
           out.string());
  EXPECT_EQ(cores.exit_code, 2) << cores.out;
  EXPECT_NE(cores.out.find("--points cores=1024,freq_ghz=2.1,lidar_hz=7: "),
            std::string::npos)
      << cores.out;
  EXPECT_NE(cores.out.find("one host CPU per core of the point, 1024 here"),
            std::string::npos)
      << cores.out;
  EXPECT_EQ(cores.out.find("run ..."), std::string::npos) << cores.out;
  EXPECT_FALSE(fs::exists(out));
  const CommandRun profile =
      Adse("fidelity " + std::string(ADSE_SOURCE_DIR) +
           "/scenarios/grid_town.yaml --points cores=2,freq_ghz=1.2,beams=16 "
           "-o " +
           out.string());
  EXPECT_EQ(profile.exit_code, 2) << profile.out;
  EXPECT_NE(profile.out.find("pads every callback to its cost profile"),
            std::string::npos)
      << profile.out;
  EXPECT_FALSE(fs::exists(out));
}

TEST(CliFidelityTest, FidelityComparesTheVirtualPlatformWithARealTimeRun) {
  const std::string file = WriteScenario(
      "fidelity", Replaced(ReadText(std::string(ADSE_SOURCE_DIR) +
                                    "/scenarios/fidelity_small.yaml"),
                           "timeout_s: 30", "timeout_s: 4"));
  const fs::path out = adse::testing::TestScratch() / "adse_cli_fidelity";
  fs::remove_all(out);
  const CommandRun run = Adse(
      "fidelity " + file +
      " --points cores=1,freq_ghz=2.1,lidar_hz=7 --runs 1 -o " + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("virtual (run_to_completion; median of 5 runs, "
                         "costs x (1 ± 0.0002)) vs real-time (median of 1 "
                         "run; cgroup v"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("ctrl_rate_hz"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("callback p50 latency"), std::string::npos);
  // How each run ended leads (4 s: none reaches the goal).
  EXPECT_NE(run.out.find("  ended: virtual timeout (perturbed: timeout, "
                         "timeout, timeout, timeout); real-time timeout\n"),
            std::string::npos)
      << run.out;
  std::ifstream json_in(out / "fidelity.json");
  const nlohmann::json json = nlohmann::json::parse(json_in, nullptr, false);
  ASSERT_FALSE(json.is_discarded());
  EXPECT_EQ(json["points"][0]["ended"]["virtual"], "timeout");
  EXPECT_EQ(json["points"][0]["ended"]["virtual_perturbed"].size(), 4u);
  EXPECT_EQ(json["points"][0]["ended"]["realtime"].size(), 1u);
  EXPECT_EQ(json["points"][0]["perturbed_runs"], 4);
  for (const nlohmann::json& m : json["points"][0]["metrics"]) {
    if (m["name"] == "ctrl_rate_hz") {
      EXPECT_EQ(m["virtual_runs"].size(), 5u) << m;
    }
  }
  for (const char* name : {"fidelity.txt", "fidelity.json", "fidelity-1.png",
                           "runs/1-virtual.h5", "runs/1-virtual-p1.h5",
                           "runs/1-virtual-p4.h5", "runs/1-realtime-1.h5"}) {
    EXPECT_TRUE(fs::is_regular_file(out / name)) << name;
  }
  // A perturbed run is the same point with its costs scaled.
  for (const auto& [file, scale] :
       {std::pair{"1-virtual.h5", "1"}, std::pair{"1-virtual-p2.h5", "0.9999"},
        std::pair{"1-virtual-p3.h5", "1.0002"}}) {
    adse::Result<adse::runfile::RunData> data =
        adse::runfile::ReadRunFile((out / "runs" / file).string());
    ASSERT_TRUE(data.ok()) << data.status().message();
    EXPECT_EQ(data->platform.at("cost_scale"), scale) << file;
    EXPECT_EQ(data->design_point.at("freq_ghz"), 2.1) << file;
  }
  // Both dispatches against the same real-time run: a table, a picture and
  // a virtual run file each, and how often each met the targets.
  const fs::path both = out / "both";
  const CommandRun two =
      Adse("fidelity " + file +
           " --points cores=1,freq_ghz=2.1,lidar_hz=7 --runs 1 "
           "--perturbed-runs 1 --dispatch "
           "run_to_completion,processor_sharing -o " +
           both.string());
  ASSERT_EQ(two.exit_code, 0) << two.out;
  EXPECT_NE(two.out.find("virtual (processor_sharing; median of 2 runs, "
                         "costs x (1 ± 0.0001)) vs real-time"),
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
        "runs/1-virtual-run_to_completion-p1.h5",
        "runs/1-virtual-processor_sharing.h5",
        "runs/1-virtual-processor_sharing-p1.h5", "runs/1-realtime-1.h5"}) {
    EXPECT_TRUE(fs::is_regular_file(both / name)) << name;
  }
  // A second call into the folder of the first is refused before it runs:
  // its runs would be compared as one point's with the first's.
  const CommandRun second = Adse(
      "fidelity " + file +
      " --points cores=1,freq_ghz=1,lidar_hz=7 --runs 1 -o " + both.string());
  EXPECT_EQ(second.exit_code, 2) << second.out;
  EXPECT_NE(second.out.find(both.string() +
                            " holds an earlier adse fidelity's comparison"),
            std::string::npos)
      << second.out;
  EXPECT_EQ(second.out.find("run ..."), std::string::npos) << second.out;
  // A folder that mixes two points' runs as one point's is refused.
  const fs::path two_points = out / "two_points";
  fs::create_directories(two_points / "runs");
  fs::copy_file(out / "runs" / "1-virtual.h5",
                two_points / "runs" / "1-virtual.h5");
  const CommandRun other = Adse(
      "simulate " + file + " --point cores=1,freq_ghz=1,lidar_hz=7 -q -o " +
      (two_points / "runs" / "1-realtime-1.h5").string());
  ASSERT_EQ(other.exit_code, 0) << other.out;
  const CommandRun mix = Adse("fidelity --compare " + two_points.string());
  EXPECT_EQ(mix.exit_code, 2) << mix.out;
  EXPECT_NE(mix.out.find("point 1's run files are of different design points "
                         "(cores=1,freq_ghz=2.1,lidar_hz=7 and "
                         "cores=1,freq_ghz=1,lidar_hz=7)"),
            std::string::npos)
      << mix.out;
  // Compared again from the run files alone: the same comparison, and the
  // runs left as they were.
  const fs::path again = both / "again";
  const CommandRun compared =
      Adse("fidelity --compare " + both.string() + " -o " + again.string());
  ASSERT_EQ(compared.exit_code, 0) << compared.out;
  std::ifstream again_in(again / "fidelity.json");
  const nlohmann::json again_json =
      nlohmann::json::parse(again_in, nullptr, false);
  ASSERT_FALSE(again_json.is_discarded());
  EXPECT_EQ(again_json["points"], both_json["points"]);
  EXPECT_EQ(again_json["runs"], 1);
  // Each callback says how many invocations it compared: the fewest any
  // run that ran it made (a real-time run starved of a callback on a
  // loaded host counts as without it).
  for (const nlohmann::json& c : again_json["points"][0]["callback_p50_ms"]) {
    const nlohmann::json& n = c["invocations"];
    const int realtime = n["realtime"][0].get<int>();
    EXPECT_EQ(n["compared"], realtime == 0
                                 ? n["virtual"].get<int>()
                                 : std::min(n["virtual"].get<int>(), realtime))
        << c["name"];
  }
  for (const char* name : {"fidelity.txt", "fidelity-1-run_to_completion.png",
                           "fidelity-1-processor_sharing.png"}) {
    EXPECT_TRUE(fs::is_regular_file(again / name)) << name;
  }
  EXPECT_FALSE(fs::exists(again / "runs"));
  const CommandRun no_runs = Adse("fidelity --compare " + again.string());
  EXPECT_EQ(no_runs.exit_code, 2) << no_runs.out;
  EXPECT_NE(no_runs.out.find((again / "runs").string() + ": no such folder"),
            std::string::npos)
      << no_runs.out;
  const CommandRun mixed =
      Adse("fidelity " + file + " --compare " + both.string());
  EXPECT_EQ(mixed.exit_code, 2) << mixed.out;
  EXPECT_NE(mixed.out.find("excludes --compare"), std::string::npos)
      << mixed.out;
  const CommandRun neither = Adse("fidelity --points cores=1");
  EXPECT_EQ(neither.exit_code, 2) << neither.out;
  EXPECT_NE(neither.out.find("expected a scenario and --points, or --compare"),
            std::string::npos)
      << neither.out;
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

TEST(CliFidelityTest,
     AFidelityCallThatFailsAtAPointKeepsWhatItComparedAndSaysWhere) {
  // The second point's real-time run is refused (a CPU quota cannot stand
  // for a clock above the host's), after the first point was compared.
  const std::string file = WriteScenario(
      "fidelity_stops",
      Replaced(Replaced(ReadText(std::string(ADSE_SOURCE_DIR) +
                                 "/scenarios/fidelity_small.yaml"),
                        "timeout_s: 30", "timeout_s: 4"),
               "values: [1.0, 1.2, 1.5, 1.8, 2.1]", "values: [1.0, 9.9]"));
  const fs::path out = adse::testing::TestScratch() / "adse_cli_fidelity_stops";
  fs::remove_all(out);
  const CommandRun run =
      Adse("fidelity " + file +
           " --points cores=1,freq_ghz=1,lidar_hz=7 "
           "cores=1,freq_ghz=9.9,lidar_hz=7 --runs 1 --perturbed-runs 0 "
           "--clock-by quota -o " +
           out.string());
  EXPECT_NE(run.exit_code, 0) << run.out;
  const std::string text = ReadText((out / "fidelity.txt").string());
  EXPECT_NE(text.find("cores=1,freq_ghz=1,lidar_hz=7: virtual"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("stopped at point 2 of 2 "
                      "(cores=1,freq_ghz=9.9,lidar_hz=7): platform.clock_by: "
                      "quota"),
            std::string::npos)
      << text;
  std::ifstream json_in(out / "fidelity.json");
  const nlohmann::json json = nlohmann::json::parse(json_in, nullptr, false);
  ASSERT_FALSE(json.is_discarded());
  EXPECT_EQ(json["points"].size(), 1u);
  EXPECT_EQ(json["stopped"]["at_point"], 2);
  EXPECT_EQ(json["stopped"]["of"], 2);
  EXPECT_TRUE(fs::is_regular_file(out / "runs/1-realtime-1.h5"));
  EXPECT_FALSE(fs::exists(out / "runs/2-virtual.h5"));
}

TEST(CliFidelityTest,
     AFidelityCallWhosePointRunsCannotBeWrittenSaysWhereItStopped) {
  // A folder where the second point's virtual run file goes: the runs are
  // made, but cannot be kept.
  const std::string file =
      WriteScenario("fidelity_unwritable",
                    Replaced(ReadText(std::string(ADSE_SOURCE_DIR) +
                                      "/scenarios/fidelity_small.yaml"),
                             "timeout_s: 30", "timeout_s: 4"));
  const fs::path out =
      adse::testing::TestScratch() / "adse_cli_fidelity_unwritable";
  fs::remove_all(out);
  fs::create_directories(out / "runs/2-virtual.h5");
  const CommandRun run =
      Adse("fidelity " + file +
           " --points cores=1,freq_ghz=1,lidar_hz=7 "
           "cores=1,freq_ghz=1.2,lidar_hz=7 --runs 1 --perturbed-runs 0 -o " +
           out.string());
  EXPECT_EQ(run.exit_code, 1) << run.out;
  const std::string text = ReadText((out / "fidelity.txt").string());
  EXPECT_NE(text.find("stopped at point 2 of 2 "
                      "(cores=1,freq_ghz=1.2,lidar_hz=7): "),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("point 1 is compared above"), std::string::npos) << text;
  std::ifstream json_in(out / "fidelity.json");
  const nlohmann::json json = nlohmann::json::parse(json_in, nullptr, false);
  ASSERT_FALSE(json.is_discarded());
  EXPECT_EQ(json["points"].size(), 1u);
  EXPECT_EQ(json["stopped"]["at_point"], 2);
  EXPECT_NE(json["stopped"]["error"].get<std::string>().find("2-virtual.h5"),
            std::string::npos)
      << json.dump(1);
  EXPECT_TRUE(fs::is_regular_file(out / "runs/1-virtual.h5"));
  EXPECT_FALSE(fs::exists(out / "fidelity-2.png"));
}

}  // namespace
