// The ego obeys SUMO's traffic signals through its own detector topic, on
// a real net that Debian's sumo-tools ships (RiLSA1: one signalised
// crossing). Costs are counted from the Autoware profile with the signal
// subscription, so the run does not depend on the host.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "analysis/metrics/standing.h"
#include "analysis/runfile/run_file.h"
#include "harness/sim/simulator.h"
#include "harness/spec/spec_parser.h"
#include "stack/world/ideal_driver.h"
#include "stack/world/world.h"
#include "tests/harness/testing/net_scenario.h"
#include "tests/testing/temp_files.h"

namespace adse::sim {
namespace {

constexpr char kRilsa[] =
    "/usr/share/sumo/tools/sumolib/scenario/scenarios/RiLSA1/rilsa1.net.xml";
// nm_1 ends (its stop line) at y = 511.35, heading south; the signal (tls
// "0", link 1) shows red for this link from 0 to 45 s (its program's first
// five phases serve east-west), then green.
constexpr double kStopLineY = 511.35;
constexpr double kGreenAtS = 45.0;

// A lane-driving scenario on `net` from `start` to `goal` (flow-map
// places), costs counted from `profile`.
spec::Spec SignalScenario(
    const std::string& name, const std::string& net, const std::string& start,
    const std::string& goal, int timeout_s,
    const std::string& profile = "autoware-2022.12-i9-12900kf-signals.yaml") {
  return adse::testing::ParseNetScenario({.name = name,
                                          .net = net,
                                          .start = start,
                                          .goal = goal,
                                          .timeout_s = timeout_s,
                                          .profile = profile});
}

spec::Spec RilsaNorthToSouth(
    const std::string& profile = "autoware-2022.12-i9-12900kf-signals.yaml") {
  return SignalScenario("rilsa-signal", kRilsa,
                        "{edge: nm, pos_m: 10, lane: 1}",
                        "{edge: ms, pos_m: 60, lane: 1}", 200, profile);
}

TEST(TrafficLightsTest, TheEgoWaitsAtTheRedLightThenDrivesOnToTheGoal) {
  ASSERT_TRUE(std::filesystem::exists(kRilsa)) << "sumo-tools is not installed";
  const spec::Spec spec = RilsaNorthToSouth();
  Result<runfile::RunData> run =
      SimulatePoint(spec, {{"cores", 16}, {"freq_ghz", 2.1}});
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_EQ(run->termination_reason, "goal_reached");
  EXPECT_TRUE(run->collisions.empty());

  // Never past the stop line while red: the front bumper (3.65 m ahead of
  // the rear axle, heading south) stays north of it, within 0.3 m.
  const double front_m = 2.7 / 2 + 4.6 / 2;
  double crossed_at_s = -1.0;
  for (const runfile::EgoSample& s : run->ego) {
    if (s.t_s < kGreenAtS) {
      ASSERT_GT(s.y_m - front_m, kStopLineY - 0.3) << "at t = " << s.t_s;
    } else if (crossed_at_s < 0 && s.y_m < kStopLineY) {
      crossed_at_s = s.t_s;
    }
  }
  // ... and through the junction once green.
  EXPECT_GT(crossed_at_s, kGreenAtS);

  // The run file says why it stood: red_light, for many seconds (it
  // arrives at about 16 s and waits for the green at 45 s).
  const std::string path =
      (adse::testing::TestScratch() / "adse_traffic_lights_test.h5").string();
  ASSERT_TRUE(runfile::WriteRunFile(path, *run).ok());
  std::vector<std::string> problems;
  EXPECT_TRUE(runfile::CheckRunFile(path, &problems).ok())
      << (problems.empty() ? "" : problems.front());
  Result<runfile::RunData> read = runfile::ReadRunFile(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  std::filesystem::remove(path);
  const analysis::StandingSummary standing = analysis::SummarizeStanding(*read);
  ASSERT_FALSE(standing.by_reason.empty());
  EXPECT_EQ(standing.by_reason.front().reason, StopReason::kRedLight);
  EXPECT_GT(standing.by_reason.front().standing_s, 20.0);
  EXPECT_LT(standing.by_reason.front().standing_s, kGreenAtS);
  // The detector's topic and the planner's subscription are in the graph.
  bool has_topic = false, has_callback = false;
  for (const std::string& t : read->topic_names)
    has_topic |= t == "/perception/traffic_signal";
  for (const runfile::NamedCallback& c : read->callback_info)
    has_callback |= c.name == "behavior_velocity_planner/traffic_signal";
  EXPECT_TRUE(has_topic);
  EXPECT_TRUE(has_callback);
  // The detector's reports are in the run file: red on approach until the
  // green, then green, each published after its look.
  ASSERT_FALSE(read->signals.empty());
  bool red_before_green = false, green_after = false;
  for (const runfile::SignalSample& r : read->signals) {
    EXPECT_GE(r.t_s, r.stamp_s);
    if (r.tls_id.empty()) continue;
    red_before_green |= r.state == SignalState::kRed && r.stamp_s < kGreenAtS;
    green_after |= r.state == SignalState::kGreen && r.stamp_s >= kGreenAtS;
    if (r.state == SignalState::kRed) {
      EXPECT_LT(r.stamp_s, kGreenAtS + 0.5);
    }
    EXPECT_GE(r.stop_line_distance_m, 0.0);
  }
  EXPECT_TRUE(red_before_green);
  EXPECT_TRUE(green_after);
}

TEST(TrafficLightsTest, TheIdealDriverWaitsAtTheRedLightAsTheStackDoes) {
  ASSERT_TRUE(std::filesystem::exists(kRilsa)) << "sumo-tools is not installed";
  const spec::Spec spec = RilsaNorthToSouth();
  auto drive = [&](bool obey) -> Result<world::IdealDriveReport> {
    Result<std::unique_ptr<world::World>> w =
        world::World::Open(WorldSetupFromSpec(spec));
    if (!w.ok()) return w.status();
    world::IdealDriverOptions options;
    options.speed_limit_mps = 40 / 3.6;
    options.timeout_s = 200;
    options.scan = false;
    options.obey_signals = obey;
    Result<world::IdealDriveReport> report =
        world::DriveIdealPath(**w, nullptr, options);
    if (report.ok() && obey) {
      // Never past the stop line while red (front bumper 3.65 m ahead).
      for (const world::TrajectorySample& s : report->trajectory) {
        if (s.t_s < kGreenAtS) {
          EXPECT_GT(s.y_m - (2.7 / 2 + 4.6 / 2), kStopLineY - 0.3)
              << "at t = " << s.t_s;
        }
      }
    }
    return report;
  };
  Result<world::IdealDriveReport> waits = drive(true);
  Result<world::IdealDriveReport> drives_through = drive(false);
  ASSERT_TRUE(waits.ok()) << waits.status().ToString();
  ASSERT_TRUE(drives_through.ok()) << drives_through.status().ToString();
  EXPECT_TRUE(waits->reached_goal);
  EXPECT_GT(waits->red_light_wait_s, 20.0);
  EXPECT_LT(waits->red_light_wait_s, kGreenAtS);
  EXPECT_GT(waits->time_s, kGreenAtS);
  EXPECT_EQ(drives_through->red_light_wait_s, 0.0);
  EXPECT_LT(drives_through->time_s, waits->time_s - 20.0);
}

// tests/data/nets/dead_end_signal.net.xml: a 200 m road of two lanes each
// way ending at a signal (red for the first 60 s, then green) whose only
// link turns back, too tight for the car: the route from `ab` back along
// `ba` turns there in several moves. Until run key v21 the car started
// its moves on red (its first reverse at 23.3 s).
TEST(TrafficLightsTest, ATurnInSeveralMovesThroughASignalStartsOnGreen) {
  constexpr double kTurnGreenAtS = 60.0;
  const spec::Spec spec = SignalScenario(
      "dead_end_signal",
      std::string(ADSE_SOURCE_DIR) + "/tests/data/nets/dead_end_signal.net.xml",
      "{edge: ab, pos_m: 80, lane: 0}", "{edge: ba, pos_m: 150, lane: 0}", 300);
  Result<runfile::RunData> run =
      SimulatePoint(spec, {{"cores", 16}, {"freq_ghz", 2.1}});
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_EQ(run->termination_reason, "goal_reached");
  EXPECT_TRUE(run->collisions.empty());
  // Until the green it neither backs up nor turns (heading east, +x).
  bool turned = false;
  for (const runfile::EgoSample& e : run->ego) {
    if (e.t_s < kTurnGreenAtS) {
      ASSERT_GT(e.v_mps, -0.05) << "at t = " << e.t_s;
      ASSERT_LT(std::abs(e.yaw_rad), 0.2) << "at t = " << e.t_s;
    } else {
      turned |= std::abs(e.yaw_rad) > 3.0;
    }
  }
  EXPECT_TRUE(turned);
  // It stood for the red (it arrives at about 20 s), and says so.
  const analysis::StandingSummary standing = analysis::SummarizeStanding(*run);
  ASSERT_FALSE(standing.by_reason.empty());
  EXPECT_EQ(standing.by_reason.front().reason, StopReason::kRedLight);
  EXPECT_GT(standing.by_reason.front().standing_s, 30.0);
}

TEST(TrafficLightsTest, APlainProfileIsRefusedNamingTheOneWithTheSignals) {
  ASSERT_TRUE(std::filesystem::exists(kRilsa)) << "sumo-tools is not installed";
  Result<runfile::RunData> run =
      SimulatePoint(RilsaNorthToSouth("autoware-2022.12-i9-12900kf.yaml"),
                    {{"cores", 16}, {"freq_ghz", 2.1}});
  ASSERT_FALSE(run.ok());
  EXPECT_EQ(run.status().code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(run.status().message().rfind("platform.profile: ", 0), 0u)
      << run.status().message();
  EXPECT_NE(
      run.status().message().find("autoware-2022.12-i9-12900kf-signals.yaml"),
      std::string::npos)
      << run.status().message();
}

}  // namespace
}  // namespace adse::sim
