// Whole-trace properties of the virtual platform on a busy graph (timers,
// drops, parallel work, a shared node): counted runs repeat bit for bit,
// cores are never oversubscribed, and processor sharing keeps the same
// guarantees. The scheduling rules one by one are in
// virtual_executor_test.cc.
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <type_traits>

#include "stack/runtime/executor.h"
#include "stack/runtime/graph.h"
#include "stack/runtime/trace.h"
#include "tests/stack/runtime/executor_test_util.h"

namespace adse::stack {
namespace {

using test::Counted;
using test::CreateVirtual;
using test::Msg;
using test::Publish;

constexpr int kMixedCores = 3;

// A graph with timers, drops, parallel work and a shared node.
Trace RunMixedGraph(int cores = kMixedCores,
                    DispatchKind dispatch = DispatchKind::kRunToCompletion) {
  Graph g;
  const int lidar = g.AddTopic<Msg>("lidar");
  const int filtered = g.AddTopic<Msg>("filtered");
  const int pose = g.AddTopic<Msg>("pose");
  const int cmd = g.AddTopic<Msg>("cmd");
  g.Subscribe<Msg>(g.AddNode("filter"), lidar, "cb", 1,
                   [filtered](const Msg& m, CallbackContext& ctx) {
                     ctx.ReportWork({.units = 100.0 + m.value % 7,
                                     .parallel_fraction = 0.5,
                                     .max_threads = 3});
                     ctx.Publish(filtered, m);
                   });
  const int loc = g.AddNode("loc");
  g.Subscribe<Msg>(loc, filtered, "ndt", 2,
                   [pose](const Msg& m, CallbackContext& ctx) {
                     ctx.ReportWork({.units = 50.0 + m.value % 5});
                     ctx.Publish(pose, m);
                   });
  g.AddTimer(loc, "ekf", 0.02, [](CallbackContext&) {});
  int latest = 0;
  g.Subscribe<Msg>(
      g.AddNode("ctrl"), pose, "pose", 1,
      [&latest](const Msg& m, CallbackContext&) { latest = m.value; });
  g.AddTimer(g.AddNode("follow"), "t", 0.03,
             [&latest, cmd](CallbackContext& ctx) {
               Msg m;
               m.header.stamp_s = ctx.now_s();
               m.value = latest;
               ctx.Publish(cmd, m);
             });
  g.AddSink<Msg>(cmd, [](const Msg&, double) {});
  VirtualPlatformOptions options =
      Counted(cores, {{"filter/cb", {0.01, 0.0004}},
                      {"loc/ndt", {0.02, 0.001}},
                      {"loc/ekf", {0.004, 0}},
                      {"ctrl/pose", {0.001, 0}},
                      {"follow/t", {0.035, 0}}});
  options.dispatch = dispatch;
  auto ex = CreateVirtual(g, options);
  for (int step = 1; step <= 100; ++step) {
    const double t = step * 0.1;
    for (int j = 0; j < 3; ++j) {  // 30 Hz: faster than the filter keeps up
      Publish(*ex, lidar, 3 * step + j, t - 0.1 + 0.0137 + j * 0.033);
    }
    EXPECT_TRUE(ex->AdvanceTo(t).ok());
  }
  return ex->trace();
}

template <typename T>
void ExpectBitEqual(T a, T b, const char* what, size_t i) {
  if constexpr (std::is_floating_point_v<T>) {
    EXPECT_EQ(std::bit_cast<uint64_t>(a), std::bit_cast<uint64_t>(b))
        << what << " #" << i;
  } else {
    EXPECT_EQ(a, b) << what << " #" << i;
  }
}

// `cost_rounding`: cost_s may differ by rounding (one dispatch stores the
// cost, the other end - start).
void ExpectSameTrace(const Trace& a, const Trace& b,
                     bool cost_rounding = false) {
  ASSERT_GT(a.callbacks.size(), 100u);
  ASSERT_EQ(a.callbacks.size(), b.callbacks.size());
  ASSERT_EQ(a.topic_events.size(), b.topic_events.size());
  EXPECT_EQ(a.timer_overruns, b.timer_overruns);
  for (size_t i = 0; i < a.callbacks.size(); ++i) {
    const auto& x = a.callbacks[i];
    const auto& y = b.callbacks[i];
    ExpectBitEqual(x.callback, y.callback, "callback", i);
    ExpectBitEqual(x.node, y.node, "node", i);
    ExpectBitEqual(x.ready_s, y.ready_s, "ready_s", i);
    ExpectBitEqual(x.start_s, y.start_s, "start_s", i);
    ExpectBitEqual(x.end_s, y.end_s, "end_s", i);
    if (cost_rounding) {
      EXPECT_NEAR(x.cost_s, y.cost_s, 1e-15) << "cost_s #" << i;
    } else {
      ExpectBitEqual(x.cost_s, y.cost_s, "cost_s", i);
    }
    ExpectBitEqual(x.host_cpu_s, y.host_cpu_s, "host_cpu_s", i);
    ExpectBitEqual(x.work_units, y.work_units, "work_units", i);
    ExpectBitEqual(x.cores, y.cores, "cores", i);
    ExpectBitEqual(x.first_core, y.first_core, "first_core", i);
  }
  for (size_t i = 0; i < a.topic_events.size(); ++i) {
    const auto& x = a.topic_events[i];
    const auto& y = b.topic_events[i];
    ExpectBitEqual(static_cast<int>(x.kind), static_cast<int>(y.kind), "kind",
                   i);
    ExpectBitEqual(x.topic, y.topic, "topic", i);
    ExpectBitEqual(x.callback, y.callback, "callback", i);
    ExpectBitEqual(x.t_s, y.t_s, "t_s", i);
    ExpectBitEqual(x.seq, y.seq, "seq", i);
    ExpectBitEqual(x.stamp_s, y.stamp_s, "stamp_s", i);
  }
}

TEST(VirtualExecutorTest, CountedRunsAreBitIdentical) {
  const Trace a = RunMixedGraph();
  ExpectSameTrace(a, RunMixedGraph());
  // The graph is busy enough to exercise drops and parallel runs.
  int drops = 0;
  for (const auto& e : a.topic_events) drops += e.kind == TopicEvent::kDrop;
  EXPECT_GT(drops, 0);
  bool parallel = false;
  for (const auto& r : a.callbacks) parallel |= r.cores > 1;
  EXPECT_TRUE(parallel);
}

// Never two runs on one core, never more cores than the platform has.
TEST(VirtualExecutorTest, CoresAreNeverOversubscribed) {
  const Trace trace = RunMixedGraph();
  for (size_t i = 0; i < trace.callbacks.size(); ++i) {
    const auto& x = trace.callbacks[i];
    EXPECT_GE(x.start_s, x.ready_s);
    int busy = x.cores;
    for (size_t j = 0; j < trace.callbacks.size(); ++j) {
      const auto& y = trace.callbacks[j];
      if (i == j || y.start_s > x.start_s || y.end_s <= x.start_s) continue;
      busy += y.cores;
      EXPECT_NE(x.node, y.node) << "node overlap at " << x.start_s;
    }
    EXPECT_LE(busy, kMixedCores) << "at " << x.start_s;
  }
}

// ---- Processor sharing -----------------------------------------------------

TEST(VirtualExecutorTest, ProcessorSharingOnOneCoreIsRunToCompletion) {
  ExpectSameTrace(RunMixedGraph(1, DispatchKind::kRunToCompletion),
                  RunMixedGraph(1, DispatchKind::kProcessorSharing),
                  /*cost_rounding=*/true);
}

TEST(VirtualExecutorTest, ProcessorSharingIsDeterministic) {
  const Trace a = RunMixedGraph(kMixedCores, DispatchKind::kProcessorSharing);
  ExpectSameTrace(a,
                  RunMixedGraph(kMixedCores, DispatchKind::kProcessorSharing));
  // It differs from run to completion where teams meet other work.
  const Trace rtc = RunMixedGraph();
  ASSERT_EQ(a.callbacks.size() > 0, true);
  bool differs = a.callbacks.size() != rtc.callbacks.size();
  for (size_t i = 0; !differs && i < a.callbacks.size(); ++i) {
    differs = a.callbacks[i].end_s != rtc.callbacks[i].end_s;
  }
  EXPECT_TRUE(differs);
}

// Never more callbacks in progress than executor threads (= cores), nor
// two of one node.
TEST(VirtualExecutorTest, ProcessorSharingRunsOneCallbackPerThread) {
  const Trace trace =
      RunMixedGraph(kMixedCores, DispatchKind::kProcessorSharing);
  for (size_t i = 0; i < trace.callbacks.size(); ++i) {
    const auto& x = trace.callbacks[i];
    EXPECT_GE(x.start_s, x.ready_s);
    EXPECT_GE(x.end_s, x.start_s);
    int running = 1;
    for (size_t j = 0; j < trace.callbacks.size(); ++j) {
      const auto& y = trace.callbacks[j];
      if (i == j || y.start_s > x.start_s || y.end_s <= x.start_s) continue;
      ++running;
      EXPECT_NE(x.node, y.node) << "node overlap at " << x.start_s;
      EXPECT_NE(x.first_core, y.first_core) << "thread shared at " << x.start_s;
    }
    EXPECT_LE(running, kMixedCores) << "at " << x.start_s;
  }
}

}  // namespace
}  // namespace adse::stack
