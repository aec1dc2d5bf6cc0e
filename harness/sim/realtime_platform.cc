#include "harness/sim/realtime_platform.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <utility>

#include "harness/pool/cpu_clock.h"
#include "harness/pool/thread_group.h"
#include "harness/pool/worker_pool.h"
#include "harness/spec/types.h"

namespace adse::sim {

Result<std::unique_ptr<RealTimePlatform>> RealTimePlatform::Prepare(
    const spec::PlatformOptions& platform, stack::RealTimeOptions* options) {
  std::unique_ptr<RealTimePlatform> rt(new RealTimePlatform());
  Result<HostPlacement> placement = PlaceOnHost(platform.cores);
  if (!placement.ok()) return placement.status();

  pool::ThreadGroupOptions group;
  group.cpus = placement->stack_cpus;
  std::string clock = spec::ClockByToString(platform.clock_by);
  if (platform.clock_by == spec::ClockBy::kQuota) {
    double host_ghz = platform.host_ghz;
    std::string source = "platform.host_ghz";
    if (host_ghz <= 0.0) {
      Result<double> read = HostClockGhz();
      if (!read.ok()) return read.status();
      host_ghz = *read;
      source = "/proc/cpuinfo";
    }
    if (platform.freq_ghz > host_ghz) {
      return Status::InvalidArgument(fmt::format(
          "platform.clock_by: quota stands for a clock of {} GHz by a share "
          "of the host's {:.3g} GHz ({}), and a share cannot exceed 1: keep "
          "the points' freq_ghz at most the host's, or use clock_by: padding",
          platform.freq_ghz, host_ghz, source));
    }
    options->cpu_share = platform.freq_ghz / host_ghz;
    group.cpu_quota = options->cpu_share * platform.cores;
    clock += fmt::format(" (share {:.3f} of a {:.3g} GHz host CPU, from {})",
                         options->cpu_share, host_ghz, source);
  }
  if (platform.clock_by == spec::ClockBy::kCpufreq) {
    // The host's own clock slows the real code; the padding then works to
    // the profile cost at f on a CPU that truly runs at f.
    pool::CpuClockOptions hold;
    hold.cpus = placement->stack_cpus;
    hold.freq_ghz = platform.freq_ghz;
    Result<std::unique_ptr<pool::CpuClockGuard>> held =
        pool::CpuClockGuard::Hold(hold);
    if (!held.ok()) return held.status();
    rt->clock_ = std::move(held).value();
    clock += " (" + rt->clock_->Describe() + ")";
  }
  Result<std::unique_ptr<pool::ThreadGroup>> made =
      pool::ThreadGroup::Create(group);
  if (!made.ok()) {
    return made.status().WithContext(
        "platform.kind: cgroup confines the stack's process in a cgroup");
  }
  rt->group_ = std::move(made).value();
  const pool::ThreadGroup* stack_group = rt->group_.get();
  options->host_cpus = placement->stack_cpus;
  options->enter_thread = [stack_group] {
    return stack_group->AddCurrentThread();
  };
  // The world keeps off the stack's cores where the host has others.
  if (!placement->world_cpus.empty()) {
    Result<AffinityGuard> guard = AffinityGuard::Pin(placement->world_cpus);
    if (!guard.ok()) return guard.status();
    rt->world_affinity_.emplace(std::move(guard).value());
  }
  rt->notes_["confinement"] =
      rt->group_->Describe() + "; " +
      (placement->world_cpus.empty()
           ? std::string("the world shares these CPUs (no other is free)")
           : fmt::format("the world on CPUs {}",
                         fmt::join(placement->world_cpus, ",")));
  rt->notes_["clock_by"] = clock;
  rt->notes_["time_dilation"] = fmt::format("{}", options->time_dilation);
  // An interrupt ends the run in order (the group is removed); a second
  // one ends the process at once.
  pool::InstallInterruptHandlers();
  return rt;
}

RealTimePlatform::~RealTimePlatform() = default;

int RealTimePlatform::Interrupted() { return pool::InterruptRequested(); }

}  // namespace adse::sim
