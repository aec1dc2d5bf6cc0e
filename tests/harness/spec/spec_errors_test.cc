// Bad scenarios: every class of mistake gives a located, named error.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "harness/spec/spec_parser.h"
#include "tests/testing/temp_files.h"

namespace adse::spec {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// Valid on its own; tests replace or append lines. Line numbers matter.
constexpr char kHead[] = R"(adse: 1
world:
  map: {generate: grid}
task:
  start: {x: 0, y: 0}
  goal: {x: 100, y: 0}
design_space:
  cores: {bind: platform.cores, range: [1, 4]}
)";

std::string ErrorOf(const std::string& text, const std::string& base_dir = "") {
  Result<Spec> spec = ParseSpec(text, "bad.yaml", base_dir);
  EXPECT_FALSE(spec.ok()) << "parsed although it should not:\n" << text;
  if (spec.ok()) return "";
  EXPECT_EQ(spec.status().code(), Status::Code::kInvalidArgument);
  return spec.status().message();
}

// The message names the field and its place "bad.yaml:<line>:<col>".
void ExpectError(const std::string& text, const std::string& field, int line,
                 const std::string& detail = "") {
  const std::string message = ErrorOf(text);
  const std::string location = "bad.yaml:" + std::to_string(line) + ":";
  bool found = false;
  std::istringstream lines(message);
  for (std::string l; std::getline(lines, l);) {
    if (l.rfind(location, 0) == 0 &&
        l.find(": error: " + field + ": expected ") != std::string::npos &&
        l.find(detail) != std::string::npos) {
      found = true;
    }
  }
  EXPECT_TRUE(found) << "wanted " << location << " ... " << field << " ... "
                     << detail << "\ngot:\n"
                     << message;
}

TEST(SpecErrorsTest, HeadIsValid) {
  Result<Spec> spec = ParseSpec(kHead, "bad.yaml", "");
  ASSERT_TRUE(spec.ok()) << spec.status().message();
}

TEST(SpecErrorsTest, MessageFormatIsFileLineColumnFieldExpectedFound) {
  const std::string message = ErrorOf(std::string(kHead) + "world2: 1\n");
  EXPECT_EQ(message,
            "bad.yaml:9:1: error: world2: expected a key among {adse, name, "
            "world, task, stack, platform, design_space, cost, objectives, "
            "constraints, exploration, llm, harness, output}, found 'world2' "
            "(did you mean 'world'?)");
}

TEST(SpecErrorsTest, StringWhereANumberIsExpected) {
  ExpectError(std::string(kHead) + "harness: {run_timeout_s: soon}\n",
              "harness.run_timeout_s", 9, "found 'soon'");
  std::string text = kHead;
  text.replace(text.find("{x: 100, y: 0}"), 14, "{x: far, y: 0}");
  ExpectError(text, "task.goal.x", 6, "expected a number");
}

TEST(SpecErrorsTest, MapWhereAListIsExpected) {
  ExpectError(std::string(kHead) + "constraints: {completed: 1}\n",
              "constraints", 9, "found a map");
  ExpectError(std::string(kHead) + "objectives: nav_time_s\n", "objectives", 9,
              "expected a list");
}

TEST(SpecErrorsTest, AClockQuotaNeedsTheRealTimePlatform) {
  ExpectError(std::string(kHead) + "platform: {clock_by: quota}\n",
              "platform.clock_by", 9, "expected kind: cgroup beside it");
  ExpectError(std::string(kHead) + "platform: {kind: cgroup, clock_by: cap}\n",
              "platform.clock_by", 9, "padding, quota");
  ExpectError(std::string(kHead) + "platform: {kind: cgroup, host_ghz: -1}\n",
              "platform.host_ghz", 9);
  Result<Spec> quota = ParseSpec(
      std::string(kHead) +
          "platform: {kind: cgroup, clock_by: quota, host_ghz: 2.6}\n",
      "ok.yaml", "");
  ASSERT_TRUE(quota.ok()) << quota.status().message();
  EXPECT_EQ(quota->platform.clock_by, ClockBy::kQuota);
  EXPECT_DOUBLE_EQ(quota->platform.host_ghz, 2.6);
  // The normalised spec carries both, and reads back the same.
  Result<Spec> again = ParseSpec(NormalizedYaml(*quota), "again.yaml", "/");
  ASSERT_TRUE(again.ok()) << again.status().message();
  EXPECT_EQ(again->platform.clock_by, ClockBy::kQuota);
  EXPECT_DOUBLE_EQ(again->platform.host_ghz, 2.6);
}

