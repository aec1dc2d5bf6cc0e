// Design points: ParsePoint, DesignSpace::Check, costs, constraints and
// applying a point to the platform and stack.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "harness/spec/spec_parser.h"
#include "harness/spec/text_util.h"

namespace adse::spec {
namespace {

using ::testing::HasSubstr;

constexpr double kTol = 1e-9;

Spec Reference() {
  Result<Spec> spec = ParseSpec(R"(adse: 1
world: {map: {generate: parking_lot}}
task: {start: {x: 0, y: 0}, goal: {x: 80, y: 40}}
platform: {cores: 6, freq_ghz: 1.8}
design_space:
  cores:    {bind: platform.cores,      range: [1, 28]}
  freq_ghz: {bind: platform.freq_ghz,   values: [1.0, 1.2, 1.5, 1.8, 2.1]}
  lidar_hz: {bind: stack.lidar.rate_hz, values: [7, 14]}
constraints: [nav_time_s <= 400, ctrl_rate_hz >= 1, completed]
)",
                                "ref.yaml", "");
  EXPECT_TRUE(spec.ok()) << spec.status().message();
  return spec.ok() ? *spec : Spec();
}

TEST(DesignPointTest, ParsesAGoodPoint) {
  const Spec spec = Reference();
  Result<DesignPoint> point =
      ParsePoint(spec.design_space, "cores=4, freq_ghz=1.2,lidar_hz=14");
  ASSERT_TRUE(point.ok()) << point.status().message();
  EXPECT_NEAR(point->at("cores"), 4, kTol);
  EXPECT_NEAR(point->at("freq_ghz"), 1.2, kTol);
  EXPECT_NEAR(point->at("lidar_hz"), 14, kTol);
  EXPECT_TRUE(spec.design_space.Check(*point).ok());
}

TEST(DesignPointTest, FormatPointIsTheInverseOfParsePoint) {
  const Spec spec = Reference();
  const DesignPoint point = {{"lidar_hz", 14}, {"cores", 4}, {"freq_ghz", 1.2}};
  const std::string text = FormatPoint(spec.design_space, point);
  EXPECT_EQ(text, "cores=4,freq_ghz=1.2,lidar_hz=14");  // space order
  Result<DesignPoint> back = ParsePoint(spec.design_space, text);
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(*back, point);
}

TEST(DesignPointTest, SnapsToTheExactAllowedValue) {
  const Spec spec = Reference();
  Result<DesignPoint> point = ParsePoint(spec.design_space,
                                         "cores=4,freq_ghz=1.2000000000001,"
                                         "lidar_hz=14");
  ASSERT_TRUE(point.ok()) << point.status().message();
  EXPECT_EQ(point->at("freq_ghz"),
            spec.design_space.Find("freq_ghz")->values[1]);
}

TEST(DesignPointTest, UnknownParameterGetsASuggestion) {
  const Spec spec = Reference();
  Result<DesignPoint> point =
      ParsePoint(spec.design_space, "cores=4,freq_ghz=1.2,lidar=14");
  ASSERT_FALSE(point.ok());
  EXPECT_THAT(point.status().message(), HasSubstr("unknown parameter 'lidar'"));
  EXPECT_THAT(point.status().message(),
              HasSubstr("(did you mean 'lidar_hz'?)"));
  EXPECT_THAT(point.status().message(),
              HasSubstr("missing parameter: lidar_hz"));
}

TEST(DesignPointTest, DisallowedValueListsTheAllowedOnes) {
  const Spec spec = Reference();
  Result<DesignPoint> point =
      ParsePoint(spec.design_space, "cores=4,freq_ghz=1.3,lidar_hz=10");
  ASSERT_FALSE(point.ok());
  EXPECT_THAT(point.status().message(),
              HasSubstr("freq_ghz: expected one of 1, 1.2, 1.5, 1.8, 2.1, "
                        "found 1.3"));
  EXPECT_THAT(point.status().message(),
              HasSubstr("lidar_hz: expected one of 7, 14, found 10"));
  point = ParsePoint(spec.design_space, "cores=40,freq_ghz=1.2,lidar_hz=7");
  ASSERT_FALSE(point.ok());
  EXPECT_THAT(point.status().message(),
              HasSubstr("cores: expected one of 1, 2, 3, ..., 28 (28 values), "
                        "found 40"));
}

TEST(DesignPointTest, MissingParametersAreListed) {
  const Spec spec = Reference();
  Result<DesignPoint> point = ParsePoint(spec.design_space, "cores=4");
  ASSERT_FALSE(point.ok());
  EXPECT_THAT(point.status().message(),
              HasSubstr("missing parameters: freq_ghz, lidar_hz"));
}

TEST(DesignPointTest, MalformedText) {
  const Spec spec = Reference();
  EXPECT_THAT(ParsePoint(spec.design_space, "").status().message(),
              HasSubstr("expected name=value pairs"));
  EXPECT_THAT(ParsePoint(spec.design_space, "cores:4,freq_ghz=1,lidar_hz=7")
                  .status()
                  .message(),
              HasSubstr("expected name=value, found 'cores:4'"));
  EXPECT_THAT(ParsePoint(spec.design_space, "cores=four,freq_ghz=1,lidar_hz=7")
                  .status()
                  .message(),
              HasSubstr("cores: expected a number, found 'four'"));
  EXPECT_THAT(
      ParsePoint(spec.design_space, "cores=4,cores=5,freq_ghz=1,lidar_hz=7")
          .status()
          .message(),
      HasSubstr("cores: expected one value, found it twice"));
}

TEST(DesignPointTest, CheckNamesParameterAndAllowedValues) {
  const Spec spec = Reference();
  EXPECT_TRUE(spec.design_space
                  .Check({{"cores", 23}, {"freq_ghz", 1.5}, {"lidar_hz", 7}})
                  .ok());
  Status s = spec.design_space.Check(
      {{"cores", 23}, {"freq_ghz", 1.6}, {"lidar_hz", 7}});
  EXPECT_THAT(s.message(), HasSubstr("freq_ghz: expected one of"));
  s = spec.design_space.Check({{"cores", 23}, {"freq_ghz", 1.5}});
  EXPECT_THAT(s.message(), HasSubstr("missing parameter lidar_hz"));
  s = spec.design_space.Check(
      {{"cores", 23}, {"freq", 1.5}, {"freq_ghz", 1.5}, {"lidar_hz", 7}});
  EXPECT_THAT(s.message(), HasSubstr("unknown parameter 'freq'"));
}

TEST(DesignPointTest, SizeSaturates) {
  DesignSpace space;
  for (int i = 0; i < 10; ++i) {
    DesignParameter p;
    p.name = "p" + std::to_string(i);
    p.values.assign(100000, 0.0);
    space.parameters.push_back(p);
  }
  EXPECT_EQ(space.Size(), UINT64_MAX);
  EXPECT_EQ(DesignSpace().Size(), 0u);
}

TEST(DesignPointTest, CostUsesThePointAndPlatformDefaults) {
  const Spec spec = Reference();
  Result<double> cost =
      EvaluateCost(spec, {{"cores", 18}, {"freq_ghz", 1.8}, {"lidar_hz", 7}});
  ASSERT_TRUE(cost.ok()) << cost.status().message();
  EXPECT_NEAR(*cost, 32.4, 1e-9);

  // freq_ghz not bound: the platform's default frequency counts.
  Result<Spec> only_hz = ParseSpec(R"(adse: 1
world: {map: {generate: grid}}
task: {start: {x: 0, y: 0}, goal: {x: 1, y: 1}}
platform: {cores: 6, freq_ghz: 1.5}
design_space: {hz: {bind: stack.lidar.rate_hz, values: [7, 14]}}
cost: cores * freq_ghz + hz / 7
)",
                                   "c.yaml", "");
  ASSERT_TRUE(only_hz.ok()) << only_hz.status().message();
  cost = EvaluateCost(*only_hz, {{"hz", 14}});
  ASSERT_TRUE(cost.ok()) << cost.status().message();
  EXPECT_NEAR(*cost, 6 * 1.5 + 2, 1e-9);
  EXPECT_FALSE(EvaluateCost(*only_hz, {{"hz", 10}}).ok());
}

