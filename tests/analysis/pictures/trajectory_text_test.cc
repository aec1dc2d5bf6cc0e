// The words on a trajectory picture: its title line and the label of the
// marker where a run that did not arrive ended.
#include "analysis/pictures/internal/trajectory_text.h"

#include <gtest/gtest.h>

#include <string>

namespace adse::analysis::internal {
namespace {

using runfile::RunData;

RunData ArrivedRun() {
  RunData run;
  run.scenario_name = "robotaxi-parking-lot";
  run.status = runfile::kRunComplete;
  run.termination_reason = "goal_reached";
  run.design_point = {{"cores", 7}, {"freq_ghz", 1.2}, {"lidar_hz", 7}};
  run.metrics = {{"nav_time_s", 89.85}};
  return run;
}

TEST(TrajectoryTextTest, TheTitleNamesTheScenarioThePointAndTheNavTime) {
  EXPECT_EQ(TrajectoryTitle(ArrivedRun()),
            "robotaxi-parking-lot | cores=7, freq_ghz=1.2, lidar_hz=7 | "
            "goal_reached, nav 89.85 s");
}

TEST(TrajectoryTextTest, AStoppedRunsNavTimeIsALowerBound) {
  RunData run = ArrivedRun();
  run.status = runfile::kRunInfeasible;
  run.termination_reason = "constraint_violated: nav_time_s <= 90";
  run.metrics["nav_time_s"] = 90.05;
  EXPECT_EQ(TrajectoryTitle(run),
            "robotaxi-parking-lot | cores=7, freq_ghz=1.2, lidar_hz=7 | "
            "constraint_violated: nav_time_s <= 90, nav >= 90.05 s (stopped "
            "early)");
}

TEST(TrajectoryTextTest, TheTitleSaysFailureContactsReplansAndTheCase) {
  RunData run = ArrivedRun();
  run.status = runfile::kRunFailed;
  run.termination_reason = "worker crashed\nstack trace follows";
  run.metrics.clear();
  run.collisions = {{10.0, "veh0", 1}, {12.0, "veh1", 0}};
  run.parking.replans = 2;
  run.task_case = "reverse";
  EXPECT_EQ(TrajectoryTitle(run),
            "robotaxi-parking-lot (reverse) | cores=7, freq_ghz=1.2, "
            "lidar_hz=7 | FAILED: worker crashed, 2 collisions (1 caused by "
            "the ego), re-planned 2x");
}

TEST(TrajectoryTextTest, AnEmptyRunStillHasATitle) {
  EXPECT_EQ(TrajectoryTitle(RunData()),
            "(no scenario) | (no design point) | (no outcome)");
}

TEST(TrajectoryTextTest, TheEndMarkerSaysHowTheRunEndedAndWhenToTheSecond) {
  RunData run = ArrivedRun();
  EXPECT_EQ(EndText(run, 89.85), "");  // the goal marker says it
  const struct {
    const char* reason;
    const char* text;
  } cases[] = {
      {"constraint_violated: nav_time_s <= 90", "stopped early 90 s"},
      {"stalled: obstacle", "stalled (obstacle) 90 s"},
      {"timeout", "timeout 90 s"},
      {"no_path", "no path 90 s"},
      {"parked_out_of_tolerance", "parked out of tolerance 90 s"},
      {"something new", "ended 90 s"},
  };
  for (const auto& c : cases) {
    run.termination_reason = c.reason;
    EXPECT_EQ(EndText(run, 90.05), c.text) << c.reason;
  }
}

}  // namespace
}  // namespace adse::analysis::internal
