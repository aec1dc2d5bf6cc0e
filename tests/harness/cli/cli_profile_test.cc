// `adse profile`: the bundled profile is what importing the trimmed CARET
// report with the bundled mapping writes; bad input is exit 2 with the file
// and field named, and nothing written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
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
using adse::testing::Variant;
using adse::testing::WriteScenario;

std::string TrimmedCaret() {
  return std::string(ADSE_SOURCE_DIR) +
         "/tests/data/caret-autoware-2022.12-trimmed";
}
std::string BundledMapping() {
  return std::string(ADSE_SOURCE_DIR) +
         "/scenarios/profiles/autoware-2022.12-mapping.yaml";
}

TEST(CliProfileTest, ImportWritesTheProfileAndShowPrintsItsTotalLoad) {
  const fs::path out = adse::testing::TestScratch() / "adse_cli_profile.yaml";
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
  const fs::path out =
      adse::testing::TestScratch() / "adse_cli_bad_profile.yaml";
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

  const fs::path mapping =
      adse::testing::TestScratch() / "adse_cli_mapping.yaml";
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

  // -o never over its own mapping, nor over a file that is no profile.
  const std::string mapping_text = ReadText(mapping.string());
  const CommandRun over_map =
      Adse("profile import --caret " + TrimmedCaret() + " --map " +
           mapping.string() + " -o " + mapping.string());
  EXPECT_EQ(over_map.exit_code, 2) << over_map.out;
  EXPECT_NE(over_map.out.find("that is the mapping (--map) being read"),
            std::string::npos)
      << over_map.out;
  const std::string scenario = WriteScenario("not_a_profile", "keep me\n");
  const CommandRun over_other =
      Adse("profile import --caret " + TrimmedCaret() + " --map " +
           BundledMapping() + " -o " + scenario);
  EXPECT_EQ(over_other.exit_code, 2) << over_other.out;
  EXPECT_NE(over_other.out.find("a file that is not a profile (adse profile "
                                "import's YAML) is there"),
            std::string::npos)
      << over_other.out;
  EXPECT_EQ(ReadText(mapping.string()), mapping_text);
  EXPECT_EQ(ReadText(scenario), "keep me\n");

  EXPECT_EQ(Adse("profile import --caret " + TrimmedCaret()).exit_code, 2);
  const CommandRun show = Adse("profile show /nonexistent/profile.yaml");
  EXPECT_EQ(show.exit_code, 2) << show.out;
  EXPECT_NE(show.out.find("/nonexistent/profile.yaml"), std::string::npos);
}

TEST(CliProfileTest, CheckComparesTheChainsOnTheReferenceMachine) {
  const fs::path out = adse::testing::TestScratch() / "adse_cli_profile_check";
  fs::remove_all(out);
  const CommandRun check =
      Adse("profile check " + SmallScenarioPath() + " -o " + out.string());
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

  // A scenario with task.cases checks the case it is told to drive, by
  // default into a folder of that case's.
  const fs::path campaign =
      adse::testing::TestScratch() / "adse_cli_valet_check";
  const std::string valet = WriteScenario(
      "valet_check", Replaced(ReadText(std::string(ADSE_SOURCE_DIR) +
                                       "/scenarios/valet_parking.yaml"),
                              "output: results/valet-parking",
                              "output: " + campaign.string()));
  const fs::path parked = campaign / "profile-check";
  fs::remove_all(campaign);
  const CommandRun nose_in = Adse("profile check " + valet + " --case nose_in");
  ASSERT_EQ(nose_in.exit_code, 0) << nose_in.out;
  EXPECT_NE(nose_in.out.find(", case nose_in: goal_reached"), std::string::npos)
      << nose_in.out;
  EXPECT_TRUE(fs::is_regular_file(parked / "nose_in" / "run.h5"));
  EXPECT_FALSE(fs::exists(parked / "run.h5"));

  // A folder holding what the check does not write is refused before
  // anything runs, and kept.
  std::ofstream(out / "notes.txt") << "mine\n";
  const CommandRun others =
      Adse("profile check " + SmallScenarioPath() + " -o " + out.string());
  EXPECT_EQ(others.exit_code, 2) << others.out;
  EXPECT_NE(others.out.find("notes.txt, which this command does not write"),
            std::string::npos)
      << others.out;
  EXPECT_EQ(others.out.find("simulating"), std::string::npos) << others.out;
  EXPECT_TRUE(fs::exists(out / "run.h5"));

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
