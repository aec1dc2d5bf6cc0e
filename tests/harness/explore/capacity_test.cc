// The capacity order over designs, from the knobs' roles, and which runs
// show a lack of capacity: what a run that failed or held says of designs
// it has not run (the agent's verdicts, the headline's cheaper designs).
#include "harness/explore/capacity.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "harness/spec/spec_parser.h"
#include "tests/harness/testing/lot_scenario.h"

namespace adse::explore {
namespace {

using spec::KnobRole;

// cores, GHz, LiDAR rate, NDT voxel size, a knob of no role; each value
// is an index into the knob's allowed values (ascending).
std::vector<KnobRole> Roles() {
  return {KnobRole::kCores, KnobRole::kFrequency, KnobRole::kSensorRate,
          KnobRole::kDownsample, KnobRole::kNone};
}

int Compare(const Genes& a, const Genes& b, bool coarser_is_capacity,
            std::vector<bool> rate_raised = std::vector<bool>(5, false)) {
  return CompareCapacity(Roles(), rate_raised, a, b, coarser_is_capacity);
}

TEST(CapacityTest, MoreCoresAndClockAndASlowerSensorAreMoreCapacity) {
  EXPECT_EQ(Compare({2, 1, 0, 1, 0}, {2, 1, 0, 1, 0}, false), 0);
  EXPECT_EQ(Compare({3, 2, 0, 1, 0}, {2, 1, 0, 1, 0}, false), +1);
  EXPECT_EQ(Compare({2, 1, 0, 1, 0}, {2, 1, 1, 1, 0}, false), +1);
  EXPECT_EQ(Compare({1, 1, 1, 1, 0}, {2, 1, 0, 1, 0}, false), -1);
  // More cores on a slower clock: neither.
  EXPECT_EQ(Compare({3, 0, 0, 1, 0}, {2, 1, 0, 1, 0}, false), 2);
  // A knob of no role must be equal.
  EXPECT_EQ(Compare({3, 1, 0, 1, 1}, {2, 1, 0, 1, 0}, false), 2);
}

TEST(CapacityTest, ASensorTheDiagnosisAskedToRaiseMustBeEqual) {
  std::vector<bool> raised(5, false);
  raised[2] = true;
  EXPECT_EQ(Compare({2, 1, 0, 1, 0}, {2, 1, 1, 1, 0}, false, raised), 2);
  EXPECT_EQ(Compare({3, 1, 1, 1, 0}, {2, 1, 1, 1, 0}, false, raised), +1);
}

TEST(CapacityTest, CoarserDataIsMoreCapacityOnlyWhereAsked) {
  // Against a run that was too slow, finer voxels are more load: fewer
  // cores with finer voxels have less capacity.
  EXPECT_EQ(Compare({1, 1, 0, 0, 0}, {2, 1, 0, 1, 0}, true), -1);
  EXPECT_EQ(Compare({2, 1, 0, 2, 0}, {2, 1, 0, 1, 0}, true), +1);
  // Otherwise (a run that strayed, or one that held) coarser data costs
  // precision, and a design that differs in it is not ordered.
  EXPECT_EQ(Compare({1, 1, 0, 0, 0}, {2, 1, 0, 1, 0}, false), 2);
  EXPECT_EQ(Compare({3, 1, 0, 2, 0}, {2, 1, 0, 1, 0}, false), 2);
  // Equal voxels: the other knobs decide.
  EXPECT_EQ(Compare({1, 1, 0, 1, 0}, {2, 1, 0, 1, 0}, false), -1);
}

// A scenario with a bound on the time (a load metric), one on the
// deviation (a precision metric), one on the cost and one on a knob.
spec::Spec Scenario() {
  return adse::testing::LotScenario(
      "capacity",
      "design_space:\n"
      "  cores: {bind: platform.cores, values: [2, 4]}\n"
      "cost: cores\n"
      "objectives: [{minimize: hardware_cost}, {minimize: nav_time_s}]\n"
      "constraints: [nav_time_s <= 60, deviation_score <= 0.5,\n"
      "              hardware_cost <= 3, cores >= 4]\n");
}

Observation RunOf(double nav_time_s, double deviation_score) {
  Observation o;
  o.point = {{"cores", 4}};
  o.metrics = {{"nav_time_s", nav_time_s},
               {"deviation_score", deviation_score},
               {"hardware_cost", 4}};
  return o;
}

TEST(CapacityTest, OnlyConstraintsOnMeasuredMetricsFollowCapacity) {
  const std::vector<CapacityConstraint> constraints =
      CapacityConstraintsOf(Scenario());
  ASSERT_EQ(constraints.size(), 4u);
  EXPECT_EQ(constraints[0].expression.text(), "nav_time_s <= 60");
  EXPECT_TRUE(constraints[0].metric_only);
  EXPECT_FALSE(constraints[0].reads_precision);
  EXPECT_TRUE(constraints[1].metric_only);
  EXPECT_TRUE(constraints[1].reads_precision);
  EXPECT_FALSE(constraints[2].metric_only);  // the design's cost
  EXPECT_FALSE(constraints[3].metric_only);  // a knob
}

TEST(CapacityTest, ARunShowsALackOfCapacityByTheMetricsItMeasured) {
  const std::vector<CapacityConstraint> constraints =
      CapacityConstraintsOf(Scenario());
  // Too slow: short of capacity, on load alone too.
  EXPECT_TRUE(FailsForCapacity(constraints, RunOf(70, 0.1), false));
  EXPECT_TRUE(FailsForCapacity(constraints, RunOf(70, 0.1), true));
  // Straying: short of capacity, but finer data might rescue it.
  EXPECT_TRUE(FailsForCapacity(constraints, RunOf(40, 0.9), false));
  EXPECT_FALSE(FailsForCapacity(constraints, RunOf(40, 0.9), true));
  // Within both (it fails the cost and the knob's bound, which capacity
  // does not decide).
  EXPECT_FALSE(FailsForCapacity(constraints, RunOf(40, 0.1), false));
  // Stopped early by the time bound: its metrics withheld, the bound named.
  Observation stopped;
  stopped.point = {{"cores", 2}};
  stopped.metrics = {{"hardware_cost", 2}};
  stopped.censored = true;
  stopped.violated_constraint = "nav_time_s <= 60";
  EXPECT_TRUE(FailsForCapacity(constraints, stopped, true));
  // A run that failed (no metrics) shows nothing.
  Observation failed = RunOf(70, 0.1);
  failed.failed = true;
  EXPECT_FALSE(FailsForCapacity(constraints, failed, false));
}

}  // namespace
}  // namespace adse::explore
