// What drawing costs from a profile adds per callback invocation: the same
// graph (one subscription doing no work) on the counted model with a
// calibration entry and with a five-point profile entry. The difference per
// invocation, times the invocations of a run, bounds the profile's share of
// that run's wall time (issue 13 allows 2 %; see README "Cost profiles").
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <memory>

#include "stack/runtime/cost_profile.h"
#include "stack/runtime/executor.h"
#include "stack/runtime/graph.h"

namespace adse::stack {
namespace {

struct Msg {
  Header header;
};

void RunInvocations(benchmark::State& state, bool profiled) {
  Graph graph;
  const int topic = graph.AddTopic<Msg>("in");
  graph.Subscribe<Msg>(graph.AddNode("s"), topic, "cb", 1,
                       [](const Msg&, CallbackContext& ctx) {
                         ctx.ReportWork({.units = 1000.0});
                       });
  VirtualPlatformOptions o;
  o.cores = 1;
  o.cost_model = CostModelKind::kCounted;
  if (profiled) {
    auto profile = std::make_shared<CostProfile>();
    profile->reference_ghz = 4.9;
    CallbackCost& cost = profile->callbacks["s/cb"];
    cost.quantiles = {
        {0.0, 1e-4}, {0.5, 2e-4}, {0.95, 4e-4}, {0.99, 5e-4}, {1.0, 9e-4}};
    cost.reference_units = 900;
    o.profile = profile;
    o.profile_seed = 42;
  } else {
    o.counted["s/cb"] = {1e-4, 1e-7};
  }
  auto made = CreateVirtualExecutor(&graph, o);
  if (!made.ok()) std::abort();
  Executor& executor = **made;
  const auto message = std::make_shared<const Msg>();
  double t = 0.0;
  for (auto _ : state) {
    executor.PublishExternal(topic, message, t, t);
    t += 0.01;
    if (!executor.AdvanceTo(t).ok()) std::abort();
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_CountedCalibrationInvocation(benchmark::State& state) {
  RunInvocations(state, false);
}
void BM_CountedProfileInvocation(benchmark::State& state) {
  RunInvocations(state, true);
}
BENCHMARK(BM_CountedCalibrationInvocation);
BENCHMARK(BM_CountedProfileInvocation);

}  // namespace
}  // namespace adse::stack

BENCHMARK_MAIN();
