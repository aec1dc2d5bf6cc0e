// What the executors' tests share: a small message, a counted virtual
// platform, external publication, and the records of one callback or the
// events of one topic picked out of a trace.
#ifndef ADSE_TESTS_STACK_RUNTIME_EXECUTOR_TEST_UTIL_H_
#define ADSE_TESTS_STACK_RUNTIME_EXECUTOR_TEST_UTIL_H_

#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "stack/runtime/executor.h"
#include "stack/runtime/graph.h"
#include "stack/runtime/messages.h"
#include "stack/runtime/trace.h"

namespace adse::stack::test {

struct Msg {
  Header header;
  int value = 0;
};

// `cores` at 2 GHz, the reference clock, with the counted cost model, so
// answers are exact.
inline VirtualPlatformOptions Counted(
    int cores, std::map<std::string, CountedCost> costs) {
  VirtualPlatformOptions o;
  o.cores = cores;
  o.freq_ghz = 2.0;
  o.reference_ghz = 2.0;
  o.cost_model = CostModelKind::kCounted;
  o.counted = std::move(costs);
  return o;
}

inline std::unique_ptr<Executor> CreateVirtual(
    const Graph& graph, const VirtualPlatformOptions& options) {
  auto result = CreateVirtualExecutor(&graph, options);
  EXPECT_TRUE(result.ok()) << result.status().ToString();
  if (!result.ok()) return nullptr;
  return std::move(result).value();
}

// A message stamped and arriving at `t`.
inline void Publish(Executor& ex, int topic, int value, double t) {
  Msg m;
  m.header.stamp_s = t;
  m.value = value;
  ex.PublishExternal(topic, std::make_shared<const Msg>(m), t, t);
}

inline auto Noop() {
  return [](const Msg&, CallbackContext&) {};
}

inline std::vector<CallbackRecord> RecordsOf(const Trace& trace, int callback) {
  std::vector<CallbackRecord> out;
  for (const CallbackRecord& r : trace.callbacks) {
    if (r.callback == callback) out.push_back(r);
  }
  return out;
}

inline std::vector<TopicEvent> EventsOf(const Trace& trace,
                                        TopicEvent::Kind kind, int topic) {
  std::vector<TopicEvent> out;
  for (const TopicEvent& e : trace.topic_events) {
    if (e.kind == kind && e.topic == topic) out.push_back(e);
  }
  return out;
}

}  // namespace adse::stack::test

#endif  // ADSE_TESTS_STACK_RUNTIME_EXECUTOR_TEST_UTIL_H_
