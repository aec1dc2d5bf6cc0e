#include "stack/runtime/internal/processor_sharing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace adse::stack::internal {
namespace {

constexpr double kTol = 1e-12;

// Advances to the next end and returns the jobs that ended there.
std::vector<int> NextEnded(ProcessorSharing& ps, double* at_s) {
  *at_s = ps.NextEndS();
  std::vector<int> ended;
  ps.AdvanceTo(*at_s, &ended);
  return ended;
}

TEST(ProcessorSharingTest, AJobAloneRunsAtFullSpeed) {
  ProcessorSharing ps(2);
  EXPECT_TRUE(std::isinf(ps.NextEndS()));
  ps.Add(7, 1.0, 0.3, 0.0, 1);
  double t = 0.0;
  EXPECT_EQ(NextEnded(ps, &t), std::vector<int>{7});
  EXPECT_NEAR(t, 1.3, kTol);
  EXPECT_TRUE(ps.empty());
}

// Two cores, a serial job and a team of two: three threads share two
// cores, each at 2/3 of one, until the team ends.
TEST(ProcessorSharingTest, ThreadsOutnumberingCoresShareThem) {
  ProcessorSharing ps(2);
  ps.Add(1, 0.0, 1.0, 0.0, 1);
  ps.Add(2, 0.0, 0.0, 0.5, 2);  // all parallel
  double t = 0.0;
  EXPECT_EQ(NextEnded(ps, &t), std::vector<int>{2});
  EXPECT_NEAR(t, 0.75, kTol);  // 0.5 / (2/3)
  EXPECT_EQ(NextEnded(ps, &t), std::vector<int>{1});
  EXPECT_NEAR(t, 1.25, kTol);  // 0.5 done by 0.75, the rest at full speed
}

// The serial part runs on one thread; the team starts when it ends.
TEST(ProcessorSharingTest, ATeamStartsAfterItsSerialPart) {
  ProcessorSharing ps(2);
  ps.Add(1, 0.0, 0.2, 0.4, 2);
  ps.Add(2, 0.0, 1.0, 0.0, 1);
  double t = 0.0;
  // Until 0.2 two threads on two cores; then three, at 2/3 each.
  EXPECT_TRUE(NextEnded(ps, &t).empty());
  EXPECT_NEAR(t, 0.2, kTol);
  EXPECT_EQ(NextEnded(ps, &t), std::vector<int>{1});
  EXPECT_NEAR(t, 0.8, kTol);  // 0.2 + 0.4 / (2/3)
  EXPECT_EQ(NextEnded(ps, &t), std::vector<int>{2});
  EXPECT_NEAR(t, 1.2, kTol);  // 0.6 done by 0.8
}

TEST(ProcessorSharingTest, JobsEndingTogetherEndInTheOrderTheyCame) {
  ProcessorSharing ps(1);
  ps.Add(5, 0.0, 0.5, 0.0, 1);
  ps.Add(3, 0.0, 0.5, 0.0, 1);
  double t = 0.0;
  EXPECT_EQ(NextEnded(ps, &t), (std::vector<int>{5, 3}));
  EXPECT_NEAR(t, 1.0, kTol);
}

TEST(ProcessorSharingTest, AJobAddedLaterSharesFromWhenItCame) {
  ProcessorSharing ps(1);
  ps.Add(1, 0.0, 1.0, 0.0, 1);
  ps.Add(2, 0.5, 0.25, 0.0, 1);  // 0.5 of job 1 left
  double t = 0.0;
  EXPECT_EQ(NextEnded(ps, &t), std::vector<int>{2});
  EXPECT_NEAR(t, 1.0, kTol);  // 0.25 at half speed
  EXPECT_EQ(NextEnded(ps, &t), std::vector<int>{1});
  EXPECT_NEAR(t, 1.25, kTol);
}

// Work too small to move a late clock ends at once rather than stopping it.
TEST(ProcessorSharingTest, WorkBelowTheClocksResolutionEndsAtOnce) {
  ProcessorSharing ps(2);
  ps.Add(1, 1e6, 1e-11, 0.0, 1);  // above the floor, below 1e6's step
  double t = 0.0;
  EXPECT_EQ(NextEnded(ps, &t), std::vector<int>{1});
  EXPECT_EQ(t, 1e6);
}

}  // namespace
}  // namespace adse::stack::internal
