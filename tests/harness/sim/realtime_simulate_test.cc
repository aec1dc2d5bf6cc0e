// The real-time platform end to end: the small robotaxi scenario with its
// stack on one host CPU in real time, the world on another, and the host
// placement that decides which. Real time is noisy, so the run is checked
// for what must hold under any load, never for a measured duration.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "harness/sim/host_placement.h"
#include "harness/sim/simulator.h"
#include "tests/harness/testing/small_scenario.h"

namespace adse::sim {
namespace {

using adse::testing::SmallPoint;
using adse::testing::SmallScenario;

TEST(HostPlacementTest, TheStackTakesTheLastCpusAndTheWorldTheRest) {
  Result<HostPlacement> p = PlaceOnCpus(2, {0, 1, 2, 3});
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  EXPECT_EQ(p->stack_cpus, (std::vector<int>{2, 3}));
  EXPECT_EQ(p->world_cpus, (std::vector<int>{0, 1}));
  EXPECT_NE(p->description.find("world on 0,1"), std::string::npos);

  Result<HostPlacement> shared = PlaceOnCpus(2, {4, 7});
  ASSERT_TRUE(shared.ok());
  EXPECT_EQ(shared->stack_cpus, (std::vector<int>{4, 7}));
  EXPECT_TRUE(shared->world_cpus.empty());
  EXPECT_NE(shared->description.find("shared with the world"),
            std::string::npos);
}

TEST(HostPlacementTest, MoreCoresThanTheHostGivesAreRefusedNamingBoth) {
  Result<HostPlacement> p = PlaceOnCpus(4, {0, 1});
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.status().code(), Status::Code::kUnavailable);
  EXPECT_NE(p.status().message().find("4 here"), std::string::npos)
      << p.status().message();
  EXPECT_NE(p.status().message().find("may use only 2 (CPUs 0,1)"),
            std::string::npos)
      << p.status().message();
}

TEST(RealTimeSimulateTest,
     AOneCoreRealTimeRunDrivesTheStackAndRecordsWhereItRan) {
  spec::Spec spec = SmallScenario();
  spec.platform.kind = spec::PlatformKind::kCgroup;
  spec.task.timeout_s = 12.0;  // 12 s of real time
  Result<runfile::RunData> run = SimulatePoint(spec, SmallPoint(1, 2.1, 7));
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_EQ(run->platform.at("kind"), "cgroup");
  EXPECT_NE(run->platform.at("confinement").find("affinity"),
            std::string::npos);
  EXPECT_EQ(run->platform.at("time_dilation"), "1");
  EXPECT_TRUE(run->platform.count("world_lag_max_s"));
  // The stack ran: commands reached the car, sensing took scans, and every
  // record is a real interval on the one executor thread.
  // (Bounds that hold however loaded the host is: ctest runs other tests
  // beside this one.)
  EXPECT_GT(run->controls.size(), 3u) << "the loop closed";
  std::set<int> ran;
  for (const stack::CallbackRecord& r : run->trace.callbacks) {
    ran.insert(r.callback);
    EXPECT_GE(r.start_s, r.ready_s - 1e-6);
    EXPECT_GE(r.end_s, r.start_s);
    EXPECT_EQ(r.first_core, 0);
  }
  EXPECT_GT(ran.size(), run->callback_info.size() / 2);
  // Sim time ran with the wall clock to the timeout.
  ASSERT_FALSE(run->ego.empty());
  EXPECT_NEAR(run->ego.back().t_s, 12.0, 0.1);
  EXPECT_GT(run->metrics.at("ctrl_rate_hz"), 0.0);
}

TEST(RealTimeSimulateTest, TheRealTimePlatformNeedsACostProfile) {
  spec::Spec spec = SmallScenario();
  spec.platform.kind = spec::PlatformKind::kCgroup;
  spec.platform.cost_model = spec::CostModel::kMeasured;
  spec.platform.profile.clear();
  Result<runfile::RunData> run = SimulatePoint(spec, SmallPoint(1, 2.1, 7));
  ASSERT_FALSE(run.ok());
  EXPECT_NE(run.status().message().find("platform.profile"), std::string::npos)
      << run.status().message();
}

}  // namespace
}  // namespace adse::sim