TEST(SpecErrorsTest, ProcessorSharingIsTheVirtualPlatformsDispatch) {
  ExpectError(std::string(kHead) +
                  "platform: {kind: cgroup, dispatch: processor_sharing}\n",
              "platform.dispatch", 9, "expected kind: virtual beside it");
  ExpectError(std::string(kHead) + "platform: {dispatch: shared}\n",
              "platform.dispatch", 9, "run_to_completion, processor_sharing");
  Result<Spec> shared = ParseSpec(
      std::string(kHead) + "platform: {dispatch: processor_sharing}\n",
      "ok.yaml", "");
  ASSERT_TRUE(shared.ok()) << shared.status().message();
  EXPECT_EQ(shared->platform.dispatch, Dispatch::kProcessorSharing);
  Result<Spec> again = ParseSpec(NormalizedYaml(*shared), "again.yaml", "/");
  ASSERT_TRUE(again.ok()) << again.status().message();
  EXPECT_EQ(again->platform.dispatch, Dispatch::kProcessorSharing);
  // The default is not written, so older normalised texts stay the same.
  Result<Spec> plain = ParseSpec(kHead, "ok.yaml", "");
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(NormalizedYaml(*plain).find("dispatch"), std::string::npos);
}

TEST(SpecErrorsTest, WaypointsAreAListOfPlacesEachLocated) {
  std::string text = kHead;
  text.replace(text.find("  goal:"), 7, "  via: {x: 5, y: 0}\n  goal:");
  ExpectError(text, "task.via", 6, "a list of at most 100 places");
  text = kHead;
  text.replace(text.find("  goal:"), 7,
               "  via: [{x: 5, y: 0}, {x: 5, edge: E1}]\n  goal:");
  ExpectError(text, "task.via[1]", 6, "either {x, y} or {edge, pos_m, lane}");
}

TEST(SpecErrorsTest, UnknownKeyWithSuggestion) {
  std::string text = kHead;
  text.replace(text.find("goal:"), 5, "gaol:");
  const std::string message = ErrorOf(text);
  EXPECT_THAT(message, HasSubstr("bad.yaml:6:3: error: task.gaol: expected a "
                                 "key among {kind, start, via, goal, "
                                 "speed_limit_kmh, timeout_s, "
                                 "stall_timeout_s, traffic_stall_timeout_s, "
                                 "cases}, "
                                 "found 'gaol' "
                                 "(did you mean 'goal'?)"));
  // ... and the now missing goal is reported too.
  EXPECT_THAT(message, HasSubstr("task.goal: expected a place"));
}

TEST(SpecErrorsTest, MisspelledEnumValueWithSuggestion) {
  std::string text = kHead;
  text.replace(text.find("grid"), 4, "gird");
  ExpectError(text, "world.map.generate", 3, "(did you mean 'grid'?)");
  ExpectError(std::string(kHead) + "exploration: {strategy: nsga}\n",
              "exploration.strategy", 9, "(did you mean 'nsga2'?)");
}

TEST(SpecErrorsTest, AnUnknownKnobRoleNamesTheRoles) {
  std::string text = kHead;
  text.replace(text.find("range: [1, 4]"), 13, "range: [1, 4], role: core");
  ExpectError(text, "design_space.cores.role", 8,
              "none, cores, frequency, sensor_rate, downsample (what the "
              "knob stands for), found 'core' (did you mean 'cores'?)");
}

