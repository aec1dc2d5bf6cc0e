// The sharding rule for job arrays, the --array value and time limits.
#include "harness/slurm/sharding.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "harness/slurm/submit.h"

namespace adse::slurm {
namespace {

using ::testing::HasSubstr;

TEST(ShardingTest, ShardsRunAtLeastTenMinutesOfWork) {
  ShardingInput in;
  in.points = 280;
  in.run_estimate_s = 60;
  Sharding s = ChooseSharding(in);
  EXPECT_EQ(s.shard_size, 10);  // 10 runs of 60 s = 600 s
  EXPECT_EQ(s.shards, 28);
  in.run_estimate_s = 7;
  s = ChooseSharding(in);
  EXPECT_EQ(s.shard_size, 86);  // ceil(600 / 7)
  EXPECT_EQ(s.shards, 4);
  // Two steps at once: twice the points for the same task time.
  in.steps_per_task = 2;
  EXPECT_EQ(ChooseSharding(in).shard_size, 172);
}

TEST(ShardingTest, ArraysStayWithinMaxArraySize) {
  ShardingInput in;
  in.points = 100000;
  in.run_estimate_s = 3600;  // one run is already long enough
  Sharding s = ChooseSharding(in);
  EXPECT_EQ(s.shard_size, 100);  // ceil(100000 / 1001)
  EXPECT_LE(s.shards, 1001);
  EXPECT_THAT(s.explanation, HasSubstr("MaxArraySize 1001"));
  in.max_array_size = 50;
  EXPECT_EQ(ChooseSharding(in).shards, 50);
}

TEST(ShardingTest, AFixedShardSizeWinsAndSmallSweepsAreOneShard) {
  ShardingInput in;
  in.points = 12;
  in.fixed_shard_size = 5;
  Sharding s = ChooseSharding(in);
  EXPECT_EQ(s.shard_size, 5);
  EXPECT_EQ(s.shards, 3);
  EXPECT_EQ(s.explanation, "harness.slurm.shard_size = 5");
  in.fixed_shard_size = 0;
  in.run_estimate_s = 1;
  s = ChooseSharding(in);
  EXPECT_EQ(s.shard_size, 12);  // capped at the points
  EXPECT_EQ(s.shards, 1);
}

TEST(ShardingTest, ArraySpecCompressesRunsAndThrottles) {
  EXPECT_EQ(ArraySpec({0, 1, 2, 3}, 0), "0-3");
  EXPECT_EQ(ArraySpec({1, 4, 5, 6, 9}, 2), "1,4-6,9%2");
  EXPECT_EQ(ArraySpec({7}, 0), "7");
}

TEST(ShardingTest, TimeLimitsInEverySlurmFormat) {
  EXPECT_EQ(TimeLimitSeconds("90"), 5400);
  EXPECT_EQ(TimeLimitSeconds("90:30"), 5430);
  EXPECT_EQ(TimeLimitSeconds("02:00:00"), 7200);
  EXPECT_EQ(TimeLimitSeconds("1-02"), 93600);
  EXPECT_EQ(TimeLimitSeconds("1-02:03"), 93780);
  EXPECT_EQ(TimeLimitSeconds("1-02:03:04"), 93784);
  EXPECT_EQ(TimeLimitSeconds("UNLIMITED"), 0);
  EXPECT_EQ(TimeLimitSeconds("2h"), -1);
  EXPECT_EQ(TimeLimitSeconds("1:2:3:4"), -1);
}

}  // namespace
}  // namespace adse::slurm
