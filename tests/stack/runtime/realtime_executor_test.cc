// The real-time platform's semantics on small graphs run in real time:
// padding to the profile cost in thread CPU time, timers and overruns,
// keep-last queues, one node's callbacks never overlapping, publications
// held to the end, sinks on the caller's thread, errors and refusals.
// Timing is real, so the checks are bounds that hold under any load (CPU
// time never exceeds wall time), never a measured duration.
#include "stack/runtime/realtime_executor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <ctime>
#include <memory>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "stack/runtime/graph.h"
#include "stack/runtime/trace.h"
#include "tests/stack/runtime/executor_test_util.h"

namespace adse::stack {
namespace {

using test::EventsOf;
using test::Msg;
using test::RecordsOf;

// A flat cost of `cost_s` at 2 GHz for each named callback.
std::shared_ptr<const CostProfile> FlatProfile(
    const std::vector<std::pair<std::string, double>>& costs) {
  auto profile = std::make_shared<CostProfile>();
  profile->reference_ghz = 2.0;
  for (const auto& [name, cost_s] : costs) {
    CallbackCost c;
    c.quantiles = {{0.0, cost_s}, {1.0, cost_s}};
    profile->callbacks[name] = c;
  }
  return profile;
}

RealTimeOptions Options(int cores, double freq_ghz,
                        std::shared_ptr<const CostProfile> profile) {
  RealTimeOptions o;
  o.cores = cores;
  o.freq_ghz = freq_ghz;
  o.profile = std::move(profile);
  return o;
}

std::unique_ptr<Executor> Create(const Graph& graph,
                                 const RealTimeOptions& options) {
  auto made = CreateRealTimeExecutor(&graph, options);
  EXPECT_TRUE(made.ok()) << made.status().ToString();
  return made.ok() ? std::move(made).value() : nullptr;
}

double ProcessCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) +
         1e-9 * static_cast<double>(ts.tv_nsec);
}

// A 100 Hz timer on node "a" publishes to "t"; "b" takes it and publishes
// to "out", which a sink reads. With `threads` > 1, "b" reports itself
// data-parallel on up to that many threads.
struct Chain {
  Graph graph;
  int t = -1, out = -1, timer = -1, sub = -1;
  std::vector<double> sink_times;
  std::vector<std::thread::id> sink_threads;
  explicit Chain(int depth = 1, int threads = 1) {
    t = graph.AddTopic<Msg>("t");
    out = graph.AddTopic<Msg>("out");
    const int a = graph.AddNode("a");
    const int b = graph.AddNode("b");
    timer = graph.AddTimer(a, "tick", 0.01, [this](CallbackContext& ctx) {
      Msg m;
      m.header.stamp_s = ctx.now_s();
      ctx.Publish(t, m);
    });
    sub = graph.Subscribe<Msg>(
        b, t, "work", depth,
        [this, threads](const Msg& m, CallbackContext& ctx) {
          if (threads > 1) {
            ctx.ReportWork({1.0, 1.0, threads});
          }
          Msg o = m;
          ctx.Publish(out, o);
        });
    graph.AddSink<Msg>(out, [this](const Msg&, double t_s) {
      sink_times.push_back(t_s);
      sink_threads.push_back(std::this_thread::get_id());
    });
  }
};

// The process's CPU time over a run of the chain to `until_s`, and the
// records of its "work" callback.
struct ProcessCpuRun {
  double cpu_s = 0.0;
  std::vector<CallbackRecord> work;
};

ProcessCpuRun RunChain(const Chain& chain, const RealTimeOptions& options,
                       double until_s) {
  ProcessCpuRun run;
  auto exec = Create(chain.graph, options);
  if (exec == nullptr) return run;
  const double cpu0 = ProcessCpuSeconds();
  EXPECT_TRUE(exec->AdvanceTo(until_s).ok());
  exec->Stop();
  run.cpu_s = ProcessCpuSeconds() - cpu0;
  run.work = RecordsOf(exec->trace(), chain.sub);
  return run;
}

