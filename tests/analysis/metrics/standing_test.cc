#include "analysis/metrics/standing.h"

#include <gtest/gtest.h>

#include <cmath>

namespace adse::analysis {
namespace {

using runfile::StopSample;

// A run of end_s seconds sampled every 0.1 s. Speed 0 in [from, to)
// intervals.
runfile::RunData RunStanding(
    const std::vector<std::pair<double, double>>& stands,
    double end_s = 100.0) {
  runfile::RunData run;
  for (int i = 0; i <= static_cast<int>(std::lround(10 * end_s)); ++i) {
    const double t = 0.1 * i;
    double v = 5.0;
    for (const auto& [from, to] : stands) {
      if (t >= from - 1e-9 && t < to - 1e-9) v = 0.0;
    }
    run.ego.push_back({t, 0, 0, 0, v, 0, 0});
  }
  return run;
}

// The planner publishing `sample` every 0.1 s over [from, to).
void Publish(runfile::RunData* run, double from, double to, StopSample sample) {
  for (int i = 0; from + 0.1 * i < to - 1e-9; ++i) {
    sample.t_s = from + 0.1 * i;
    sample.stamp_s = sample.t_s - 0.05;
    run->stop_reasons.push_back(sample);
  }
}

StopSample Reason(StopReason reason, double distance_m) {
  return {0, 0, reason, distance_m, -1, -1, 0};
}

StopSample Obstacle(int track, double gap_m, bool structure) {
  return {0, 0, StopReason::kObstacle, 0.0, track, gap_m, structure ? 1 : 0};
}

TEST(StandingTest, EachStandingStretchGoesToTheReasonThatHeldTheCar) {
  // 0-10 s: drives; 10-40 s: stands behind track 7 on map structure (its
  // gap shrinking); 40-45: behind track 9; 50-55: localization lost;
  // 60-63: the planner silent (no fresh trajectory); 70-72: the plan
  // stops 30 m ahead only, yet the car stands; 90-100: at the goal.
  runfile::RunData run = RunStanding(
      {{10, 40}, {40, 45}, {50, 55}, {60, 63}, {70, 72}, {90, 100}});
  Publish(&run, 0, 10, Reason(StopReason::kNone, -1));
  Publish(&run, 10, 20, Obstacle(7, 4.0, true));
  Publish(&run, 20, 40, Obstacle(7, 3.1, true));
  Publish(&run, 40, 45, Obstacle(9, 3.0, false));
  Publish(&run, 45, 50, Reason(StopReason::kNone, -1));
  Publish(&run, 50, 55, Reason(StopReason::kLocalizationLost, 0.0));
  Publish(&run, 55, 59, Reason(StopReason::kNone, -1));
  Publish(&run, 63, 70, Reason(StopReason::kNone, -1));
  Publish(&run, 70, 90, Reason(StopReason::kGoal, 30.0));
  Publish(&run, 90, 100.05, Reason(StopReason::kGoal, 0.0));

  const StandingSummary s = SummarizeStanding(run);
  EXPECT_TRUE(s.has_reasons);
  // 30 + 5 + 5 + 3 + 2 + 10 s (the last sample covers no time).
  EXPECT_NEAR(s.standing_s, 55.0, 1e-6);
  ASSERT_EQ(s.by_reason.size(), 5u);
  EXPECT_EQ(s.by_reason[0].reason, StopReason::kObstacle);
  EXPECT_NEAR(s.by_reason[0].standing_s, 35.0, 1e-6);
  EXPECT_EQ(s.by_reason[0].track_id, 7);  // held longest
  EXPECT_NEAR(s.by_reason[0].obstacle_gap_m, 3.1, 1e-12);
  EXPECT_TRUE(s.by_reason[0].static_structure);
  EXPECT_EQ(s.by_reason[1].reason, StopReason::kGoal);
  EXPECT_NEAR(s.by_reason[1].standing_s, 10.0, 1e-6);
  EXPECT_EQ(s.by_reason[2].reason, StopReason::kLocalizationLost);
  EXPECT_NEAR(s.by_reason[2].standing_s, 5.0, 1e-6);
  // 59-63 s without a word from the planner: 60-63 is stale after 1 s.
  EXPECT_EQ(s.by_reason[3].reason, StopReason::kNoTrajectory);
  EXPECT_NEAR(s.by_reason[3].standing_s, 3.0, 1e-6);
  // A stop 30 m ahead does not hold a standing car.
  EXPECT_EQ(s.by_reason[4].reason, StopReason::kNone);
  EXPECT_NEAR(s.by_reason[4].standing_s, 2.0, 1e-6);
}

TEST(StandingTest, AnObjectBesideTheCarKeepsItsNearestNegativeGap) {
  // A car cutting in beside the ego: its near edge 6.5 m, then 8.8 m,
  // then 7.0 m behind the front bumper.
  runfile::RunData run = RunStanding({{10, 40}});
  Publish(&run, 0, 10, Reason(StopReason::kNone, -1));
  Publish(&run, 10, 20, Obstacle(37, -6.5, false));
  Publish(&run, 20, 30, Obstacle(37, -8.8, false));
  Publish(&run, 30, 40, Obstacle(37, -7.0, false));
  Publish(&run, 40, 100.05, Reason(StopReason::kNone, -1));
  const StandingSummary s = SummarizeStanding(run);
  ASSERT_EQ(s.by_reason.size(), 1u);
  EXPECT_EQ(s.by_reason[0].track_id, 37);
  EXPECT_DOUBLE_EQ(s.by_reason[0].obstacle_gap_m, -8.8);
}

TEST(StandingTest, BeforeThePlannerSpeaksThereIsNoTrajectory) {
  runfile::RunData run = RunStanding({{0, 2}});
  Publish(&run, 0.55, 100, Reason(StopReason::kNone, -1));
  const StandingSummary s = SummarizeStanding(run);
  ASSERT_EQ(s.by_reason.size(), 2u);
  EXPECT_EQ(s.by_reason[0].reason, StopReason::kNone);
  EXPECT_NEAR(s.by_reason[0].standing_s, 1.4, 1e-6);
  EXPECT_EQ(s.by_reason[1].reason, StopReason::kNoTrajectory);
  EXPECT_NEAR(s.by_reason[1].standing_s, 0.6, 1e-6);
}

TEST(StandingTest, AnOldRunFileKnowsTheTimeNotTheReasons) {
  const StandingSummary s = SummarizeStanding(RunStanding({{10, 20}}));
  EXPECT_FALSE(s.has_reasons);
  EXPECT_NEAR(s.standing_s, 10.0, 1e-6);
  EXPECT_TRUE(s.by_reason.empty());
}

TEST(StandingTest, ACarThatNeverStoodHasNoReasons) {
  runfile::RunData run = RunStanding({});
  Publish(&run, 0, 100, Reason(StopReason::kObstacle, 0.0));
  const StandingSummary s = SummarizeStanding(run);
  EXPECT_EQ(s.standing_s, 0.0);
  EXPECT_TRUE(s.by_reason.empty());
}

TEST(StandingTest, EachStandIsListedWithWhereItWasAndWhatHeldTheCarLongest) {
  // Stands: 10-40 s (behind track 7 on structure), 50-55 (localization
  // lost), 60-63 (the planner silent), 90-100 (goal);
  // 70-72 is shorter than the 3 s asked for.
  runfile::RunData run =
      RunStanding({{10, 40}, {50, 55}, {60, 63}, {70, 72}, {90, 100}});
  for (runfile::EgoSample& e : run.ego) e.x_m = e.t_s;  // x = t: the place
  Publish(&run, 0, 10, Reason(StopReason::kNone, -1));
  Publish(&run, 10, 40, Obstacle(7, 3.1, true));
  Publish(&run, 40, 50, Reason(StopReason::kNone, -1));
  Publish(&run, 50, 55, Reason(StopReason::kLocalizationLost, 0.0));
  Publish(&run, 55, 59, Reason(StopReason::kNone, -1));
  Publish(&run, 63, 90, Reason(StopReason::kNone, -1));
  Publish(&run, 90, 100.05, Reason(StopReason::kGoal, 0.0));

  const std::vector<Stand> stands = ListStands(run, 3.0);
  ASSERT_EQ(stands.size(), 4u);
  EXPECT_NEAR(stands[0].start_s, 10.0, 1e-6);
  EXPECT_NEAR(stands[0].standing_s, 30.0, 1e-6);
  EXPECT_NEAR(stands[0].x_m, 10.0, 1e-6);
  EXPECT_TRUE(stands[0].known);
  EXPECT_EQ(stands[0].cause.reason, StopReason::kObstacle);
  EXPECT_EQ(stands[0].cause.track_id, 7);
  EXPECT_TRUE(stands[0].cause.static_structure);
  EXPECT_EQ(stands[1].cause.reason, StopReason::kLocalizationLost);
  EXPECT_NEAR(stands[1].standing_s, 5.0, 1e-6);
  EXPECT_EQ(stands[2].cause.reason, StopReason::kNoTrajectory);
  EXPECT_NEAR(stands[2].standing_s, 3.0, 1e-6);
  EXPECT_EQ(stands[3].cause.reason, StopReason::kGoal);
  EXPECT_NEAR(stands[3].standing_s, 10.0, 1e-6);

  run.stop_reasons.clear();  // an old run file: places and times only
  const std::vector<Stand> old = ListStands(run, 3.0);
  ASSERT_EQ(old.size(), 4u);
  EXPECT_FALSE(old[0].known);
  EXPECT_NEAR(old[0].standing_s, 30.0, 1e-6);
}

// Feeds `run` to a StallWatch sample by sample, as the simulator does;
// the time it stalled, or -1.
double StalledAt(const runfile::RunData& run, StallWatch* watch) {
  std::vector<StopSample> published;
  size_t next = 0;
  for (const runfile::EgoSample& e : run.ego) {
    while (next < run.stop_reasons.size() &&
           run.stop_reasons[next].t_s <= e.t_s + 1e-9) {
      published.push_back(run.stop_reasons[next++]);
    }
    if (watch->Observe(e.t_s, e.v_mps, published)) return e.t_s;
  }
  return -1;
}

TEST(StallWatchTest, ACarHeldByLostLocalizationStallsAfterTheTimeout) {
  runfile::RunData run = RunStanding({{10, 100}});
  Publish(&run, 0, 10, Reason(StopReason::kNone, -1));
  Publish(&run, 10, 100, Reason(StopReason::kLocalizationLost, 0.0));
  StallWatch watch(60.0);
  EXPECT_NEAR(StalledAt(run, &watch), 70.0, 0.11);
  EXPECT_EQ(watch.reason(), StopReason::kLocalizationLost);
  EXPECT_EQ(watch.track_id(), -1);
  EXPECT_NEAR(watch.stood_s(), 60.0, 0.11);
}

TEST(StallWatchTest, StaticStructureTakenForAnObstacleStallsNamingTheTrack) {
  // 10-30 s held by the planner's silence, then by track 4 on structure:
  // the track held the car longest.
  runfile::RunData run = RunStanding({{10, 100}});
  Publish(&run, 0, 10, Reason(StopReason::kNone, -1));
  Publish(&run, 30, 100, Obstacle(4, 2.5, true));
  StallWatch watch(60.0);
  EXPECT_NEAR(StalledAt(run, &watch), 70.0, 0.11);
  EXPECT_EQ(watch.reason(), StopReason::kObstacle);
  EXPECT_EQ(watch.track_id(), 4);
}

TEST(StallWatchTest, RedLightsAndOtherTrafficNeverStallACar) {
  // 95 s at a red light, then behind a road user: traffic releases both.
  runfile::RunData run = RunStanding({{0, 100}});
  Publish(&run, 0, 50, Reason(StopReason::kRedLight, 0.5));
  Publish(&run, 50, 100, Obstacle(3, 4.0, false));
  StallWatch watch(60.0);
  EXPECT_EQ(StalledAt(run, &watch), -1);
}

TEST(StallWatchTest,
     ARoadUserThatNeverMovesOnStallsTheCarAfterTheTrafficTimeout) {
  // 20 s at a red light, then 280 s behind track 3 (no map structure
  // there): a 120 s traffic bound stalls it at 140 s, naming the track;
  // the red light paused the count.
  runfile::RunData run = RunStanding({{0, 300}}, 300.0);
  Publish(&run, 0, 20, Reason(StopReason::kRedLight, 0.5));
  Publish(&run, 20, 300, Obstacle(3, 4.0, false));
  StallWatch watch(60.0, 120.0);
  EXPECT_NEAR(StalledAt(run, &watch), 140.0, 0.11);
  EXPECT_EQ(watch.reason(), StopReason::kObstacle);
  EXPECT_EQ(watch.track_id(), 3);
  EXPECT_TRUE(watch.held_by_traffic());
  EXPECT_NEAR(watch.stood_s(), 120.0, 0.11);

  // Shorter than the bound, or with the bound off, it waits.
  StallWatch longer(60.0, 300.0);
  EXPECT_EQ(StalledAt(run, &longer), -1);
  StallWatch off(60.0, 0.0);
  EXPECT_EQ(StalledAt(run, &off), -1);
  // Moving on between two road users starts the count again.
  runfile::RunData twice = RunStanding({{0, 100}, {100.5, 200}}, 200.0);
  Publish(&twice, 0, 200, Obstacle(3, 4.0, false));
  StallWatch split(60.0, 120.0);
  EXPECT_EQ(StalledAt(twice, &split), -1);
  // Static structure still stalls by the stall timeout, not the traffic one.
  runfile::RunData wall = RunStanding({{0, 300}}, 300.0);
  Publish(&wall, 0, 300, Obstacle(5, 2.0, true));
  StallWatch by_wall(60.0, 120.0);
  EXPECT_NEAR(StalledAt(wall, &by_wall), 60.0, 0.11);
  EXPECT_FALSE(by_wall.held_by_traffic());
}

TEST(StallWatchTest, ATargetLaneThatNeverHasAGapStallsTheCarAsTraffic) {
  // 200 s waiting to change lane beside track 8: a road user, so the
  // traffic bound (120 s), not the stall timeout (60 s), ends it.
  runfile::RunData run = RunStanding({{0, 200}}, 200.0);
  StopSample waiting = Obstacle(8, -2.5, false);
  waiting.reason = StopReason::kLaneChange;
  Publish(&run, 0, 200, waiting);
  StallWatch watch(60.0, 120.0);
  EXPECT_NEAR(StalledAt(run, &watch), 120.0, 0.11);
  EXPECT_EQ(watch.reason(), StopReason::kLaneChange);
  EXPECT_EQ(watch.track_id(), 8);
  EXPECT_TRUE(watch.held_by_traffic());
  // The summary names the track and its gap beside the car.
  const StandingSummary summary = SummarizeStanding(run);
  ASSERT_EQ(summary.by_reason.size(), 1u);
  EXPECT_EQ(summary.by_reason[0].reason, StopReason::kLaneChange);
  EXPECT_EQ(summary.by_reason[0].track_id, 8);
  EXPECT_DOUBLE_EQ(summary.by_reason[0].obstacle_gap_m, -2.5);
}

TEST(StallWatchTest, TimeHeldByTrafficPausesTheCountWithoutResettingIt) {
  // 40 s lost, 20 s at a red light, 30 s lost: 70 s counted.
  runfile::RunData run = RunStanding({{0, 100}});
  Publish(&run, 0, 40, Reason(StopReason::kLocalizationLost, 0.0));
  Publish(&run, 40, 60, Reason(StopReason::kRedLight, 0.5));
  Publish(&run, 60, 100, Reason(StopReason::kLocalizationLost, 0.0));
  StallWatch watch(60.0);
  EXPECT_NEAR(StalledAt(run, &watch), 80.0, 0.11);
}

TEST(StallWatchTest, MovingStartsTheCountAgain) {
  // Two 50 s stands with a drive between them: neither reaches 60 s.
  runfile::RunData run = RunStanding({{0, 50}, {50.5, 100}});
  Publish(&run, 0, 100, Reason(StopReason::kLocalizationLost, 0.0));
  StallWatch watch(60.0);
  EXPECT_EQ(StalledAt(run, &watch), -1);
}

TEST(StallWatchTest, CreepingACoupleOfCentimetresDoesNotStartTheCountAgain) {
  // Behind a car that never moves on (the reference study's (14, 2.1,
  // 14) crept 6 cm in 362 s): blips of 0.2 s at 0.15 m/s every 50 s.
  runfile::RunData run = RunStanding({{0, 300}}, 300.0);
  for (runfile::EgoSample& e : run.ego) {
    if (std::fmod(e.t_s + 1e-6, 50.0) < 0.2) e.v_mps = 0.15;
  }
  Publish(&run, 0, 300, Obstacle(3, 4.0, false));
  StallWatch watch(60.0, 120.0);
  EXPECT_NEAR(StalledAt(run, &watch), 120.0, 0.11);
  EXPECT_TRUE(watch.held_by_traffic());
  // Creeping a metre ends the stand: 1 s at 1.2 m/s every 50 s.
  for (runfile::EgoSample& e : run.ego) {
    if (e.v_mps > 0) e.v_mps = 0;
    if (std::fmod(e.t_s + 1e-6, 50.0) < 1.0) e.v_mps = 1.2;
  }
  StallWatch moved(60.0, 120.0);
  EXPECT_EQ(StalledAt(run, &moved), -1);
}

TEST(StallWatchTest, APlannerThatNeverSpeaksStallsForNoTrajectory) {
  runfile::RunData run = RunStanding({{0, 100}});
  StallWatch watch(60.0);
  EXPECT_NEAR(StalledAt(run, &watch), 60.0, 0.11);
  EXPECT_EQ(watch.reason(), StopReason::kNoTrajectory);
}

TEST(StallWatchTest, ATimeoutOfZeroNeverStalls) {
  runfile::RunData run = RunStanding({{0, 100}});
  StallWatch watch(0.0);
  EXPECT_EQ(StalledAt(run, &watch), -1);
}

}  // namespace
}  // namespace adse::analysis
