// The real-time platform: a Graph's callbacks run on N host threads in
// real time, as a ROS 2 multi-threaded executor runs them, each padded to
// its profile cost at the point's frequency. The OS schedules the threads
// preemptively; nothing about the timing is simulated. It implements the
// same Executor interface as the virtual platform, so the world, the trace
// and everything downstream are unchanged.
#ifndef ADSE_STACK_RUNTIME_REALTIME_EXECUTOR_H_
#define ADSE_STACK_RUNTIME_REALTIME_EXECUTOR_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "stack/base/status.h"
#include "stack/runtime/cost_profile.h"
#include "stack/runtime/executor.h"
#include "stack/runtime/graph.h"

namespace adse::stack {

struct RealTimeOptions {
  // Executor threads: the point's cores.
  int cores = 1;
  // The point's clock. A callback busy-works after its real code until its
  // thread has used its profile cost at this frequency in CPU time:
  // draw * (profile reference_ghz / freq_ghz)^freq_exponent * cost_scale.
  double freq_ghz = 2.1;
  // Required: every callback of the graph needs an entry.
  std::shared_ptr<const CostProfile> profile;
  // Seeds the draws as on the virtual platform (same streams per callback).
  uint64_t profile_seed = 0;
  double cost_scale = 1.0;
  // Wall seconds per simulated second (>= 1): slows the sim clock and
  // stretches every cost by the same factor, so a small host can hold a
  // heavy stack. It assumes the host's own overheads (scheduling, cache,
  // the world's steps) scale the same way, which they do not exactly.
  double time_dilation = 1.0;
  // Host CPUs the executor threads may run on (sched_setaffinity, as
  // taskset); empty: wherever the OS likes.
  std::vector<int> host_cpus;
  // The share of a host CPU each thread is granted over time, in (0, 1]:
  // < 1 when a CPU quota (cgroup cpu.max) stands for a slower clock. The
  // padding in CPU time is scaled by it, so that under that quota a
  // callback's wall time is still its cost at freq_ghz.
  double cpu_share = 1.0;
  // Called first on each of the executor's threads (the N workers and the
  // clock), e.g. to move the thread into a cgroup. A failure stops the
  // executor and CreateRealTimeExecutor returns it.
  std::function<Status()> enter_thread;
};

// InvalidArgument naming the field: cores in [1, 256], freq_ghz and
// cost_scale finite > 0, time_dilation finite >= 1, a valid profile,
// host_cpus non-negative and distinct, cpu_share in (0, 1].
Status ValidateRealTimeOptions(const RealTimeOptions& options);

// Starts the executor threads (they wait for the first AdvanceTo; the sim
// clock starts then). Semantics, where they differ from the virtual
// platform's (executor.h):
// - Time: sim time = wall time since the first AdvanceTo / time_dilation.
//   AdvanceTo(t) sleeps until then; it never runs faster than real time.
// - PublishExternal(t_s): delivered when the sim clock reaches t_s (at once
//   when it has already passed: a world running late delivers late).
// - Dispatch: any idle thread takes the ready callback (its node idle)
//   with the earliest ready time (a subscription's: the oldest message it
//   has not taken, as on the virtual platform); the OS preempts freely. A
//   callback's publications are held to its end, as on the virtual platform.
// - Data-parallel callbacks: k = min(max_threads, cores) threads pad the
//   parallel part together (the callback's thread and k - 1 helpers, in
//   the same CPUs and group), each its 1/k share in thread CPU time after
//   the serial part; the OS shares the CPUs between them and everything
//   else (the virtual platform gives such a callback only the cores free
//   when it starts).
// - Sinks run on the thread that calls AdvanceTo, in publication order,
//   with their publication time, before AdvanceTo returns.
// - CallbackRecord: times are sim seconds read from the clock; cost_s =
//   end - start (with preemption); host_cpu_s the real code's thread CPU
//   time, without the padding; first_core the thread's index.
// - trace() may be read only after the last AdvanceTo; Stop() (or the
//   destructor) ends the threads, and callbacks still running complete
//   without their records.
Result<std::unique_ptr<Executor>> CreateRealTimeExecutor(
    const Graph* graph, const RealTimeOptions& options);

}  // namespace adse::stack

#endif  // ADSE_STACK_RUNTIME_REALTIME_EXECUTOR_H_