TEST(RealTimeExecutorTest, EveryCallbackKeepsItsThreadBusyForItsProfileCost) {
  Chain chain;
  // 2 ms at 2 GHz, run at 1 GHz: 4 ms of thread CPU time per message.
  auto exec = Create(
      chain.graph,
      Options(2, 1.0, FlatProfile({{"a/tick", 0.0001}, {"b/work", 0.002}})));
  ASSERT_NE(exec, nullptr);
  ASSERT_TRUE(exec->AdvanceTo(0.5).ok());
  exec->Stop();
  const std::vector<CallbackRecord> work = RecordsOf(exec->trace(), chain.sub);
  ASSERT_GT(work.size(), 3u);
  for (const CallbackRecord& r : work) {
    // Wall time includes the CPU time it was padded to.
    EXPECT_GE(r.cost_s, 0.004 - 1e-5);
    EXPECT_GE(r.start_s, r.ready_s);
    EXPECT_DOUBLE_EQ(r.cost_s, r.end_s - r.start_s);
    EXPECT_LT(r.host_cpu_s, 0.004) << "the real code alone, not the padding";
  }
  // The timer fired every 10 ms of the 500 ms: each fire ran and published
  // once, or was skipped and counted as an overrun.
  const size_t fires = RecordsOf(exec->trace(), chain.timer).size();
  EXPECT_EQ(fires,
            EventsOf(exec->trace(), TopicEvent::kPublish, chain.t).size());
  EXPECT_GE(
      fires + static_cast<size_t>(exec->trace().timer_overruns[chain.timer]),
      45u);
}

TEST(RealTimeExecutorTest, PublicationsLeaveAtTheEndAndSinksRunOnTheCaller) {
  Chain chain;
  auto exec = Create(
      chain.graph,
      Options(1, 2.0, FlatProfile({{"a/tick", 0.0001}, {"b/work", 0.003}})));
  ASSERT_NE(exec, nullptr);
  for (double t = 0.05; t <= 0.3001; t += 0.05) {
    ASSERT_TRUE(exec->AdvanceTo(t).ok());
  }
  exec->Stop();
  ASSERT_FALSE(chain.sink_times.empty());
  EXPECT_TRUE(std::is_sorted(chain.sink_times.begin(), chain.sink_times.end()));
  for (std::thread::id id : chain.sink_threads) {
    EXPECT_EQ(id, std::this_thread::get_id());
  }
  // Each output is published exactly when its callback ended.
  const std::vector<CallbackRecord> work = RecordsOf(exec->trace(), chain.sub);
  std::vector<double> ends;
  for (const CallbackRecord& r : work) ends.push_back(r.end_s);
  for (const TopicEvent& e : exec->trace().topic_events) {
    if (e.kind != TopicEvent::kPublish || e.topic != chain.out) continue;
    EXPECT_EQ(e.callback, chain.sub);
    EXPECT_NE(std::find(ends.begin(), ends.end(), e.t_s), ends.end());
  }
}

TEST(RealTimeExecutorTest, AFullKeepLastQueueDropsItsOldestMessage) {
  Chain chain(/*depth=*/1);
  // 30 ms per message against one every 10 ms: most are dropped.
  auto exec = Create(
      chain.graph,
      Options(2, 2.0, FlatProfile({{"a/tick", 0.0001}, {"b/work", 0.03}})));
  ASSERT_NE(exec, nullptr);
  ASSERT_TRUE(exec->AdvanceTo(0.4).ok());
  exec->Stop();
  const size_t published =
      EventsOf(exec->trace(), TopicEvent::kPublish, chain.t).size();
  const size_t taken =
      EventsOf(exec->trace(), TopicEvent::kTake, chain.t).size();
  const size_t dropped =
      EventsOf(exec->trace(), TopicEvent::kDrop, chain.t).size();
  EXPECT_GT(dropped, 0u);
  EXPECT_LE(taken, 15u) << "at most one per 30 ms of CPU";
  // Every message was taken, dropped, or is the one still queued.
  EXPECT_LE(taken + dropped, published);
  EXPECT_GE(taken + dropped + 1, published);
}

