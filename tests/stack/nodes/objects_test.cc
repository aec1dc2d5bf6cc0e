#include "stack/nodes/objects.h"

#include <gtest/gtest.h>

namespace adse::stack {
namespace {

// A box standing across the map's axes: its heading is what tells it from
// an axis-aligned one of the same extents.
algorithms::Detection Slanted() {
  algorithms::Detection d;
  d.center = {167.25, 54.6};
  d.length_m = 5.0;
  d.width_m = 1.8;
  d.yaw_rad = 1.5;
  return d;
}

void ExpectSameBox(const TrackedObject& o, const algorithms::Detection& d) {
  EXPECT_EQ(o.position, d.center);
  EXPECT_EQ(o.length_m, d.length_m);
  EXPECT_EQ(o.width_m, d.width_m);
  EXPECT_EQ(o.yaw_rad, d.yaw_rad);
}

TEST(ObjectsTest, ADetectionCrossesToTheTrackerWithItsHeading) {
  const TrackedObject object = ObjectFromDetection(Slanted());
  ExpectSameBox(object, Slanted());
  const algorithms::Detection back = DetectionFromObject(object);
  EXPECT_EQ(back.center, Slanted().center);
  EXPECT_EQ(back.length_m, 5.0);
  EXPECT_EQ(back.width_m, 1.8);
  EXPECT_EQ(back.yaw_rad, 1.5);
}

TEST(ObjectsTest, ATrackReachesThePlannerWithItsHeading) {
  algorithms::Tracker tracker;
  tracker.Update(0.0, {Slanted()});
  ASSERT_EQ(tracker.tracks().size(), 1u);
  const TrackedObject object = ObjectFromTrack(tracker.tracks()[0]);
  ExpectSameBox(object, Slanted());
  EXPECT_EQ(object.id, tracker.tracks()[0].id);
  const algorithms::PlannerObstacle obstacle = ObstacleFromObject(object);
  EXPECT_EQ(obstacle.id, object.id);
  EXPECT_EQ(obstacle.position, object.position);
  EXPECT_EQ(obstacle.length_m, 5.0);
  EXPECT_EQ(obstacle.width_m, 1.8);
  EXPECT_EQ(obstacle.yaw_rad, 1.5);
  EXPECT_EQ(obstacle.age, object.age);
}

}  // namespace
}  // namespace adse::stack
