// Recent poses by the time they describe, looked up at a past time: what a
// ROS node gets from tf2 when it moves a sensor message into the map frame
// at the message's stamp rather than at the latest pose. A scan that
// reaches clustering 0.3 s after capture, placed by the newest pose of a
// car at 8 m/s, lands its objects 2.5 m off. Eigen and std types only.
#ifndef ADSE_STACK_ALGORITHMS_POSE_BUFFER_H_
#define ADSE_STACK_ALGORITHMS_POSE_BUFFER_H_

#include <cstddef>
#include <deque>
#include <optional>

#include "stack/geometry/geometry.h"

namespace adse::algorithms {

// `pose` moved straight along its heading at `v_mps` for `dt_s` (negative:
// back): where a pose stamped earlier is now, to first order.
geometry::Pose2 PoseAhead(const geometry::Pose2& pose, double v_mps,
                          double dt_s);

class PoseBuffer {
 public:
  // Poses older than window_s before the newest are forgotten; the newest
  // is always kept.
  explicit PoseBuffer(double window_s = 3.0) : window_s_(window_s) {}

  // The pose at time t_s, moving at v_mps. Times must not go backwards: an
  // older pose than the newest replaces nothing and is ignored.
  void Add(double t_s, const geometry::Pose2& pose, double v_mps);

  // The pose at t_s: interpolated between the two kept poses around it;
  // before the oldest, the oldest; after the newest, the newest moved on
  // along its heading at its speed. Empty when nothing was added.
  std::optional<geometry::Pose2> At(double t_s) const;

  size_t size() const { return poses_.size(); }
  bool empty() const { return poses_.empty(); }

 private:
  struct Stamped {
    double t_s;
    geometry::Pose2 pose;
    double v_mps;
  };
  double window_s_;
  std::deque<Stamped> poses_;  // oldest first
};

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_POSE_BUFFER_H_