TEST(RealTimeExecutorTest, CallbacksOfOneNodeNeverOverlap) {
  Graph graph;
  const int t = graph.AddTopic<Msg>("t");
  const int a = graph.AddNode("a");
  const int b = graph.AddNode("b");
  graph.AddTimer(a, "tick", 0.005, [t](CallbackContext& ctx) {
    Msg m;
    m.header.stamp_s = ctx.now_s();
    ctx.Publish(t, m);
  });
  const int first = graph.Subscribe<Msg>(b, t, "first", 5,
                                         [](const Msg&, CallbackContext&) {});
  const int second = graph.Subscribe<Msg>(b, t, "second", 5,
                                          [](const Msg&, CallbackContext&) {});
  auto exec = Create(graph, Options(3, 2.0,
                                    FlatProfile({{"a/tick", 0.0001},
                                                 {"b/first", 0.004},
                                                 {"b/second", 0.004}})));
  ASSERT_NE(exec, nullptr);
  // Long enough that both of b's callbacks run several times even on a
  // loaded host (0.6 s once gave the second a single run beside a build).
  ASSERT_TRUE(exec->AdvanceTo(1.5).ok());
  exec->Stop();
  std::vector<CallbackRecord> b_runs = RecordsOf(exec->trace(), first);
  const std::vector<CallbackRecord> more = RecordsOf(exec->trace(), second);
  b_runs.insert(b_runs.end(), more.begin(), more.end());
  ASSERT_GT(more.size(), 1u);
  ASSERT_GT(b_runs.size(), more.size() + 1);
  std::sort(b_runs.begin(), b_runs.end(),
            [](const CallbackRecord& x, const CallbackRecord& y) {
              return x.start_s < y.start_s;
            });
  for (size_t i = 1; i < b_runs.size(); ++i) {
    EXPECT_GE(b_runs[i].start_s, b_runs[i - 1].end_s) << i;
  }
}

// As on the virtual platform: a timer that overruns its period (60 ms of
// work every 25 ms) leaves its node's keep-last subscription a turn after
// at least every second run, however often its queue turned over meanwhile
// (every run when the pose's wait began before the timer's next fire).
TEST(RealTimeExecutorTest,
     AnOverrunningTimerDoesNotStarveItsNodesSubscription) {
  Graph graph;
  const int pose = graph.AddTopic<Msg>("pose");
  const int source = graph.AddNode("source");
  const int node = graph.AddNode("planner");
  graph.AddTimer(source, "tick", 0.005, [pose](CallbackContext& ctx) {
    Msg m;
    m.header.stamp_s = ctx.now_s();
    ctx.Publish(pose, m);
  });
  const int plan = graph.AddTimer(node, "plan", 0.025, [](CallbackContext&) {});
  const int sub = graph.Subscribe<Msg>(node, pose, "pose", 1,
                                       [](const Msg&, CallbackContext&) {});
  auto exec = Create(graph, Options(3, 2.0,
                                    FlatProfile({{"source/tick", 0.0001},
                                                 {"planner/plan", 0.06},
                                                 {"planner/pose", 0.0001}})));
  ASSERT_NE(exec, nullptr);
  ASSERT_TRUE(exec->AdvanceTo(1.0).ok());
  exec->Stop();
  const auto plans = RecordsOf(exec->trace(), plan);
  const auto takes = RecordsOf(exec->trace(), sub);
  ASSERT_GE(plans.size(), 3u);
  // Counted between runs, never timed: a loaded host slows both alike.
  for (size_t i = 0; i + 2 < plans.size(); ++i) {
    EXPECT_TRUE(std::any_of(takes.begin(), takes.end(),
                            [&](const CallbackRecord& r) {
                              return r.start_s >= plans[i].end_s &&
                                     r.start_s <= plans[i + 2].start_s;
                            }))
        << "no pose between plan " << i << " and plan " << i + 2;
  }
}

