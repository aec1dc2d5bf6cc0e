// The agent's capacity order over designs, from the knobs' roles: what a
// run that failed or held says of designs it has not run.
#include <gtest/gtest.h>

#include <vector>

#include "harness/explore/internal/agent_strategy.h"

namespace adse::explore::internal {
namespace {

// cores, GHz, LiDAR rate, NDT voxel size, a knob of no role; each value
// is an index into the knob's allowed values (ascending).
std::vector<Knob> Knobs() {
  std::vector<Knob> knobs(5);
  knobs[0].role = KnobRole::kCores;
  knobs[1].role = KnobRole::kFrequency;
  knobs[2].role = KnobRole::kSensorRate;
  knobs[3].role = KnobRole::kDownsample;
  knobs[4].role = KnobRole::kNone;
  return knobs;
}

int Compare(const Genes& a, const Genes& b, bool coarser_is_capacity,
            std::vector<bool> rate_raised = std::vector<bool>(5, false)) {
  return CompareCapacity(Knobs(), rate_raised, a, b, coarser_is_capacity);
}

TEST(CapacityTest, MoreCoresAndClockAndASlowerSensorAreMoreCapacity) {
  EXPECT_EQ(Compare({2, 1, 0, 1, 0}, {2, 1, 0, 1, 0}, false), 0);
  EXPECT_EQ(Compare({3, 2, 0, 1, 0}, {2, 1, 0, 1, 0}, false), +1);
  EXPECT_EQ(Compare({2, 1, 0, 1, 0}, {2, 1, 1, 1, 0}, false), +1);
  EXPECT_EQ(Compare({1, 1, 1, 1, 0}, {2, 1, 0, 1, 0}, false), -1);
  // More cores on a slower clock: neither.
  EXPECT_EQ(Compare({3, 0, 0, 1, 0}, {2, 1, 0, 1, 0}, false), 2);
  // A knob of no role must be equal.
  EXPECT_EQ(Compare({3, 1, 0, 1, 1}, {2, 1, 0, 1, 0}, false), 2);
}

TEST(CapacityTest, ASensorTheDiagnosisAskedToRaiseMustBeEqual) {
  std::vector<bool> raised(5, false);
  raised[2] = true;
  EXPECT_EQ(Compare({2, 1, 0, 1, 0}, {2, 1, 1, 1, 0}, false, raised), 2);
  EXPECT_EQ(Compare({3, 1, 1, 1, 0}, {2, 1, 1, 1, 0}, false, raised), +1);
}

TEST(CapacityTest, CoarserDataIsMoreCapacityOnlyWhereAsked) {
  // Against a run that was too slow, finer voxels are more load: fewer
  // cores with finer voxels have less capacity.
  EXPECT_EQ(Compare({1, 1, 0, 0, 0}, {2, 1, 0, 1, 0}, true), -1);
  EXPECT_EQ(Compare({2, 1, 0, 2, 0}, {2, 1, 0, 1, 0}, true), +1);
  // Otherwise (a run that strayed, or one that held) coarser data costs
  // precision, and a design that differs in it is not ordered.
  EXPECT_EQ(Compare({1, 1, 0, 0, 0}, {2, 1, 0, 1, 0}, false), 2);
  EXPECT_EQ(Compare({3, 1, 0, 2, 0}, {2, 1, 0, 1, 0}, false), 2);
  // Equal voxels: the other knobs decide.
  EXPECT_EQ(Compare({1, 1, 0, 1, 0}, {2, 1, 0, 1, 0}, false), -1);
}

}  // namespace
}  // namespace adse::explore::internal
