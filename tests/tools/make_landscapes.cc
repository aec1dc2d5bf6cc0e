// make_landscapes [--held-out] <out dir>: writes every synthetic landscape
// (tests/tools/landscapes.h) of the committed family, or with --held-out
// of the held-out one, as <out dir>/<name>/campaign.h5 and prints each
// one's size. The committed ones are regenerated with
//   make_landscapes tests/data/landscapes
// and make_landscapes_test fails when they and this generator drift apart.
//
// make_landscapes --noise-limit <name> [--budget N] [--draws N]: prints
// how many true Pareto points a noisy landscape lets any search expect
// within N runs (landscapes.h, NoiseLimit).
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <cstdio>
#include <string>
#include <vector>

#include "analysis/runfile/campaign_file.h"
#include "tests/tools/landscapes.h"

namespace {

using adse::landscapes::LandscapeFamily;

int Write(const std::string& out_dir, LandscapeFamily family) {
  const adse::Status written =
      adse::landscapes::WriteLandscapes(out_dir, family);
  if (!written.ok()) {
    std::fprintf(stderr, "error: %s\n", written.message().c_str());
    return adse::ExitCodeFor(written);
  }
  // Read back, so that what is reported is what was written.
  for (const std::string& name : adse::landscapes::LandscapeNames(family)) {
    const std::string path = out_dir + "/" + name + "/campaign.h5";
    adse::Result<adse::runfile::CampaignIndex> index =
        adse::runfile::ReadCampaignIndex(path);
    if (!index.ok()) {
      std::fprintf(stderr, "error: %s\n", index.status().message().c_str());
      return 1;
    }
    int feasible = 0, censored = 0;
    for (const adse::runfile::EvaluationRow& row : index->evaluations) {
      feasible += row.feasible;
      auto it = row.metrics.find("censored");
      censored += it != row.metrics.end() && it->second == 1.0;
    }
    const size_t n = index->evaluations.size();
    std::printf("%s: %zu points, %d feasible (%.1f %%), %d censored\n",
                path.c_str(), n, feasible, 100.0 * feasible / n, censored);
  }
  return 0;
}

int PrintNoiseLimit(const std::string& name, int budget, int draws,
                    LandscapeFamily family) {
  adse::Result<adse::landscapes::NoiseLimit> limit =
      adse::landscapes::ComputeNoiseLimit(name, budget, draws, family);
  if (!limit.ok()) {
    std::fprintf(stderr, "error: %s\n", limit.status().message().c_str());
    return adse::ExitCodeFor(limit.status());
  }
  fmt::print(
      "{}: {} true Pareto points as written; {:.1f} on average over {} "
      "redraws of its noise\n"
      "within {} runs: points chosen in advance expect at most {:.2f} of "
      "them; a greedy oracle that knows the model and its noise's law finds "
      "{}\n",
      name, limit->front_size, limit->mean_front_size, draws, budget,
      limit->best_fixed_expected, limit->greedy_found);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Write the synthetic landscapes (campaign indexes for `adse explore "
      "--replay`), or say how much of a noisy one's front any search can "
      "expect to find"};
  bool held_out = false;
  std::string out_dir;
  std::string noise_limit;
  int budget = 15;
  int draws = 200;
  app.add_flag("--held-out", held_out,
               "The held-out family, which no strategy was tuned on");
  app.add_option("out_dir", out_dir, "Folder to write <name>/campaign.h5 into");
  CLI::Option* limit_option = app.add_option(
      "--noise-limit", noise_limit,
      "Instead of writing, print how many true Pareto points this "
      "landscape's noise lets any search expect within --budget runs");
  app.add_option("--budget", budget, "Runs, with --noise-limit")
      ->check(CLI::Range(1, 100000));
  app.add_option("--draws", draws, "Redraws of the noise, with --noise-limit")
      ->check(CLI::Range(1, 100000));
  CLI11_PARSE(app, argc, argv);
  const LandscapeFamily family =
      held_out ? LandscapeFamily::kHeldOut : LandscapeFamily::kCommitted;
  if (limit_option->count() > 0) {
    if (!out_dir.empty()) {
      std::fprintf(stderr, "error: --noise-limit writes nothing; drop '%s'\n",
                   out_dir.c_str());
      return 2;
    }
    return PrintNoiseLimit(noise_limit, budget, draws, family);
  }
  if (out_dir.empty()) {
    std::fprintf(stderr, "error: an output folder is required\n%s",
                 app.help().c_str());
    return 2;
  }
  return Write(out_dir, family);
}
