// The small robotaxi scenario as closed-loop tests use it.
#ifndef ADSE_TESTS_HARNESS_TESTING_SMALL_SCENARIO_H_
#define ADSE_TESTS_HARNESS_TESTING_SMALL_SCENARIO_H_

#include <gtest/gtest.h>

#include <string>

#include "harness/spec/spec_parser.h"

namespace adse::testing {

inline std::string SmallScenarioPath() {
  return std::string(ADSE_SOURCE_DIR) + "/scenarios/robotaxi_small.yaml";
}

// scenarios/robotaxi_small.yaml, which uses the counted cost model and the
// bundled Autoware profile: the same answers on any machine and under any load,
// so thresholds cannot flake.
inline spec::Spec SmallScenario() {
  Result<spec::Spec> spec = spec::LoadSpec(SmallScenarioPath());
  EXPECT_TRUE(spec.ok()) << spec.status().ToString();
  EXPECT_EQ(spec->platform.cost_model, spec::CostModel::kCounted);
  return std::move(spec).value();
}

inline spec::DesignPoint SmallPoint(double cores, double freq_ghz,
                                    double lidar_hz) {
  return {{"cores", cores}, {"freq_ghz", freq_ghz}, {"lidar_hz", lidar_hz}};
}

}  // namespace adse::testing

#endif  // ADSE_TESTS_HARNESS_TESTING_SMALL_SCENARIO_H_
