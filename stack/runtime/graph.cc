#include "stack/runtime/graph.h"

namespace adse::stack {
namespace {

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

}  // namespace adse::stack
