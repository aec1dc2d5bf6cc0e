#include "stack/algorithms/pose_buffer.h"

#include <algorithm>
#include <cmath>

namespace adse::algorithms {

geometry::Pose2 PoseAhead(const geometry::Pose2& pose, double v_mps,
                          double dt_s) {
  geometry::Pose2 out = pose;
  out.x_m += v_mps * dt_s * std::cos(pose.yaw_rad);
  out.y_m += v_mps * dt_s * std::sin(pose.yaw_rad);
  return out;
}

void PoseBuffer::Add(double t_s, const geometry::Pose2& pose, double v_mps) {
  if (!poses_.empty() && t_s < poses_.back().t_s) return;
  if (!poses_.empty() && t_s == poses_.back().t_s) poses_.pop_back();
  poses_.push_back({t_s, pose, v_mps});
  while (poses_.size() > 1 && poses_.front().t_s < t_s - window_s_) {
    poses_.pop_front();
  }
}

std::optional<geometry::Pose2> PoseBuffer::At(double t_s) const {
  if (poses_.empty()) return std::nullopt;
  if (t_s <= poses_.front().t_s) return poses_.front().pose;
  if (t_s >= poses_.back().t_s) {
    const Stamped& last = poses_.back();
    return PoseAhead(last.pose, last.v_mps, t_s - last.t_s);
  }
  const auto after =
      std::lower_bound(poses_.begin(), poses_.end(), t_s,
                       [](const Stamped& p, double t) { return p.t_s < t; });
  const Stamped& b = *after;
  const Stamped& a = *(after - 1);
  return geometry::InterpolatePose(a.pose, b.pose,
                                   (t_s - a.t_s) / (b.t_s - a.t_s));
}

}  // namespace adse::algorithms
