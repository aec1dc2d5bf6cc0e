// Synthetic landscapes to measure exploration strategies on (issue 16):
// campaign indexes in the format `adse explore --replay` reads, one
// complete row per point of a grid, with metrics from a closed-form model
// of a driving stack instead of simulation. Each landscape has one shape
// that a strategy must cope with (a front that saturates, constraints that
// cut the space and stop runs early, noise, another cost, a knob that does
// nothing, four dimensions); its scenario is the reference study's with
// another design space, cost, objectives or constraints. Recordings of real
// campaigns take hours; these are rebuilt in a second, and deterministic.
#ifndef ADSE_TESTS_TOOLS_LANDSCAPES_H_
#define ADSE_TESTS_TOOLS_LANDSCAPES_H_

#include <string>
#include <vector>

#include "analysis/runfile/campaign_file.h"
#include "stack/base/status.h"

namespace adse::landscapes {

// The landscapes committed under tests/data/landscapes, which tests and
// the README measure the strategies on, or a held-out family with other
// loads, grids, costs and bounds that no strategy was tuned on, written
// on demand and never committed.
enum class LandscapeFamily { kCommitted, kHeldOut };

// Every landscape's name in a family, in the order WriteLandscapes writes
// them; each committed one is also its folder under tests/data/landscapes.
std::vector<std::string> LandscapeNames(
    LandscapeFamily family = LandscapeFamily::kCommitted);

// One landscape's index: its scenario text and one row per design point in
// lexicographic order (first parameter slowest), as an exhaustive campaign
// of that scenario would hold them. InvalidArgument for an unknown name;
// any other error is a bug in the landscape's definition (its scenario does
// not parse, a constraint does not evaluate).
Result<runfile::CampaignIndex> BuildLandscape(
    const std::string& name,
    LandscapeFamily family = LandscapeFamily::kCommitted);

// Writes <out_dir>/<name>/campaign.h5 for every landscape of the family,
// creating the folders.
Status WriteLandscapes(const std::string& out_dir,
                       LandscapeFamily family = LandscapeFamily::kCommitted);

// What a noisy landscape lets a search expect at a budget, whatever its
// strategy. The landscape is rebuilt `draws` times from the same model
// with fresh noise; a point's chance of being on the true front is the
// share of redraws in which it is.
struct NoiseLimit {
  // True Pareto points of the landscape as written, and on average over
  // the redraws.
  int front_size = 0;
  double mean_front_size = 0.0;
  // The most true Pareto points `budget` points chosen in advance can
  // expect: the sum of the `budget` largest chances.
  double best_fixed_expected = 0.0;
  // True Pareto points of the landscape as written found by a greedy
  // oracle that knows the model and the law of its noise, and sees what
  // each of its points measured: each pick is the point most often on the
  // front over the redraws, with the points already picked held at their
  // values.
  int greedy_found = 0;
};

// InvalidArgument for an unknown name or a budget or draws below 1.
Result<NoiseLimit> ComputeNoiseLimit(
    const std::string& name, int budget, int draws,
    LandscapeFamily family = LandscapeFamily::kCommitted);

}  // namespace adse::landscapes

#endif  // ADSE_TESTS_TOOLS_LANDSCAPES_H_
