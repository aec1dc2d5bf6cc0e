// The velocity planner's traffic-light stage: where it stops for red,
// yellow and unknown signals, and how it lets the car go again.
#include "stack/algorithms/traffic_light.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "stack/algorithms/planning.h"

namespace adse::algorithms {
namespace {

constexpr double kEgoFrontM = 3.8;  // the default params' rear axle to nose
constexpr double kMarginM = 1.0;    // ... and stop margin

// A straight path along x from route s `s0` (the ego's rear axle), one
// point per metre, at `v_mps`.
std::vector<PlannedPoint> PathFrom(double s0, double v_mps = 8.0,
                                   int points = 51) {
  std::vector<PlannedPoint> out;
  for (int i = 0; i < points; ++i) {
    PlannedPoint p;
    p.x_m = s0 + i;
    p.s_m = s0 + i;
    p.v_mps = v_mps;
    out.push_back(p);
  }
  return out;
}

SignalObservation Seen(double stamp_s, SignalState state, double distance_m,
                       const std::string& id = "J1") {
  return {stamp_s, state, distance_m, id};
}

// Every point from stop_s on stands, every point before it moves.
void ExpectStopsAt(const std::vector<PlannedPoint>& points, double stop_s) {
  bool has_point_there = false;
  for (const PlannedPoint& p : points) {
    if (p.s_m >= stop_s - 1e-6) {
      EXPECT_EQ(p.v_mps, 0.0) << "at s=" << p.s_m;
    } else {
      EXPECT_GT(p.v_mps, 0.0) << "at s=" << p.s_m;
    }
    has_point_there |= std::abs(p.s_m - stop_s) < 1e-9;
  }
  EXPECT_TRUE(has_point_there) << "no point exactly at the stop " << stop_s;
}

TEST(TrafficLightPlanner, RedStopsTheCarWithItsNoseBeforeTheStopLine) {
  TrafficLightPlanner planner;
  planner.Observe(Seen(0.0, SignalState::kRed, 30.0));
  std::vector<PlannedPoint> points = PathFrom(10.0);
  const SignalStop stop = planner.Apply(0.05, 0.0, 8.0, &points);
  const double line_s = 10.0 + 30.0;
  ASSERT_TRUE(stop.stop);
  EXPECT_EQ(stop.state, SignalState::kRed);
  EXPECT_EQ(stop.tls_id, "J1");
  EXPECT_NEAR(stop.stop_s_m, line_s - kMarginM - kEgoFrontM, 1e-9);
  ExpectStopsAt(points, stop.stop_s_m);

  // The planner publishes it as red_light, unless an obstacle stands
  // nearer (a queue at the line is what the car waits for).
  std::vector<PlannedPoint> decided = points;
  const StopDecision decision =
      DecideStop(&decided, false, false, ObstacleStop(), stop.stop_s_m);
  EXPECT_EQ(decision.reason, StopReason::kRedLight);
  EXPECT_NEAR(decision.distance_m, stop.stop_s_m - 10.0, 1e-9);
  EXPECT_EQ(decision.obstacle_id, -1);
  ObstacleStop queue;
  queue.stop = true;
  queue.obstacle_id = 7;
  queue.stop_s_m = stop.stop_s_m - 6.0;
  EXPECT_EQ(DecideStop(&decided, false, false, queue, stop.stop_s_m).reason,
            StopReason::kObstacle);
  // Without a signal stop the decision is what it always was.
  EXPECT_EQ(DecideStop(&decided, true, false, ObstacleStop()).reason,
            StopReason::kGoal);
}

TEST(TrafficLightPlanner, TheDetectorsLatencyIsMadeUpByTheCarsSpeed) {
  // Seen 0.5 s before the pose the path starts from, at 10 m/s: the car
  // was 5 m further back when the detector measured 30 m.
  TrafficLightPlanner planner;
  planner.Observe(Seen(9.5, SignalState::kRed, 30.0));
  std::vector<PlannedPoint> points = PathFrom(100.0, 10.0);
  const SignalStop stop = planner.Apply(10.05, 10.0, 10.0, &points);
  ASSERT_TRUE(stop.stop);
  EXPECT_NEAR(stop.stop_s_m, 100.0 - 5.0 + 30.0 - kMarginM - kEgoFrontM, 1e-9);
}

TEST(TrafficLightPlanner, GreenOrNoSignalInRangeDoesNotStop) {
  TrafficLightPlanner planner;
  planner.Observe(Seen(0.0, SignalState::kGreen, 30.0));
  std::vector<PlannedPoint> points = PathFrom(0.0);
  EXPECT_FALSE(planner.Apply(0.05, 0.0, 8.0, &points).stop);
  for (const PlannedPoint& p : points) EXPECT_EQ(p.v_mps, 8.0);
  planner.Observe(Seen(0.1, SignalState::kUnknown, -1.0, ""));
  EXPECT_FALSE(planner.Apply(0.15, 0.1, 8.0, &points).stop);
  // A stop line beyond the path's end is not this path's stop.
  planner.Observe(Seen(0.2, SignalState::kRed, 80.0));
  EXPECT_FALSE(planner.Apply(0.25, 0.2, 8.0, &points).stop);
}

TEST(TrafficLightPlanner, YellowStopsOnlyWhereAComfortableBrakeSuffices) {
  // 10 m/s, 55 m to the stop: 0.9 m/s^2 needed, within 2.5: stop.
  TrafficLightPlanner far;
  far.Observe(Seen(0.0, SignalState::kYellow, 60.0));
  std::vector<PlannedPoint> points = PathFrom(0.0, 10.0, 61);
  EXPECT_TRUE(far.Apply(0.0, 0.0, 10.0, &points).stop);

  // 10 m/s, 5.2 m to the stop: 9.6 m/s^2: the car goes on, and keeps
  // going when the signal turns red behind the yellow.
  TrafficLightPlanner near;
  near.Observe(Seen(0.0, SignalState::kYellow, 10.0));
  points = PathFrom(0.0, 10.0);
  EXPECT_FALSE(near.Apply(0.0, 0.0, 10.0, &points).stop);
  near.Observe(Seen(0.3, SignalState::kRed, 7.0));
  points = PathFrom(3.0, 10.0);
  EXPECT_FALSE(near.Apply(0.3, 0.3, 10.0, &points).stop);

  // A car standing at the line stops for yellow.
  TrafficLightPlanner standing;
  standing.Observe(Seen(0.0, SignalState::kYellow, kEgoFrontM + kMarginM));
  points = PathFrom(0.0, 8.0);
  EXPECT_TRUE(standing.Apply(0.0, 0.0, 0.0, &points).stop);
}

TEST(TrafficLightPlanner, AnOldStateIsUnknownAndIsWaitedOutAtTheLine) {
  TrafficLightParams params;  // state_timeout_s 1, unknown_wait_s 5
  TrafficLightPlanner planner(params);
  const double line_s = 50.0;
  const double stop_s = line_s - kMarginM - kEgoFrontM;
  planner.Observe(Seen(0.0, SignalState::kGreen, line_s));
  std::vector<PlannedPoint> points = PathFrom(0.0);
  EXPECT_FALSE(planner.Apply(0.5, 0.0, 8.0, &points).stop);
  // 2 s later nothing new came: unknown, so the car stops at the line.
  points = PathFrom(16.0);
  SignalStop stop = planner.Apply(2.0, 2.0, 8.0, &points);
  ASSERT_TRUE(stop.stop);
  EXPECT_EQ(stop.state, SignalState::kUnknown);
  EXPECT_NEAR(stop.stop_s_m, stop_s, 1e-9);
  // Standing at the line from t = 10 s: held until 15 s, then it goes.
  for (const double t : {10.0, 12.0, 14.9}) {
    points = PathFrom(stop_s - 0.3, 0.0);
    EXPECT_TRUE(planner.Apply(t, t, 0.0, &points).stop) << t;
  }
  points = PathFrom(stop_s - 0.3, 8.0);
  EXPECT_FALSE(planner.Apply(15.1, 15.1, 0.0, &points).stop);
  // A fresh red at the line holds it again.
  planner.Observe(Seen(15.2, SignalState::kRed, line_s - (stop_s - 0.3)));
  EXPECT_TRUE(planner.Apply(15.25, 15.2, 0.0, &points).stop);
}

TEST(TrafficLightPlanner, ARedThatNeverEndsIsTakenAsBrokenAfterMaxRedWait) {
  TrafficLightParams params;
  params.max_red_wait_s = 120.0;
  TrafficLightPlanner planner(params);
  const double line_s = 30.0;
  const double at_stop_s = line_s - kMarginM - kEgoFrontM - 0.2;
  for (double t = 0.0; t < 120.0; t += 0.5) {
    planner.Observe(Seen(t, SignalState::kRed, line_s - at_stop_s));
    std::vector<PlannedPoint> points = PathFrom(at_stop_s, 0.0);
    ASSERT_TRUE(planner.Apply(t, t, 0.0, &points).stop) << t;
  }
  planner.Observe(Seen(120.5, SignalState::kRed, line_s - at_stop_s));
  std::vector<PlannedPoint> points = PathFrom(at_stop_s, 8.0);
  EXPECT_FALSE(planner.Apply(120.5, 120.5, 0.0, &points).stop);
}

TEST(TrafficLightPlanner, ANosePastTheLineIsInTheJunctionAndGoesOn) {
  TrafficLightPlanner planner;
  // The rear axle is 2 m before the line, the nose 1.8 m past it.
  planner.Observe(Seen(0.0, SignalState::kRed, 2.0));
  std::vector<PlannedPoint> points = PathFrom(100.0, 5.0);
  EXPECT_FALSE(planner.Apply(0.0, 0.0, 5.0, &points).stop);
  for (const PlannedPoint& p : points) EXPECT_EQ(p.v_mps, 5.0);
}

TEST(TrafficLightPlanner, APathEndingForATurnInMovesWaitsAtItsEndForItsLine) {
  // The path ends 8 m short of a red line, where the car stops to turn
  // through that junction in several moves: it waits at the path's end.
  std::vector<PlannedPoint> points = PathFrom(0.0, 8.0, 21);
  TrafficLightPlanner turning;
  turning.Observe(Seen(0.0, SignalState::kRed, 28.0));
  const SignalStop stop = turning.Apply(0.0, 0.0, 8.0, &points, true);
  ASSERT_TRUE(stop.stop);
  EXPECT_NEAR(stop.stop_s_m, 20.0, 1e-9);
  // Driving on along its lanes instead, the path reaches the line later.
  TrafficLightPlanner driving;
  driving.Observe(Seen(0.0, SignalState::kRed, 28.0));
  points = PathFrom(0.0, 8.0, 21);
  EXPECT_FALSE(driving.Apply(0.0, 0.0, 8.0, &points).stop);
  // A line farther past the turn's start than turn_line_reach_m is
  // another junction's, and green lets the car turn.
  for (const auto& [state, line_m] : {std::pair(SignalState::kRed, 31.0),
                                      std::pair(SignalState::kGreen, 28.0)}) {
    TrafficLightPlanner planner;
    planner.Observe(Seen(0.0, state, line_m));
    points = PathFrom(0.0, 8.0, 21);
    EXPECT_FALSE(planner.Apply(0.0, 0.0, 8.0, &points, true).stop) << line_m;
  }
}

TEST(TrafficLightPlanner, AnotherSignalStartsAfresh) {
  // Committed to pass J1 on yellow; J2 further on is red: stop there.
  TrafficLightPlanner planner;
  planner.Observe(Seen(0.0, SignalState::kYellow, 8.0, "J1"));
  std::vector<PlannedPoint> points = PathFrom(0.0, 10.0);
  EXPECT_FALSE(planner.Apply(0.0, 0.0, 10.0, &points).stop);
  planner.Observe(Seen(2.0, SignalState::kRed, 40.0, "J2"));
  points = PathFrom(20.0, 10.0);
  const SignalStop stop = planner.Apply(2.0, 2.0, 10.0, &points);
  EXPECT_TRUE(stop.stop);
  EXPECT_EQ(stop.tls_id, "J2");
}

}  // namespace
}  // namespace adse::algorithms
