// The real-time platform's padding helpers: each helper really spends its
// share in CPU time, a team grows only when no helper is idle, and a
// helper that cannot enter (its cgroup refused it) fails the region.
#include "stack/runtime/internal/padding_team.h"

#include <gtest/gtest.h>

#include <atomic>
#include <ctime>

#include "stack/runtime/internal/executor_parts.h"

namespace adse::stack::internal {
namespace {

double ProcessCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) +
         1e-9 * static_cast<double>(ts.tv_nsec);
}

TEST(PaddingTeamTest, EveryHelperAndTheCallerSpendTheirShareInCpuTime) {
  PaddingTeam team(nullptr);
  bool own_ran = false;
  const double cpu0 = ProcessCpuSeconds();
  ASSERT_TRUE(team.Run(2, 0.02,
                       [&] {
                         BusyUntilThreadCpu(ThreadCpuSeconds(), 0.02);
                         own_ran = true;
                       })
                  .ok());
  EXPECT_TRUE(own_ran);
  EXPECT_GE(ProcessCpuSeconds() - cpu0, 3 * 0.02 * 0.99);
  EXPECT_EQ(team.size(), 2);
  // Idle helpers are reused, not started again.
  ASSERT_TRUE(team.Run(1, 0.001, nullptr).ok());
  ASSERT_TRUE(team.Run(2, 0.001, nullptr).ok());
  EXPECT_EQ(team.size(), 2);
  team.Stop();
  EXPECT_FALSE(team.Run(1, 0.001, nullptr).ok());
}

TEST(PaddingTeamTest, AHelperThatCannotEnterFailsTheRegionWithItsReason) {
  std::atomic<int> entered{0};
  PaddingTeam team([&] {
    ++entered;
    return Status::Unavailable("cgroup v1: no room");
  });
  const Status status = team.Run(1, 0.001, nullptr);
  EXPECT_EQ(status.code(), Status::Code::kUnavailable);
  EXPECT_EQ(status.message(), "cgroup v1: no room");
  EXPECT_EQ(entered.load(), 1);
}

}  // namespace
}  // namespace adse::stack::internal
