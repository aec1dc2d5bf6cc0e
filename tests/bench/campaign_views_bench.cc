// The cost of writing a campaign's views (campaign.h5, summary.json,
// report.md, pareto.png) once, as a running campaign does on every
// proposal: on the recorded robotaxi campaign's first 12 and all 280 rows.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>

#include <unistd.h>

#include "harness/campaign/campaign.h"
#include "harness/campaign/replay.h"

namespace adse::campaign {
namespace {

void BM_WriteCampaignViews(benchmark::State& state) {
  Result<Recording> recording = LoadRecording(
      std::string(ADSE_SOURCE_DIR) + "/tests/data/robotaxi_exhaustive");
  if (!recording.ok()) {
    state.SkipWithError(recording.status().ToString().c_str());
    return;
  }
  const std::string dir = std::filesystem::temp_directory_path().string() +
                          "/adse-views-bench-" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  CampaignSummary summary;
  summary.output_dir = dir;
  summary.in_progress = true;
  recording->rows.resize(static_cast<size_t>(state.range(0)));
  summary.exploration.evaluations = recording->rows;
  for (auto _ : state) {
    Status s = WriteCampaignViews(recording->spec, summary, Env::Default());
    if (!s.ok()) {
      state.SkipWithError(s.ToString().c_str());
      break;
    }
  }
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_WriteCampaignViews)
    ->Arg(12)
    ->Arg(280)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace adse::campaign

BENCHMARK_MAIN();
