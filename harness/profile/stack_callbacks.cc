// The callback names of adse's stack graph, from the graph itself: a
// mapping or profile that covers this list covers every callback the
// executor will charge (it refuses a graph callback the profile lacks).
#include <Eigen/Core>

#include "harness/profile/profile.h"
#include "stack/config/stack_config.h"
#include "stack/nodes/ad_stack.h"
#include "stack/runtime/graph.h"

namespace adse::profile {

Result<std::vector<std::string>> StackCallbackNames() {
  // AdStack::Build needs only what a car carries, not a world: a route of
  // two points and a localization cloud the NDT accepts (a small grid of
  // points over two heights). Nothing here touches SUMO.
  stack::StackInputs inputs;
  inputs.route.points = {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(10.0, 0.0)};
  inputs.route.UpdateArcLength();
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 10; ++j) {
      for (int k = 0; k < 2; ++k) {
        inputs.map_cloud.emplace_back(0.5f * i, 0.5f * j, 0.5f * k);
      }
    }
  }
  stack::Graph graph;
  Result<std::unique_ptr<stack::AdStack>> built =
      stack::AdStack::Build(StackConfig(), inputs, &graph);
  if (!built.ok()) {
    return Status::Internal("listing the stack's callbacks: " +
                            built.status().message());
  }
  std::vector<std::string> names;
  for (const stack::CallbackSpec& spec : graph.callbacks()) {
    names.push_back(spec.name);
  }
  return names;
}

}  // namespace adse::profile
