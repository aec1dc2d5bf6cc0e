// A row of a parking lot as the bundled map lays it out, for the freespace
// planner's and the parking controller's tests.
#ifndef ADSE_TESTS_STACK_ALGORITHMS_TESTING_PARKING_ROW_H_
#define ADSE_TESTS_STACK_ALGORITHMS_TESTING_PARKING_ROW_H_

#include <cmath>
#include <vector>

#include "stack/algorithms/occupancy_grid.h"
#include "stack/geometry/geometry.h"

namespace adse::algorithms::testing {

using geometry::OrientedBox;
using geometry::Pose2;

// A row of the bundled parking lot: a 7 m aisle along x (y in [0, 7]), a
// row of 2.5 x 5 m slots on each side, a wall behind the upper row, every
// slot but the target (upper row, slot 5) holding a parked car.
constexpr double kSlotWidth = 2.5;
constexpr double kSlotDepth = 5.0;
constexpr double kAisle = 7.0;
constexpr int kTargetSlot = 5;

inline OrientedBox Box(double cx, double cy, double length, double width,
                       double yaw = 0.0) {
  OrientedBox b;
  b.center = {cx, cy};
  b.length_m = length;
  b.width_m = width;
  b.yaw_rad = yaw;
  return b;
}

inline double SlotCentreX(int s) { return (s + 0.5) * kSlotWidth; }

struct Lot {
  std::vector<OrientedBox> boxes;  // everything solid, as boxes
  std::vector<std::vector<Eigen::Vector2d>> Outlines() const {
    std::vector<std::vector<Eigen::Vector2d>> out;
    for (const OrientedBox& b : boxes) out.push_back(geometry::BoxCorners(b));
    return out;
  }
};

inline Lot MakeLot() {
  Lot lot;
  for (int s = 0; s < 12; ++s) {
    // Parked cars nose-in with a little offset, as the world jitters them.
    if (s != kTargetSlot) {
      lot.boxes.push_back(Box(SlotCentreX(s) + 0.1 * ((s % 3) - 1),
                              kAisle + kSlotDepth / 2, 4.5, 1.8, M_PI / 2));
    }
    lot.boxes.push_back(Box(SlotCentreX(s) - 0.1 * ((s % 3) - 1),
                            -kSlotDepth / 2, 4.5, 1.8, M_PI / 2));
  }
  // Wall behind the upper row and poles at the row's ends.
  lot.boxes.push_back(Box(15, kAisle + kSlotDepth + 0.5, 40, 0.2));
  lot.boxes.push_back(Box(-1.0, kAisle + kSlotDepth / 2, 0.3, 0.3));
  lot.boxes.push_back(
      Box(12 * kSlotWidth + 1.0, kAisle + kSlotDepth / 2, 0.3, 0.3));
  return lot;
}

inline VehicleFootprint Footprint() { return VehicleFootprint{}; }

// Rear-axle goal with the body centred in the target slot.
inline Pose2 SlotGoal(bool nose_in) {
  const VehicleFootprint fp = Footprint();
  const double ahead = 0.5 * (fp.front_m - fp.rear_m);  // axle to body centre
  const double cy = kAisle + kSlotDepth / 2;
  return nose_in ? Pose2{SlotCentreX(kTargetSlot), cy - ahead, M_PI / 2}
                 : Pose2{SlotCentreX(kTargetSlot), cy + ahead, -M_PI / 2};
}

inline const Pose2 kStart{1.5, kAisle / 2, 0.0};

inline OrientedBox BodyAt(const Pose2& pose, const VehicleFootprint& fp) {
  return FootprintBox(pose, fp);
}

}  // namespace adse::algorithms::testing

#endif  // ADSE_TESTS_STACK_ALGORITHMS_TESTING_PARKING_ROW_H_