// A cores x clock space on a generated grid (each knob's values or range
// as `cores` and `freq` say), then `rest`, as c.yaml.
Spec CoresAndClock(const std::string& cores, const std::string& freq,
                   const std::string& rest) {
  Result<Spec> spec = ParseSpec(
      "adse: 1\nworld: {map: {generate: grid}}\n"
      "task: {start: {x: 0, y: 0}, goal: {x: 1, y: 1}}\n"
      "design_space:\n"
      "  cores: {bind: platform.cores, " +
          cores +
          "}\n"
          "  freq_ghz: {bind: platform.freq_ghz, " +
          freq + "}\n" + rest,
      "c.yaml", "");
  EXPECT_TRUE(spec.ok()) << spec.status().message();
  return *spec;
}

TEST(DesignPointTest, ACostOfShortDecimalsIsStoredWithoutFloatNoise) {
  const Spec spec = CoresAndClock("range: [1, 8]", "values: [1.2, 1.8, 2.1]",
                                  "cost: cores * freq_ghz\n");
  // 6 x 1.2 and 7 x 2.1 are 7.199999999999999 and 14.700000000000001 in
  // binary floating point; what a user reads and compares is 7.2 and 14.7.
  ASSERT_NE(6 * 1.2, 7.2);
  ASSERT_NE(7 * 2.1, 14.7);
  EXPECT_EQ(*EvaluateCost(spec, {{"cores", 6}, {"freq_ghz", 1.2}}), 7.2);
  EXPECT_EQ(*EvaluateCost(spec, {{"cores", 7}, {"freq_ghz", 2.1}}), 14.7);
  // Equally priced designs tie exactly, whatever their factors.
  EXPECT_EQ(*EvaluateCost(spec, {{"cores", 6}, {"freq_ghz", 1.2}}),
            *EvaluateCost(spec, {{"cores", 4}, {"freq_ghz", 1.8}}));
  std::vector<double> costs;
  ASSERT_TRUE(ForEachPointCost(spec, [&](const DesignPoint&, double cost) {
                costs.push_back(cost);
              }).ok());
  EXPECT_NE(std::find(costs.begin(), costs.end(), 14.7), costs.end());
}