TEST(RealTimeExecutorTest, AnExternalMessageArrivesWhenItsTimeComes) {
  Graph graph;
  const int t = graph.AddTopic<Msg>("t");
  const int n = graph.AddNode("n");
  const int sub = graph.Subscribe<Msg>(n, t, "take", 1,
                                       [](const Msg&, CallbackContext&) {});
  auto exec = Create(graph, Options(1, 2.0, FlatProfile({{"n/take", 0.001}})));
  ASSERT_NE(exec, nullptr);
  Msg m;
  m.header.stamp_s = 0.1;
  exec->PublishExternal(t, std::make_shared<const Msg>(m), 0.1, 0.1);
  ASSERT_TRUE(exec->AdvanceTo(0.2).ok());
  exec->Stop();
  const std::vector<CallbackRecord> runs = RecordsOf(exec->trace(), sub);
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_GE(runs[0].ready_s, 0.1);
  EXPECT_LT(runs[0].end_s, 0.2);
}

TEST(RealTimeExecutorTest, ACallbackThatThrowsStopsTheRunNamingIt) {
  Graph graph;
  const int n = graph.AddNode("n");
  graph.AddTimer(n, "boom", 0.01, [](CallbackContext&) {
    throw std::runtime_error("bad input");
  });
  auto exec = Create(graph, Options(1, 2.0, FlatProfile({{"n/boom", 0.0001}})));
  ASSERT_NE(exec, nullptr);
  const Status s = exec->AdvanceTo(0.05);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("n/boom"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("bad input"), std::string::npos) << s.message();
}

TEST(RealTimeExecutorTest, RefusesBadOptionsAndUnknownHostCpusByName) {
  Chain chain;
  auto profile = FlatProfile({{"a/tick", 0.0001}, {"b/work", 0.001}});
  struct Case {
    RealTimeOptions options;
    std::string field;
  };
  std::vector<Case> cases;
  cases.push_back({Options(0, 2.0, profile), "cores"});
  cases.push_back({Options(1, 0.0, profile), "freq_ghz"});
  cases.push_back({Options(1, 2.0, nullptr), "profile"});
  Case dilation{Options(1, 2.0, profile), "time_dilation"};
  dilation.options.time_dilation = 0.5;
  cases.push_back(dilation);
  Case twice{Options(1, 2.0, profile), "host_cpus"};
  twice.options.host_cpus = {0, 0};
  cases.push_back(twice);
  for (double share : {0.0, 1.5}) {
    Case c{Options(1, 2.0, profile), "cpu_share"};
    c.options.cpu_share = share;
    cases.push_back(c);
  }
  for (const Case& c : cases) {
    auto made = CreateRealTimeExecutor(&chain.graph, c.options);
    ASSERT_FALSE(made.ok()) << c.field;
    EXPECT_NE(made.status().message().find(c.field), std::string::npos)
        << made.status().message();
  }
  // A profile without an entry for a callback.
  auto partial = CreateRealTimeExecutor(
      &chain.graph, Options(1, 2.0, FlatProfile({{"a/tick", 0.0001}})));
  ASSERT_FALSE(partial.ok());
  EXPECT_NE(partial.status().message().find("b/work"), std::string::npos);
  // A CPU this process may not run on.
  RealTimeOptions absent = Options(1, 2.0, profile);
  absent.host_cpus = {1000};
  auto pinned = CreateRealTimeExecutor(&chain.graph, absent);
  ASSERT_FALSE(pinned.ok());
  EXPECT_EQ(pinned.status().code(), Status::Code::kUnavailable);
  EXPECT_NE(pinned.status().message().find("1000"), std::string::npos);
}

