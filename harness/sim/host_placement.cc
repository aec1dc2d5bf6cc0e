#include "harness/sim/host_placement.h"

#include <sched.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace adse::sim {
namespace {

Result<std::vector<int>> ThreadCpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) != 0) {
    return Status::IoError(
        fmt::format("sched_getaffinity: {}", std::strerror(errno)));
  }
  std::vector<int> cpus;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &set)) cpus.push_back(cpu);
  }
  return cpus;
}

}  // namespace

Status SetThreadCpus(const std::vector<int>& cpus) {
  cpu_set_t set;
  CPU_ZERO(&set);
  for (int cpu : cpus) CPU_SET(cpu, &set);
  if (sched_setaffinity(0, sizeof(set), &set) != 0) {
    return Status::Unavailable(fmt::format("cannot pin to host CPUs {}: {}",
                                           fmt::join(cpus, ","),
                                           std::strerror(errno)));
  }
  return Status::Ok();
}

Result<HostPlacement> PlaceOnCpus(int cores, const std::vector<int>& usable) {
  const int n = static_cast<int>(usable.size());
  if (cores < 1 || cores > n) {
    return Status::Unavailable(fmt::format(
        "platform.kind: cgroup runs the stack in real time on one host CPU "
        "per core of the point, {} here, but this process may use only {} "
        "(CPUs {}): choose points with at most {} cores, or a larger host",
        cores, n, fmt::join(usable, ","), n));
  }
  HostPlacement p;
  // The stack takes the last CPUs, the world the first: CPU 0 usually
  // carries the host's interrupts and daemons, which the world tolerates
  // better than the stack under test.
  p.stack_cpus.assign(usable.end() - cores, usable.end());
  p.world_cpus.assign(usable.begin(), usable.end() - cores);
  p.description =
      p.world_cpus.empty()
          ? fmt::format(
                "affinity: stack threads on host CPUs {}, shared "
                "with the world (no other CPU free)",
                fmt::join(p.stack_cpus, ","))
          : fmt::format("affinity: stack threads on host CPUs {}, world on {}",
                        fmt::join(p.stack_cpus, ","),
                        fmt::join(p.world_cpus, ","));
  return p;
}

Result<HostPlacement> PlaceOnHost(int cores) {
  Result<std::vector<int>> usable = ThreadCpus();
  if (!usable.ok()) return usable.status();
  return PlaceOnCpus(cores, *usable);
}

Result<double> HostClockGhz(const std::string& cpuinfo) {
  std::ifstream in(cpuinfo);
  if (!in) {
    return Status::Unavailable(fmt::format(
        "cannot read {} for the host's clock: set platform.host_ghz", cpuinfo));
  }
  double mhz = 0.0;
  std::string line;
  while (std::getline(in, line)) {
    if (line.compare(0, 7, "cpu MHz") != 0) continue;
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    mhz = std::max(mhz, std::strtod(line.c_str() + colon + 1, nullptr));
  }
  if (!(mhz > 0.0)) {
    return Status::Unavailable(
        fmt::format("{} names no 'cpu MHz': set platform.host_ghz", cpuinfo));
  }
  return mhz / 1000.0;
}

Result<AffinityGuard> AffinityGuard::Pin(const std::vector<int>& cpus) {
  Result<std::vector<int>> previous = ThreadCpus();
  if (!previous.ok()) return previous.status();
  ADSE_RETURN_IF_ERROR(SetThreadCpus(cpus));
  AffinityGuard guard;
  guard.previous_ = std::move(previous).value();
  guard.active_ = true;
  return guard;
}

AffinityGuard::AffinityGuard(AffinityGuard&& other) noexcept
    : previous_(std::move(other.previous_)), active_(other.active_) {
  other.active_ = false;
}

AffinityGuard::~AffinityGuard() {
  if (active_) (void)SetThreadCpus(previous_);
}

}  // namespace adse::sim
