// The cost profile's distribution and validation, and how the virtual
// platform charges a profiled callback: a seeded draw, scaled by work units,
// its parallel part and the clock ratio to the power freq_exponent.
#include "stack/runtime/cost_profile.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "stack/runtime/executor.h"
#include "stack/runtime/graph.h"

namespace adse::stack {
namespace {

constexpr double kTol = 1e-12;

struct Msg {
  Header header;
  int value = 0;
};

// min 1 ms, p50 2 ms, p95 4 ms, max 10 ms.
CallbackCost FourPoints() {
  CallbackCost c;
  c.quantiles = {{0.0, 1e-3}, {0.5, 2e-3}, {0.95, 4e-3}, {1.0, 10e-3}};
  return c;
}

CallbackCost Constant(double cost_s) {
  CallbackCost c;
  c.quantiles = {{0.0, cost_s}, {1.0, cost_s}};
  return c;
}

TEST(SampleCostTest, FollowsTheQuantilesPiecewiseLinearly) {
  const CallbackCost c = FourPoints();
  EXPECT_NEAR(SampleCost(c, 0.0), 1e-3, kTol);
  EXPECT_NEAR(SampleCost(c, 0.25), 1.5e-3, kTol);
  EXPECT_NEAR(SampleCost(c, 0.5), 2e-3, kTol);
  EXPECT_NEAR(SampleCost(c, 0.725), 3e-3, kTol);
  EXPECT_NEAR(SampleCost(c, 0.975), 7e-3, kTol);
  EXPECT_NEAR(SampleCost(c, 1.0), 10e-3, kTol);
  EXPECT_NEAR(SampleCost(c, -1.0), 1e-3, kTol);  // clamped
  EXPECT_NEAR(SampleCost(c, 2.0), 10e-3, kTol);
}

TEST(ValidateCostProfileTest, NamesTheCallbackAndTheFieldThatIsWrong) {
  auto error_of = [](CallbackCost cost) {
    CostProfile p;
    p.reference_ghz = 4.9;
    p.callbacks["ndt/points"] = std::move(cost);
    return ValidateCostProfile(p).message();
  };
  CostProfile ok;
  ok.reference_ghz = 4.9;
  ok.callbacks["ndt/points"] = FourPoints();
  EXPECT_TRUE(ValidateCostProfile(ok).ok());

  CallbackCost c = FourPoints();
  c.quantiles[2].cost_s = 1e-3;  // p95 below p50
  EXPECT_NE(error_of(c).find("callbacks.ndt/points: cost must not fall"),
            std::string::npos)
      << error_of(c);
  c = FourPoints();
  c.quantiles[1].cost_s = std::nan("");
  EXPECT_NE(error_of(c).find("finite"), std::string::npos);
  c = FourPoints();
  c.quantiles.front().q = 0.1;
  EXPECT_NE(error_of(c).find("from q = 0 to q = 1"), std::string::npos);
  c = FourPoints();
  c.parallel_fraction = 1.5;
  EXPECT_NE(error_of(c).find("parallel_fraction"), std::string::npos);
  c = FourPoints();
  c.max_threads = 0;
  EXPECT_NE(error_of(c).find("max_threads"), std::string::npos);
  c = FourPoints();
  c.freq_exponent = -1;
  EXPECT_NE(error_of(c).find("freq_exponent"), std::string::npos);
  c = FourPoints();
  c.reference_units = -3;
  EXPECT_NE(error_of(c).find("reference_units"), std::string::npos);

  CostProfile no_clock = ok;
  no_clock.reference_ghz = 0;
  EXPECT_NE(ValidateCostProfile(no_clock).message().find("reference_ghz"),
            std::string::npos);
}

// One subscription "s/cb" that reports `value` work units, on a platform
// charging it from `cost` (measured at 4 GHz).
struct OneCallback {
  Graph graph;
  int topic = 0;
  int callback = 0;
  std::unique_ptr<Executor> executor;

  OneCallback(CallbackCost cost, int cores, double freq_ghz, uint64_t seed,
              double cost_scale = 1.0) {
    topic = graph.AddTopic<Msg>("in");
    callback = graph.Subscribe<Msg>(
        graph.AddNode("s"), topic, "cb", 1000,
        [](const Msg& m, CallbackContext& ctx) {
          // Runs with up to 6 threads, as a knob like ndt_threads says.
          ctx.ReportWork({.units = static_cast<double>(m.value),
                          .parallel_fraction = 0.0,
                          .max_threads = 6});
        });
    auto profile = std::make_shared<CostProfile>();
    profile->reference_ghz = 4.0;
    profile->callbacks["s/cb"] = std::move(cost);
    VirtualPlatformOptions o;
    o.cores = cores;
    o.freq_ghz = freq_ghz;
    o.cost_model = CostModelKind::kCounted;
    o.profile = profile;
    o.profile_seed = seed;
    o.cost_scale = cost_scale;
    auto created = CreateVirtualExecutor(&graph, o);
    EXPECT_TRUE(created.ok()) << created.status().ToString();
    if (created.ok()) executor = std::move(created).value();
  }

