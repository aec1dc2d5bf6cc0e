// Reading the allocation from Slurm's variables, and how many steps fit.
#include "harness/slurm/allocation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>
#include <string>

namespace adse::slurm {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

Environment Env(std::map<std::string, std::string> vars) {
  auto owned = std::make_shared<std::map<std::string, std::string>>(vars);
  return [owned](const char* name) -> const char* {
    auto it = owned->find(name);
    return it == owned->end() ? nullptr : it->second.c_str();
  };
}

TEST(AllocationTest, OutsideAnAllocationThereIsNone) {
  Result<std::optional<Allocation>> a = CurrentAllocation(Env({}));
  ASSERT_TRUE(a.ok());
  EXPECT_FALSE(a->has_value());
}

TEST(AllocationTest, ReadsCpusPerNodeMemoryAndArrayIds) {
  Result<std::optional<Allocation>> a =
      CurrentAllocation(Env({{"SLURM_JOB_ID", "4711"},
                             {"SLURM_JOB_CPUS_PER_NODE", "4(x2),2"},
                             {"SLURM_MEM_PER_NODE", "8192"},
                             {"SLURM_JOB_NODELIST", "n[1-3]"},
                             {"SLURM_ARRAY_JOB_ID", "4700"},
                             {"SLURM_ARRAY_TASK_ID", "11"},
                             {"SLURM_RESTART_COUNT", "2"}}));
  ASSERT_TRUE(a.ok()) << a.status().message();
  ASSERT_TRUE(a->has_value());
  const Allocation& x = **a;
  EXPECT_EQ(x.job_id, "4711");
  EXPECT_THAT(x.cpus_per_node, ElementsAre(4, 4, 2));
  EXPECT_EQ(x.TotalCpus(), 10);
  EXPECT_EQ(x.memory_per_node_mb, 8192);
  EXPECT_EQ(x.array_task_id, "11");
  EXPECT_EQ(x.restart_count, 2);
  EXPECT_EQ(x.Describe(),
            "job 4711 on n[1-3]: 10 CPUs on 3 nodes, 8192 MB per node");
}

TEST(AllocationTest, MalformedVariablesAreNamed) {
  Result<std::optional<Allocation>> a = CurrentAllocation(
      Env({{"SLURM_JOB_ID", "1"}, {"SLURM_JOB_CPUS_PER_NODE", "4(x"}}));
  ASSERT_FALSE(a.ok());
  EXPECT_THAT(a.status().message(), HasSubstr("SLURM_JOB_CPUS_PER_NODE"));
  a = CurrentAllocation(Env({{"SLURM_JOB_ID", "1"}}));
  ASSERT_FALSE(a.ok());
  EXPECT_THAT(a.status().message(),
              HasSubstr("SLURM_JOB_CPUS_PER_NODE is not"));
  a = CurrentAllocation(Env({{"SLURM_JOB_ID", "1"},
                             {"SLURM_JOB_CPUS_PER_NODE", "2"},
                             {"SLURM_MEM_PER_CPU", "lots"}}));
  ASSERT_FALSE(a.ok());
  EXPECT_THAT(a.status().message(), HasSubstr("SLURM_MEM_PER_CPU"));
}

TEST(AllocationTest, StepsThatFitCountCpusPerNodeAndMemory) {
  Allocation a;
  a.cpus_per_node = {4, 4, 2};
  EXPECT_EQ(StepsThatFit(a, 1, 4096), 10);  // no memory limit
  EXPECT_EQ(StepsThatFit(a, 2, 4096), 5);
  EXPECT_EQ(StepsThatFit(a, 3, 4096), 2);  // steps do not span nodes
  EXPECT_EQ(StepsThatFit(a, 5, 4096), 0);
  a.memory_per_node_mb = 2 * 1024 + 1024;  // adse submit's sizing
  EXPECT_EQ(StepsThatFit(a, 1, 1024), 8);  // 3 + 3 (memory) + 2 (CPUs)
  EXPECT_EQ(StepsThatFit(a, 1, 1500), 6);  // 2 per node by memory
  a.memory_per_node_mb = 0;
  a.memory_per_cpu_mb = 500;
  EXPECT_EQ(StepsThatFit(a, 1, 1000), 5);  // 2 + 2 + 1
}

}  // namespace
}  // namespace adse::slurm