TEST(SpecErrorsTest, ValetGoalForms) {
  const std::string head = R"(adse: 1
world:
  map: {generate: grid}
task:
  kind: valet_parking
  start: {x: 0, y: 0}
)";
  const std::string space =
      "design_space:\n  cores: {bind: platform.cores, range: [1, 4]}\n";
  ExpectError(head + "  goal: {slot: s1, x: 3, y: 4}\n" + space, "task.goal", 7,
              "fields of more than one");
  ExpectError(head + "  goal: {slot: s1, yaw_deg: 400}\n" + space,
              "task.goal.yaw_deg", 7);
  ExpectError(
      head + "  goal: {slot: s1, yaw_deg: 90, yaw_tolerance_deg: 0}\n" + space,
      "task.goal.yaw_tolerance_deg", 7);
  // Only a goal may name a slot.
  ExpectError(std::string("adse: 1\nworld:\n  map: {generate: grid}\ntask:\n") +
                  "  start: {slot: s1}\n  goal: {x: 1, y: 1}\n" + space,
              "task.start.slot", 5, "found 'slot'");
}

TEST(SpecErrorsTest, DuplicateKey) {
  ExpectError(std::string(kHead) + "task:\n  kind: valet_parking\n", "task", 9,
              "found 'task' again (first at line 4)");
  ExpectError(
      std::string(kHead) + "platform: {cores: 2, freq_ghz: 1, cores: 3}\n",
      "platform.cores", 9, "again");
}

TEST(SpecErrorsTest, EmptyRange) {
  std::string text = kHead;
  text.replace(text.find("range: [1, 4]"), 13, "range: []");
  ExpectError(text, "design_space.cores.range", 8, "two numbers");
  text = kHead;
  text.replace(text.find("range: [1, 4]"), 13, "values: []");
  ExpectError(text, "design_space.cores.values", 8, "at least one value");
}

TEST(SpecErrorsTest, InvertedRange) {
  std::string text = kHead;
  text.replace(text.find("range: [1, 4]"), 13, "range: [8, 2]");
  ExpectError(text, "design_space.cores.range", 8,
              "found [8, 2] (an inverted range)");
}

TEST(SpecErrorsTest, RangeAndValuesTogetherOrNeither) {
  std::string text = kHead;
  text.replace(text.find("range: [1, 4]"), 13, "range: [1, 4], values: [2]");
  ExpectError(text, "design_space.cores", 8, "found both");
  text = kHead;
  text.replace(text.find(", range: [1, 4]"), 15, "");
  ExpectError(text, "design_space.cores", 8, "found neither");
}

TEST(SpecErrorsTest, DuplicateValues) {
  ExpectError(std::string(kHead) +
                  "  hz: {bind: stack.lidar.rate_hz, values: [7, 14, 7]}\n",
              "design_space.hz.values[2]", 9, "distinct values");
}

TEST(SpecErrorsTest, ValuesOutsideTheTargetRange) {
  ExpectError(std::string(kHead) +
                  "  hz: {bind: stack.lidar.rate_hz, values: [7, 500]}\n",
              "design_space.hz.values[1]", 9, "found 500");
  ExpectError(std::string(kHead) +
                  "  beams: {bind: stack.lidar.beams, values: [8, 16.5]}\n",
              "design_space.beams.values[1]", 9, "integers");
  std::string text = kHead;
  text.replace(text.find("range: [1, 4]"), 13, "range: [0, 4]");
  ExpectError(text, "design_space.cores.range", 8, "found 0");
}

