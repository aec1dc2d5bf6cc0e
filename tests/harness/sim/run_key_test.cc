#include "harness/sim/run_key.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "harness/spec/spec_parser.h"
#include "tests/testing/temp_files.h"

namespace adse::sim {
namespace {

spec::Spec Small() {
  Result<spec::Spec> spec = spec::LoadSpec(std::string(ADSE_SOURCE_DIR) +
                                           "/scenarios/robotaxi_small.yaml");
  EXPECT_TRUE(spec.ok()) << spec.status().ToString();
  return std::move(spec).value();
}

const spec::DesignPoint kPoint = {
    {"cores", 4}, {"freq_ghz", 2.1}, {"lidar_hz", 7}};

std::string Key(const spec::Spec& s, const spec::DesignPoint& p = kPoint,
                uint64_t seed = 3) {
  Result<std::string> key = RunKey(s, p, seed);
  EXPECT_TRUE(key.ok()) << key.status().ToString();
  return key.ok() ? *key : "";
}

TEST(RunKeyTest, IgnoresExplorationHarnessAndOutput) {
  const spec::Spec base = Small();
  spec::Spec other = base;
  other.exploration.strategy = "ga";
  other.exploration.budget = 99;
  other.harness.workers = 7;
  other.output = "elsewhere";
  other.name = "renamed";
  EXPECT_EQ(Key(base), Key(other));
  EXPECT_EQ(Key(base).size(), 64u);
}

TEST(RunKeyTest, ChangesWithWhatChangesARun) {
  const spec::Spec base = Small();
  const std::string key = Key(base);
  EXPECT_NE(key,
            Key(base, {{"cores", 16}, {"freq_ghz", 2.1}, {"lidar_hz", 7}}));
  EXPECT_NE(key, Key(base, kPoint, 4));
  spec::Spec knob = base;
  ASSERT_TRUE(knob.stack.Set("control.rate_hz", 20).ok());
  EXPECT_NE(key, Key(knob));
  spec::Spec traffic = base;
  traffic.world.traffic.flows.at(0).vehicles_per_hour = 61;
  EXPECT_NE(key, Key(traffic));
  spec::Spec goal = base;
  goal.task.goal.x_m += 0.5;
  EXPECT_NE(key, Key(goal));
  spec::Spec platform = base;
  platform.platform.cost_scale = 20;
  EXPECT_NE(key, Key(platform));
  spec::Spec shared = base;
  shared.platform.dispatch = spec::Dispatch::kProcessorSharing;
  EXPECT_NE(key, Key(shared));
}

// Keys of maps without signals stay as they were before the ego obeyed
// them; keys of maps with signals hold the traffic_light knobs.
TEST(RunKeyTest, TrafficLightKnobsEnterOnlyKeysOfMapsWithSignals) {
  const spec::Spec lot = Small();  // a generated parking lot
  spec::Spec lot_knob = lot;
  ASSERT_TRUE(lot_knob.stack.Set("traffic_light.detector_latency_s", 0.5).ok());
  EXPECT_EQ(Key(lot), Key(lot_knob));

  const std::string dir =
      (adse::testing::TestScratch() / "adse_run_key_signals").string();
  std::filesystem::create_directories(dir);
  auto net_key = [&](const std::string& text, double latency_s) {
    const std::string net = dir + "/map.net.xml";
    std::ofstream(net) << text;
    spec::Spec s = lot;
    s.world.map.generator.clear();
    s.world.map.generator_params.clear();
    s.world.map.net_path = net;
    EXPECT_TRUE(
        s.stack.Set("traffic_light.detector_latency_s", latency_s).ok());
    return Key(s);
  };
  const std::string plain = "<net>\n  <edge id=\"a\"/>\n</net>\n";
  const std::string signalled =
      "<net>\n  <tlLogic id=\"J\" type=\"static\"/>\n</net>\n";
  EXPECT_EQ(net_key(plain, 0.1), net_key(plain, 0.5));
  EXPECT_NE(net_key(signalled, 0.1), net_key(signalled, 0.5));
  std::filesystem::remove_all(dir);
}

// A knob the keys leave out would make every point drive alike: sweeping
// it is refused, naming the parameter.
TEST(RunKeyTest, SweepingAKnobThatCannotActIsRefusedByName) {
  EXPECT_TRUE(CheckKnobsAct(Small()).ok());
  auto with_knob = [](spec::Spec s, const std::string& bind) {
    spec::DesignParameter knob;
    knob.name = "knob";
    knob.bind = bind;
    knob.values = {1, 2};
    s.design_space.parameters.push_back(knob);
    return s;
  };
  const Status parking =
      CheckKnobsAct(with_knob(Small(), "stack.parking.rate_hz"));
  EXPECT_EQ(parking.code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(parking.message().rfind("design_space.knob: binds "
                                    "stack.parking.rate_hz, which acts only "
                                    "in valet_parking tasks",
                                    0),
            0u)
      << parking.message();
  const Status signals = CheckKnobsAct(
      with_knob(Small(), "stack.traffic_light.detector_latency_s"));
  EXPECT_EQ(signals.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(signals.message().find("acts only on maps with traffic signals, "
                                   "and world.map has none"),
            std::string::npos)
      << signals.message();
  // Where they act, they may be swept.
  spec::Spec valet = Small();
  valet.task.kind = world::TaskKind::kValetParking;
  EXPECT_TRUE(CheckKnobsAct(with_knob(valet, "stack.parking.rate_hz")).ok());
  Result<spec::Spec> rilsa = spec::LoadSpec(
      std::string(ADSE_SOURCE_DIR) + "/scenarios/rilsa_traffic_light.yaml");
  ASSERT_TRUE(rilsa.ok()) << rilsa.status().ToString();
  EXPECT_TRUE(CheckKnobsAct(*rilsa).ok());
}

TEST(RunKeyTest, ConstraintsEnterOnlyWhenTheyCanStopTheRunEarly) {
  const spec::Spec base = Small();  // nav_time_s <= 60, ctrl_rate_hz >= 1, ...
  spec::Spec off = base;
  off.harness.early_stop = false;
  spec::Spec tighter = base;
  tighter.constraints[0] = "nav_time_s <= 50";
  spec::Spec undecidable = base;  // only constraints decided at the end
  undecidable.constraints = {"completed", "max_deviation_m < 1"};
  spec::Spec undecidable_off = undecidable;
  undecidable_off.harness.early_stop = false;
  EXPECT_NE(Key(base), Key(off));
  EXPECT_NE(Key(base), Key(tighter));
  EXPECT_EQ(Key(undecidable), Key(undecidable_off));
  EXPECT_EQ(Key(undecidable), Key(off));
}

TEST(RunKeyTest, MissingCalibrationFileIsAnError) {
  spec::Spec s = Small();
  s.platform.cost_model = spec::CostModel::kCounted;
  s.platform.profile.clear();
  s.platform.calibration = "/nonexistent/calibration.json";
  Result<std::string> key = RunKey(s, kPoint, 3);
  ASSERT_FALSE(key.ok());
  EXPECT_NE(key.status().message().find("platform.calibration"),
            std::string::npos);
}

TEST(RunKeyTest, AProfileEntersByContent) {
  const std::string bundled =
      std::string(ADSE_SOURCE_DIR) +
      "/scenarios/profiles/autoware-2022.12-i9-12900kf.yaml";
  const std::string copy =
      (adse::testing::TestScratch() / "adse_run_key_profile.yaml").string();
  std::filesystem::copy_file(bundled, copy,
                             std::filesystem::copy_options::overwrite_existing);
  spec::Spec s = Small();  // names the bundled profile
  s.platform.profile = copy;
  const std::string key = Key(s);
  EXPECT_EQ(key, Key(Small()));  // the same content elsewhere
  std::ofstream(copy, std::ios::app) << "# edited\n";
  EXPECT_NE(key, Key(s));
  s.platform.profile = "/nonexistent/profile.yaml";
  Result<std::string> missing = RunKey(s, kPoint, 3);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("platform.profile"),
            std::string::npos);
}

}  // namespace
}  // namespace adse::sim
