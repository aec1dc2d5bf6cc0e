#include "harness/pool/cpu_clock.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>

#include <fmt/format.h>

#include "harness/pool/cgroup.h"
#include "stack/base/files.h"

namespace adse::pool {
namespace {

namespace fs = std::filesystem;

constexpr const char* kRecordPrefix = "cpufreq-";

std::string FreqDir(const std::string& root, int cpu) {
  return fmt::format("{}/cpu{}/cpufreq", root, cpu);
}

Result<long> ReadKhz(const std::string& path) {
  Result<std::string> text = internal::ReadControl(path);
  if (!text.ok()) {
    return Status::Unavailable("cannot read " + text.status().message());
  }
  const std::string value = internal::Trim(*text);
  char* end = nullptr;
  const long khz = std::strtol(value.c_str(), &end, 10);
  if (value.empty() || *end != '\0' || khz <= 0) {
    return Status::Unavailable(fmt::format(
        "{}: expected a frequency in kHz, found '{}'", path, value));
  }
  return khz;
}

Status WriteKhz(const std::string& path, long khz) {
  // O_TRUNC, as `echo khz > path`: a test folder's file then holds the
  // value alone (sysfs ignores it).
  const int error =
      internal::WriteValueErrno(path, std::to_string(khz) + "\n", O_TRUNC);
  if (error == 0) return Status::Ok();
  return Status::Unavailable(fmt::format(
      "{}: cannot write {}: {}{}", path, khz, std::strerror(error),
      error == EACCES || error == EPERM ? " (setting a CPU's clock needs root)"
                                        : ""));
}

// Sets a CPU's limits to [min_khz, max_khz], in the order that keeps
// min <= max at every step (the driver refuses anything else), and reads
// them back: a driver may round or ignore a value.
Status SetLimits(const std::string& dir, long min_khz, long max_khz) {
  Result<long> max_now = ReadKhz(dir + "/scaling_max_freq");
  if (!max_now.ok()) return max_now.status();
  const std::string min_path = dir + "/scaling_min_freq";
  const std::string max_path = dir + "/scaling_max_freq";
  if (min_khz > *max_now) {
    ADSE_RETURN_IF_ERROR(WriteKhz(max_path, max_khz));
    ADSE_RETURN_IF_ERROR(WriteKhz(min_path, min_khz));
  } else {
    ADSE_RETURN_IF_ERROR(WriteKhz(min_path, min_khz));
    ADSE_RETURN_IF_ERROR(WriteKhz(max_path, max_khz));
  }
  Result<long> min_set = ReadKhz(min_path);
  Result<long> max_set = ReadKhz(max_path);
  if (!min_set.ok()) return min_set.status();
  if (!max_set.ok()) return max_set.status();
  if (*min_set != min_khz || *max_set != max_khz) {
    return Status::Unavailable(fmt::format(
        "{}: the driver kept the limits at {}..{} kHz where {}..{} was "
        "written",
        dir, *min_set, *max_set, min_khz, max_khz));
  }
  return Status::Ok();
}

// The record's lines: "<cpu> <min_khz> <max_khz>".
std::string FormatRecord(const std::vector<CpuClockGuard::Saved>& saved) {
  std::string text;
  for (const CpuClockGuard::Saved& s : saved) {
    text += fmt::format("{} {} {}\n", s.cpu, s.min_khz, s.max_khz);
  }
  return text;
}

// Puts back the limits recorded by processes that are gone.
void RestoreStale(const CpuClockOptions& options) {
  std::error_code ec;
  if (!fs::is_directory(options.state_dir, ec)) return;
  for (const auto& entry : fs::directory_iterator(options.state_dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kRecordPrefix, 0) != 0) continue;
    const int pid = std::atoi(name.c_str() + std::strlen(kRecordPrefix));
    if (pid <= 0 || pid == ::getpid() || internal::DefaultPidAlive(pid)) {
      continue;
    }
    Result<std::string> text = ReadFile(entry.path().string());
    bool restored = text.ok();
    std::istringstream lines(text.ok() ? *text : std::string());
    int cpu = 0;
    long min_khz = 0, max_khz = 0;
    while (lines >> cpu >> min_khz >> max_khz) {
      const Status s =
          SetLimits(FreqDir(options.sysfs_cpu_root, cpu), min_khz, max_khz);
      if (!s.ok()) {
        restored = false;
        std::fprintf(stderr,
                     "warning: cannot put back the clock process %d left "
                     "held: %s\n",
                     pid, s.message().c_str());
      }
    }
    if (restored) fs::remove(entry.path(), ec);
  }
}

Status Validate(const CpuClockOptions& o) {
  ADSE_RETURN_IF_ERROR(internal::ValidateCpuList(o.cpus));
  if (!std::isfinite(o.freq_ghz) || o.freq_ghz <= 0.0) {
    return Status::InvalidArgument(
        fmt::format("freq_ghz must be positive, got {}", o.freq_ghz));
  }
  return Status::Ok();
}

// The frequency to hold a CPU at: `want_khz` itself, or where the driver
// lists its steps, the highest at or below it (the lowest when none is).
Result<long> ChooseKhz(const std::string& dir, int cpu, long want_khz) {
  Result<long> lo = ReadKhz(dir + "/cpuinfo_min_freq");
  Result<long> hi = ReadKhz(dir + "/cpuinfo_max_freq");
  if (!lo.ok()) return lo.status();
  if (!hi.ok()) return hi.status();
  if (want_khz < *lo || want_khz > *hi) {
    return Status::InvalidArgument(fmt::format(
        "freq_ghz: {:.4g} GHz is outside CPU {}'s range {:.4g}..{:.4g} GHz "
        "({}/cpuinfo_min_freq, cpuinfo_max_freq)",
        want_khz / 1e6, cpu, *lo / 1e6, *hi / 1e6, dir));
  }
  const std::string steps_path = dir + "/scaling_available_frequencies";
  if (!internal::Exists(steps_path)) return want_khz;
  Result<std::string> steps = internal::ReadControl(steps_path);
  if (!steps.ok()) {
    return Status::Unavailable("cannot read " + steps.status().message());
  }
  std::istringstream in(*steps);
  long step = 0, below = 0, lowest = 0;
  while (in >> step) {
    if (step <= want_khz) below = std::max(below, step);
    if (lowest == 0 || step < lowest) lowest = step;
  }
  if (lowest == 0) return want_khz;
  return below > 0 ? below : lowest;
}

}  // namespace