TEST(SpecErrorsTest, BindToANonExistentTarget) {
  ExpectError(
      std::string(kHead) + "  hz: {bind: stack.lidar.rate_hzz, values: [7]}\n",
      "design_space.hz.bind", 9, "(did you mean 'stack.lidar.rate_hz'?)");
  ExpectError(
      std::string(kHead) + "  m: {bind: platform.memory, values: [1]}\n",
      "design_space.m.bind", 9, "found 'platform.memory'");
}

TEST(SpecErrorsTest, TwoParametersBindTheSameTarget) {
  ExpectError(std::string(kHead) + "  n: {bind: platform.cores, values: [2]}\n",
              "design_space.n.bind", 9, "already bound by 'cores'");
}

TEST(SpecErrorsTest, ParameterNameMustBeAnIdentifier) {
  ExpectError(std::string(kHead) +
                  "  lidar-hz: {bind: stack.lidar.rate_hz, values: [7]}\n",
              "design_space.lidar-hz", 9, "usable in expressions");
  ExpectError(std::string(kHead) +
                  "  nav_time_s: {bind: stack.lidar.rate_hz, values: [7]}\n",
              "design_space.nav_time_s", 9, "not a metric name");
}

TEST(SpecErrorsTest, StartPointOutsideTheSpace) {
  ExpectError(std::string(kHead) + "exploration:\n  start_from: {cores: 6}\n",
              "exploration.start_from.cores", 10, "found 6");
  ExpectError(
      std::string(kHead) + "exploration:\n  start_from: {cores: 2, corez: 1}\n",
      "exploration.start_from.corez", 10, "(did you mean 'cores'?)");
  ExpectError(std::string(kHead) +
                  "  hz: {bind: stack.lidar.rate_hz, values: [7]}\n"
                  "exploration:\n  start_from: {cores: 2}\n",
              "exploration.start_from", 11, "no value for hz");
}

TEST(SpecErrorsTest, MissingMapFile) {
  std::string text = kHead;
  text.replace(text.find("{generate: grid}"), 16, "{net: maps/none.net.xml}");
  const std::string message = ErrorOf(text, "/nonexistent-adse-dir");
  EXPECT_THAT(message,
              HasSubstr("bad.yaml:3:14: error: world.map.net: expected an "
                        "existing SUMO network file"));
  EXPECT_THAT(message, HasSubstr("/nonexistent-adse-dir/maps/none.net.xml"));
}

TEST(SpecErrorsTest, AProfileNeedsTheCountedModelAndNoCalibration) {
  const std::string dir = ADSE_SOURCE_DIR;  // README.md stands for a file
  EXPECT_THAT(
      ErrorOf(std::string(kHead) + "platform: {profile: none.yaml}\n", dir),
      HasSubstr("platform.profile: expected an existing cost profile "
                "file, found 'none.yaml' (no such file: " +
                dir + "/none.yaml)"));
  EXPECT_THAT(
      ErrorOf(std::string(kHead) + "platform: {profile: README.md}\n", dir),
      HasSubstr("platform.profile: expected cost_model: counted beside it, "
                "found cost_model: measured"));
  EXPECT_THAT(
      ErrorOf(std::string(kHead) + "platform: {calibration: README.md}\n", dir),
      HasSubstr("platform.calibration: expected cost_model: counted beside "
                "it, found cost_model: measured (a calibration costs the "
                "counted model's callbacks)"));
  EXPECT_THAT(ErrorOf(std::string(kHead) +
                          "platform: {cost_model: counted, profile: README.md, "
                          "calibration: README.md}\n",
                      dir),
              HasSubstr("platform.profile: expected a profile or a "
                        "calibration, not both"));
  Result<Spec> ok =
      ParseSpec(std::string(kHead) +
                    "platform: {cost_model: counted, profile: README.md}\n",
                "ok.yaml", dir);
  ASSERT_TRUE(ok.ok()) << ok.status().ToString();
  EXPECT_EQ(ok->platform.profile, dir + "/README.md");
}

