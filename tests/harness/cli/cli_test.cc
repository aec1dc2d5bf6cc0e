// The adse binary as a user runs it: exit codes, messages that cite the
// scenario's lines, and the world check's output folder.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sys/wait.h>

namespace {

namespace fs = std::filesystem;

struct CommandRun {
  int exit_code;
  std::string out;  // stdout and stderr
};

CommandRun Adse(const std::string& args) {
  const std::string command = std::string(ADSE_BINARY_DIR) + "/bin/adse " + args + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  std::string out;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) out.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

std::string Example() { return std::string(ADSE_SOURCE_DIR) + "/scenarios/robotaxi_parking_lot.yaml"; }

// A copy of the robotaxi example with one line replaced.
std::string Variant(const std::string& name, const std::string& from, const std::string& to) {
  std::ifstream in(Example());
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  const fs::path path = fs::temp_directory_path() / ("adse_cli_" + name + ".yaml");
  std::ofstream(path) << text;
  return path.string();
}

TEST(CliTest, ValidateReportsTheRobotaxiSpaceOf280Points) {
  const CommandRun run = Adse("validate --quiet " + Example());
  EXPECT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("design space: 280 points (cores 28 x freq_ghz 5 x lidar_hz 2)"),
            std::string::npos)
      << run.out;
}

TEST(CliTest, ValidatePrintsAReloadableNormalisedSpec) {
  const CommandRun run = Adse("validate --no-world " + Example() + " 2>/dev/null");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const fs::path copy = fs::temp_directory_path() / "adse_cli_normalised.yaml";
  std::ofstream(copy) << run.out;
  const CommandRun again = Adse("validate --quiet --no-world " + copy.string());
  EXPECT_EQ(again.exit_code, 0) << again.out;
  EXPECT_NE(again.out.find("280 points"), std::string::npos);
}

TEST(CliTest, StartOffTheRoadIsReportedAtItsLineWithExitCode2) {
  const std::string file =
      Variant("offroad", "start: {x: 20.0, y: -1.75}", "start: {x: 20.0, y: 6.0}");
  const CommandRun run = Adse("validate -q " + file);
  EXPECT_EQ(run.exit_code, 2) << run.out;
  // The start is on line 16 of the example.
  EXPECT_TRUE(std::regex_search(run.out, std::regex("adse_cli_offroad\\.yaml:16:[0-9]+: error: task\\.start")))
      << run.out;
  EXPECT_NE(run.out.find("off the road network"), std::string::npos) << run.out;
}

TEST(CliTest, UnknownFlowEdgeIsReportedAtItsLine) {
  const std::string file = Variant("flow", "from: E4_W4", "from: E9_W9");
  const CommandRun run = Adse("validate -q " + file);
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_NE(run.out.find("world.traffic.flows[0].from: no edge 'E9_W9'"), std::string::npos) << run.out;
  EXPECT_TRUE(std::regex_search(run.out, std::regex("adse_cli_flow\\.yaml:10:[0-9]+:"))) << run.out;
}

TEST(CliTest, MisspelledKeyGetsADidYouMeanAndNothingIsWritten) {
  const std::string file = Variant("typo", "weather: clear", "wether: clear");
  const fs::path out = fs::temp_directory_path() / "adse_cli_typo_out";
  fs::remove_all(out);
  const CommandRun run = Adse("world " + file + " --follow-ideal -o " + out.string());
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_NE(run.out.find("did you mean 'weather'"), std::string::npos) << run.out;
  EXPECT_FALSE(fs::exists(out));
}

TEST(CliTest, BadFlagsAndMissingFilesExitWith2) {
  EXPECT_EQ(Adse("validate").exit_code, 2);
  EXPECT_EQ(Adse("world " + Example() + " --save-scans -3").exit_code, 2);
  const CommandRun missing = Adse("validate /nonexistent/scenario.yaml");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.out.find("/nonexistent/scenario.yaml"), std::string::npos) << missing.out;
  const CommandRun help = Adse("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("validate"), std::string::npos);
}

TEST(CliTest, WorldFollowIdealReachesTheGoalAndWritesWhatItSaw) {
  const fs::path out = fs::temp_directory_path() / "adse_cli_world_check";
  fs::remove_all(out);
  const CommandRun run = Adse("world " + Example() + " --follow-ideal --json --save-scans 50 -o " + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  std::ifstream summary_file(out / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_TRUE(summary["reached_goal"].get<bool>());
  EXPECT_EQ(summary["collisions"].get<int>(), 0);
  EXPECT_LT(summary["max_lateral_error_m"].get<double>(), 0.35);
  // 168 m of path at 30 km/h with four slow corners.
  EXPECT_NEAR(summary["time_s"].get<double>(), 27.0, 6.0);
  // Scans at the scenario's 10 Hz.
  EXPECT_NEAR(summary["scans"].get<int>(), summary["time_s"].get<double>() * 10, 2);
  EXPECT_TRUE(fs::exists(out / "trajectory.csv"));
  EXPECT_TRUE(fs::exists(out / "ideal_path.csv"));
  EXPECT_TRUE(fs::exists(out / "scans" / "scan_00000.pcd"));
  EXPECT_TRUE(fs::exists(out / "scans" / "scan_00050.pcd"));
  EXPECT_FALSE(fs::exists(out / "scans" / "scan_00010.pcd"));
}

}  // namespace
