// The comparison `adse profile check` prints: chains measured from a
// trace's topic events by message stamp, callbacks from its records, each
// beside what the profile's source measured.
#include "harness/profile/profile_check.h"

#include <gtest/gtest.h>

#include <string>

namespace adse::profile {
namespace {

using stack::TopicEvent;

// A run with topics 0 raw scan, 1 processed scan, 2 NDT pose, 3 fused
// pose, one callback "lidar_driver/points_raw", and two scans.
runfile::RunData TwoScans() {
  runfile::RunData run;
  run.topic_names = {"/sensing/lidar/points_raw", "/sensing/lidar/points",
                     "/localization/ndt_pose", "/localization/pose"};
  run.callback_info.push_back(
      {"lidar_driver/points_raw", 0, runfile::CallbackKind::kSubscription});
  auto& events = run.trace.topic_events;
  // Scan stamped 1.0: raw at 1.00, processed at 1.08, its NDT pose taken
  // by the EKF at 1.13, fused poses at 1.12 (too early) and 1.14.
  events.push_back({TopicEvent::kPublish, 0, -1, 1.00, 0, 1.0});
  events.push_back({TopicEvent::kPublish, 1, 0, 1.08, 0, 1.0});
  events.push_back({TopicEvent::kPublish, 3, 1, 1.12, 0, 0.9});
  events.push_back({TopicEvent::kTake, 2, 1, 1.13, 0, 1.0});
  events.push_back({TopicEvent::kPublish, 3, 1, 1.14, 1, 1.0});
  // Scan stamped 2.0: processed 0.10 s after it arrived; no NDT pose.
  events.push_back({TopicEvent::kPublish, 0, -1, 2.00, 1, 2.0});
  events.push_back({TopicEvent::kPublish, 1, 0, 2.10, 1, 2.0});
  run.trace.callbacks.push_back({0, 0, 1.00, 1.00, 1.08, 0.08});
  run.trace.callbacks.push_back({0, 0, 2.00, 2.00, 2.10, 0.10});
  // Steered by the pose of scan 1.2, its trajectory checked against the
  // objects of scan 1.0: the chain runs through perception.
  run.controls.push_back({1.40, 1.2, 0.0, 0.0, 1.0});
  run.controls.push_back({1.50, 1.2, 0.0, 0.0, -1.0});  // no objects yet
  return run;
}

Profile SourceOf() {
  Profile p;
  p.costs.reference_ghz = 4.9;
  stack::CallbackCost& c = p.costs.callbacks["lidar_driver/points_raw"];
  c.quantiles = {{0.0, 0.05}, {0.95, 0.2}, {1.0, 0.3}};
  p.provenance["lidar_driver/points_raw"].avg_ms = 80.0;
  p.chains["sensing"] = {"component_sensing_0", 85.0, 116.0, 250.0};
  return p;
}

TEST(ProfileCheckTest, ChainsFollowTheScanStampAndSitBesideTheSource) {
  const ProfileCheck check = CompareWithProfile(TwoScans(), SourceOf());
  ASSERT_EQ(check.chains.size(), 3u);
  const CheckRow& sensing = check.chains[0];
  EXPECT_EQ(sensing.name, "sensing");
  EXPECT_EQ(sensing.samples, 2);
  EXPECT_NEAR(sensing.adse_avg_ms, 90.0, 1e-9);
  EXPECT_NEAR(sensing.adse_p95_ms, 100.0, 1e-9);
  ASSERT_TRUE(sensing.source_avg_ms.has_value());
  EXPECT_EQ(*sensing.source_avg_ms, 85.0);
  EXPECT_EQ(*sensing.tolerance, 0.15);
  const CheckRow& localization = check.chains[1];
  EXPECT_EQ(localization.name, "localization");
  EXPECT_EQ(localization.samples, 1);
  // From the processed scan (1.08) to the first fused pose after the take.
  EXPECT_NEAR(localization.adse_avg_ms, 60.0, 1e-9);
  EXPECT_FALSE(localization.source_avg_ms.has_value());
  const CheckRow& to_control = check.chains[2];
  EXPECT_EQ(to_control.samples, 1);
  EXPECT_NEAR(to_control.adse_avg_ms, 400.0, 1e-9);
  EXPECT_EQ(*to_control.tolerance, 0.25);

  ASSERT_EQ(check.callbacks.size(), 1u);
  EXPECT_EQ(check.callbacks[0].samples, 2);
  EXPECT_NEAR(check.callbacks[0].adse_avg_ms, 90.0, 1e-9);
  EXPECT_EQ(*check.callbacks[0].source_avg_ms, 80.0);
  EXPECT_NEAR(*check.callbacks[0].source_p95_ms, 200.0, 1e-9);
}

TEST(ProfileCheckTest, TheTableSaysWhetherEachTargetIsMet) {
  const std::string table =
      FormatProfileCheck(CompareWithProfile(TwoScans(), SourceOf()));
  // sensing: 90 ms against 85 ms is +6 %, within 15 %.
  EXPECT_NE(table.find("+6 %  within 15 %: met"), std::string::npos) << table;
  // No source figure for sensing to control: no verdict.
  EXPECT_EQ(table.find("within 25 %"), std::string::npos) << table;
  EXPECT_NE(table.find("lidar_driver/points_raw"), std::string::npos);
}

TEST(ProfileCheckTest, WorkUnitsThatDriftFromTheReferenceAreFlagged) {
  runfile::RunData run = TwoScans();
  run.trace.callbacks[0].work_units = 900.0;
  run.trace.callbacks[1].work_units = 1020.0;
  Profile profile = SourceOf();
  profile.costs.callbacks["lidar_driver/points_raw"].reference_units = 1000.0;
  // A callback that does not scale with its work has no units row.
  profile.costs.callbacks["ekf_localizer/publish"].quantiles = {{0.0, 0.001},
                                                                {1.0, 0.002}};
  ProfileCheck check = CompareWithProfile(run, profile);
  ASSERT_EQ(check.units.size(), 1u);
  EXPECT_EQ(check.units[0].samples, 2);
  EXPECT_NEAR(check.units[0].adse_mean_units, 960.0, 1e-9);
  EXPECT_FALSE(check.units[0].beyond_tolerance());  // -4 %, within 5 %
  EXPECT_EQ(FormatProfileCheck(check).find("  beyond 5 %"), std::string::npos);

  run.trace.callbacks[0].work_units = 680.0;  // mean 850: -15 %
  check = CompareWithProfile(run, profile);
  EXPECT_TRUE(check.units[0].beyond_tolerance());
  const std::string table = FormatProfileCheck(check);
  EXPECT_NE(table.find("850.0     1000.0  -15.0 %  beyond 5 %\n"),
            std::string::npos)
      << table;
}

}  // namespace
}  // namespace adse::profile
