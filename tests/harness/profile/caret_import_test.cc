// The CARET importer on the trimmed copy of TIER IV's Autoware report:
// sources are summed quantile by quantile, NDT is divided by its Amdahl
// factor, the bundled profile is exactly what the bundled mapping gives and
// covers adse's whole stack graph, and every bad input is refused with its
// file and field path.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "harness/profile/profile.h"
#include "tests/testing/temp_files.h"

namespace adse::profile {
namespace {

namespace fs = std::filesystem;

const std::string kSource = ADSE_SOURCE_DIR;
const std::string kTrimmed =
    kSource + "/tests/data/caret-autoware-2022.12-trimmed";
const std::string kMapping =
    kSource + "/scenarios/profiles/autoware-2022.12-mapping.yaml";
const std::string kBundled =
    kSource + "/scenarios/profiles/autoware-2022.12-i9-12900kf.yaml";
const std::string kNdt =
    "/localization/pose_estimator/ndt_scan_matcher/callback_1";

// A fresh folder for one test.
fs::path TestDir() { return adse::testing::TestTempDir("adse-caret-import"); }

std::string ReadText(const fs::path& path) {
  return adse::testing::Slurp(path.string());
}

// Replaces the one occurrence of `from` in `text`.
void ReplaceOnce(std::string* text, const std::string& from,
                 const std::string& to) {
  const size_t at = text->find(from);
  ASSERT_NE(at, std::string::npos) << from;
  ASSERT_EQ(text->find(from, at + 1), std::string::npos) << from;
  text->replace(at, from.size(), to);
}

// The bundled mapping with one edit, in `dir`.
std::string MappingWith(const fs::path& dir, const std::string& from = "",
                        const std::string& to = "") {
  std::string text = ReadText(kMapping);
  if (!from.empty()) ReplaceOnce(&text, from, to);
  const fs::path path = dir / "mapping.yaml";
  std::ofstream(path) << text;
  return path.string();
}

// A copy of the trimmed report in `dir` with one edit to an area's stats.
std::string ReportWith(const fs::path& dir, const std::string& area,
                       const std::string& from, const std::string& to) {
  const fs::path copy = dir / "caret";
  fs::copy(kTrimmed, copy, fs::copy_options::recursive);
  const fs::path stats = copy / "analyze_node" / area / "stats_node.yaml";
  std::string text = ReadText(stats);
  ReplaceOnce(&text, from, to);
  std::ofstream(stats) << text;
  return copy.string();
}

double Ms(const stack::CallbackCost& c, double q) {
  for (const stack::CostQuantile& p : c.quantiles) {
    if (p.q == q) return p.cost_s * 1000.0;
  }
  ADD_FAILURE() << "no quantile " << q;
  return 0.0;
}

TEST(CaretImportTest, SourcesAreSummedQuantileByQuantile) {
  Result<Profile> p = ImportCaret(kTrimmed, kMapping);
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  // voxel_filter: localization's range crop, voxel grid and random
  // downsample, from the report.
  const stack::CallbackCost& d = p->costs.callbacks.at("voxel_filter/points");
  EXPECT_NEAR(Ms(d, 0.0), 0.793 + 3.712 + 0.06, 1e-9);
  EXPECT_NEAR(Ms(d, 0.5), 1.707 + 8.311 + 0.145, 1e-9);
  EXPECT_NEAR(Ms(d, 0.95), 4.129 + 20.248 + 0.415, 1e-9);
  EXPECT_NEAR(Ms(d, 0.99), 5.749 + 21.996 + 0.485, 1e-9);
  EXPECT_NEAR(Ms(d, 1.0), 5.884 + 24.087 + 0.517, 1e-9);
  EXPECT_EQ(d.reference_units, 8471);
  const CallbackProvenance& dp = p->provenance.at("voxel_filter/points");
  ASSERT_EQ(dp.sources.size(), 3u);
  EXPECT_EQ(dp.sources[1],
            "/localization/util/voxel_grid_downsample_filter/callback_0");
  EXPECT_NEAR(dp.avg_ms, 2.038 + 9.893 + 0.18, 1e-9);
  // A single source is taken as it is: the top LiDAR's driver.
  const stack::CallbackCost& l =
      p->costs.callbacks.at("lidar_driver/points_raw");
  EXPECT_NEAR(Ms(l, 0.5), 19.189, 1e-9);
  EXPECT_NEAR(Ms(l, 0.95), 36.133, 1e-9);
  EXPECT_EQ(l.reference_units, 8546);
  // ground_filter: the obstacle-segmentation range crop and ground filter.
  const stack::CallbackCost& g = p->costs.callbacks.at("ground_filter/points");
  EXPECT_NEAR(Ms(g, 0.0), 0.761 + 17.838, 1e-9);
  EXPECT_NEAR(Ms(g, 0.5), 1.638 + 33.636, 1e-9);
  EXPECT_NEAR(Ms(g, 0.95), 3.279 + 71.549, 1e-9);
  EXPECT_NEAR(Ms(g, 0.99), 4.903 + 74.74, 1e-9);
  EXPECT_NEAR(Ms(g, 1.0), 5.663 + 77.052, 1e-9);
  EXPECT_EQ(g.reference_units, 13284);
  EXPECT_EQ(g.parallel_fraction, 0.0);
  const CallbackProvenance& gp = p->provenance.at("ground_filter/points");
  ASSERT_EQ(gp.sources.size(), 2u);
  EXPECT_EQ(
      gp.sources[1],
      "/perception/obstacle_segmentation/common_ground_filter/callback_0");
  EXPECT_NEAR(gp.avg_ms, 1.846 + 38.865, 1e-9);
  // The controller: one source, as measured.
  const stack::CallbackCost& c =
      p->costs.callbacks.at("trajectory_follower/control");
  EXPECT_NEAR(Ms(c, 0.5), 1.822, 1e-12);
  EXPECT_NEAR(Ms(c, 0.95), 4.209, 1e-12);
  EXPECT_NEAR(p->provenance.at("trajectory_follower/control").rate_hz, 33.3,
              1e-12);
  EXPECT_EQ(p->costs.reference_ghz, 4.9);
  EXPECT_TRUE(p->source.reference_ghz_assumed);
  EXPECT_NE(p->source.note.find("preemption"), std::string::npos);
}

TEST(CaretImportTest, NdtIsDividedByItsAmdahlFactorAtItsReferenceThreads) {
  Result<Profile> p = ImportCaret(kTrimmed, kMapping);
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  // Measured with 4 threads, p = 0.85: factor 1 - p + p / 4 = 0.3625.
  const stack::CallbackCost& ndt =
      p->costs.callbacks.at("ndt_scan_matcher/points");
  EXPECT_NEAR(Ms(ndt, 0.5), 19.328 / 0.3625,
              1e-6);  // the importer keeps nanoseconds
  EXPECT_NEAR(Ms(ndt, 0.95), 43.792 / 0.3625,
              1e-6);  // the importer keeps nanoseconds
  EXPECT_NEAR(Ms(ndt, 1.0), 55.686 / 0.3625,
              1e-6);  // the importer keeps nanoseconds
  EXPECT_EQ(ndt.parallel_fraction, 0.85);
  EXPECT_EQ(ndt.max_threads, 8);
  // The executor's charge at 4 threads gives the measurement back.
  EXPECT_NEAR(stack::SampleCost(ndt, 0.95) * (1 - 0.85 + 0.85 / 4) * 1000,
              43.792, 1e-6);  // the importer keeps nanoseconds
  // The provenance keeps what was measured, undivided.
  EXPECT_NEAR(p->provenance.at("ndt_scan_matcher/points").avg_ms, 21.173,
              1e-12);

  // Another reference: 2 threads at p = 0.5 divides by 0.75.
  const fs::path dir = TestDir();
  Result<Profile> two = ImportCaret(
      kTrimmed, MappingWith(dir,
                            "parallel_fraction: 0.85\n    max_threads: 8\n"
                            "    reference_threads: 4",
                            "parallel_fraction: 0.5\n    max_threads: 4\n"
                            "    reference_threads: 2"));
  ASSERT_TRUE(two.ok()) << two.status().ToString();
  EXPECT_NEAR(Ms(two->costs.callbacks.at("ndt_scan_matcher/points"), 0.5),
              19.328 / 0.75, 1e-6);  // the importer keeps nanoseconds
}

TEST(CaretImportTest, TheTrimmedReportGivesExactlyTheBundledProfile) {
  Result<Profile> p = ImportCaret(kTrimmed, kMapping);
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  const fs::path out = TestDir() / "profile.yaml";
  ASSERT_TRUE(WriteProfile(out.string(), *p).ok());
  // If this fails, the mapping changed without re-importing (see
  // scenarios/profiles/NOTICE.md for the command) or the trimmed copy lacks
  // a source the mapping now names.
  EXPECT_EQ(ReadText(out), ReadText(kBundled));
}

TEST(CaretImportTest, TheBundledProfileParsesAndCoversEveryStackCallback) {
  Result<Profile> p = ReadProfile(kBundled);
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  Result<std::vector<std::string>> names = StackCallbackNames();
  ASSERT_TRUE(names.ok()) << names.status().ToString();
  for (const std::string& name : *names) {
    EXPECT_EQ(p->costs.callbacks.count(name), 1u) << name;
    EXPECT_FALSE(p->provenance.at(name).sources.empty()) << name;
  }
  EXPECT_EQ(p->costs.callbacks.size(), names->size());
  EXPECT_EQ(p->name, "autoware-2022.12-i9-12900kf");
  // About 2.5 cores busy at the reference clock (adse maps a part of
  // Autoware: one LiDAR, no CenterPoint, no occupancy grid).
  EXPECT_GT(TotalLoadCores(*p), 2.0);
  EXPECT_LT(TotalLoadCores(*p), 3.0);
}

TEST(CaretImportTest, TheStackGraphListsItsCallbacksWithoutAWorld) {
  Result<std::vector<std::string>> names = StackCallbackNames();
  ASSERT_TRUE(names.ok()) << names.status().ToString();
  EXPECT_EQ(names->size(), 30u);
  for (const char* expected :
       {"lidar_driver/points_raw", "crop_box_filter_self/points",
        "distortion_corrector/points", "ring_outlier_filter/points",
        "behavior_path_planner/plan", "behavior_velocity_planner/path",
        "obstacle_stop_planner/trajectory", "ndt_scan_matcher/points",
        "ndt_scan_matcher_pose_buffer/ekf_pose", "ekf_localizer/publish",
        "mission_planner/route", "trajectory_follower/control",
        "multi_object_tracker/detections", "multi_object_tracker/publish"}) {
    EXPECT_NE(std::find(names->begin(), names->end(), expected), names->end())
        << expected;
  }
}

// The message starts "<file>:<line>:<column>: error: " and contains each
// of `expected`.
void ExpectLocatedError(const Status& s, const std::string& file,
                        const std::vector<std::string>& expected) {
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(ExitCodeFor(s), 2) << s.ToString();
  const std::string& m = s.message();
  ASSERT_EQ(m.rfind(file + ":", 0), 0u) << m;
  EXPECT_TRUE(std::regex_search(m.substr(file.size()),
                                std::regex("^:[0-9]+:[0-9]+: error: ")))
      << m;
  for (const std::string& e : expected) {
    EXPECT_NE(m.find(e), std::string::npos) << m << "\nwanted: " << e;
  }
}

// Imports and writes as `adse profile import` does: nothing on error.
Status ImportTo(const std::string& caret, const std::string& mapping,
                const fs::path& out) {
  Result<Profile> p = ImportCaret(caret, mapping);
  if (!p.ok()) return p.status();
  return WriteProfile(out.string(), *p);
}

TEST(CaretImportTest, AMissingReportOrMappingIsRefusedByName) {
  const fs::path dir = TestDir();
  const fs::path out = dir / "out.yaml";
  Status s = ImportTo((dir / "nowhere").string(), kMapping, out);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(ExitCodeFor(s), 2);
  EXPECT_NE(s.message().find((dir / "nowhere").string()), std::string::npos);
  EXPECT_NE(s.message().find("expected a CARET report folder holding "
                             "analyze_node/<area>/stats_node.yaml, found "
                             "nothing"),
            std::string::npos)
      << s.message();

  fs::create_directories(dir / "empty/analyze_node/sensing");
  s = ImportTo((dir / "empty").string(), kMapping, out);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("found no stats_node.yaml"), std::string::npos)
      << s.message();

