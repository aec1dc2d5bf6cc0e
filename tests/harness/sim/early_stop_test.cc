// Early stop decides a constraint only when no continuation of the run can
// satisfy it.
#include "harness/sim/early_stop.h"

#include <gtest/gtest.h>

#include "harness/spec/spec_parser.h"

namespace adse::sim {
namespace {

spec::Spec Scenario(const std::string& constraints,
                    const std::string& harness = "") {
  const std::string text =
      "adse: 1\nname: early-stop\n"
      "world: {map: {generate: parking_lot}}\n"
      "task: {start: {x: 5, y: -1.75}, goal: {x: 150, y: -1.75}, "
      "timeout_s: 300}\n"
      "design_space:\n"
      "  cores: {bind: platform.cores, values: [1, 4]}\n"
      "  freq_ghz: {bind: platform.freq_ghz, values: [1.0, 2.0]}\n"
      "constraints: " +
      constraints + "\n" + harness;
  spec::ParseOptions options;
  options.check_files = false;
  Result<spec::Spec> spec =
      spec::ParseSpec(text, "early_stop.yaml", ".", options);
  EXPECT_TRUE(spec.ok()) << spec.status().ToString();
  return std::move(spec).value();
}

const spec::DesignPoint kPoint = {{"cores", 4}, {"freq_ghz", 2.0}};

EarlyStop Make(const spec::Spec& spec) {
  Result<EarlyStop> stop = EarlyStop::Create(spec, kPoint, 30.0);
  EXPECT_TRUE(stop.ok()) << stop.status().ToString();
  return std::move(stop).value();
}

TEST(EarlyStopTest, ANavTimeBoundStopsTheRunOnlyOnceItHasPassed) {
  const EarlyStop stop = Make(Scenario("[nav_time_s <= 90, completed]"));
  EXPECT_FALSE(stop.Violated({89.0, 2600, 0}));
  EXPECT_FALSE(stop.Violated({90.0, 2600, 0}));
  EXPECT_EQ(stop.Violated({90.05, 2600, 0}).value_or(""), "nav_time_s <= 90");
}

TEST(EarlyStopTest, ABoundThatDependsOnThePointUsesThePoint) {
  // 4 cores: the bound is 100 s.
  const EarlyStop stop = Make(Scenario("[nav_time_s <= 25 * cores]"));
  EXPECT_FALSE(stop.Violated({99.0, 0, 0}));
  EXPECT_TRUE(stop.Violated({100.5, 0, 0}));
}

TEST(EarlyStopTest, AControlRateIsStoppedOnlyWhenNoFutureCanLiftIt) {
  // 300 s timeout, 30 Hz controller: at 100 s with 10 commands the rate
  // could still reach (10 + 1 + 6000) / 300 = 20 Hz.
  const EarlyStop stop = Make(Scenario("[ctrl_rate_hz >= 1]"));
  EXPECT_FALSE(stop.Violated({100.0, 10, 0}));
  // At 295 s, 100 commands: at most (100 + 1 + 150) / 300 < 1 Hz.
  EXPECT_EQ(stop.Violated({295.0, 100, 0}).value_or(""), "ctrl_rate_hz >= 1");
  // An upper bound on the rate is certainly violated as soon as the count
  // alone, over the longest run, exceeds it.
  const EarlyStop upper = Make(Scenario("[ctrl_rate_hz <= 5]"));
  EXPECT_FALSE(upper.Violated({10.0, 1400, 0}));
  EXPECT_TRUE(upper.Violated({10.0, 1600, 0}));
}

TEST(EarlyStopTest, ACollisionBoundStopsAtTheFirstCollisionTooMany) {
  const EarlyStop stop = Make(Scenario("[collisions < 2]"));
  EXPECT_FALSE(stop.Violated({5.0, 100, 1}));
  EXPECT_TRUE(stop.Violated({5.0, 100, 2}));
}

TEST(EarlyStopTest, ConstraintsItCannotDecideAreLeftToTheEnd) {
  // completed, two accumulating metrics at once, and a metric that is only
  // known at the end never stop a run.
  const spec::Spec spec = Scenario(
      "[completed, nav_time_s + collisions <= 10, max_deviation_m < 0.5]");
  EXPECT_TRUE(EarlyStoppableConstraints(spec).empty());
  EXPECT_TRUE(Make(spec).empty());
  EXPECT_FALSE(Make(spec).Violated({299.0, 0, 7}));
}

TEST(EarlyStopTest, TurnedOffItDecidesNothing) {
  const spec::Spec spec =
      Scenario("[nav_time_s <= 90]", "harness: {early_stop: false}\n");
  EXPECT_FALSE(spec.harness.early_stop);
  EXPECT_TRUE(EarlyStoppableConstraints(spec).empty());
  EXPECT_FALSE(Make(spec).Violated({200.0, 0, 0}));
}

TEST(EarlyStopTest, AnEarlyStopFlagThatIsNotABooleanIsRefusedByName) {
  spec::ParseOptions options;
  options.check_files = false;
  const std::string text =
      "adse: 1\nname: x\nworld: {map: {generate: parking_lot}}\n"
      "task: {start: {x: 5, y: -1.75}, goal: {x: 150, y: -1.75}}\n"
      "harness: {early_stop: yes}\n";
  Result<spec::Spec> spec = spec::ParseSpec(text, "flag.yaml", ".", options);
  ASSERT_FALSE(spec.ok());
  EXPECT_NE(spec.status().message().find("flag.yaml:5"), std::string::npos)
      << spec.status().message();
  EXPECT_NE(spec.status().message().find("harness.early_stop"),
            std::string::npos)
      << spec.status().message();
  EXPECT_NE(spec.status().message().find("true or false"), std::string::npos)
      << spec.status().message();
}

}  // namespace
}  // namespace adse::sim
