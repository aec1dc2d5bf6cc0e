// Scenarios as tests of what adse makes of runs write them: a generated
// parking lot, a start and a goal, then the test's own design space,
// objectives and constraints, parsed without file checks (no map, profile
// or calibration to find).
#ifndef ADSE_TESTS_HARNESS_TESTING_LOT_SCENARIO_H_
#define ADSE_TESTS_HARNESS_TESTING_LOT_SCENARIO_H_

#include <gtest/gtest.h>

#include <string>
#include <utility>

#include "harness/spec/spec_parser.h"

namespace adse::testing {

// `rest` (the design space and what follows, each line ending in '\n')
// under the name `name`, as if read from <name>.yaml.
inline spec::Spec LotScenario(const std::string& name,
                              const std::string& rest) {
  spec::ParseOptions options;
  options.check_files = false;
  Result<spec::Spec> spec = spec::ParseSpec(
      "adse: 1\nname: " + name +
          "\nworld: {map: {generate: parking_lot}}\n"
          "task: {start: {x: 5, y: -1.75}, goal: {x: 60, y: 29.75}}\n" +
          rest,
      name + ".yaml", ".", options);
  EXPECT_TRUE(spec.ok()) << spec.status().ToString();
  return std::move(spec).value();
}

}  // namespace adse::testing

#endif  // ADSE_TESTS_HARNESS_TESTING_LOT_SCENARIO_H_