TEST(RealTimeExecutorTest, EveryThreadEntersFirstAndAFailedEntryIsReturned) {
  Chain chain;
  auto profile = FlatProfile({{"a/tick", 0.0001}, {"b/work", 0.001}});
  // Two workers and the clock each enter once, on their own thread.
  std::mutex mu;
  std::set<std::thread::id> entered;
  RealTimeOptions options = Options(2, 2.0, profile);
  options.enter_thread = [&] {
    std::lock_guard<std::mutex> lock(mu);
    entered.insert(std::this_thread::get_id());
    return Status::Ok();
  };
  auto exec = Create(chain.graph, options);
  ASSERT_NE(exec, nullptr);
  {
    std::lock_guard<std::mutex> lock(mu);
    EXPECT_EQ(entered.size(), 3u);
    EXPECT_FALSE(entered.count(std::this_thread::get_id()));
  }
  ASSERT_TRUE(exec->AdvanceTo(0.05).ok());
  exec->Stop();

  // One thread that cannot enter (its cgroup refused it) fails the start.
  std::atomic<int> calls{0};
  options.enter_thread = [&] {
    return ++calls == 2 ? Status::Unavailable("cgroup v1: no room")
                        : Status::Ok();
  };
  auto refused = CreateRealTimeExecutor(&chain.graph, options);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), Status::Code::kUnavailable);
  EXPECT_EQ(refused.status().message(), "cgroup v1: no room");
  EXPECT_EQ(calls.load(), 3);
}

TEST(RealTimeExecutorTest, ACpuShareScalesThePaddingInCpuTime) {
  Chain chain;
  // 2 ms at 2 GHz, run at 1 GHz with a share of 0.5: 2 ms of thread CPU
  // time, which a quota of half a CPU would stretch back to 4 ms of wall.
  RealTimeOptions options =
      Options(1, 1.0, FlatProfile({{"a/tick", 0.0001}, {"b/work", 0.002}}));
  options.cpu_share = 0.5;
  const ProcessCpuRun run = RunChain(chain, options, 0.3);
  const double cpu_s = run.cpu_s;
  const std::vector<CallbackRecord>& work = run.work;
  ASSERT_GT(work.size(), 3u);
  for (const CallbackRecord& r : work) {
    EXPECT_GE(r.cost_s, 0.002 - 1e-5);
  }
  // The process used about 2 ms per message, not the 4 ms of a share of 1
  // (CPU time, which a loaded host cannot inflate; the ticks add 3 ms).
  EXPECT_LT(cpu_s, 0.003 * static_cast<double>(work.size()) + 0.01);
}

TEST(RealTimeExecutorTest,
     ADataParallelCallbackOccupiesItsThreadsForItsWholeCost) {
  Chain chain(/*depth=*/1, /*threads=*/4);
  // 8 ms at 2 GHz, 75 % of it parallel over up to 4 threads, on 2 cores:
  // 2 ms serial, then 3 ms on each of two threads, 8 ms of CPU time in all
  // (an Amdahl time of 5 ms), not the 5 ms of one thread standing for two.
  auto profile = std::make_shared<CostProfile>(
      *FlatProfile({{"a/tick", 0.0001}, {"b/work", 0.008}}));
  CallbackCost& work_cost = profile->callbacks.at("b/work");
  work_cost.parallel_fraction = 0.75;
  work_cost.max_threads = 4;
  const ProcessCpuRun run = RunChain(chain, Options(2, 2.0, profile), 0.3);
  const double cpu_s = run.cpu_s;
  const std::vector<CallbackRecord>& work = run.work;
  ASSERT_GT(work.size(), 3u);
  for (const CallbackRecord& r : work) {
    EXPECT_GE(r.cost_s, 0.005 - 1e-5);
    EXPECT_EQ(r.cores, 2);
  }
  // CPU time a loaded host cannot deflate: at least 8 ms per message.
  EXPECT_GE(cpu_s, 0.008 * static_cast<double>(work.size()) * 0.99);
}

}  // namespace
}  // namespace adse::stack
