// Where a real-time run's threads go on the host: the stack's executor
// threads on as many host CPUs as the point has cores, the world's thread
// on the others (sharing them only when the host has no others). Threads
// are confined with CPU affinity, as taskset does — what the reference
// study used to limit its cores.
#ifndef ADSE_HARNESS_SIM_HOST_PLACEMENT_H_
#define ADSE_HARNESS_SIM_HOST_PLACEMENT_H_

#include <string>
#include <vector>

#include "stack/base/status.h"

namespace adse::sim {

struct HostPlacement {
  std::vector<int> stack_cpus;  // one per point core
  std::vector<int> world_cpus;  // empty: the world shares the stack's
  std::string description;      // for the run file's platform record
};

// The placement for `cores` stack threads among the CPUs this process may
// use (sched_getaffinity). Unavailable, naming how many it may use and
// which, when they are fewer than `cores`.
Result<HostPlacement> PlaceOnHost(int cores);
// The same from an explicit list of usable CPUs (tests).
Result<HostPlacement> PlaceOnCpus(int cores, const std::vector<int>& usable);

// The host's clock in GHz: the largest "cpu MHz" in `cpuinfo` (the
// current clock of each CPU as the kernel reports it; on a VM the
// hypervisor's figure). Unavailable naming the file when none is found.
Result<double> HostClockGhz(const std::string& cpuinfo = "/proc/cpuinfo");

// Pins the calling thread to `cpus` (as `taskset`).
Status SetThreadCpus(const std::vector<int>& cpus);

// Pins the calling thread to `cpus` and restores its previous affinity
// when destroyed.
class AffinityGuard {
 public:
  static Result<AffinityGuard> Pin(const std::vector<int>& cpus);
  AffinityGuard(AffinityGuard&& other) noexcept;
  AffinityGuard& operator=(AffinityGuard&&) = delete;
  ~AffinityGuard();

 private:
  AffinityGuard() = default;
  std::vector<int> previous_;
  bool active_ = false;
};

}  // namespace adse::sim

#endif  // ADSE_HARNESS_SIM_HOST_PLACEMENT_H_