Result<std::unique_ptr<CpuClockGuard>> CpuClockGuard::Hold(
    const CpuClockOptions& options) {
  ADSE_RETURN_IF_ERROR(Validate(options));
  RestoreStale(options);
  const long want_khz = std::lround(options.freq_ghz * 1e6);
  std::unique_ptr<CpuClockGuard> guard(new CpuClockGuard());
  guard->root_ = options.sysfs_cpu_root;
  std::vector<long> chosen;
  for (int cpu : options.cpus) {
    const std::string dir = FreqDir(options.sysfs_cpu_root, cpu);
    if (!internal::Exists(dir)) {
      return Status::Unavailable(fmt::format(
          "platform.clock_by: cpufreq needs {} (this host has no cpufreq "
          "driver for CPU {}; virtual machines usually have none): use "
          "clock_by: padding or quota",
          dir, cpu));
    }
    Result<long> khz = ChooseKhz(dir, cpu, want_khz);
    if (!khz.ok()) return khz.status();
    Result<long> min_khz = ReadKhz(dir + "/scaling_min_freq");
    Result<long> max_khz = ReadKhz(dir + "/scaling_max_freq");
    if (!min_khz.ok()) return min_khz.status();
    if (!max_khz.ok()) return max_khz.status();
    guard->saved_.push_back({cpu, *min_khz, *max_khz});
    chosen.push_back(*khz);
  }
  // The record first: a process killed while changing the clocks leaves
  // what the next one needs to put them back.
  const std::string record =
      fmt::format("{}/{}{}", options.state_dir, kRecordPrefix, ::getpid());
  Status written = MakeDirs(options.state_dir);
  if (written.ok())
    written = WriteFileAtomic(record, FormatRecord(guard->saved_));
  if (!written.ok()) {
    return written.WithContext(
        "platform.clock_by: cpufreq records the clocks it replaces");
  }
  guard->record_ = record;
  for (size_t i = 0; i < options.cpus.size(); ++i) {
    // On failure the destructor puts back the CPUs touched so far (a
    // refused write may have changed one limit of the pair).
    guard->touched_ = i + 1;
    ADSE_RETURN_IF_ERROR(
        SetLimits(FreqDir(options.sysfs_cpu_root, options.cpus[i]), chosen[i],
                  chosen[i]));
  }
  guard->held_khz_ = *std::min_element(chosen.begin(), chosen.end());
  guard->description_ =
      fmt::format("cpufreq: CPUs {} held at {:.4g} GHz (asked {:.4g})",
                  internal::FormatCpuList(options.cpus), guard->held_ghz(),
                  options.freq_ghz);
  return guard;
}

CpuClockGuard::~CpuClockGuard() { Restore(); }

void CpuClockGuard::Restore() {
  bool restored = true;
  for (size_t i = 0; i < touched_ && i < saved_.size(); ++i) {
    const Saved& s = saved_[i];
    const Status status =
        SetLimits(FreqDir(root_, s.cpu), s.min_khz, s.max_khz);
    if (!status.ok()) {
      restored = false;
      std::fprintf(stderr, "warning: cannot put back CPU %d's clock: %s\n",
                   s.cpu, status.message().c_str());
    }
  }
  // Kept when something stayed held, so the next guard tries again.
  if (restored && !record_.empty()) {
    std::error_code ec;
    fs::remove(record_, ec);
  }
  saved_.clear();
}

}  // namespace adse::pool
