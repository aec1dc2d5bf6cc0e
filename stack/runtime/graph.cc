#include "stack/runtime/graph.h"

#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace adse::stack {
namespace {

bool IsFinitePositive(double v) { return std::isfinite(v) && v > 0.0; }

template <typename T>
int FindByName(const std::vector<T>& items, const std::string& name) {
  for (size_t i = 0; i < items.size(); ++i) {
    if (items[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace

int Graph::FindTopic(const std::string& name) const {
  return FindByName(topics_, name);
}
int Graph::FindNode(const std::string& name) const {
  return FindByName(nodes_, name);
}
int Graph::FindCallback(const std::string& name) const {
  return FindByName(callbacks_, name);
}

Status ValidateGraph(const Graph& graph) {
  const int num_topics = static_cast<int>(graph.topics().size());
  const int num_nodes = static_cast<int>(graph.nodes().size());
  for (const CallbackSpec& spec : graph.callbacks()) {
    if (spec.node < 0 || spec.node >= num_nodes) {
      return Status::InvalidArgument(fmt::format(
          "callback '{}': node index {} out of range", spec.name, spec.node));
    }
    if (spec.kind == CallbackSpec::Kind::kSubscription) {
      if (spec.topic < 0 || spec.topic >= num_topics) {
        return Status::InvalidArgument(
            fmt::format("callback '{}': topic index {} out of range", spec.name,
                        spec.topic));
      }
      if (spec.queue_depth < 1) {
        return Status::InvalidArgument(
            fmt::format("callback '{}': queue_depth must be >= 1, got {}",
                        spec.name, spec.queue_depth));
      }
      if (!spec.on_message) {
        return Status::InvalidArgument(
            fmt::format("callback '{}': no function", spec.name));
      }
    } else {
      if (!IsFinitePositive(spec.period_s)) {
        return Status::InvalidArgument(
            fmt::format("timer '{}': period_s must be finite and > 0, got {}",
                        spec.name, spec.period_s));
      }
      if (!std::isfinite(spec.phase_s) || spec.phase_s < 0.0) {
        return Status::InvalidArgument(
            fmt::format("timer '{}': phase_s must be finite and >= 0, got {}",
                        spec.name, spec.phase_s));
      }
      if (!spec.on_timer) {
        return Status::InvalidArgument(
            fmt::format("timer '{}': no function", spec.name));
      }
    }
  }
  for (size_t s = 0; s < graph.sinks().size(); ++s) {
    const SinkSpec& sink = graph.sinks()[s];
    if (sink.topic < 0 || sink.topic >= num_topics) {
      return Status::InvalidArgument(
          fmt::format("sink #{}: topic index {} out of range", s, sink.topic));
    }
    if (!sink.fn) {
      return Status::InvalidArgument(fmt::format("sink #{}: no function", s));
    }
  }
  return Status::Ok();
}

Status CheckProfileCovers(const CostProfile& profile, const Graph& graph) {
  std::vector<std::string> missing;
  for (const CallbackSpec& spec : graph.callbacks()) {
    if (profile.callbacks.count(spec.name) == 0) missing.push_back(spec.name);
  }
  if (missing.empty()) return Status::Ok();
  return Status::InvalidArgument(
      fmt::format("cost profile has no entry for callback(s): {}",
                  fmt::join(missing, ", ")));
}

}  // namespace adse::stack