TEST(SpecErrorsTest, MapFileThatIsNotASumoNetwork) {
  const std::string dir = adse::testing::TestScratch().string();
  std::ofstream(dir + "/x.net.xml") << "<html>not a network</html>\n";
  std::string text = kHead;
  text.replace(text.find("{generate: grid}"), 16, "{net: x.net.xml}");
  const std::string message = ErrorOf(text, dir);
  EXPECT_THAT(message, HasSubstr("bad.yaml:3:14: error: world.map.net: "
                                 "expected a SUMO network file"));
}

TEST(SpecErrorsTest, MapNeedsExactlyOneSource) {
  std::string text = kHead;
  text.replace(text.find("{generate: grid}"), 16,
               "{generate: grid, net: a.net.xml}");
  ExpectError(text, "world.map", 3, "found both");
  text = kHead;
  text.replace(text.find("{generate: grid}"), 16, "{}");
  ExpectError(text, "world.map", 3, "found neither");
  text = kHead;
  text.replace(text.find("{generate: grid}"), 16,
               "{generate: grid, params: {number: 40, lenght_m: 50}}");
  ExpectError(text, "world.map.params.number", 3, "in [2, 12]");
  ExpectError(text, "world.map.params.lenght_m", 3, "did you mean 'length_m'");
}

TEST(SpecErrorsTest, NonPositiveRatesAndTimeouts) {
  ExpectError(std::string(kHead) + "stack: {lidar: {rate_hz: 0}}\n",
              "stack.lidar.rate_hz", 9, "in [0.5, 100]");
  ExpectError(std::string(kHead) + "harness: {run_timeout_s: 0}\n",
              "harness.run_timeout_s", 9, "a number > 0");
  ExpectError(std::string(kHead) + "llm: {timeout_s: -5}\n", "llm.timeout_s", 9,
              "a number > 0");
  std::string text = kHead;
  text.replace(text.find("  goal:"), 0,
               "  timeout_s: 0\n  speed_limit_kmh: -1\n");
  ExpectError(text, "task.timeout_s", 6, "a number > 0");
  ExpectError(text, "task.speed_limit_kmh", 7, "a number in (0, 300]");
  text = kHead;
  text.replace(text.find("  goal:"), 0, "  stall_timeout_s: -1\n");
  ExpectError(text, "task.stall_timeout_s", 6, "a number >= 0");
  text = kHead;
  text.replace(text.find("  map:"), 0, "  step_s: 0\n");
  ExpectError(text, "world.step_s", 3, "a number in [0.001, 1]");
  text = kHead;
  // Under SUMO's smallest step, said at its line (not by SUMO's loader).
  text.replace(text.find("  map:"), 0, "  step_s: 1e-9\n");
  ExpectError(text, "world.step_s", 3, "a number in [0.001, 1]");
  ExpectError(std::string(kHead) + "exploration: {budget: 0, batch: -1}\n",
              "exploration.budget", 9, "an integer in [1, ");
  ExpectError(std::string(kHead) + "exploration: {budget: 0, batch: -1}\n",
              "exploration.batch", 9, "an integer in [1, ");
  ExpectError(std::string(kHead) + "exploration: {confirm_runs: -1}\n",
              "exploration.confirm_runs", 9, "an integer in [0, ");
  ExpectError(std::string(kHead) + "exploration: {initial_points: 1.5}\n",
              "exploration.initial_points", 9, "an integer in [0, ");
  ExpectError(std::string(kHead) +
                  "harness: {memory_mb: 0, cores_per_worker: 0, replicas: 0, "
                  "retries: -1, workers: 0}\n",
              "harness.workers", 9, "'auto' or an integer >= 1");
}

