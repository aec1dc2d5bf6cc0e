// The poses a node looks up by time, as tf2's buffer serves an Autoware
// node: filled by a listener callback in a node of its own (tf2's listener
// spins its own thread, so a node busy with scans never starves it) and
// read by the node's callbacks at a message's stamp. On the real-time
// platform the two run on different threads, hence the lock.
#ifndef ADSE_STACK_NODES_POSE_LISTENER_H_
#define ADSE_STACK_NODES_POSE_LISTENER_H_

#include <mutex>
#include <optional>

#include "stack/algorithms/pose_buffer.h"
#include "stack/runtime/messages.h"

namespace adse::stack {

class PoseListener {
 public:
  // Keeps the pose at the time it describes (PoseMsg::time_s).
  void Add(const PoseMsg& pose);
  // The pose at t_s (algorithms::PoseBuffer::At); empty before any pose.
  std::optional<geometry::Pose2> At(double t_s) const;

 private:
  mutable std::mutex mutex_;
  algorithms::PoseBuffer buffer_;
};

}  // namespace adse::stack

#endif  // ADSE_STACK_NODES_POSE_LISTENER_H_
