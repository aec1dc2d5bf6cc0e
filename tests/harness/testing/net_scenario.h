// The sim tests' lane-driving scenarios on a net: one YAML text, parsed,
// for the real nets and the test nets alike.
#ifndef ADSE_TESTS_HARNESS_TESTING_NET_SCENARIO_H_
#define ADSE_TESTS_HARNESS_TESTING_NET_SCENARIO_H_

#include <gtest/gtest.h>

#include <string>
#include <utility>

#include "harness/spec/spec_parser.h"

namespace adse::testing {

struct NetScenario {
  std::string name;
  std::string net;    // a .net.xml path
  std::string start;  // flow-map places
  std::string goal;
  std::string flows = "[]";    // a flow-sequence of flows ...
  int traffic_seed = 1;        // ... drawn from this seed
  std::string stopped = "[]";  // a flow-sequence of places
  int timeout_s = 600;
  // Costs counted from this profile of scenarios/profiles.
  std::string profile = "autoware-2022.12-i9-12900kf-signals.yaml";
};

// The scenario at 40 km/h, with cores and the clock as its design space.
inline spec::Spec ParseNetScenario(const NetScenario& s) {
  const std::string text =
      "adse: 1\n"
      "name: " +
      s.name +
      "\n"
      "world:\n"
      "  map: {net: " +
      s.net +
      "}\n"
      "  traffic: {seed: " +
      std::to_string(s.traffic_seed) + ", flows: " + s.flows +
      ", stopped_vehicles: " + s.stopped +
      "}\n"
      "task:\n"
      "  start: " +
      s.start +
      "\n"
      "  goal: " +
      s.goal +
      "\n"
      "  speed_limit_kmh: 40\n"
      "  timeout_s: " +
      std::to_string(s.timeout_s) +
      "\n"
      "platform: {kind: virtual, cost_model: counted, profile: " +
      std::string(ADSE_SOURCE_DIR) + "/scenarios/profiles/" + s.profile +
      "}\n"
      "design_space:\n"
      "  cores:    {bind: platform.cores,    range: [1, 16]}\n"
      "  freq_ghz: {bind: platform.freq_ghz, values: [1.2, 2.1]}\n";
  Result<spec::Spec> spec = spec::ParseSpec(text, s.name + ".yaml", "");
  EXPECT_TRUE(spec.ok()) << spec.status().ToString();
  return std::move(spec).value();
}

}  // namespace adse::testing

#endif  // ADSE_TESTS_HARNESS_TESTING_NET_SCENARIO_H_