TEST(SpecErrorsTest, OtherBoundedNumbers) {
  std::string text = kHead;
  text.replace(text.find("  map:"), 0,
               "  traffic: {parked_occupancy: 1.5, flows: [{from: A, to: B, "
               "vehicles_per_hour: 0}]}\n");
  ExpectError(text, "world.traffic.parked_occupancy", 3, "in [0, 1]");
  ExpectError(text, "world.traffic.flows[0].vehicles_per_hour", 3, "> 0");
  text = kHead;
  text.replace(text.find("  map:"), 0,
               "  traffic: {signal_program_switch_s: -5}\n");
  ExpectError(text, "world.traffic.signal_program_switch_s", 3,
              "a number >= 0");
  text = kHead;
  text.replace(text.find("{x: 100, y: 0}"), 14,
               "{x: 100, y: 0, tolerance_m: 0}");
  ExpectError(text, "task.goal.tolerance_m", 6, "a number > 0");
  ExpectError(std::string(kHead) + "platform: {cores: 2000}\n",
              "platform.cores", 9, "an integer in [1, 1024]");
}

TEST(SpecErrorsTest, OutputEscapingTheWorkingDirectory) {
  ExpectError(std::string(kHead) + "output: ../elsewhere\n", "output", 9,
              "escapes");
  ExpectError(std::string(kHead) + "output: a/../../x\n", "output", 9,
              "escapes");
  // Staying inside after normalisation, or absolute, is fine.
  Result<Spec> ok =
      ParseSpec(std::string(kHead) + "output: a/../b\n", "bad.yaml", "");
  EXPECT_TRUE(ok.ok()) << ok.status().message();
  ok = ParseSpec(std::string(kHead) + "output: /tmp/results\n", "bad.yaml", "");
  EXPECT_TRUE(ok.ok()) << ok.status().message();
}

TEST(SpecErrorsTest, YamlSyntaxErrorHasItsLocation) {
  const std::string message =
      ErrorOf(std::string(kHead) + "cost: [cores, \nobjectives: }\n");
  EXPECT_THAT(message, HasSubstr("bad.yaml:10:"));
  EXPECT_THAT(message, HasSubstr("error: (file): expected valid YAML"));
  const std::string tabs = ErrorOf("adse: 1\nworld:\n\tmap: x\n");
  EXPECT_THAT(tabs, HasSubstr("bad.yaml:3:"));
}

TEST(SpecErrorsTest, ExpressionErrors) {
  ExpectError(std::string(kHead) + "cost: corez * freq_ghz\n", "cost", 9,
              "unknown name 'corez' (did you mean 'cores'?)");
  ExpectError(std::string(kHead) + "cost: cores *\n", "cost", 9,
              "syntax error");
  ExpectError(
      std::string(kHead) + "constraints: [completed, nav_time <= 400]\n",
      "constraints[1]", 9,
      "unknown name 'nav_time' (did you mean 'nav_time_s'?)");
  ExpectError(std::string(kHead) + "constraints: [nav_time_s = 400]\n",
              "constraints[0]", 9, "use '==' to compare");
}

TEST(SpecErrorsTest, ObjectiveErrors) {
  ExpectError(std::string(kHead) + "objectives: [{minimise: nav_time_s}]\n",
              "objectives[0].minimise", 9, "(did you mean 'minimize'?)");
  ExpectError(std::string(kHead) + "objectives: [{minimize: nav_time}]\n",
              "objectives[0].minimize", 9, "(did you mean 'nav_time_s'?)");
  ExpectError(std::string(kHead) +
                  "objectives: [{minimize: nav_time_s, maximize: "
                  "ctrl_rate_hz}]\n",
              "objectives[0]", 9, "exactly one of minimize or maximize");
}

TEST(SpecErrorsTest, AValetParkingMetricInALaneDrivingTaskIsRefused) {
  ExpectError(std::string(kHead) + "objectives: [{minimize: gear_changes}]\n",
              "objectives[0].minimize", 9,
              "expected metrics a lane_driving run reports, found "
              "'gear_changes', which valet_parking runs alone report");
  ExpectError(
      std::string(kHead) + "constraints: [completed, parking_time_s < 10]\n",
      "constraints[1]", 9,
      "found 'parking_time_s', which valet_parking runs alone "
      "report");
}

