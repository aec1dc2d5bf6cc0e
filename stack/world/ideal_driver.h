// Drives the ego along the ideal path with a ground-truth controller
// (predictive steering on the true pose, a curvature- and goal-aware speed
// profile). It checks the world before, and independently of, the stack under
// test.
#ifndef ADSE_STACK_WORLD_IDEAL_DRIVER_H_
#define ADSE_STACK_WORLD_IDEAL_DRIVER_H_

#include <functional>
#include <vector>

#include "stack/base/status.h"
#include "stack/world/lidar.h"
#include "stack/world/predictive_steering.h"
#include "stack/world/world.h"

namespace adse::world {

struct IdealDriverOptions {
  double speed_limit_mps = 30.0 / 3.6;
  PredictiveSteeringOptions steering;
  double max_lateral_accel_mps2 = 2.0;  // sets the speed in curves
  double comfort_decel_mps2 = 2.0;      // braking towards the goal
  double timeout_s = 600.0;
  // Scan with the LiDAR (when one is given) at its rate.
  bool scan = true;
  // Stop at the route's red (and stoppable yellow) signals as the stack's
  // planner does, reading their true state, and go on after standing
  // max_red_wait_s at one (traffic_light.max_red_wait_s).
  bool obey_signals = true;
  double max_red_wait_s = 300.0;
};

struct TrajectorySample {
  double t_s, x_m, y_m, yaw_rad, v_mps, steer_rad, accel_mps2;
};

struct IdealDriveReport {
  bool reached_goal = false;
  double time_s = 0.0;  // time to reach the goal (or timeout)
  int collisions = 0;
  double max_lateral_error_m = 0;  // distance of the ego from the ideal path
  double red_light_wait_s = 0.0;   // standing at signals' stop lines
  int scans = 0;
  double mean_points_per_scan = 0.0;
  double lidar_wall_s = 0.0;  // wall time spent ray casting
  double world_wall_s = 0.0;  // wall time spent in World::Step
  std::vector<TrajectorySample> trajectory;
};

// Called after every LiDAR scan with the scan and the pose it was taken at.
using ScanCallback =
    std::function<void(const PointCloud&, const geometry::Pose2&)>;

Result<IdealDriveReport> DriveIdealPath(World& world, LidarSimulator* lidar,
                                        const IdealDriverOptions& options,
                                        const ScanCallback& on_scan = nullptr);

}  // namespace adse::world

#endif  // ADSE_STACK_WORLD_IDEAL_DRIVER_H_