TEST(DesignPointTest, ACostNotFiniteAtSomeDesignPointIsNamedAtThatPoint) {
  auto parsed = [](const std::string& cost, const std::string& cores,
                   const std::string& freq = "values: [1.0, 2.1]") {
    return CoresAndClock(cores, freq, "cost: " + cost + "\n");
  };
  EXPECT_TRUE(
      CheckCostOverSpace(parsed("cores * freq_ghz", "range: [1, 8]")).ok());
  const Spec broken = parsed("10 / (cores - 4)", "range: [1, 8]");
  const Status status = CheckCostOverSpace(broken);
  EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(status.message(),
            "cost: expected a finite cost at every design point, found "
            "'10 / (cores - 4)' = inf at cores=4,freq_ghz=1");
  // A run of that point is refused the same way; its neighbours are priced.
  EXPECT_EQ(EvaluateCost(broken, {{"cores", 4}, {"freq_ghz", 2.1}})
                .status()
                .message(),
            "cost: expected a finite cost at every design point, found "
            "'10 / (cores - 4)' = inf at cores=4,freq_ghz=2.1");
  EXPECT_NEAR(*EvaluateCost(broken, {{"cores", 5}, {"freq_ghz", 2.1}}), 10.0,
              1e-12);
  EXPECT_FALSE(
      CheckCostOverSpace(parsed("ln(cores - 4)", "range: [4, 8]")).ok());
  // A space past kMaxCostCheckPoints is left to each run.
  EXPECT_TRUE(CheckCostOverSpace(parsed("10 / (cores - 4)", "range: [1, 1024]",
                                        "range: [1.0, 3.0], step: 0.01"))
                  .ok());
}