TEST(SpecErrorsTest, VersionAndRequiredSections) {
  std::string text = kHead;
  text.replace(0, 7, "adse: 2");
  const std::string message = ErrorOf(text);
  EXPECT_EQ(message,
            "bad.yaml:1:7: error: adse: expected 1, found 2 (unsupported "
            "spec version)");
  const std::string missing = ErrorOf("name: x\n");
  EXPECT_THAT(missing, HasSubstr("error: adse: expected the spec version"));
  EXPECT_THAT(missing, HasSubstr("error: world: expected"));
  EXPECT_THAT(missing, HasSubstr("error: task: expected"));
  EXPECT_THAT(missing, HasSubstr("error: design_space: expected"));
  EXPECT_THAT(ErrorOf(""), HasSubstr("bad.yaml:1:1: error: (top level): "
                                     "expected a scenario map"));
  EXPECT_THAT(ErrorOf("- 1\n- 2\n"), HasSubstr("found a list of 2 items"));
}

TEST(SpecErrorsTest, LlmReplayNeedsAFolder) {
  ExpectError(std::string(kHead) + "llm: {backend: replay}\n",
              "llm.replay_from", 9, "required by backend: replay");
  ExpectError(std::string(kHead) + "llm: {endpoint: localhost:11434}\n",
              "llm.endpoint", 9, "http://");
  ExpectError(std::string(kHead) + "llm: {models: {vison: x}}\n",
              "llm.models.vison", 9, "(did you mean 'vision'?)");
}

TEST(SpecErrorsTest, SlurmTimeLimit) {
  ExpectError(std::string(kHead) + "harness:\n  slurm: {time_limit: 2h}\n",
              "harness.slurm.time_limit", 10, "a Slurm time limit");
}

TEST(SpecErrorsTest, SlurmExtraArgsAndSignalLead) {
  ExpectError(std::string(kHead) + "harness:\n  slurm: {extra_args: [qos]}\n",
              "harness.slurm.extra_args[0]", 10, "starting with '-'");
  ExpectError(
      std::string(kHead) + "harness:\n  slurm: {extra_args: [--array=1-9]}\n",
      "harness.slurm.extra_args[0]", 10,
      "--array is set by adse submit itself");
  ExpectError(
      std::string(kHead) + "harness:\n  slurm: {signal_lead_s: 70000}\n",
      "harness.slurm.signal_lead_s", 10);
  ExpectError(std::string(kHead) + "harness:\n  slurm: {run_estimate_s: 0}\n",
              "harness.slurm.run_estimate_s", 10);
}

TEST(SpecErrorsTest, AllErrorsAreCollectedInFileOrder) {
  const std::string message = ErrorOf(std::string(kHead) +
                                      "harness: {memory_mb: 0}\n"
                                      "output: ../x\n"
                                      "llm: {retries: -1}\n");
  const size_t a = message.find("bad.yaml:9:");
  const size_t b = message.find("bad.yaml:10:");
  const size_t c = message.find("bad.yaml:11:");
  ASSERT_NE(a, std::string::npos) << message;
  ASSERT_NE(b, std::string::npos) << message;
  ASSERT_NE(c, std::string::npos) << message;
  EXPECT_LT(a, b);
  EXPECT_LT(b, c);
}

TEST(SpecErrorsTest, ErrorCountIsCapped) {
  std::string text = kHead;
  for (int i = 0; i < 60; ++i) text += "unknown_" + std::to_string(i) + ": 1\n";
  const std::string message = ErrorOf(text);
  const size_t lines = std::count(message.begin(), message.end(), '\n') + 1;
  EXPECT_LE(lines, static_cast<size_t>(kMaxSpecErrors) + 1);
  EXPECT_THAT(message, HasSubstr("stopped after"));
}

}  // namespace
}  // namespace adse::spec
