// Holds host CPUs at a clock through cpufreq (platform.clock_by: cpufreq):
// each CPU's scaling_min_freq and scaling_max_freq are both set to the
// point's frequency (the nearest the driver offers at or below it, when it
// lists scaling_available_frequencies), and put back when the guard goes.
//
// The limits a guard replaced are also written to
// <state_dir>/cpufreq-<pid>, so that the next guard puts back the clocks a
// killed process left held (as the cgroups of a SIGKILLed worker are
// removed by the next one).
//
// Tests point `sysfs_cpu_root` at a folder laid out like
// /sys/devices/system/cpu.
#ifndef ADSE_HARNESS_POOL_CPU_CLOCK_H_
#define ADSE_HARNESS_POOL_CPU_CLOCK_H_

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "stack/base/status.h"

namespace adse::pool {

struct CpuClockOptions {
  // Host CPUs to hold; required, each listed once.
  std::vector<int> cpus;
  // The clock to hold them at, GHz.
  double freq_ghz = 0.0;
  // cpufreq's sysfs folder.
  std::string sysfs_cpu_root = "/sys/devices/system/cpu";
  // Where a guard records the limits it replaced.
  std::string state_dir = "/run/adse";
};

class CpuClockGuard {
 public:
  // Puts back the clocks of dead processes' records, then holds `cpus` at
  // `freq_ghz`. InvalidArgument naming the field for bad options or a
  // frequency outside a CPU's range (with the range); Unavailable naming
  // the file that is missing or refused a write.
  static Result<std::unique_ptr<CpuClockGuard>> Hold(
      const CpuClockOptions& options);
  // Puts every CPU's limits back as they were and removes the record.
  ~CpuClockGuard();
  CpuClockGuard(const CpuClockGuard&) = delete;
  CpuClockGuard& operator=(const CpuClockGuard&) = delete;

  // The clock the CPUs are held at, GHz (the driver's step at or below the
  // one asked for).
  double held_ghz() const { return held_khz_ / 1e6; }
  // "cpufreq: CPUs 0-1 held at 1.2 GHz (asked 1.2)".
  std::string Describe() const { return description_; }

  // One CPU's limits before the guard, kHz.
  struct Saved {
    int cpu = 0;
    long min_khz = 0;
    long max_khz = 0;
  };

 private:
  CpuClockGuard() = default;
  void Restore();

  std::string root_;
  std::string record_;  // <state_dir>/cpufreq-<pid>, empty: none written
  std::vector<Saved> saved_;
  size_t touched_ = 0;  // the first CPUs of saved_ whose limits were written
  long held_khz_ = 0;
  std::string description_;
};

}  // namespace adse::pool

#endif  // ADSE_HARNESS_POOL_CPU_CLOCK_H_