  // Publishes `n` messages of `units` one second apart and returns each
  // invocation's cost.
  std::vector<double> Costs(int n, int units) {
    for (int i = 0; i < n; ++i) {
      Msg m;
      m.value = units;
      executor->PublishExternal(topic, std::make_shared<const Msg>(m), i, i);
    }
    EXPECT_TRUE(executor->AdvanceTo(n + 1.0).ok());
    std::vector<double> costs;
    for (const CallbackRecord& r : executor->trace().callbacks) {
      costs.push_back(r.cost_s);
    }
    return costs;
  }
};

TEST(ProfiledCostTest, ScalesWithTheClockToThePowerOfTheExponent) {
  for (double alpha : {1.0, 0.5}) {
    CallbackCost c = Constant(0.010);
    c.freq_exponent = alpha;
    OneCallback one(c, 1, 2.0, 7, /*cost_scale=*/3.0);
    const std::vector<double> costs = one.Costs(1, 0);
    ASSERT_EQ(costs.size(), 1u);
    EXPECT_NEAR(costs[0], 0.010 * std::pow(4.0 / 2.0, alpha) * 3.0, 1e-12)
        << alpha;
  }
}

TEST(ProfiledCostTest, ScalesWithTheWorkUnitsOfThisInvocation) {
  CallbackCost c = Constant(0.010);
  c.reference_units = 1000;
  OneCallback one(c, 1, 4.0, 7);
  const std::vector<double> costs = one.Costs(1, 2500);
  ASSERT_EQ(costs.size(), 1u);
  EXPECT_NEAR(costs[0], 0.025, 1e-12);
}

TEST(ProfiledCostTest, ItsParallelPartUsesTheFreeCoresUpToBothMaxima) {
  CallbackCost c = Constant(0.040);
  c.parallel_fraction = 0.75;
  for (int max_threads : {4, 8}) {
    c.max_threads = max_threads;
    for (int cores : {1, 2, 8}) {
      OneCallback one(c, cores, 4.0, 7);
      const std::vector<double> costs = one.Costs(1, 0);
      ASSERT_EQ(costs.size(), 1u);
      // The profile's maximum, the callback's 6 threads, the free cores.
      const int k = std::min({cores, max_threads, 6});
      EXPECT_NEAR(costs[0], 0.040 * (0.25 + 0.75 / k), 1e-12) << cores;
      EXPECT_EQ(one.executor->trace().callbacks[0].cores, k);
    }
  }
}

TEST(ProfiledCostTest, DrawsAreSeededAndFollowTheDistribution) {
  const int n = 4000;
  const std::vector<double> a =
      OneCallback(FourPoints(), 1, 4.0, 11).Costs(n, 0);
  const std::vector<double> b =
      OneCallback(FourPoints(), 1, 4.0, 11).Costs(n, 0);
  const std::vector<double> other =
      OneCallback(FourPoints(), 1, 4.0, 12).Costs(n, 0);
  ASSERT_EQ(a.size(), static_cast<size_t>(n));
  EXPECT_EQ(a, b);  // bit-identical for one seed
  EXPECT_NE(a, other);
  // The distribution's mean: the average of each linear piece's midpoint
  // weighted by its probability mass.
  const double want = 0.5 * 1.5e-3 + 0.45 * 3e-3 + 0.05 * 7e-3;
  const double mean = std::accumulate(a.begin(), a.end(), 0.0) / n;
  EXPECT_NEAR(mean, want, 0.03 * want);
  std::vector<double> sorted = a;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_NEAR(sorted[n / 2], 2e-3, 0.1e-3);
  EXPECT_NEAR(sorted[n * 95 / 100], 4e-3, 0.3e-3);
  EXPECT_GE(sorted.front(), 1e-3);
  EXPECT_LE(sorted.back(), 10e-3);
}

TEST(ProfiledCostTest, ACallbackTheProfileDoesNotCostIsRefusedByName) {
  Graph g;
  const int in = g.AddTopic<Msg>("in");
  const int node = g.AddNode("s");
  g.Subscribe<Msg>(node, in, "cb", 1, [](const Msg&, CallbackContext&) {});
  g.Subscribe<Msg>(node, in, "other", 1, [](const Msg&, CallbackContext&) {});
  auto profile = std::make_shared<CostProfile>();
  profile->reference_ghz = 4.0;
  profile->callbacks["s/cb"] = Constant(0.01);
  VirtualPlatformOptions o;
  o.cost_model = CostModelKind::kCounted;
  o.profile = profile;
  auto created = CreateVirtualExecutor(&g, o);
  ASSERT_FALSE(created.ok());
  EXPECT_NE(
      created.status().message().find("no entry for callback(s): s/other"),
      std::string::npos)
      << created.status().message();
}

}  // namespace
}  // namespace adse::stack
