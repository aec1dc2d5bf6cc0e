// A cores x clock scenario and rows of it, for tests of what a campaign
// makes of its rows (headline, cheaper designs): cost cores * freq_ghz,
// feasible within 60 s unless the constraints say otherwise.
#ifndef ADSE_TESTS_HARNESS_TESTING_GRID_CAMPAIGN_H_
#define ADSE_TESTS_HARNESS_TESTING_GRID_CAMPAIGN_H_

#include <gtest/gtest.h>

#include <string>

#include "harness/campaign/evaluation.h"
#include "tests/harness/testing/lot_scenario.h"

namespace adse::testing {

inline constexpr char kGrid[] =
    "  cores: {bind: platform.cores, values: [2, 4, 6, 8]}\n"
    "  freq_ghz: {bind: platform.freq_ghz, values: [1.5, 2.0, 3.0]}\n";

// `constraints` as the scenario writes them; `space` the design space's
// lines.
inline spec::Spec GridScenario(
    const std::string& constraints = "[nav_time_s <= 60]",
    const std::string& space = kGrid) {
  return LotScenario("ties", "design_space:\n" + space +
                                 "cost: cores * freq_ghz\n"
                                 "objectives: [{minimize: hardware_cost}, "
                                 "{minimize: nav_time_s}]\n"
                                 "constraints: " +
                                 constraints + "\n");
}

// A complete run of the grid, feasible when it arrives within 60 s.
inline campaign::EvaluationRow GridRow(int index, double cores, double freq_ghz,
                                       double nav_time_s) {
  campaign::EvaluationRow row;
  row.index = index;
  row.content_key = std::string(64, static_cast<char>('a' + index));
  row.status = "complete";
  row.reason = "goal_reached";
  row.source = "simulated";
  row.attempts = 1;
  row.point = {{"cores", cores}, {"freq_ghz", freq_ghz}};
  row.metrics = {{"nav_time_s", nav_time_s},
                 {"hardware_cost", cores * freq_ghz},
                 {"ctrl_rate_hz", 10},
                 {"completed", 1}};
  row.feasible = nav_time_s <= 60;
  row.bottlenecks_json = "[]";
  return row;
}

}  // namespace adse::testing

#endif  // ADSE_TESTS_HARNESS_TESTING_GRID_CAMPAIGN_H_
