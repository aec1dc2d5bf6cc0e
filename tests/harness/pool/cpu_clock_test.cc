// clock_by: cpufreq's guard against a folder laid out like
// /sys/devices/system/cpu: the CPUs held at the point's clock and put back,
// the driver's step taken, refusals naming what is wrong, and the clocks a
// killed process left held put back by the next guard. On this host, which
// has no cpufreq, the guard refuses naming the folder it lacks.
#include "harness/pool/cpu_clock.h"

#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/harness/pool/pool_test_util.h"

namespace adse::pool {
namespace {

namespace fs = std::filesystem;
using testing::ReadText;
using testing::TempDir;
using testing::Trimmed;
using testing::WriteText;

// A CPU of 0.8-3 GHz whose limits are its whole range.
void LayOutCpu(const TempDir& tmp, int cpu, const std::string& steps = "") {
  const std::string dir =
      tmp.path() + "/cpu/cpu" + std::to_string(cpu) + "/cpufreq";
  WriteText(dir + "/cpuinfo_min_freq", "800000\n");
  WriteText(dir + "/cpuinfo_max_freq", "3000000\n");
  WriteText(dir + "/scaling_min_freq", "800000\n");
  WriteText(dir + "/scaling_max_freq", "3000000\n");
  if (!steps.empty()) {
    WriteText(dir + "/scaling_available_frequencies", steps + "\n");
  }
}

std::string Limit(const TempDir& tmp, int cpu, const std::string& which) {
  return Trimmed(ReadText(tmp.path() + "/cpu/cpu" + std::to_string(cpu) +
                          "/cpufreq/scaling_" + which + "_freq"));
}

CpuClockOptions Options(const TempDir& tmp, std::vector<int> cpus,
                        double freq_ghz) {
  CpuClockOptions o;
  o.cpus = std::move(cpus);
  o.freq_ghz = freq_ghz;
  o.sysfs_cpu_root = tmp.path() + "/cpu";
  o.state_dir = tmp.path() + "/run";
  return o;
}

std::string Record(const TempDir& tmp) {
  return tmp.path() + "/run/cpufreq-" + std::to_string(::getpid());
}

TEST(CpuClockTest, HoldsEachCpuAtTheClockAndPutsItBack) {
  TempDir tmp;
  LayOutCpu(tmp, 0);
  LayOutCpu(tmp, 1);
  {
    Result<std::unique_ptr<CpuClockGuard>> guard =
        CpuClockGuard::Hold(Options(tmp, {0, 1}, 1.2));
    ASSERT_TRUE(guard.ok()) << guard.status().ToString();
    for (int cpu : {0, 1}) {
      EXPECT_EQ(Limit(tmp, cpu, "min"), "1200000");
      EXPECT_EQ(Limit(tmp, cpu, "max"), "1200000");
    }
    EXPECT_DOUBLE_EQ((*guard)->held_ghz(), 1.2);
    EXPECT_EQ((*guard)->Describe(),
              "cpufreq: CPUs 0-1 held at 1.2 GHz (asked 1.2)");
    // What it replaced is on record while it holds them.
    EXPECT_EQ(ReadText(Record(tmp)), "0 800000 3000000\n1 800000 3000000\n");
  }
  for (int cpu : {0, 1}) {
    EXPECT_EQ(Limit(tmp, cpu, "min"), "800000");
    EXPECT_EQ(Limit(tmp, cpu, "max"), "3000000");
  }
  EXPECT_FALSE(fs::exists(Record(tmp)));
}

TEST(CpuClockTest, TakesTheDriversStepAtOrBelowTheClock) {
  TempDir tmp;
  LayOutCpu(tmp, 2, "3000000 2400000 1800000 1200000 800000");
  Result<std::unique_ptr<CpuClockGuard>> guard =
      CpuClockGuard::Hold(Options(tmp, {2}, 2.1));
  ASSERT_TRUE(guard.ok()) << guard.status().ToString();
  EXPECT_EQ(Limit(tmp, 2, "max"), "1800000");
  EXPECT_DOUBLE_EQ((*guard)->held_ghz(), 1.8);
  EXPECT_EQ((*guard)->Describe(),
            "cpufreq: CPUs 2 held at 1.8 GHz (asked 2.1)");
}

TEST(CpuClockTest, AClockOutsideTheCpusRangeIsRefusedNamingIt) {
  TempDir tmp;
  LayOutCpu(tmp, 0);
  Result<std::unique_ptr<CpuClockGuard>> guard =
      CpuClockGuard::Hold(Options(tmp, {0}, 3.5));
  ASSERT_FALSE(guard.ok());
  EXPECT_EQ(guard.status().code(), Status::Code::kInvalidArgument);
  EXPECT_NE(guard.status().message().find(
                "freq_ghz: 3.5 GHz is outside CPU 0's range 0.8..3 GHz"),
            std::string::npos)
      << guard.status().message();
  EXPECT_EQ(Limit(tmp, 0, "max"), "3000000");  // untouched
}

TEST(CpuClockTest, WithoutCpufreqItRefusesNamingTheFolder) {
  TempDir tmp;
  LayOutCpu(tmp, 0);
  Result<std::unique_ptr<CpuClockGuard>> guard =
      CpuClockGuard::Hold(Options(tmp, {0, 1}, 1.2));
  ASSERT_FALSE(guard.ok());
  EXPECT_EQ(guard.status().code(), Status::Code::kUnavailable);
  EXPECT_NE(guard.status().message().find(tmp.path() + "/cpu/cpu1/cpufreq"),
            std::string::npos)
      << guard.status().message();
  EXPECT_NE(guard.status().message().find("clock_by: padding or quota"),
            std::string::npos);
  EXPECT_EQ(Limit(tmp, 0, "max"), "3000000");  // CPU 0 was not held
}

TEST(CpuClockTest, ARefusedWriteNamesTheFileAndPutsTheOthersBack) {
  TempDir tmp;
  LayOutCpu(tmp, 0);
  LayOutCpu(tmp, 1);
  // A folder where CPU 1's limit should be: the write fails (EISDIR).
  const std::string blocked = tmp.path() + "/cpu/cpu1/cpufreq/scaling_min_freq";
  fs::remove(blocked);
  fs::create_directory(blocked);
  Result<std::unique_ptr<CpuClockGuard>> guard =
      CpuClockGuard::Hold(Options(tmp, {0, 1}, 1.2));
  ASSERT_FALSE(guard.ok());
  EXPECT_NE(guard.status().message().find("cpu1/cpufreq/scaling_min_freq"),
            std::string::npos)
      << guard.status().message();
  EXPECT_EQ(Limit(tmp, 0, "min"), "800000");
  EXPECT_EQ(Limit(tmp, 0, "max"), "3000000");
}

TEST(CpuClockTest, TheClocksAKilledProcessLeftHeldArePutBackByTheNext) {
  TempDir tmp;
  LayOutCpu(tmp, 0);
  LayOutCpu(tmp, 1);
  // A process that held CPU 0 at 1.2 GHz and died without putting it back.
  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ASSERT_GT(dead, 0);
  ::waitpid(dead, nullptr, 0);
  WriteText(tmp.path() + "/run/cpufreq-" + std::to_string(dead),
            "0 800000 3000000\n");
  WriteText(tmp.path() + "/cpu/cpu0/cpufreq/scaling_min_freq", "1200000\n");
  WriteText(tmp.path() + "/cpu/cpu0/cpufreq/scaling_max_freq", "1200000\n");

  Result<std::unique_ptr<CpuClockGuard>> guard =
      CpuClockGuard::Hold(Options(tmp, {1}, 2.0));
  ASSERT_TRUE(guard.ok()) << guard.status().ToString();
  EXPECT_EQ(Limit(tmp, 0, "min"), "800000");
  EXPECT_EQ(Limit(tmp, 0, "max"), "3000000");
  EXPECT_FALSE(fs::exists(tmp.path() + "/run/cpufreq-" + std::to_string(dead)));
  EXPECT_EQ(Limit(tmp, 1, "max"), "2000000");
}

TEST(CpuClockTest, BadOptionsAreRefusedNamingTheField) {
  TempDir tmp;
  LayOutCpu(tmp, 0);
  Result<std::unique_ptr<CpuClockGuard>> none =
      CpuClockGuard::Hold(Options(tmp, {}, 1.2));
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.status().message().rfind("cpus:", 0), 0u);
  Result<std::unique_ptr<CpuClockGuard>> twice =
      CpuClockGuard::Hold(Options(tmp, {0, 0}, 1.2));
  ASSERT_FALSE(twice.ok());
  EXPECT_EQ(twice.status().message().rfind("cpus:", 0), 0u);
  Result<std::unique_ptr<CpuClockGuard>> zero =
      CpuClockGuard::Hold(Options(tmp, {0}, 0.0));
  ASSERT_FALSE(zero.ok());
  EXPECT_EQ(zero.status().message().rfind("freq_ghz", 0), 0u);
}

TEST(CpuClockTest, OnAHostWithoutCpufreqTheRealGuardRefuses) {
  if (fs::exists("/sys/devices/system/cpu/cpu0/cpufreq")) {
    GTEST_SKIP() << "this host has cpufreq; the refusal is shown on a folder";
  }
  TempDir tmp;
  CpuClockOptions o;
  o.cpus = {0};
  o.freq_ghz = 1.0;
  o.state_dir = tmp.path() + "/run";
  Result<std::unique_ptr<CpuClockGuard>> guard = CpuClockGuard::Hold(o);
  ASSERT_FALSE(guard.ok());
  EXPECT_EQ(guard.status().code(), Status::Code::kUnavailable);
  EXPECT_NE(
      guard.status().message().find("/sys/devices/system/cpu/cpu0/cpufreq"),
      std::string::npos)
      << guard.status().message();
}

}  // namespace
}  // namespace adse::pool