TEST(DesignPointTest, AConfirmPhaseOverASpaceTooLargeToEnumerateIsRefused) {
  auto parsed = [](const std::string& cores, int confirm_runs) {
    return CoresAndClock(
        cores, "range: [1.0, 3.0], step: 0.01",
        "exploration: {confirm_runs: " + std::to_string(confirm_runs) + "}\n");
  };
  EXPECT_TRUE(CheckConfirmRuns(parsed("range: [1, 8]", 5)).ok());
  EXPECT_TRUE(CheckConfirmRuns(parsed("range: [1, 1024]", 0)).ok());
  const Status status = CheckConfirmRuns(parsed("range: [1, 1024]", 5));
  EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(status.message().find("c.yaml:"), std::string::npos)
      << status.message();
  EXPECT_NE(status.message().find(
                "exploration.confirm_runs: the confirm phase runs designs "
                "cheaper than the answer, which adse enumerates in spaces of "
                "at most 100000 designs; this space holds 205824: expected "
                "0, found 5"),
            std::string::npos)
      << status.message();
}

TEST(DesignPointTest, ConstraintsOverMetrics) {
  const Spec spec = Reference();
  const DesignPoint point = {{"cores", 18}, {"freq_ghz", 1.8}, {"lidar_hz", 7}};
  std::map<std::string, double> metrics = {
      {"nav_time_s", 165}, {"ctrl_rate_hz", 7.8}, {"completed", 1}};
  for (const std::string& c : spec.constraints) {
    Result<bool> ok = EvaluateConstraint(spec, c, metrics, point);
    ASSERT_TRUE(ok.ok()) << ok.status().message();
    EXPECT_TRUE(*ok) << c;
  }
  metrics = {{"nav_time_s", 1248}, {"ctrl_rate_hz", 0.91}, {"completed", 0}};
  for (const std::string& c : spec.constraints) {
    Result<bool> ok = EvaluateConstraint(spec, c, metrics, point);
    ASSERT_TRUE(ok.ok()) << ok.status().message();
    EXPECT_FALSE(*ok) << c;
  }
  metrics["nav_time_s"] = std::nan("");
  EXPECT_FALSE(*EvaluateConstraint(spec, "nav_time_s", metrics, point));
  EXPECT_FALSE(EvaluateConstraint(spec, "collisions == 0", {}, point).ok());
}

TEST(DesignPointTest, AConstraintCheckerParsedOnceAgreesRowByRow) {
  Spec spec = Reference();
  const DesignPoint point = {{"cores", 4}, {"freq_ghz", 1.2}, {"lidar_hz", 14}};
  const ConstraintChecker checker(spec);
  const std::vector<std::map<std::string, double>> rows = {
      {{"nav_time_s", 165}, {"ctrl_rate_hz", 7.8}, {"completed", 1}},
      {{"nav_time_s", 1248}, {"ctrl_rate_hz", 7.8}, {"completed", 1}},
      {{"nav_time_s", 1248}, {"ctrl_rate_hz", 0.91}, {"completed", 0}},
      {{"nav_time_s", std::nan("")}, {"completed", 1}}};
  const std::vector<int> expected = {0, 1, 3, 2};
  for (size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(checker.Violated(rows[i], point),
              ViolatedConstraints(spec, rows[i], point))
        << i;
    EXPECT_EQ(checker.ViolatedCount(rows[i], point), expected[i]) << i;
  }
  // A constraint that does not parse never holds.
  spec.constraints.push_back("nav_time_s <=");
  EXPECT_EQ(ConstraintChecker(spec).Violated(rows[0], point),
            std::vector<std::string>{"nav_time_s <="});
}

