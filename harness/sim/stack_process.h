// The stack in a process of its own (platform.kind: cgroup), as a ROS 2
// stack runs apart from its simulator: the world keeps its process and
// drives the stack's through an Executor that stands in for it. Sensor
// messages go to the stack's process, and what the graph's sinks take
// (commands, poses, stop reasons) comes back, over a Unix socket, each
// message stamped with its sim times; the trace follows at Stop().
#ifndef ADSE_HARNESS_SIM_STACK_PROCESS_H_
#define ADSE_HARNESS_SIM_STACK_PROCESS_H_

#include <sys/types.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "stack/base/status.h"
#include "stack/runtime/executor.h"
#include "stack/runtime/graph.h"

namespace adse::sim {

// Makes the executor that runs the graph, in the stack's process (after
// fork: whatever it needs, such as joining a cgroup, it does there).
using MakeStackExecutor =
    std::function<Result<std::unique_ptr<stack::Executor>>(
        const stack::Graph*)>;

class StackProcess : public stack::Executor {
 public:
  // Forks the stack's process, which runs `graph` on the executor `make`
  // returns there; the graph's sinks run here, in this process, in the
  // order and with the times the stack's executor gave them. Every topic
  // with a sink, and every one published to, must have a message codec
  // (all of messages.h have). `make`'s error is returned as it is.
  // `graph` must outlive the StackProcess and not change.
  static Result<std::unique_ptr<StackProcess>> Start(const stack::Graph* graph,
                                                     MakeStackExecutor make);
  // Ends the stack's process (closing the socket ends it; SIGKILL after
  // 5 s) and reaps it.
  ~StackProcess() override;
  StackProcess(const StackProcess&) = delete;
  StackProcess& operator=(const StackProcess&) = delete;

  // A failure to send (the stack's process gone) is returned by the next
  // AdvanceTo.
  void PublishExternal(int topic, stack::MessagePtr message, double stamp_s,
                       double t_s) override;
  // Internal naming how the stack's process ended when it did (a signal, an
  // exit status); Unavailable when it has said nothing for 60 s of wall
  // time (then it is killed).
  Status AdvanceTo(double t_s) override;
  double now_s() const override { return now_s_; }
  // The stack's trace, after Stop().
  const stack::Trace& trace() const override { return trace_; }
  // Ends execution and fetches the trace. A failure leaves the trace
  // empty and is kept in stop_status().
  void Stop() override;
  const Status& stop_status() const { return stop_status_; }

  pid_t pid() const { return pid_; }
  // For the run file: "process <pid>, N messages (X MB) to it and M (Y MB)
  // back over a Unix socket" (sensor messages in, sinks' messages out).
  std::string Describe() const;

 private:
  StackProcess() = default;
  Status Send(uint32_t kind, int32_t index, double a_s, double b_s,
              const std::string& payload);
  // Reads the next frame into the in_ members below.
  Status Receive();
  // Reaps the stack's process (killing it first when `kill`) and says how
  // it ended, after `what` happened.
  Status Ended(const std::string& what, bool kill);

  const stack::Graph* graph_ = nullptr;
  pid_t pid_ = -1;
  bool alive_ = false;  // not yet reaped
  int fd_ = -1;
  double now_s_ = 0.0;
  Status send_status_;
  Status stop_status_;
  bool stopped_ = false;
  stack::Trace trace_;
  int64_t messages_out_ = 0, bytes_out_ = 0;
  int64_t messages_in_ = 0, bytes_in_ = 0;
  // The frame Receive read last.
  uint32_t in_kind_ = 0;
  int32_t in_index_ = 0;
  std::string in_payload_;
};

}  // namespace adse::sim

#endif  // ADSE_HARNESS_SIM_STACK_PROCESS_H_
