// The agent's surrogate of one metric: measured values are interpolated,
// and a value known only to lie past a bound (a run stopped early) pulls
// the prediction past that bound without fixing it there.
#include "harness/explore/internal/surrogate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace adse::explore::internal {
namespace {

// Navigation time over one normalised knob (more cores to the right).
MetricModel NavTimeModel() {
  MetricModel model;
  model.name = "nav_time_s";
  model.good_direction = -1;  // lower is better
  model.in_constraint = true;
  return model;
}

double Predicted(const MetricModel& model, double u) {
  double mean = 0.0, sd = 0.0;
  model.Predict({u}, &mean, &sd);
  return model.ToMetric(mean);
}

TEST(SurrogateTest, MeasuredValuesAreInterpolated) {
  MetricModel model = NavTimeModel();
  model.Fit({{0.2}, {0.5}, {0.8}}, {300, 200, 150}, {}, {1.0}, {0.25});
  ASSERT_TRUE(model.fitted());
  EXPECT_NEAR(Predicted(model, 0.5), 200, 20);
  EXPECT_GT(Predicted(model, 0.2), Predicted(model, 0.8));
}

TEST(SurrogateTest, RunsStoppedPastABoundArePredictedPastIt) {
  MetricModel model = NavTimeModel();
  // Two starved runs stopped at the 400 s bound (true value above it), one
  // measured run with more capacity.
  model.Fit({{0.0}, {0.2}, {0.8}}, {400, 400, 150}, {+1, +1, 0}, {1.0}, {0.25});
  ASSERT_TRUE(model.fitted());
  EXPECT_GT(Predicted(model, 0.0), 400);
  EXPECT_GT(Predicted(model, 0.2), 400);
  EXPECT_NEAR(Predicted(model, 0.8), 150, 20);
  // Only censored runs: still a model, all of it past the bound there.
  MetricModel only = NavTimeModel();
  only.Fit({{0.1}, {0.3}}, {400, 400}, {+1, +1}, {1.0}, {0.25});
  ASSERT_TRUE(only.fitted());
  EXPECT_GT(Predicted(only, 0.1), 400);
  // ... and more capacity is predicted faster (the prior's direction).
  EXPECT_LT(Predicted(only, 1.0), Predicted(only, 0.1));
}

TEST(SurrogateTest, AKnobWhoseRoleFixesItsDirectionIsNotCreditedTheOther) {
  // Two knobs: capacity (u0, helps) and a sensor rate (u1, a load). A slow
  // first run with little capacity and the slow sensor, then two fast ones
  // with much capacity and the fast sensor: the runs alone cannot tell the
  // knobs apart, and a free trend credits part of the speed-up to the
  // faster sensor. Its role says a faster sensor never lightens the stack.
  const std::vector<std::vector<double>> u = {
      {0.2, 0.0}, {1.0, 1.0}, {0.9, 1.0}};
  const std::vector<double> nav = {800, 130, 150};
  auto at = [](const MetricModel& model, std::vector<double> point) {
    double mean = 0.0, sd = 0.0;
    model.Predict(point, &mean, &sd);
    return model.ToMetric(mean);
  };
  MetricModel model = NavTimeModel();
  model.signed_slopes = {true, true};
  model.Fit(u, nav, {}, {1.0, -0.35}, {0.25, 1.0});
  ASSERT_TRUE(model.fitted());
  // The same computer with the slower sensor is no slower, to within what
  // the residual GP bends (its kernels are free: 5.5 % here), where a free
  // trend makes it 30 % slower.
  EXPECT_LE(at(model, {1.0, 0.0}), 1.1 * at(model, {1.0, 1.0}));
  EXPECT_NEAR(at(model, {1.0, 1.0}), 130, 15);
}

TEST(SurrogateTest, ATimeThatBlowsUpWhereCapacityRunsOutIsModelledAsARate) {
  // 12 runs of a stack that needs capacity 0.2: the time is the route's
  // 100 s over the share of capacity left, which no trend in log time
  // follows towards 0.2; as a rate (1 / time) it is a straight line.
  std::vector<std::vector<double>> u;
  std::vector<double> pole, power;
  for (int i = 0; i < 12; ++i) {
    const double x = 0.25 + 0.065 * i;
    u.push_back({x});
    pole.push_back(100.0 / (1.0 - 0.2 / x));
    power.push_back(300.0 * std::exp(-1.2 * x));  // log-linear
  }
  MetricModel rate = NavTimeModel();
  rate.rate_hint = true;
  rate.Fit(u, pole, {}, {1.0}, {0.25});
  ASSERT_TRUE(rate.fitted());
  EXPECT_EQ(rate.space(), MetricSpace::kReciprocal);

  MetricModel log = NavTimeModel();
  log.rate_hint = true;
  log.Fit(u, power, {}, {1.0}, {0.25});
  EXPECT_EQ(log.space(), MetricSpace::kLog);
  // Without the hint, or with fewer than 10 measured runs, never a rate.
  MetricModel unhinted = NavTimeModel();
  unhinted.Fit(u, pole, {}, {1.0}, {0.25});
  EXPECT_EQ(unhinted.space(), MetricSpace::kLog);
  // Just past the last run towards the capacity the stack needs (0.22 of
  // 0.2; the truth is 1100 s), the rate model follows the climb further.
  EXPECT_GT(Predicted(rate, 0.22), Predicted(unhinted, 0.22)) << "log model";
  EXPECT_GT(Predicted(rate, 0.22), 500);
  MetricModel few = NavTimeModel();
  few.rate_hint = true;
  few.Fit({u.begin(), u.begin() + 9}, {pole.begin(), pole.begin() + 9}, {},
          {1.0}, {0.25});
  EXPECT_EQ(few.space(), MetricSpace::kLog);
}

TEST(SurrogateTest, ABoundOnAFlagIsIgnoredRatherThanTakenForAValue) {
  MetricModel model;
  model.name = "completed";
  model.boolean_hint = true;
  model.good_direction = +1;
  model.Fit({{0.2}, {0.8}, {0.9}}, {0, 1, 1}, {+1, 0, 0}, {1.0}, {0.25});
  ASSERT_TRUE(model.fitted());
  EXPECT_EQ(model.points(), 2);  // the bound left out
  EXPECT_EQ(model.space(), MetricSpace::kBoolean);
}

TEST(SurrogateTest, ACountIsSampledAsAWholeNumberSoThatABoundOfZeroCanHold) {
  // Collisions folded over two cases and replicas: 0, a mean of 0.5, 2.
  // Not 0/1, so modelled as a plain value; its samples must still be whole
  // numbers, or `obstacle_collisions == 0` would never hold on one.
  MetricModel model;
  model.name = "obstacle_collisions";
  model.count_hint = true;
  model.good_direction = -1;
  model.in_constraint = true;
  model.Fit({{0.1}, {0.4}, {0.7}, {0.9}}, {2, 0.5, 0, 0}, {}, {1.0}, {0.25});
  ASSERT_TRUE(model.fitted());
  EXPECT_EQ(model.space(), MetricSpace::kLinear);
  int zeros = 0;
  for (double z = -2.0; z <= 2.0; z += 0.25) {
    double mean = 0.0, sd = 0.0;
    model.Predict({0.9}, &mean, &sd);
    const double v = model.ToMetric(mean + z * sd);
    EXPECT_EQ(v, std::round(v));
    EXPECT_GE(v, 0.0);
    zeros += v == 0.0;
  }
  EXPECT_GT(zeros, 8);  // where the runs had none, mostly none
  double mean = 0.0, sd = 0.0;
  model.Predict({0.1}, &mean, &sd);
  EXPECT_GE(model.ToMetric(mean), 1.0);
}

}  // namespace
}  // namespace adse::explore::internal
