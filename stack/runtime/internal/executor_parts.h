// Pieces both executors (virtual and real-time) keep the same way. Internal
// to stack/runtime.
#ifndef ADSE_STACK_RUNTIME_INTERNAL_EXECUTOR_PARTS_H_
#define ADSE_STACK_RUNTIME_INTERNAL_EXECUTOR_PARTS_H_

#include <time.h>

#include <cstdint>

#include "stack/runtime/graph.h"

namespace adse::stack::internal {

// CPU time of the calling thread, seconds.
inline double ThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) +
         static_cast<double>(ts.tv_nsec) * 1e-9;
}

// A message waiting in a subscription's keep-last queue.
struct QueuedMessage {
  MessagePtr message;
  uint64_t seq = 0;
  double stamp_s = 0.0;
  double arrival_s = 0.0;
};

// A running callback's publication, released when the callback ends.
struct HeldPublication {
  int32_t topic;
  MessagePtr message;
  double stamp_s;
};

}  // namespace adse::stack::internal

#endif  // ADSE_STACK_RUNTIME_INTERNAL_EXECUTOR_PARTS_H_
