// The stack in a process of its own: its callbacks run there, the graph's
// sinks here, in the order and at the times its executor gives them, the
// trace comes back whole, and how the process ended is said when it did.
#include "harness/sim/stack_process.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <memory>
#include <string>
#include <vector>

#include "stack/runtime/executor.h"
#include "stack/runtime/messages.h"

namespace adse::sim {
namespace {

// odometry -> "ctl/odometry" -> control (accel: the pid that ran it, steer:
// the speed it was given) -> a sink. A negative speed kills the process.
struct Loop {
  stack::Graph graph;
  int odometry = -1;
  std::vector<stack::ControlMsg> seen;
  std::vector<double> seen_at_s;

  Loop() {
    odometry = graph.AddTopic<stack::OdometryMsg>("odometry");
    const int control = graph.AddTopic<stack::ControlMsg>("control");
    const int node = graph.AddNode("ctl");
    graph.Subscribe<stack::OdometryMsg>(
        node, odometry, "odometry", 4,
        [control](const stack::OdometryMsg& m, stack::CallbackContext& ctx) {
          if (m.v_mps < 0) ::kill(::getpid(), SIGKILL);
          stack::ControlMsg out;
          out.header = m.header;
          out.accel_mps2 = ::getpid();
          out.steer_rad = m.v_mps;
          ctx.Publish(control, out);
        });
    graph.AddSink<stack::ControlMsg>(
        control, [this](const stack::ControlMsg& m, double t_s) {
          seen.push_back(m);
          seen_at_s.push_back(t_s);
        });
  }
  void Publish(stack::Executor& executor, double t_s, double v_mps) {
    stack::OdometryMsg m;
    m.header.stamp_s = t_s;
    m.v_mps = v_mps;
    executor.PublishExternal(
        odometry, std::make_shared<const stack::OdometryMsg>(m), t_s, t_s);
  }
};

MakeStackExecutor Virtual() {
  return [](const stack::Graph* graph) {
    stack::VirtualPlatformOptions o;
    o.cores = 1;
    o.freq_ghz = 2.0;
    o.reference_ghz = 2.0;
    o.cost_model = stack::CostModelKind::kCounted;
    o.counted["ctl/odometry"] = {0.01, 0.0};
    return stack::CreateVirtualExecutor(graph, o);
  };
}

TEST(StackProcessTest, TheGraphRunsInAnotherProcessAndItsSinksRunHere) {
  Loop loop;
  Result<std::unique_ptr<StackProcess>> started =
      StackProcess::Start(&loop.graph, Virtual());
  ASSERT_TRUE(started.ok()) << started.status().ToString();
  StackProcess& process = **started;
  EXPECT_NE(process.pid(), ::getpid());
  for (int i = 0; i < 3; ++i) loop.Publish(process, 0.1 * i, 1.0 + i);
  ASSERT_TRUE(process.AdvanceTo(0.5).ok());
  EXPECT_DOUBLE_EQ(process.now_s(), 0.5);

  // The same graph on the same platform in this process.
  Loop here;
  Result<std::unique_ptr<stack::Executor>> local = Virtual()(&here.graph);
  ASSERT_TRUE(local.ok());
  for (int i = 0; i < 3; ++i) here.Publish(**local, 0.1 * i, 1.0 + i);
  ASSERT_TRUE((*local)->AdvanceTo(0.5).ok());

  ASSERT_EQ(loop.seen.size(), 3u);
  EXPECT_EQ(loop.seen_at_s, here.seen_at_s);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(loop.seen[i].accel_mps2, process.pid()) << "ran there";
    EXPECT_EQ(loop.seen[i].steer_rad, here.seen[i].steer_rad) << "in order";
    EXPECT_EQ(loop.seen[i].header.stamp_s, here.seen[i].header.stamp_s);
  }
  EXPECT_NEAR(loop.seen_at_s[2], 0.21, 1e-9);

