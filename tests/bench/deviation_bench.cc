// Trajectory deviation fit of a 20-minute drive sampled at 20 Hz (24,000
// samples) on a 7.2 km route with 48 right-angle corners, driven with a
// 0.3 m offset, a 0.25 m / 5 s weave and 5 cm position noise.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "analysis/deviation/deviation.h"

namespace adse::analysis {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Drive {
  std::vector<Eigen::Vector2d> path;
  std::vector<TimedXy> actual;
};

// A staircase route: 150 m east, 150 m north, repeated.
Drive TwentyMinuteDrive(int samples) {
  Drive d;
  d.path.emplace_back(0.0, 0.0);
  for (int k = 0; k < 48; ++k) {
    Eigen::Vector2d next = d.path.back();
    next[k % 2] += 150.0;
    d.path.push_back(next);
  }
  std::vector<double> cum{0.0};
  for (size_t k = 1; k < d.path.size(); ++k) {
    cum.push_back(cum.back() + (d.path[k] - d.path[k - 1]).norm());
  }
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (int i = 0; i < samples; ++i) {
    const double t = 0.05 * i;
    const double s = std::min(cum.back(), 5.1 * t);
    size_t k = 1;
    while (k + 1 < d.path.size() && cum[k] < s) ++k;
    const Eigen::Vector2d dir = (d.path[k] - d.path[k - 1]).normalized();
    const Eigen::Vector2d normal(-dir.y(), dir.x());
    const double lateral = 0.3 + 0.25 * std::sin(2.0 * kPi * t / 5.0);
    const Eigen::Vector2d p =
        d.path[k - 1] + (s - cum[k - 1]) * dir + lateral * normal;
    d.actual.push_back({t, p.x() + noise(rng), p.y() + noise(rng)});
  }
  return d;
}

void BM_FitDeviation(benchmark::State& state) {
  const Drive d = TwentyMinuteDrive(static_cast<int>(state.range(0)));
  DeviationResult last;
  for (auto _ : state) {
    Result<DeviationResult> r = FitDeviation(d.path, d.actual, 3.5);
    if (!r.ok()) {
      state.SkipWithError(r.status().ToString().c_str());
      return;
    }
    last = std::move(r).value();
    benchmark::DoNotOptimize(last);
  }
  state.counters["iterations"] = last.iterations;
  state.counters["offset_m"] = last.offset_m;
  state.counters["osc_rms_m"] = last.oscillation_rms_m;
  state.counters["zigzag"] = last.zigzag_index;
}
BENCHMARK(BM_FitDeviation)
    ->Arg(2400)
    ->Arg(24000)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace adse::analysis

BENCHMARK_MAIN();