TEST(DesignPointTest, TheMetricsConstraintsReadLeaveOutDesignParameters) {
  Spec spec = Reference();
  spec.constraints = {"nav_time_s <= 60 && cores <= 8", "completed",
                      "ctrl_rate_hz >= 1 || nav_time_s < 10", "nav_time_s <="};
  EXPECT_EQ(
      ConstraintMetrics(spec),
      (std::vector<std::string>{"nav_time_s", "completed", "ctrl_rate_hz"}));
  spec.constraints.clear();
  EXPECT_TRUE(ConstraintMetrics(spec).empty());
}

TEST(DesignPointTest, ApplyPointSetsPlatformAndStack) {
  const Spec spec = Reference();
  Result<PointConfig> config =
      ApplyPoint(spec, {{"cores", 23}, {"freq_ghz", 1.5}, {"lidar_hz", 14}});
  ASSERT_TRUE(config.ok()) << config.status().message();
  EXPECT_EQ(config->platform.cores, 23);
  EXPECT_NEAR(config->platform.freq_ghz, 1.5, kTol);
  EXPECT_NEAR(config->stack.Get("lidar.rate_hz"), 14, kTol);
  EXPECT_NEAR(config->stack.Lidar().rate_hz, 14, kTol);
  EXPECT_FALSE(ApplyPoint(spec, {{"cores", 23}}).ok());
}

// Every regular list a range expands to is recognised as that range, in
// text that reads back to exactly the same values.
TEST(RangeOfTest, ExpandedRangesAreRecognisedAndReadBackExactly) {
  const struct {
    double lo, hi, step;
  } kRanges[] = {{1, 16, 1},    {0.5, 3.0, 0.1},         {2, 300, 0.00350001},
                 {-5, 5, 0.25}, {1e-3, 2e-3, 1e-5},      {10, 1e5, 7},
                 {0, 0.9, 0.3}, {1.2, 99.7, 0.123456789}};
  for (const auto& r : kRanges) {
    SCOPED_TRACE(r.step);
    const std::vector<double> values = ExpandRange(r.lo, r.hi, r.step);
    std::string lo, hi, step;
    ASSERT_TRUE(RangeOf(values, &lo, &hi, &step));
    double l = 0, h = 0, s = 0;
    ASSERT_TRUE(ParseNumber(lo, &l) && ParseNumber(hi, &h) &&
                ParseNumber(step, &s));
    EXPECT_EQ(ExpandRange(l, h, s), values);
  }
  std::string lo, hi, step;
  EXPECT_FALSE(RangeOf({1, 2, 4}, &lo, &hi, &step)) << "not evenly spaced";
  EXPECT_FALSE(RangeOf({1, 2}, &lo, &hi, &step)) << "too short to say";
}

// A long range normalises to its range, not to 85 000 values, so the
// normalised text parses back (found by fuzz_spec_parser).
TEST(RangeOfTest, ALongRangeNormalisesToARangeThatParsesBack) {
  ParseOptions options;
  options.check_files = false;
  Result<Spec> spec = ParseSpec(
      "adse: 1\nworld: {map: {generate: grid}}\n"
      "task: {start: {x: 0, y: 0}, goal: {x: 10, y: 0}}\n"
      "design_space: {r: {bind: stack.lidar.range_m, range: [2, 300], "
      "step: 0.00350001}}\n",
      "long.yaml", "", options);
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  const std::string normalized = NormalizedYaml(*spec);
  EXPECT_LT(normalized.size(), 4096u);
  Result<Spec> again = ParseSpec(normalized, "long.yaml", "", options);
  ASSERT_TRUE(again.ok()) << again.status().message();
  EXPECT_EQ(again->design_space.parameters[0].values,
            spec->design_space.parameters[0].values);
  EXPECT_EQ(NormalizedYaml(*again), normalized);
}

}  // namespace
}  // namespace adse::spec
