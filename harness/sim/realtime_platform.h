// What a run on the real-time platform (platform.kind: cgroup) holds while
// it runs: a cgroup of N host CPUs for the stack's process (and a CPU quota
// when a quota stands for the clock, or those CPUs held at the point's
// clock by cpufreq), the world's thread on the other CPUs,
// and handlers that turn Ctrl-C and SIGTERM into an orderly end, so that the
// group is removed on every exit path but SIGKILL (after which the next
// run removes it).
#ifndef ADSE_HARNESS_SIM_REALTIME_PLATFORM_H_
#define ADSE_HARNESS_SIM_REALTIME_PLATFORM_H_

#include <map>
#include <memory>
#include <optional>
#include <string>

#include "harness/sim/host_placement.h"
#include "harness/spec/spec.h"
#include "stack/base/status.h"
#include "stack/runtime/realtime_executor.h"

namespace adse::pool {
class CpuClockGuard;
class ThreadGroup;
}  // namespace adse::pool

namespace adse::sim {

class RealTimePlatform {
 public:
  // Places the stack (platform.cores host CPUs), creates its thread group
  // and pins the calling (world) thread to the other CPUs. `options` comes
  // with the profile and clock filled in; Prepare adds host_cpus,
  // cpu_share and enter_thread. Unavailable naming what is missing: too
  // few host CPUs, no cgroup cpuset (or cpu, for a quota) controller, no
  // permission, no cpufreq for clock_by: cpufreq; InvalidArgument when a
  // quota or cpufreq cannot stand for the clock (beyond the host's).
  static Result<std::unique_ptr<RealTimePlatform>> Prepare(
      const spec::PlatformOptions& platform, stack::RealTimeOptions* options);
  ~RealTimePlatform();

  // The run file's platform record: confinement, clock_by, time_dilation.
  const std::map<std::string, std::string>& notes() const { return notes_; }
  // The signal (SIGINT, SIGTERM) that asked the run to end, or 0.
  static int Interrupted();

 private:
  RealTimePlatform() = default;
  // Held before the group is made and put back after it is removed.
  std::unique_ptr<pool::CpuClockGuard> clock_;
  std::unique_ptr<pool::ThreadGroup> group_;
  std::optional<AffinityGuard> world_affinity_;
  std::map<std::string, std::string> notes_;
};

}  // namespace adse::sim

#endif  // ADSE_HARNESS_SIM_REALTIME_PLATFORM_H_
