#include "stack/nodes/pose_listener.h"

namespace adse::stack {

void PoseListener::Add(const PoseMsg& pose) {
  std::lock_guard<std::mutex> lock(mutex_);
  buffer_.Add(pose.time_s, pose.pose, pose.v_mps);
}

std::optional<geometry::Pose2> PoseListener::At(double t_s) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return buffer_.At(t_s);
}

}  // namespace adse::stack
