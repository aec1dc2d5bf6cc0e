#include "stack/algorithms/freespace_planner.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "tests/stack/algorithms/testing/parking_row.h"

namespace adse::algorithms {
namespace {

using geometry::OrientedBox;
using geometry::Pose2;
using testing::BodyAt;
using testing::Box;
using testing::Footprint;
using testing::kAisle;
using testing::kSlotDepth;
using testing::kStart;
using testing::kTargetSlot;
using testing::Lot;
using testing::MakeLot;
using testing::SlotCentreX;
using testing::SlotGoal;

// Exact check: the body at every returned pose overlaps no obstacle box.
void ExpectNoCollision(const FreespacePath& path, const Lot& lot) {
  for (size_t i = 0; i < path.poses.size(); ++i) {
    const OrientedBox body = BodyAt(path.poses[i].pose, Footprint());
    for (const OrientedBox& b : lot.boxes) {
      ASSERT_FALSE(geometry::BoxesOverlap(body, b))
          << "pose " << i << " at (" << path.poses[i].pose.x_m << ", "
          << path.poses[i].pose.y_m << ") hits the box at " << b.center.x()
          << ", " << b.center.y();
    }
  }
}

void ExpectEndsAt(const FreespacePath& path, const Pose2& goal) {
  ASSERT_GE(path.poses.size(), 2u);
  const Pose2& end = path.poses.back().pose;
  EXPECT_NEAR(end.x_m, goal.x_m, 1e-6);
  EXPECT_NEAR(end.y_m, goal.y_m, 1e-6);
  EXPECT_NEAR(std::remainder(end.yaw_rad - goal.yaw_rad, 2 * M_PI), 0, 1e-6);
  // Poses are close enough for a controller to follow.
  for (size_t i = 1; i < path.poses.size(); ++i) {
    const Pose2& a = path.poses[i - 1].pose;
    const Pose2& b = path.poses[i].pose;
    EXPECT_LE(std::hypot(b.x_m - a.x_m, b.y_m - a.y_m), 0.26);
  }
}

TEST(FreespacePlanner, ForwardIntoTheSlot) {
  const Lot lot = MakeLot();
  FreespacePlanner planner({}, Footprint());
  const Result<FreespacePath> path =
      planner.Plan(kStart, SlotGoal(true), lot.Outlines());
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  ExpectEndsAt(*path, SlotGoal(true));
  ExpectNoCollision(*path, lot);
  // It arrives driving forwards.
  EXPECT_FALSE(path->poses.back().reverse);
  EXPECT_GT(planner.last_stats().expansions, 0);
  EXPECT_GT(planner.last_stats().work_units, 0);
}

TEST(FreespacePlanner, ReverseIntoTheSlot) {
  const Lot lot = MakeLot();
  FreespacePlanner planner({}, Footprint());
  const Result<FreespacePath> path =
      planner.Plan(kStart, SlotGoal(false), lot.Outlines());
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  ExpectEndsAt(*path, SlotGoal(false));
  ExpectNoCollision(*path, lot);
  // The start faces along the aisle and the goal faces out of the slot:
  // the car must back in, so the last leg is in reverse after a change.
  EXPECT_TRUE(path->poses.back().reverse);
  EXPECT_GE(path->gear_changes, 1);
  int changes = 0;
  for (size_t i = 1; i < path->poses.size(); ++i) {
    if (path->poses[i].reverse != path->poses[i - 1].reverse) ++changes;
  }
  EXPECT_EQ(changes, path->gear_changes);
}

TEST(FreespacePlanner, SameInputsSamePath) {
  const Lot lot = MakeLot();
  FreespacePlanner a({}, Footprint()), b({}, Footprint());
  const Result<FreespacePath> pa =
      a.Plan(kStart, SlotGoal(false), lot.Outlines());
  const Result<FreespacePath> pb =
      b.Plan(kStart, SlotGoal(false), lot.Outlines());
  ASSERT_TRUE(pa.ok() && pb.ok());
  ASSERT_EQ(pa->poses.size(), pb->poses.size());
  EXPECT_EQ(a.last_stats().expansions, b.last_stats().expansions);
  for (size_t i = 0; i < pa->poses.size(); ++i) {
    EXPECT_EQ(pa->poses[i].pose.x_m, pb->poses[i].pose.x_m);
  }
}

TEST(FreespacePlanner, BlockedSlotHasNoPathAtOnce) {
  Lot lot = MakeLot();
  // A pole in the middle of the target slot.
  lot.boxes.push_back(Box(SlotCentreX(kTargetSlot), kAisle + 2.0, 0.3, 0.3));
  FreespacePlanner planner({}, Footprint());
  const auto t0 = std::chrono::steady_clock::now();
  const Result<FreespacePath> path =
      planner.Plan(kStart, SlotGoal(true), lot.Outlines());
  const double ms = std::chrono::duration<double, std::milli>(
                        std::chrono::steady_clock::now() - t0)
                        .count();
  ASSERT_FALSE(path.ok());
  EXPECT_EQ(path.status().code(), Status::Code::kNotFound);
  EXPECT_NE(path.status().message().find("does not fit at the goal"),
            std::string::npos)
      << path.status().message();
  EXPECT_EQ(planner.last_stats().expansions, 0);
  EXPECT_LT(ms, 200.0);
}

TEST(FreespacePlanner, WalledOffSlotHasNoPathWithoutSearching) {
  Lot lot = MakeLot();
  // A wall across the aisle between the start and the slot.
  lot.boxes.push_back(Box(8.0, kAisle / 2, 0.2, kAisle + 2 * kSlotDepth));
  FreespacePlanner planner({}, Footprint());
  const Result<FreespacePath> path =
      planner.Plan(kStart, SlotGoal(true), lot.Outlines());
  ASSERT_FALSE(path.ok());
  EXPECT_EQ(path.status().code(), Status::Code::kNotFound);
  EXPECT_NE(path.status().message().find("no passage"), std::string::npos)
      << path.status().message();
  EXPECT_EQ(planner.last_stats().expansions, 0);
}

TEST(FreespacePlanner, ACarCloserThanTheMarginKeepsTheClearanceItHas) {
  // Backed in but 0.3 m to the right: 0.25 m from the car parked there,
  // which the 0.2 m grid sees as less than the 0.25 m margin. The
  // correction keeps the clearance the grid sees.
  const Lot lot = MakeLot();
  Pose2 start = SlotGoal(false);
  start.x_m += 0.3;
  FreespacePlanner planner({}, Footprint());
  const Result<FreespacePath> path =
      planner.Plan(start, SlotGoal(false), lot.Outlines());
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  ExpectEndsAt(*path, SlotGoal(false));
  ExpectNoCollision(*path, lot);
  const double kept_m = planner.last_stats().collision_margin_m;
  EXPECT_GT(kept_m, 0.1);
  EXPECT_LT(kept_m, 0.2);

  // From the aisle the full margin holds.
  ASSERT_TRUE(planner.Plan(kStart, SlotGoal(false), lot.Outlines()).ok());
  EXPECT_EQ(planner.last_stats().collision_margin_m, 0.25);

  // Against the parked car (0.05 m off, closer on the grid): no path.
  start.x_m += 0.2;
  const Result<FreespacePath> touching =
      planner.Plan(start, SlotGoal(false), lot.Outlines());
  ASSERT_FALSE(touching.ok());
  EXPECT_NE(touching.status().message().find("within 0.05 m of an obstacle"),
            std::string::npos)
      << touching.status().message();
}

TEST(FreespacePlanner, ExpansionBudgetEndsTheSearch) {
  const Lot lot = MakeLot();
  FreespacePlannerParams params;
  params.max_expansions = 3;
  params.analytic_range_m = 1.0;  // no shot from the start
  FreespacePlanner planner(params, Footprint());
  const Result<FreespacePath> path =
      planner.Plan(kStart, SlotGoal(false), lot.Outlines());
  ASSERT_FALSE(path.ok());
  EXPECT_NE(path.status().message().find("after 3 expansions"),
            std::string::npos)
      << path.status().message();
}

TEST(FreespacePlanner, FootprintCheckSeesAPoleUnderTheCar) {
  OccupancyGrid grid({-10, -10}, {10, 10}, 0.2);
  grid.AddObstacle(geometry::BoxCorners(Box(1.5, 0.0, 0.3, 0.3)));
  const VehicleFootprint fp = Footprint();
  EXPECT_TRUE(grid.FootprintCollides({0, 0, 0}, fp, 0.0));
  EXPECT_FALSE(grid.FootprintCollides({0, 3.0, 0}, fp, 0.0));
  // Beside the car: only the margin reaches it.
  EXPECT_FALSE(grid.FootprintCollides({0, 1.5, 0}, fp, 0.0));
  EXPECT_TRUE(grid.FootprintCollides({0, 1.5, 0}, fp, 0.5));
  // A thin wall (two points) is seen too; outside the grid is occupied.
  grid.AddObstacle({{-10, 5}, {10, 5}});
  EXPECT_TRUE(grid.FootprintCollides({0, 4.5, 0}, fp, 0.0));
  EXPECT_TRUE(grid.FootprintCollides({9.0, -5, 0}, fp, 0.0));
}

// A straight street along x, `width_m` across (two lanes), 80 m long: the
// drivable area of a dead-end street's last stretch.
std::vector<std::vector<Eigen::Vector2d>> Street(double width_m) {
  return {{{-40, -width_m / 2},
           {40, -width_m / 2},
           {40, width_m / 2},
           {-40, width_m / 2}}};
}

// The body's corners at every pose stay within the street (up to the
// grid's cell, which the margin covers).
void ExpectWithinStreet(const FreespacePath& path, double width_m) {
  for (size_t i = 0; i < path.poses.size(); ++i) {
    for (const Eigen::Vector2d& c :
         geometry::BoxCorners(BodyAt(path.poses[i].pose, Footprint()))) {
      ASSERT_LT(std::abs(c.y()), width_m / 2) << "pose " << i;
    }
  }
}

TEST(OccupancyGrid, KeepInsideMarksEverythingOutsideTheAreas) {
  OccupancyGrid grid({-10, -10}, {10, 10}, 0.2);
  grid.KeepInside({{{-5, -1}, {5, -1}, {5, 1}, {-5, 1}},
                   {{-1, 0}, {1, 0}, {1, 6}, {-1, 6}}});
  EXPECT_FALSE(grid.OccupiedAt({0, 0}));
  EXPECT_FALSE(grid.OccupiedAt({4.9, 0.9}));
  EXPECT_FALSE(grid.OccupiedAt({0, 5.5}));  // the second area
  EXPECT_TRUE(grid.OccupiedAt({0, -1.5}));
  EXPECT_TRUE(grid.OccupiedAt({3, 3}));
  EXPECT_TRUE(grid.OccupiedAt({-9, 9}));
  // No areas: no limit.
  OccupancyGrid open({-10, -10}, {10, 10}, 0.2);
  open.KeepInside({});
  EXPECT_FALSE(open.OccupiedAt({-9, 9}));
}

TEST(FreespacePlanner, TurnsRoundAtASideStreetInSeveralMoves) {
  // A two-lane street 6.4 m across with a side street of two lanes going
  // off to the left at x = 0: the car (5 m planning radius) needs 10 m to
  // turn in one move, and backs into the side street as a driver does.
  const double width_m = 6.4;
  std::vector<std::vector<Eigen::Vector2d>> area = Street(width_m);
  area.push_back({{-3.2, 0}, {3.2, 0}, {3.2, 30}, {-3.2, 30}});
  FreespacePlanner planner({}, Footprint());
  const Pose2 start{-12, -1.6, 0};
  const Pose2 goal{-12, 1.6, M_PI};
  const Result<FreespacePath> path = planner.Plan(start, goal, {}, area);
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  ExpectEndsAt(*path, goal);
  EXPECT_GE(path->gear_changes, 1);
  bool reverses = false;
  for (const GearedPose& p : path->poses) {
    reverses |= p.reverse;
    // Every corner of the body on the street or in the side street.
    for (const Eigen::Vector2d& c :
         geometry::BoxCorners(BodyAt(p.pose, Footprint()))) {
      const bool on_street = std::abs(c.y()) < width_m / 2;
      const bool in_side_street = std::abs(c.x()) < 3.2 && c.y() > 0;
      ASSERT_TRUE(on_street || in_side_street)
          << "corner (" << c.x() << ", " << c.y() << ")";
    }
  }
  EXPECT_TRUE(reverses);
}

TEST(FreespacePlanner, TurnsRoundOnAWideStreetInSeveralMoves) {
  // 8 m across (two lanes and parking lanes), no side street.
  const double width_m = 8.0;
  FreespacePlanner planner({}, Footprint());
  const Pose2 start{0, -2.0, 0};
  const Pose2 goal{0, 2.0, M_PI};
  const Result<FreespacePath> path =
      planner.Plan(start, goal, {}, Street(width_m));
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  ExpectEndsAt(*path, goal);
  ExpectWithinStreet(*path, width_m);
  EXPECT_GE(path->gear_changes, 2);  // a three-point turn at least
}

TEST(FreespacePlanner, NoTurnFitsInAStreetShorterAcrossThanTheCar) {
  // 4.4 m across, the car 4.6 m long: it cannot stand across the street.
  FreespacePlannerParams params;
  params.max_expansions = 20000;
  FreespacePlanner planner(params, Footprint());
  const Result<FreespacePath> path =
      planner.Plan({0, -1.1, 0}, {0, 1.1, M_PI}, {}, Street(4.4));
  ASSERT_FALSE(path.ok());
  EXPECT_EQ(path.status().code(), Status::Code::kNotFound);
  EXPECT_NE(path.status().message().find("no path"), std::string::npos)
      << path.status().message();
}

TEST(FreespacePlanner, WhereTheCarStandsIsDrivableAtTheAreasEdge) {
  // The car has brushed the street's edge: its right side 0.1 m over it.
  // It may still go on (the lane's edge on a map is no kerb).
  FreespacePlanner planner({}, Footprint());
  const Pose2 start{0, -2.3, 0};  // right side at -3.25, the edge at -3.2
  const Result<FreespacePath> path =
      planner.Plan(start, {20, -1.6, 0}, {}, Street(6.4));
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  EXPECT_NEAR(path->poses.back().pose.x_m, 20.0, 1e-6);
}

TEST(FreespacePlanner,
     ACarStandingInTheMoveUnderWayBlocksItAndOneBeyondDoesNot) {
  // A turn on the 8 m street; a car stands where the first move goes.
  FreespacePlanner planner({}, Footprint());
  const Pose2 start{0, -2.0, 0};
  const Result<FreespacePath> path =
      planner.Plan(start, {0, 2.0, M_PI}, {}, Street(8.0));
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  size_t cusp = 0;  // the first move's last pose
  while (cusp + 1 < path->poses.size() &&
         path->poses[cusp + 1].reverse == path->poses[0].reverse) {
    ++cusp;
  }
  ASSERT_LT(cusp + 1, path->poses.size());
  const double margin_m = planner.params().collision_margin_m;
  // A car 0.2 m beyond the body at the end of the first move.
  const OrientedBox at_cusp = BodyAt(path->poses[cusp].pose, Footprint());
  const Pose2& c = path->poses[cusp].pose;
  OrientedBox ahead;
  ahead.center = at_cusp.center +
                 (at_cusp.length_m / 2 + 0.2 + 2.25) *
                     Eigen::Vector2d(std::cos(c.yaw_rad), std::sin(c.yaw_rad));
  ahead.yaw_rad = c.yaw_rad;
  ahead.length_m = 4.5;
  const int blocked =
      FirstBlockedPose(path->poses, 0, {ahead}, Footprint(), margin_m);
  EXPECT_GE(blocked, 0);
  EXPECT_LE(blocked, static_cast<int>(cusp));
  // Without the margin the body never reaches it.
  EXPECT_EQ(FirstBlockedPose(path->poses, 0, {ahead}, Footprint(), 0.0), -1);
  // From the next move on it is not in the way of the move under way
  // (the car backs away from it).
  EXPECT_EQ(
      FirstBlockedPose(path->poses, cusp + 1, {ahead}, Footprint(), margin_m),
      -1);
  EXPECT_EQ(FirstBlockedPose(path->poses, 0, {}, Footprint(), margin_m), -1);
}

TEST(FreespacePlanner, APathPlannedWithACarAsAnObstacleKeepsClearOfIt) {
  // The same turn with a car parked where the first move went: the planner
  // given its outline finds another way, which it does not block.
  FreespacePlanner planner({}, Footprint());
  const Pose2 start{0, -2.0, 0};
  const Pose2 goal{0, 2.0, M_PI};
  OrientedBox parked;
  parked.center = {8.0, 2.0};
  parked.length_m = 4.5;
  const Result<FreespacePath> path =
      planner.Plan(start, goal, {geometry::BoxCorners(parked)}, Street(8.0));
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  ExpectEndsAt(*path, goal);
  for (size_t from = 0; from < path->poses.size(); ++from) {
    ASSERT_EQ(FirstBlockedPose(path->poses, from, {parked}, Footprint(),
                               0.5 * planner.params().collision_margin_m),
              -1)
        << "from pose " << from;
  }
}

TEST(FreespacePlanner, ParamsValidationNamesTheField) {
  FreespacePlannerParams p;
  p.yaw_bins = 3;
  EXPECT_EQ(ValidateFreespacePlannerParams(p).message().rfind("yaw_bins", 0),
            0u);
  p = {};
  p.step_m = 0.5;
  EXPECT_EQ(ValidateFreespacePlannerParams(p).message().rfind("step_m", 0), 0u);
  p = {};
  p.reverse_penalty = 0.5;
  EXPECT_EQ(
      ValidateFreespacePlannerParams(p).message().rfind("reverse_penalty", 0),
      0u);
  p = {};
  p.min_start_clearance_m = -0.1;
  EXPECT_EQ(ValidateFreespacePlannerParams(p).message().rfind(
                "min_start_clearance_m", 0),
            0u);
  EXPECT_TRUE(ValidateFreespacePlannerParams({}).ok());
}

}  // namespace
}  // namespace adse::algorithms
