// Who caused a contact between the ego and another vehicle
// (EgoCausedContact): plain geometry on the two bodies, no SUMO.
#include <gtest/gtest.h>

#include <cmath>

#include "stack/geometry/geometry.h"
#include "stack/world/vehicle_model.h"
#include "stack/world/world.h"

namespace adse::world {
namespace {

TEST(WorldTest, AContactIsTheEgosWhenItClosedOnTheOtherAtLeastAsFast) {
  // The ego heading +x with its body centred at the origin.
  VehicleState ego;
  ego.yaw_rad = 0.0;
  geometry::OrientedBox body;
  body.center = Eigen::Vector2d::Zero();
  auto other_at = [](double x, double y, double yaw, double speed) {
    OtherVehicle v;
    v.id = "v";
    v.box.center = Eigen::Vector2d(x, y);
    v.box.yaw_rad = yaw;
    v.speed_mps = speed;
    return v;
  };
  // Standing, driven into from behind or the side: not the ego's.
  ego.v_mps = 0.0;
  EXPECT_FALSE(EgoCausedContact(ego, 0.0, body, other_at(-4, 0, 0, 10)));
  EXPECT_FALSE(EgoCausedContact(ego, 0.0, body, other_at(-2, -1.5, 0.2, 14)));
  // Braking at 2 m/s, passed by a car at 14 m/s that cuts in: not either.
  ego.v_mps = 2.0;
  EXPECT_FALSE(EgoCausedContact(ego, 0.0, body, other_at(-2, 2, -0.3, 14)));
  // Into a slower car ahead, or a standing one: the ego's.
  ego.v_mps = 8.0;
  EXPECT_TRUE(EgoCausedContact(ego, 0.0, body, other_at(4.5, 0, 0, 3)));
  EXPECT_TRUE(EgoCausedContact(ego, 0.0, body, other_at(4.5, 0.5, 0, 0)));
  // Backing into a standing car behind: the ego's.
  ego.v_mps = -1.0;
  EXPECT_TRUE(EgoCausedContact(ego, 0.0, body, other_at(-4.5, 0, 0, 0)));
  // Head on, both at 5 m/s: the ego closed as fast, so it counts.
  ego.v_mps = 5.0;
  EXPECT_TRUE(EgoCausedContact(ego, 0.0, body, other_at(4.5, 0, M_PI, 5)));
}

TEST(WorldTest, ACarCuttingInWhoseRearSwingsIntoTheBrakingEgoCausedTheContact) {
  // RiLSA2, route 0 of seed 3 at run key v20, 83.45 s: leaving the same
  // green side by side, a flow's car from the lane on the ego's right
  // swung into the ego's lane in the junction, 7 m/s and turning
  // clockwise, while the ego braked through 1.6 m/s turning left, away
  // from it. The two bodies along the line between their centres closed
  // (the ego was behind it), which until v22 made it the ego's.
  VehicleLimits car;
  car.length_m = 4.6;
  car.width_m = 1.9;
  car.wheelbase_m = 2.7;
  VehicleState ego;
  ego.x_m = 502.216;
  ego.y_m = 507.337;
  ego.yaw_rad = -2.916;
  ego.v_mps = 1.60;
  ego.steer_rad = 0.306;
  const double ego_yaw_rate = ego.v_mps * std::tan(ego.steer_rad) / 2.7;
  const geometry::OrientedBox body =
      BodyAt({ego.x_m, ego.y_m, ego.yaw_rad}, car);
  OtherVehicle cutting_in;
  cutting_in.box.center = Eigen::Vector2d(495.988, 508.010);
  cutting_in.box.yaw_rad = -3.005;
  cutting_in.box.length_m = 5.0;
  cutting_in.box.width_m = 1.8;
  cutting_in.speed_mps = 7.03;
  cutting_in.yaw_rate_rps = -0.64;
  ASSERT_TRUE(geometry::BoxesOverlap(body, cutting_in.box));
  EXPECT_FALSE(EgoCausedContact(ego, ego_yaw_rate, body, cutting_in));

  // The same ego swinging its front corner into a car standing beside
  // it: the ego's.
  OtherVehicle standing = cutting_in;
  standing.speed_mps = 0.0;
  standing.yaw_rate_rps = 0.0;
  ego.v_mps = 3.0;
  ego.steer_rad = -0.5;  // turning right, into it
  EXPECT_TRUE(EgoCausedContact(ego, ego.v_mps * std::tan(ego.steer_rad) / 2.7,
                               body, standing));
}

}  // namespace
}  // namespace adse::world
