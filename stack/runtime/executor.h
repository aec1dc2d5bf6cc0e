// Executors decide when a graph's callbacks run and what they cost. The
// `virtual` platform simulates N cores at f GHz as discrete events; the
// real-time platform (realtime_executor.h) runs them on host threads.
#ifndef ADSE_STACK_RUNTIME_EXECUTOR_H_
#define ADSE_STACK_RUNTIME_EXECUTOR_H_

#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "stack/base/status.h"
#include "stack/runtime/cost_profile.h"
#include "stack/runtime/graph.h"
#include "stack/runtime/trace.h"

namespace adse::stack {

// Linear cost of one callback at the reference frequency: fixed + per unit.
struct CountedCost {
  double fixed_s = 0.0;
  double per_unit_s = 0.0;
};

enum class CostModelKind { kMeasured, kCounted };

// How the virtual platform's cores run the callbacks in progress.
enum class DispatchKind {
  // A callback holds its cores from start to end: one core, or a
  // data-parallel callback as many free cores as it can use when it starts.
  kRunToCompletion,
  // Each of `cores` executor threads runs one callback; a data-parallel
  // callback's parallel part runs on a team of min(max_threads, cores)
  // threads whether or not cores are free (as an OpenMP team does), and the
  // cores are shared equally among all threads that have work (as the OS's
  // preemptive scheduler shares them), so everything in progress runs
  // slower while threads outnumber cores.
  kProcessorSharing,
};

struct VirtualPlatformOptions {
  int cores = 4;               // virtual cores
  double freq_ghz = 2.1;       // their frequency
  double reference_ghz = 2.1;  // frequency at which host costs count as-is
  CostModelKind cost_model = CostModelKind::kMeasured;
  DispatchKind dispatch = DispatchKind::kRunToCompletion;
  // kCounted: cost per callback name ("<node>/<callback>"). A callback
  // without an entry costs `default_counted`.
  std::map<std::string, CountedCost> counted;
  CountedCost default_counted{1e-4, 0.0};
  // kCounted with a profile: each invocation's cost is drawn from the
  // profile's distribution for its callback (which every callback of the
  // graph must have), scaled by its work units, its parallel part and
  // (profile->reference_ghz / freq_ghz)^freq_exponent; `counted`,
  // `default_counted` and `reference_ghz` are then unused.
  std::shared_ptr<const CostProfile> profile;
  // Seeds the draws: invocation i of callback "<name>" draws from a stream
  // derived from (profile_seed, name, i), so a run is reproducible and one
  // callback's draws do not depend on how often the others ran.
  uint64_t profile_seed = 0;
  // Scales every cost: how much heavier the modelled production stack is
  // than adse's own (1 = as measured).
  double cost_scale = 1.0;
  // kCounted runs leave CallbackRecord::host_cpu_s at 0 so that their traces
  // are bit-identical; true measures it anyway (for calibration), at the
  // price of that identity.
  bool record_host_cpu_when_counted = false;
};

class Executor {
 public:
  virtual ~Executor() = default;

  // Publishes a message from outside the graph (a sensor) at time t_s >=
  // now_s(). Subscribers see it at t_s.
  virtual void PublishExternal(int topic, MessagePtr message, double stamp_s,
                               double t_s) = 0;
  // Processes every event before t_s (arrivals, timers, starts, ends) and
  // leaves the clock at t_s.
  virtual Status AdvanceTo(double t_s) = 0;
  virtual double now_s() const = 0;
  // The trace so far; on a real-time platform only after Stop().
  virtual const Trace& trace() const = 0;
  // Ends execution: no callback runs once it returns. The virtual platform
  // runs nothing between AdvanceTo calls and has nothing to stop.
  virtual void Stop() {}
};

// Validates `options` (cores >= 1, frequencies > 0, ...), naming the field.
Status ValidateVirtualPlatformOptions(const VirtualPlatformOptions& options);

// The virtual platform. `graph` must outlive the executor and not change
// while it exists. Its exact semantics (event order, readiness, dispatch,
// cost) are documented at the top of virtual_executor.cc. Rejects invalid
// options and graphs (timer period <= 0, queue depth < 1, bad indices,
// empty functions).
Result<std::unique_ptr<Executor>> CreateVirtualExecutor(
    const Graph* graph, const VirtualPlatformOptions& options);

}  // namespace adse::stack

#endif  // ADSE_STACK_RUNTIME_EXECUTOR_H_
