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

}  // namespace adse::landscapes

#endif  // ADSE_TESTS_TOOLS_LANDSCAPES_H_
