// What an executor records while running a graph: every callback execution
// and every publish, take and drop per topic. Plain data, written to the
// run file by the harness.
#ifndef ADSE_STACK_RUNTIME_TRACE_H_
#define ADSE_STACK_RUNTIME_TRACE_H_

#include <cstdint>
#include <string>
#include <vector>

namespace adse::stack {

struct CallbackRecord {
  int32_t callback = -1;  // index into Graph::callbacks()
  int32_t node = -1;
  double ready_s = 0.0;     // message arrived / timer fired
  double start_s = 0.0;     // got a core
  double end_s = 0.0;       // outputs published
  double cost_s = 0.0;      // simulated execution time (end - start)
  double host_cpu_s = 0.0;  // thread CPU time the real code took on the host
                            // (0 in counted runs unless asked for)
  double work_units = 0.0;
  int32_t cores = 1;       // virtual cores held
  int32_t first_core = 0;  // lowest index of the cores held
};

struct TopicEvent {
  enum Kind : int8_t { kPublish = 0, kTake = 1, kDrop = 2 };
  Kind kind = kPublish;
  int32_t topic = -1;
  int32_t callback = -1;  // subscriber for take/drop; publisher for publish
                          // (-1: published from outside the graph)
  double t_s = 0.0;
  uint64_t seq = 0;      // per-topic sequence number of the message
  double stamp_s = 0.0;  // the message's header stamp
};

struct Trace {
  std::vector<CallbackRecord> callbacks;
  std::vector<TopicEvent> topic_events;
  // Timer fires skipped because the previous one had not started yet.
  std::vector<int64_t> timer_overruns;  // per callback index
};

}  // namespace adse::stack

#endif  // ADSE_STACK_RUNTIME_TRACE_H_