  process.Stop();
  ASSERT_TRUE(process.stop_status().ok()) << process.stop_status().ToString();
  (*local)->Stop();
  const stack::Trace& there = process.trace();
  const stack::Trace& mine = (*local)->trace();
  ASSERT_EQ(there.callbacks.size(), 3u);
  ASSERT_EQ(there.callbacks.size(), mine.callbacks.size());
  for (size_t i = 0; i < there.callbacks.size(); ++i) {
    EXPECT_EQ(there.callbacks[i].start_s, mine.callbacks[i].start_s);
    EXPECT_EQ(there.callbacks[i].end_s, mine.callbacks[i].end_s);
  }
  EXPECT_EQ(there.topic_events.size(), mine.topic_events.size());
  const std::string said = process.Describe();
  EXPECT_NE(said.find("process " + std::to_string(process.pid())),
            std::string::npos)
      << said;
  EXPECT_NE(said.find("3 messages"), std::string::npos) << said;
}

TEST(StackProcessTest, AStackProcessThatDiesIsNamedByItsSignal) {
  Loop loop;
  Result<std::unique_ptr<StackProcess>> started =
      StackProcess::Start(&loop.graph, Virtual());
  ASSERT_TRUE(started.ok()) << started.status().ToString();
  loop.Publish(**started, 0.0, -1.0);
  const Status s = (*started)->AdvanceTo(0.5);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), Status::Code::kInternal);
  EXPECT_NE(s.message().find("killed by signal 9"), std::string::npos)
      << s.message();
  // Later calls say it is gone rather than hang.
  loop.Publish(**started, 0.6, 1.0);
  EXPECT_FALSE((*started)->AdvanceTo(1.0).ok());
  (*started)->Stop();
  EXPECT_FALSE((*started)->stop_status().ok());
}

TEST(StackProcessTest, TheExecutorsErrorThereIsReturnedAsItIs) {
  Loop loop;
  Result<std::unique_ptr<StackProcess>> started = StackProcess::Start(
      &loop.graph,
      [](const stack::Graph*) -> Result<std::unique_ptr<stack::Executor>> {
        return Status::Unavailable("cgroup: no cpuset controller");
      });
  ASSERT_FALSE(started.ok());
  EXPECT_EQ(started.status().code(), Status::Code::kUnavailable);
  EXPECT_EQ(started.status().message(), "cgroup: no cpuset controller");
  // ... and the process was reaped.
  EXPECT_EQ(::waitpid(-1, nullptr, WNOHANG), -1);
  EXPECT_EQ(errno, ECHILD);
}

TEST(StackProcessTest, ASinkWhoseMessagesCannotCrossIsRefusedAtStart) {
  struct Local {
    stack::Header header;
  };
  stack::Graph graph;
  const int topic = graph.AddTopic<Local>("local_topic");
  graph.AddSink<Local>(topic, [](const Local&, double) {});
  Result<std::unique_ptr<StackProcess>> started =
      StackProcess::Start(&graph, Virtual());
  ASSERT_FALSE(started.ok());
  EXPECT_EQ(started.status().code(), Status::Code::kInvalidArgument);
  EXPECT_NE(started.status().message().find("local_topic"), std::string::npos)
      << started.status().message();
}

TEST(StackProcessTest, TheStackProcessEndsWithItsProxy) {
  Loop loop;
  pid_t pid = -1;
  {
    Result<std::unique_ptr<StackProcess>> started =
        StackProcess::Start(&loop.graph, Virtual());
    ASSERT_TRUE(started.ok()) << started.status().ToString();
    pid = (*started)->pid();
    ASSERT_EQ(::kill(pid, 0), 0);
  }
  EXPECT_EQ(::kill(pid, 0), -1) << "still there, or a zombie";
  EXPECT_EQ(errno, ESRCH);
}

}  // namespace
}  // namespace adse::sim
