#include "analysis/metrics/run_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <tuple>

namespace adse::analysis {
namespace {

runfile::RunData TenSecondRun() {
  runfile::RunData run;
  run.status = "complete";
  run.termination_reason = "goal_reached";
  run.platform["cores"] = "2";
  for (int i = 0; i <= 100; ++i) run.ego.push_back({i * 0.1, 0, 0, 0, 0, 0, 0});
  run.topic_names = {"/sensing/lidar/points_raw", "/control/command"};
  // 20 Hz control for 10 s, and 5 commands after the end that must not count.
  for (int i = 0; i < 205; ++i) {
    stack::TopicEvent e;
    e.kind = stack::TopicEvent::kPublish;
    e.topic = 1;
    e.t_s = i * 0.05;
    run.trace.topic_events.push_back(e);
    // Latencies 0.10 s .. 0.29 s repeating.
    run.controls.push_back({e.t_s, e.t_s - 0.10 - 0.01 * (i % 20), 0.0, 0.0});
  }
  for (int i = 0; i < 7; ++i) {
    stack::TopicEvent e;
    e.kind = stack::TopicEvent::kDrop;
    e.topic = 0;
    e.t_s = i;
    run.trace.topic_events.push_back(e);
  }
  stack::CallbackRecord r;
  r.start_s = 1.0;
  r.cost_s = 5.0;
  r.cores = 2;
  run.trace.callbacks.push_back(r);
  run.collisions.push_back({3.0, "car", 1});
  run.collisions.push_back({4.0, "truck", 0});  // it drove into the ego
  run.collisions.push_back({5.0, "bus", -1});   // not known: counted
  return run;
}

TEST(RunMetricsTest, KnownRunGivesKnownMetrics) {
  const auto m = ComputeRunMetrics(TenSecondRun());
  EXPECT_EQ(m.at("completed"), 1.0);
  EXPECT_NEAR(m.at("nav_time_s"), 10.0, 1e-9);
  EXPECT_NEAR(m.at("ctrl_rate_hz"), 20.1, 1e-9);  // 201 commands up to t = 10 s
  EXPECT_EQ(m.at("dropped_messages"), 7.0);
  EXPECT_EQ(m.at("lidar_frames_dropped"), 7.0);
  EXPECT_EQ(m.at("collisions"), 3.0);
  EXPECT_EQ(m.at("ego_collisions"), 2.0);
  EXPECT_NEAR(m.at("e2e_latency_p50_s"), 0.195, 0.011);
  EXPECT_NEAR(m.at("e2e_latency_p99_s"), 0.29, 0.002);
  EXPECT_NEAR(m.at("cpu_utilization"), 10.0 / 20.0, 1e-9);
}

TEST(RunMetricsTest, ANavTimeSummedFromStepsIsStoredWithoutFloatNoise) {
  runfile::RunData run = TenSecondRun();
  run.ego.clear();
  double t_s = 0.0;
  for (int i = 0; i < 820; ++i) {
    run.ego.push_back({t_s, 0, 0, 0, 0, 0, 0});
    t_s += 0.05;  // as the world's clock advances
  }
  run.ego.push_back({t_s, 0, 0, 0, 0, 0, 0});
  ASSERT_NE(t_s, 41.0);  // 40.99999999999981
  EXPECT_EQ(ComputeRunMetrics(run).at("nav_time_s"), 41.0);
}

// Processor sharing and real time: a team of two and another callback on
// two cores hold three threads, but only two cores can be busy.
TEST(RunMetricsTest, ThreadsBeyondThePlatformsCoresAreNotBusyCores) {
  runfile::RunData run = TenSecondRun();
  run.trace.callbacks.clear();
  for (const auto& [start, end, cores] :
       {std::tuple{0.0, 4.0, 2}, std::tuple{1.0, 3.0, 1}}) {
    stack::CallbackRecord r;
    r.start_s = start;
    r.end_s = end;
    r.cost_s = end - start;
    r.cores = cores;
    run.trace.callbacks.push_back(r);
  }
  // 2 x 4 + 1 x 2 thread-seconds, of which 1 x 2 beyond two cores.
  EXPECT_NEAR(ComputeRunMetrics(run).at("cpu_utilization"), 8.0 / 20.0, 1e-12);
}

TEST(RunMetricsTest, LocalizationLostCountsTheTimeEachLostPlanHeldUpToTheEnd) {
  runfile::RunData run = TenSecondRun();
  EXPECT_TRUE(std::isnan(ComputeRunMetrics(run).at("localization_lost_s")));
  auto stop = [](double t_s, StopReason reason) {
    return runfile::StopSample{t_s, t_s - 0.1, reason, -1.0, -1, -1.0, 0};
  };
  // Lost from 2 to 3.5 s (three samples), found again, lost from 9.5 s to
  // the run's end at 10 s; a sample after the end does not count.
  run.stop_reasons = {stop(1.0, StopReason::kNone),
                      stop(2.0, StopReason::kLocalizationLost),
                      stop(2.5, StopReason::kLocalizationLost),
                      stop(3.0, StopReason::kLocalizationLost),
                      stop(3.5, StopReason::kGoal),
                      stop(9.5, StopReason::kLocalizationLost),
                      stop(10.5, StopReason::kLocalizationLost)};
  EXPECT_NEAR(ComputeRunMetrics(run).at("localization_lost_s"), 1.5 + 0.5,
              1e-9);
  run.stop_reasons.resize(5);
  EXPECT_NEAR(ComputeRunMetrics(run).at("localization_lost_s"), 1.5, 1e-9);
}

TEST(RunMetricsTest, TimeoutIsNotCompleted) {
  runfile::RunData run = TenSecondRun();
  run.termination_reason = "timeout";
  EXPECT_EQ(ComputeRunMetrics(run).at("completed"), 0.0);
}

TEST(RunMetricsTest, PercentileInterpolates) {
  EXPECT_NEAR(Percentile({4, 1, 3, 2}, 0.5), 2.5, 1e-12);
  EXPECT_NEAR(Percentile({1, 2, 3, 4, 5}, 0.99), 4.96, 1e-12);
  EXPECT_TRUE(std::isnan(Percentile({}, 0.5)));
}

}  // namespace
}  // namespace adse::analysis
