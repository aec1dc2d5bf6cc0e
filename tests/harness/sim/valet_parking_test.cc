// The bundled valet scenario end to end, each of its task.cases: SUMO, the
// stack on the virtual platform costed by the valet profile, the freespace
// planner and the controller's parking mode. Each test is its own process
// (one SUMO each).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "analysis/runfile/run_file.h"
#include "harness/sim/simulator.h"
#include "harness/spec/spec_parser.h"
#include "tests/testing/temp_files.h"

namespace adse::sim {
namespace {

// scenarios/valet_parking.yaml as case `task_case` runs it.
spec::Spec Bundled(const std::string& task_case) {
  Result<spec::Spec> spec = spec::LoadSpec(std::string(ADSE_SOURCE_DIR) +
                                           "/scenarios/valet_parking.yaml");
  EXPECT_TRUE(spec.ok()) << spec.status().ToString();
  const int index = spec::FindCase(*spec, task_case);
  EXPECT_GE(index, 0) << task_case;
  return spec::ForCase(*spec, index);
}

const spec::DesignPoint kGenerous = {{"cores", 8}, {"freq_ghz", 3.0}};

// Parked in the slot within the tolerances, without touching anything,
// having driven the planned manoeuvre closely.
void ExpectParked(const runfile::RunData& run, int min_gear_changes) {
  const auto& m = run.metrics;
  EXPECT_EQ(run.termination_reason, "goal_reached");
  EXPECT_EQ(m.at("completed"), 1.0);
  EXPECT_EQ(m.at("parked"), 1.0);
  EXPECT_LE(m.at("parking_position_error_m"), 0.5);
  EXPECT_LE(m.at("parking_yaw_error_deg"), 10.0);
  EXPECT_EQ(m.at("obstacle_collisions"), 0.0);
  EXPECT_EQ(m.at("collisions"), 0.0);
  EXPECT_GT(m.at("min_clearance_m"), 0.1);
  EXPECT_LT(m.at("parking_path_deviation_max_m"), 0.5);
  EXPECT_GE(m.at("gear_changes"), min_gear_changes);
  EXPECT_LT(m.at("nav_time_s"), 90.0);
  ASSERT_TRUE(run.parking.present);
  EXPECT_EQ(run.parking.path_found, 1);
  EXPECT_GT(run.parking.planned_path.size(), 10u);
  // The record survives the run file and passes the schema check.
  const std::string path =
      (adse::testing::TestScratch() / "adse_valet_test.h5").string();
  ASSERT_TRUE(runfile::WriteRunFile(path, run).ok());
  std::vector<std::string> problems;
  EXPECT_TRUE(runfile::CheckRunFile(path, &problems).ok());
  EXPECT_TRUE(problems.empty()) << problems.front();
}

TEST(ValetParkingTest, BacksIntoTheSlot) {
  Result<runfile::RunData> run =
      SimulatePoint(Bundled("backing_in"), kGenerous);
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_EQ(run->task_case, "backing_in");
  // The road ends beside the slot facing west; backing in needs at least
  // one change from forward to reverse.
  ExpectParked(*run, 1);
  EXPECT_EQ(run->parking.planned_path.back().reverse, 1);
  // Within the default course (1 m) all the way: one plan.
  EXPECT_EQ(run->metrics.at("parking_replans"), 0.0);
  EXPECT_EQ(run->parking.first_planned_at_s, run->parking.planned_at_s);
}

TEST(ValetParkingTest, DrivesNoseFirstIntoTheSlot) {
  Result<runfile::RunData> run = SimulatePoint(Bundled("nose_in"), kGenerous);
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_EQ(run->task_case, "nose_in");
  ExpectParked(*run, 1);
  // Nose first: the manoeuvre enters the slot driving forward (the first
  // planned pose within 2 m of the goal); a short reverse to straighten up
  // at the end may follow, as it does since issue 17's localization fixes
  // moved the pose the manoeuvre is planned from.
  const auto& plan = run->parking.planned_path;
  auto entering = std::find_if(plan.begin(), plan.end(), [&](const auto& p) {
    return std::hypot(p.x_m - run->parking.goal_x_m,
                      p.y_m - run->parking.goal_y_m) < 2.0;
  });
  ASSERT_NE(entering, plan.end());
  EXPECT_EQ(entering->reverse, 0);
  // Here the plan runs 0.55 m past the goal and backs up to it; standing
  // at that cusp the car is within the 0.5 m tolerance (0.48 m), but it is
  // parked only once the manoeuvre is over, at the goal.
  EXPECT_LT(run->metrics.at("parking_position_error_m"), 0.15);
}

TEST(ValetParkingTest, UnreachableSlotEndsTheRunWithNoPathNotATimeout) {
  spec::Spec spec = Bundled("backing_in");
  // A planner that keeps 0.8 m around the body cannot fit the car between
  // the parked neighbours (3.2 m apart, the car 1.9 m wide).
  ASSERT_TRUE(spec.stack.Set("parking.collision_margin_m", 0.8).ok());
  Result<runfile::RunData> run = SimulatePoint(spec, kGenerous);
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_EQ(run->termination_reason, "no_path");
  // The planner's own words say why.
  EXPECT_NE(run->termination_detail.find("no path"), std::string::npos)
      << run->termination_detail;
  EXPECT_EQ(run->metrics.at("completed"), 0.0);
  EXPECT_EQ(run->metrics.at("parked"), 0.0);
  EXPECT_EQ(run->parking.path_found, 0);
  EXPECT_TRUE(run->parking.planned_path.empty());
  // It ends once the car stands at the aisle, far from the 300 s timeout.
  EXPECT_LT(run->metrics.at("nav_time_s"), 40.0);
  EXPECT_GE(run->parking.planned_at_s, 0.0);
}

TEST(ValetParkingTest, AManoeuvreEndingOutsideTheTolerancesIsCorrected) {
  spec::Spec spec = Bundled("backing_in");
  // Tighter than the manoeuvre ends here (0.09 m off): the planner plans
  // again from where the car stands, and that short manoeuvre ends within.
  spec.task.goal_tolerance_m = 0.08;
  Result<runfile::RunData> run = SimulatePoint(spec, kGenerous);
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_EQ(run->termination_reason, "goal_reached");
  EXPECT_EQ(run->metrics.at("parked"), 1.0);
  EXPECT_LE(run->metrics.at("parking_position_error_m"), 0.08);
  EXPECT_EQ(run->metrics.at("obstacle_collisions"), 0.0);
  // The plan recorded is the correction: a short one, ending at the goal.
  ASSERT_GE(run->parking.planned_path.size(), 2u);
  EXPECT_NEAR(run->parking.planned_path.back().x_m, run->parking.goal_x_m,
              1e-6);
  EXPECT_NEAR(run->parking.planned_path.back().y_m, run->parking.goal_y_m,
              1e-6);
  EXPECT_GE(run->parking.replans, 1);
  EXPECT_EQ(run->metrics.at("parking_replans"), run->parking.replans);
  // The manoeuvre it replaced is kept: the first plan, from the aisle.
  ASSERT_GT(run->parking.earlier_plans.size(), 10u);
  EXPECT_EQ(run->parking.earlier_plans.front().plan, 0);
  EXPECT_EQ(run->parking.earlier_plans.back().plan, run->parking.replans - 1);

  // With no re-plan left it stays where the first manoeuvre ended.
  ASSERT_TRUE(spec.stack.Set("parking.max_replans", 0).ok());
  Result<runfile::RunData> first = SimulatePoint(spec, kGenerous);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  EXPECT_EQ(first->termination_reason, "parked_out_of_tolerance");
  EXPECT_EQ(first->parking.replans, 0);
  EXPECT_GT(first->metrics.at("parking_position_error_m"), 0.08);
  EXPECT_LT(first->metrics.at("nav_time_s"), run->metrics.at("nav_time_s"));
}

TEST(ValetParkingTest, ParkedOutsideTheToleranceEndsTheRunAtOnce) {
  spec::Spec spec = Bundled("backing_in");
  // Tighter than the manoeuvre ends (about 1.4 degrees off at this point),
  // and no re-plan to correct it.
  spec.task.goal_yaw_tolerance_deg = 0.2;
  ASSERT_TRUE(spec.stack.Set("parking.max_replans", 0).ok());
  Result<runfile::RunData> run = SimulatePoint(spec, kGenerous);
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_EQ(run->termination_reason, "parked_out_of_tolerance");
  EXPECT_EQ(run->metrics.at("completed"), 0.0);
  EXPECT_EQ(run->metrics.at("parked"), 0.0);
  EXPECT_GT(run->metrics.at("parking_yaw_error_deg"), 0.2);
  EXPECT_LT(run->metrics.at("parking_position_error_m"), 0.5);
  // Standing in the slot, not waiting for the 300 s timeout.
  EXPECT_LT(run->metrics.at("nav_time_s"), 60.0);
}

TEST(ValetParkingTest, OffTheCourseOfItsPathTheCarStopsAndGetsANewOne) {
  spec::Spec spec = Bundled("backing_in");
  // A course narrower than the car follows the plan here (within a few
  // centimetres): it leaves it, stops, and the planner plans again from
  // there.
  ASSERT_TRUE(spec.stack.Set("parking.course_out_m", 0.05).ok());
  ASSERT_TRUE(spec.stack.Set("parking.max_replans", 20).ok());
  Result<runfile::RunData> run = SimulatePoint(spec, kGenerous);
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  ExpectParked(*run, 1);
  EXPECT_GE(run->metrics.at("parking_replans"), 1.0);
  EXPECT_EQ(run->parking.replans, run->metrics.at("parking_replans"));
  // The last plan came later than the first; the parking time counts from
  // the first.
  EXPECT_GT(run->parking.planned_at_s, run->parking.first_planned_at_s);
  EXPECT_NEAR(run->metrics.at("parking_time_s"),
              run->ego.back().t_s - run->parking.first_planned_at_s, 1e-9);
}

TEST(ValetParkingTest, PastItsReplansAnOffCourseCarEndsTheRunWithNoPath) {
  spec::Spec spec = Bundled("backing_in");
  ASSERT_TRUE(spec.stack.Set("parking.course_out_m", 0.05).ok());
  ASSERT_TRUE(spec.stack.Set("parking.max_replans", 0).ok());
  Result<runfile::RunData> run = SimulatePoint(spec, kGenerous);
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_EQ(run->termination_reason, "no_path");
  EXPECT_NE(run->termination_detail.find("off the course of its path"),
            std::string::npos)
      << run->termination_detail;
  EXPECT_EQ(run->parking.replans, 0);
  EXPECT_EQ(run->parking.path_found, 0);
  EXPECT_EQ(run->metrics.at("parked"), 0.0);
  // Ended where it stopped, not at the 300 s timeout.
  EXPECT_LT(run->metrics.at("nav_time_s"), 90.0);
}

TEST(ValetParkingTest, TheScenarioWithItsCasesIsNotOneRun) {
  Result<spec::Spec> spec = spec::LoadSpec(std::string(ADSE_SOURCE_DIR) +
                                           "/scenarios/valet_parking.yaml");
  ASSERT_TRUE(spec.ok()) << spec.status().ToString();
  Result<runfile::RunData> run = SimulatePoint(*spec, kGenerous);
  ASSERT_FALSE(run.ok());
  EXPECT_NE(run.status().message().find("task.cases"), std::string::npos)
      << run.status().message();
}

}  // namespace
}  // namespace adse::sim