  s = ImportTo(kTrimmed, (dir / "no-mapping.yaml").string(), out);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(ExitCodeFor(s), 2);
  EXPECT_NE(s.message().find((dir / "no-mapping.yaml").string() +
                             ": error: expected a profile mapping"),
            std::string::npos)
      << s.message();
  EXPECT_FALSE(fs::exists(out));
}

TEST(CaretImportTest, AMappingOfTheWrongShapeIsRefusedAtItsField) {
  const fs::path dir = TestDir();
  const fs::path out = dir / "out.yaml";
  // `callbacks:` as a list instead of the entries.
  std::string text = ReadText(kMapping);
  text.resize(text.find("callbacks:\n  # --- sensing"));
  std::ofstream(dir / "list.yaml") << text + "callbacks: [a, b]\n";
  std::string m = (dir / "list.yaml").string();
  ExpectLocatedError(ImportTo(kTrimmed, m, out), m,
                     {"callbacks: expected a map, found a list"});
  m = MappingWith(dir, "reference_units: 8546\n",
                  "reference_units: 8546\n    max_thread: 2\n");
  ExpectLocatedError(
      ImportTo(kTrimmed, m, out), m,
      {"callbacks.lidar_driver/points_raw.max_thread: expected one of the "
       "keys",
       "did you mean 'max_threads'"});
  m = MappingWith(dir, "adse_profile_mapping: 1", "adse_profile_mapping: 7");
  ExpectLocatedError(ImportTo(kTrimmed, m, out), m,
                     {"adse_profile_mapping: expected 1"});
  EXPECT_FALSE(fs::exists(out));
}

TEST(CaretImportTest, ASourceTheReportLacksIsNamedWithCloseMatches) {
  const fs::path dir = TestDir();
  const fs::path out = dir / "out.yaml";
  const std::string m =
      MappingWith(dir, "[/sensing/lidar/top/velodyne_convert_node/callback_0]",
                  "[/sensing/lidar/top/velodyne_convert_node/callback_9]");
  ExpectLocatedError(
      ImportTo(kTrimmed, m, out), m,
      {"callbacks.lidar_driver/points_raw.sources[0]: expected a callback id "
       "of the CARET report",
       "found '/sensing/lidar/top/velodyne_convert_node/callback_9', which the "
       "report lacks",
       "did you mean '/sensing/lidar/top/velodyne_convert_node/callback_0'"});
  EXPECT_FALSE(fs::exists(out));
}

TEST(CaretImportTest, AnUncoveredOrUnknownStackCallbackIsRefused) {
  const fs::path dir = TestDir();
  const fs::path out = dir / "out.yaml";
  std::string m = MappingWith(dir, "  trajectory_follower/control:\n",
                              "  not_in_adse/control:\n");
  ExpectLocatedError(ImportTo(kTrimmed, m, out), m,
                     {"callbacks.not_in_adse/control: expected a callback of "
                      "adse's stack graph"});
  m = MappingWith(dir, "  trajectory_follower/control:\n",
                  "  trajectory_folower/control:\n");
  ExpectLocatedError(ImportTo(kTrimmed, m, out), m,
                     {"did you mean 'trajectory_follower/control'"});
  // Removing the entry (its key and body) leaves the callback uncovered.
  std::string text = ReadText(kMapping);
  const size_t at = text.find("  trajectory_follower/control:\n");
  ASSERT_NE(at, std::string::npos);
  text.resize(at);
  std::ofstream(dir / "short.yaml") << text;
  m = (dir / "short.yaml").string();
  Result<std::vector<std::string>> names = StackCallbackNames();
  ASSERT_TRUE(names.ok()) << names.status().ToString();
  ExpectLocatedError(
      ImportTo(kTrimmed, m, out), m,
      {fmt::format("callbacks: expected an entry for each of the {} "
                   "callbacks of adse's stack graph, found none for 1 "
                   "callback(s): trajectory_follower/control",
                   names->size())});
  EXPECT_FALSE(fs::exists(out));
}

TEST(CaretImportTest, BadStatisticsAreRefusedAtTheirFileAndPath) {
  const std::string ndt_path =
      "/localization/pose_estimator/ndt_scan_matcher.callbacks." + kNdt +
      ".Latency.";
  struct Case {
    std::string area, from, to;
    std::vector<std::string> expected;
  };
  const std::vector<Case> cases = {
      {"localization",
       "        p95: 43.792\n",
       "",
       {ndt_path + "p95: expected a number >= 0 (required), found nothing"}},
      {"localization",
       "        p50: 19.328\n",
       "        p50: -1.5\n",
       {ndt_path + "p50: expected a number >= 0, found '-1.5'"}},
      {"localization",
       "        p50: 19.328\n",
       "        p50: .nan\n",
       {ndt_path + "p50: expected a number >= 0, found '.nan'"}},
      {"localization",
       "        p99: 50.105\n",
       "        p99: 12.0\n",
       {ndt_path + "p99: expected a latency >= 43.792 ms (p95)"}},
      {"localization",
       "  callbacks:\n    /localization/pose_estimator/ndt_scan_matcher/"
       "callback_0:",
       "  callbacks: [a]\n  old:\n    /localization/pose_estimator/"
       "ndt_scan_matcher/callback_0:",
       {"/localization/pose_estimator/ndt_scan_matcher.callbacks: expected a "
        "map, found a list"}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.from + " -> " + c.to);
    const fs::path dir = TestDir();
    const std::string caret = ReportWith(dir, c.area, c.from, c.to);
    const fs::path out = dir / "out.yaml";
    ExpectLocatedError(ImportTo(caret, kMapping, out),
                       caret + "/analyze_node/" + c.area + "/stats_node.yaml",
                       c.expected);
    EXPECT_FALSE(fs::exists(out));
  }
}

TEST(CaretImportTest, ACallbackThatNeverRanCannotBeASource) {
  const fs::path dir = TestDir();
  const std::string m = MappingWith(
      dir, "[/planning/mission_planning/mission_planner/callback_0]",
      "[/planning/mission_planning/mission_planner/callback_1]");
  ExpectLocatedError(
      ImportCaret(kTrimmed, m).status(),
      kTrimmed + "/analyze_node/planning/stats_node.yaml",
      {"/planning/mission_planning/mission_planner/callback_1.Latency.min: "
       "expected a measured latency in ms, found '---'",
       "never ran"});
}

TEST(CaretImportTest, TheMappedChainsComeFromThePathStatistics) {
  Result<Profile> p = ImportCaret(kTrimmed, kMapping);
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  ASSERT_EQ(p->chains.size(), 3u);
  const ChainReference& sensing = p->chains.at("sensing");
  EXPECT_EQ(sensing.source, "component_sensing_0");
  EXPECT_NEAR(sensing.avg_ms, 85.125, 1e-12);
  EXPECT_NEAR(sensing.p95_ms, 116.72, 1e-12);
  EXPECT_NEAR(sensing.worst_max_ms, 250.757, 1e-12);
  EXPECT_NEAR(p->chains.at("localization").avg_ms, 46.314, 1e-12);
  EXPECT_NEAR(p->chains.at("sensing_to_control").avg_ms, 370.46, 1e-12);
  EXPECT_NEAR(p->chains.at("sensing_to_control").worst_max_ms, 666.593, 1e-12);
}

TEST(CaretImportTest, AChainTheReportLacksOrAnUnknownChainIsRefused) {
  const fs::path dir = TestDir();
  const fs::path out = dir / "out.yaml";
  std::string m = MappingWith(dir, "sensing: component_sensing_0",
                              "sensing: component_sensing_9");
  ExpectLocatedError(ImportTo(kTrimmed, m, out), m,
                     {"chains.sensing: expected a target_path_name of",
                      "found 'component_sensing_9', which it lacks",
                      "did you mean 'component_sensing_0'"});
  m = MappingWith(dir, "sensing: component_sensing_0",
                  "perception: component_sensing_0");
  ExpectLocatedError(ImportTo(kTrimmed, m, out), m, {"chains.perception"});
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace adse::profile
