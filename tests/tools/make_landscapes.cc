// make_landscapes [--held-out] <out dir>: writes every synthetic landscape
// (tests/tools/landscapes.h) of the committed family, or with --held-out
// of the held-out one, as <out dir>/<name>/campaign.h5 and prints each
// one's size. The committed ones are regenerated with
//   make_landscapes tests/data/landscapes
// and make_landscapes_test fails when they and this generator drift apart.
#include <cstdio>
#include <string>
#include <vector>

#include "analysis/runfile/campaign_file.h"
#include "tests/tools/landscapes.h"

int main(int argc, char** argv) {
  using adse::landscapes::LandscapeFamily;
  std::vector<std::string> args(argv + 1, argv + argc);
  LandscapeFamily family = LandscapeFamily::kCommitted;
  if (!args.empty() && args.front() == "--held-out") {
    family = LandscapeFamily::kHeldOut;
    args.erase(args.begin());
  }
  if (args.size() != 1 || args[0].empty() || args[0][0] == '-') {
    std::fprintf(stderr,
                 "usage: make_landscapes [--held-out] <out dir>\n"
                 "Writes <out dir>/<name>/campaign.h5 for every synthetic "
                 "landscape (with --held-out, for those of the held-out "
                 "family, which no strategy was tuned on).\n");
    return 2;
  }
  const std::string out_dir = args[0];
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
