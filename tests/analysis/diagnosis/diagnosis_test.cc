#include "analysis/diagnosis/diagnosis.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace adse::analysis {
namespace {

using stack::TopicEvent;

// Builds a synthetic RunData with a known graph and trace.
class TraceBuilder {
 public:
  explicit TraceBuilder(double end_s, int cores = 4) {
    run_.platform["cores"] = std::to_string(cores);
    run_.ego.push_back({0, 0, 0, 0, 0, 0, 0});
    run_.ego.push_back({end_s, 0, 0, 0, 0, 0, 0});
  }

  int Node(const std::string& name) {
    for (size_t i = 0; i < run_.node_names.size(); ++i) {
      if (run_.node_names[i] == name) return static_cast<int>(i);
    }
    run_.node_names.push_back(name);
    return static_cast<int>(run_.node_names.size()) - 1;
  }
  int Topic(const std::string& name) {
    for (size_t i = 0; i < run_.topic_names.size(); ++i) {
      if (run_.topic_names[i] == name) return static_cast<int>(i);
    }
    run_.topic_names.push_back(name);
    return static_cast<int>(run_.topic_names.size()) - 1;
  }
  int Subscription(const std::string& node, const std::string& cb,
                   const std::string& topic) {
    runfile::NamedCallback info;
    info.name = node + "/" + cb;
    info.node = Node(node);
    info.kind = runfile::CallbackKind::kSubscription;
    info.topic = Topic(topic);
    run_.callback_info.push_back(info);
    run_.trace.timer_overruns.push_back(0);
    return static_cast<int>(run_.callback_info.size()) - 1;
  }
  int Timer(const std::string& node, const std::string& cb, double period_s) {
    runfile::NamedCallback info;
    info.name = node + "/" + cb;
    info.node = Node(node);
    info.kind = runfile::CallbackKind::kTimer;
    info.period_s = period_s;
    run_.callback_info.push_back(info);
    run_.trace.timer_overruns.push_back(0);
    return static_cast<int>(run_.callback_info.size()) - 1;
  }

  void Event(TopicEvent::Kind kind, int topic, int callback, double t_s) {
    TopicEvent e;
    e.kind = kind;
    e.topic = topic;
    e.callback = callback;
    e.t_s = t_s;
    e.stamp_s = t_s;
    run_.trace.topic_events.push_back(e);
  }
  // `count` publishes of `topic` by `publisher` (-1: external) at `rate_hz`
  // from `t0_s`.
  void Publishes(int topic, int publisher, double rate_hz, int count,
                 double t0_s = 0.0) {
    for (int i = 0; i < count; ++i) {
      Event(TopicEvent::kPublish, topic, publisher, t0_s + i / rate_hz);
    }
  }
  // `count` takes by `subscriber` at `rate_hz` from `t0_s`, each with a run
  // becoming ready at the take, starting `wait_s` later and costing `cost_s`.
  void Takes(int topic, int subscriber, double rate_hz, int count,
             double cost_s, double wait_s = 0.0, double t0_s = 0.0) {
    for (int i = 0; i < count; ++i) {
      const double t = t0_s + i / rate_hz;
      Event(TopicEvent::kTake, topic, subscriber, t);
      Record(subscriber, t, t + wait_s, cost_s);
    }
  }
  void Record(int callback, double ready_s, double start_s, double cost_s,
              int cores = 1, int first_core = 0) {
    stack::CallbackRecord r;
    r.callback = callback;
    r.node = run_.callback_info[callback].node;
    r.ready_s = ready_s;
    r.start_s = start_s;
    r.cost_s = cost_s;
    r.end_s = start_s + cost_s;
    r.cores = cores;
    r.first_core = first_core;
    run_.trace.callbacks.push_back(r);
  }

  runfile::RunData& run() { return run_; }

 private:
  runfile::RunData run_;
};

const Finding* FindKind(const Diagnosis& d, FindingKind kind) {
  for (const Finding& f : d.findings) {
    if (f.kind == kind) return &f;
  }
  return nullptr;
}

// External 10 Hz topic /in for 10 s, subscribed by node "filter" taking
// `takes` messages at `take_hz`.
runfile::RunData SensorRun(double take_hz, int takes, double cost_s,
                           double wait_s = 0.0) {
  TraceBuilder b(10.0);
  const int in = b.Topic("/in");
  const int sub = b.Subscription("filter", "on_in", "/in");
  b.Publishes(in, -1, 10.0, 100);
  b.Takes(in, sub, take_hz, takes, cost_s, wait_s);
  return b.run();
}

TEST(DiagnosisCpuBoundTest, TopicTakenAtItsRateHasNoFinding) {
  const Diagnosis d = Diagnose(SensorRun(10.0, 100, 0.01));
  EXPECT_NEAR(d.window_s, 10.0, 1e-12);
  EXPECT_TRUE(d.findings.empty());
  ASSERT_EQ(d.topics.size(), 1u);
  EXPECT_EQ(d.topics[0].name, "/in");
  EXPECT_EQ(d.topics[0].publisher, "external");
  EXPECT_EQ(d.topics[0].publishes, 100);
  EXPECT_NEAR(d.topics[0].publish_rate_hz, 10.0, 1e-9);
  ASSERT_EQ(d.topics[0].subscribers.size(), 1u);
  EXPECT_EQ(d.topics[0].subscribers[0].callback, "filter/on_in");
  EXPECT_NEAR(d.topics[0].subscribers[0].take_rate_hz, 10.0, 1e-9);
  EXPECT_EQ(d.topics[0].subscribers[0].drops, 0);
  // Taken every 0.1 s from 0 s: the longest stretch without a take is the
  // last, from the 100th take (at 9.9 s) to the window's end.
  EXPECT_NEAR(d.topics[0].subscribers[0].longest_gap_s, 0.1, 1e-9);
}

TEST(DiagnosisCpuBoundTest, SlowSubscriberIsCpuBoundWithEvidence) {
  // Each run costs 0.2 s of a 0.1 s period: execution alone is too slow.
  const Diagnosis d = Diagnose(SensorRun(4.0, 40, 0.2));
  ASSERT_EQ(d.findings.size(), 1u);
  const Finding& f = d.findings[0];
  EXPECT_EQ(f.kind, FindingKind::kCpuBound);
  EXPECT_EQ(f.origin.kind, RateOriginKind::kNone);  // not frequency_bound
  EXPECT_EQ(f.node, "filter");
  EXPECT_EQ(f.topics, std::vector<std::string>{"/in"});
  EXPECT_EQ(f.upstream, "external");
  EXPECT_NEAR(f.rates_hz.at("publish_hz"), 10.0, 1e-9);
  EXPECT_NEAR(f.rates_hz.at("take_hz"), 4.0, 1e-9);
  EXPECT_NEAR(f.rates_hz.at("deficit"), 0.6, 1e-9);
  EXPECT_NEAR(f.rates_hz.at("allowed_deficit"), 0.3 / 2.0 + 0.05, 1e-12);
  EXPECT_NEAR(f.rates_hz.at("exec_load"), 2.0, 1e-9);
  EXPECT_NEAR(f.rates_hz.at("core_wait_ratio"), 0.0, 1e-12);
  EXPECT_NEAR(f.severity, 0.6, 1e-9);
  // First stage after a sensor: a lower sensor rate also helps.
  EXPECT_EQ(f.remedies,
            (std::vector<Remedy>{{RemedyKind::kHigherFrequency, "filter"},
                                 {RemedyKind::kLowerSensorRate, "/in"}}));
  EXPECT_EQ(f.remedy, "higher frequency; lower sensor rate");
  EXPECT_NE(f.message.find("4.00 Hz of 10.00 Hz"), std::string::npos)
      << f.message;
  EXPECT_NE(f.message.find("0.3/(1+10.00/10)+0.05"), std::string::npos)
      << f.message;
}

TEST(DiagnosisCpuBoundTest, WaitingForACoreSuggestsMoreCores) {
  TraceBuilder b(10.0);
  const int raw = b.Topic("/raw");
  const int mid = b.Topic("/mid");
  const int driver = b.Subscription("driver", "on_raw", "/raw");
  const int sub = b.Subscription("filter", "on_mid", "/mid");
  b.Publishes(raw, -1, 10.0, 100);
  b.Takes(raw, driver, 10.0, 100, 0.001);
  b.Publishes(mid, driver, 10.0, 100);
  // Cheap runs (0.02 s, load 0.2) that wait 0.15 s for a core each.
  b.Takes(mid, sub, 5.0, 50, 0.02, 0.15);
  const Diagnosis d = Diagnose(b.run());
  ASSERT_EQ(d.findings.size(), 1u);
  const Finding& f = d.findings[0];
  EXPECT_EQ(f.node, "filter");
  EXPECT_EQ(f.upstream, "driver");
  EXPECT_NEAR(f.rates_hz.at("exec_load"), 0.2, 1e-9);
  EXPECT_NEAR(f.rates_hz.at("core_wait_ratio"), 7.5, 1e-9);
  EXPECT_EQ(f.remedies,  // not fed by a sensor
            (std::vector<Remedy>{{RemedyKind::kMoreCores, "filter"}}));
  EXPECT_EQ(f.remedy, "more cores");
}

TEST(DiagnosisCpuBoundTest, WaitingForItsOwnNodeIsNotCoreWait) {
  TraceBuilder b(10.0);
  const int in = b.Topic("/in");
  const int sub = b.Subscription("planner", "on_in", "/in");
  const int timer = b.Timer("planner", "on_timer", 1.0);
  b.Publishes(in, -1, 10.0, 100);
  // The node's timer holds it for 0.95 s of every second; the subscription
  // gets in once per second, after waiting the whole timer run.
  for (int i = 0; i < 10; ++i) {
    b.Record(timer, i, i, 0.95);
    b.Event(TopicEvent::kTake, in, sub, i);
    b.Record(sub, i, i + 0.95, 0.01);
  }
  const Diagnosis d = Diagnose(b.run());
  const Finding* f = FindKind(d, FindingKind::kCpuBound);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->node, "planner");
  EXPECT_NEAR(f->rates_hz.at("core_wait_ratio"), 0.0, 1e-9);
  // 0.01 s x 10 Hz + the timer's 0.95 share of the node.
  EXPECT_NEAR(f->rates_hz.at("exec_load"), 1.05, 1e-9);
  EXPECT_EQ(f->remedies,
            (std::vector<Remedy>{{RemedyKind::kHigherFrequency, "planner"},
                                 {RemedyKind::kLowerSensorRate, "/in"}}));
  EXPECT_EQ(f->remedy, "higher frequency; lower sensor rate");
}

TEST(DiagnosisCpuBoundTest, ThresholdTightensWithRate) {
  const DiagnosisOptions o;
  EXPECT_NEAR(AllowedDeficit(o, 1.0), 0.3 / 1.1 + 0.05, 1e-12);
  EXPECT_NEAR(AllowedDeficit(o, 10.0), 0.20, 1e-12);
  EXPECT_NEAR(AllowedDeficit(o, 100.0), 0.3 / 11.0 + 0.05, 1e-12);
  EXPECT_GT(AllowedDeficit(o, 7.0), AllowedDeficit(o, 14.0));

  // The same relative deficit at 100 Hz and at 1 Hz, over 100 s.
  auto run = [](double rate_hz, double deficit) {
    TraceBuilder b(100.0);
    const int in = b.Topic("/in");
    const int sub = b.Subscription("node", "on_in", "/in");
    const int n = static_cast<int>(std::lround(rate_hz * 100.0));
    b.Publishes(in, -1, rate_hz, n);
    const int takes = static_cast<int>(std::lround(n * (1.0 - deficit)));
    b.Takes(in, sub, takes / 100.0, takes, 0.0001);
    return b.run();
  };
  // 10 %: over 7.7 % at 100 Hz, far under 32.3 % at 1 Hz.
  EXPECT_EQ(Diagnose(run(100.0, 0.10)).findings.size(), 1u);
  EXPECT_TRUE(Diagnose(run(1.0, 0.10)).findings.empty());
  // 5 % sits on the default floor (5 %), so it is flagged at 100 Hz only
  // with a lower floor; at 1 Hz it is tolerated either way.
  EXPECT_TRUE(Diagnose(run(100.0, 0.05)).findings.empty());
  DiagnosisOptions strict;
  strict.cpu_bound_floor_fraction = 0.02;
  EXPECT_EQ(Diagnose(run(100.0, 0.05), strict).findings.size(), 1u);
  EXPECT_TRUE(Diagnose(run(1.0, 0.05), strict).findings.empty());
}

TEST(DiagnosisCpuBoundTest, FewMessagesAreIgnored) {
  TraceBuilder b(10.0);
  const int in = b.Topic("/latched");
  b.Subscription("node", "on_latched", "/latched");
  b.Publishes(in, -1, 1.0, 4);  // never taken, but only 4 publishes
  EXPECT_TRUE(Diagnose(b.run()).findings.empty());
  DiagnosisOptions o;
  o.min_messages = 4;
  EXPECT_EQ(Diagnose(b.run(), o).findings.size(), 1u);
}

// Node "filter" turns an external 10 Hz /points into /out and keeps the
// last of an external 50 Hz /pose, taken at `pose_take_hz`.
runfile::RunData StateInputRun(double pose_take_hz) {
  TraceBuilder b(10.0);
  const int points = b.Topic("/points");
  const int out = b.Topic("/out");
  const int pose = b.Topic("/pose");
  const int on_points = b.Subscription("filter", "on_points", "/points");
  const int on_pose = b.Subscription("filter", "on_pose", "/pose");
  b.Publishes(points, -1, 10.0, 100);
  b.Takes(points, on_points, 10.0, 100, 0.05);
  b.Publishes(out, on_points, 10.0, 100, 0.05);
  b.Publishes(pose, -1, 50.0, 500);
  b.Takes(pose, on_pose, pose_take_hz,
          static_cast<int>(std::lround(10.0 * pose_take_hz)), 0.0001);
  return b.run();
}

TEST(DiagnosisCpuBoundTest, StateInputNeedsOneMessagePerOutputOfItsNode) {
  // 15 of 50 poses a second are more than one per output at 10 Hz.
  EXPECT_EQ(FindKind(Diagnose(StateInputRun(15.0)), FindingKind::kCpuBound),
            nullptr);

  // As the rule is stated, against the publish rate: 70 % behind.
  DiagnosisOptions every_message;
  ASSERT_TRUE(
      SetOption(&every_message, "cpu_bound_state_inputs_per_output", 0).ok());
  const Diagnosis d = Diagnose(StateInputRun(15.0), every_message);
  const Finding* f = FindKind(d, FindingKind::kCpuBound);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->topics, std::vector<std::string>{"/pose"});
  EXPECT_NEAR(f->rates_hz.at("deficit"), 0.7, 1e-9);
  EXPECT_EQ(f->rates_hz.count("needed_hz"), 0u);
}

TEST(DiagnosisCpuBoundTest, StateInputTakenLessThanItsNodeOutputsIsFlagged) {
  // 5 poses a second for 10 outputs: half of them use a stale pose.
  const Diagnosis d = Diagnose(StateInputRun(5.0));
  const Finding* found = FindKind(d, FindingKind::kCpuBound);
  ASSERT_NE(found, nullptr);
  const Finding& f = *found;
  EXPECT_EQ(f.node, "filter");
  EXPECT_EQ(f.topics, std::vector<std::string>{"/pose"});
  EXPECT_NEAR(f.rates_hz.at("publish_hz"), 50.0, 1e-9);
  EXPECT_NEAR(f.rates_hz.at("needed_hz"), 10.0, 1e-9);
  EXPECT_NEAR(f.rates_hz.at("deficit"), 0.5, 1e-9);
  EXPECT_NEAR(f.rates_hz.at("allowed_deficit"), 0.3 / 2.0 + 0.05, 1e-12);
  EXPECT_NE(f.message.find("needing 10.00 Hz (a state input"),
            std::string::npos)
      << f.message;
}

// Node "fusion" takes every message of inputs at the given rates (10 s).
runfile::RunData FusionRun(const std::vector<double>& rates_hz) {
  TraceBuilder b(10.0);
  for (size_t i = 0; i < rates_hz.size(); ++i) {
    const std::string name = "/in" + std::to_string(i);
    const int topic = b.Topic(name);
    const int pub =
        b.Timer("pub" + std::to_string(i), "on_timer", 1.0 / rates_hz[i]);
    const int sub = b.Subscription("fusion", "on_in" + std::to_string(i), name);
    const int n = static_cast<int>(std::lround(rates_hz[i] * 10.0));
    b.Publishes(topic, pub, rates_hz[i], n);
    b.Takes(topic, sub, rates_hz[i], n, 0.001);
  }
  return b.run();
}

TEST(DiagnosisFrequencyBoundTest, SlowInputIsNamedWithItsPublisher) {
  const Diagnosis d = Diagnose(FusionRun({20.0, 10.0}));
  ASSERT_EQ(d.findings.size(), 1u);
  const Finding& f = d.findings[0];
  EXPECT_EQ(f.kind, FindingKind::kFrequencyBound);
  EXPECT_EQ(f.node, "fusion");
  EXPECT_EQ(f.topics, std::vector<std::string>{"/in1"});
  EXPECT_EQ(f.upstream, "pub1");
  EXPECT_NEAR(f.rates_hz.at("slowest_hz"), 10.0, 1e-9);
  EXPECT_NEAR(f.rates_hz.at("others_median_hz"), 20.0, 1e-9);
  EXPECT_NEAR(f.rates_hz.at("input_hz:/in0"), 20.0, 1e-9);
  EXPECT_NEAR(f.rates_hz.at("deficit"), 0.5, 1e-9);
  EXPECT_NEAR(f.severity, 0.5, 1e-9);
  EXPECT_EQ(f.origin.kind, RateOriginKind::kTimer);
  EXPECT_EQ(f.origin.where, "pub1/on_timer");
  EXPECT_NEAR(f.origin.rate_hz, 10.0, 1e-9);
  EXPECT_NEAR(f.rates_hz.at("origin_hz"), 10.0, 1e-9);
  EXPECT_EQ(f.remedies,
            (std::vector<Remedy>{
                {RemedyKind::kRaisePublisherRate, "/in1", "pub1"},
                {RemedyKind::kShortenTimerPeriod, "pub1/on_timer"}}));
  EXPECT_EQ(f.remedy,
            "raise the rate of /in1's publisher (pub1); shorten the period of "
            "pub1/on_timer");
  EXPECT_NE(f.message.find("configuration choice"), std::string::npos)
      << f.message;
}

TEST(DiagnosisFrequencyBoundTest, MedianOfTheOtherInputs) {
  const Diagnosis d = Diagnose(FusionRun({20.0, 30.0, 10.0}));
  ASSERT_EQ(d.findings.size(), 1u);
  EXPECT_EQ(d.findings[0].topics[0], "/in2");
  EXPECT_NEAR(d.findings[0].rates_hz.at("others_median_hz"), 25.0, 1e-9);
}

TEST(DiagnosisFrequencyBoundTest, CloseRatesAndLatchedInputsAreFine) {
  EXPECT_TRUE(Diagnose(FusionRun({20.0, 19.0})).findings.empty());  // 5 %
  EXPECT_TRUE(Diagnose(FusionRun({20.0, 0.4})).findings.empty());   // 4 msgs
  EXPECT_TRUE(Diagnose(FusionRun({20.0})).findings.empty());
  DiagnosisOptions o;
  o.frequency_bound_fraction = 0.04;
  EXPECT_EQ(Diagnose(FusionRun({20.0, 19.0}), o).findings.size(), 1u);
}

TEST(DiagnosisFrequencyBoundTest, UpstreamCpuBoundIsNamedAsTheCause) {
  // sensor (10 Hz) -> slow (takes 5 Hz, publishes 5 Hz) -> /mid -> fusion,
  // which also takes a 10 Hz external topic.
  TraceBuilder b(10.0);
  const int raw = b.Topic("/raw");
  const int mid = b.Topic("/mid");
  const int odom = b.Topic("/odom");
  const int slow = b.Subscription("slow", "on_raw", "/raw");
  const int f_mid = b.Subscription("fusion", "on_mid", "/mid");
  const int f_odom = b.Subscription("fusion", "on_odom", "/odom");
  b.Publishes(raw, -1, 10.0, 100);
  b.Takes(raw, slow, 5.0, 50, 0.2);
  b.Publishes(mid, slow, 5.0, 50, 0.1);
  b.Takes(mid, f_mid, 5.0, 50, 0.001, 0.0, 0.1);
  b.Publishes(odom, -1, 10.0, 100);
  b.Takes(odom, f_odom, 10.0, 100, 0.001);
  const Diagnosis d = Diagnose(b.run());
  ASSERT_EQ(d.findings.size(), 2u);
  // Equal severity (0.5): cpu_bound sorts before frequency_bound.
  EXPECT_EQ(d.findings[0].kind, FindingKind::kCpuBound);
  EXPECT_EQ(d.findings[0].node, "slow");
  EXPECT_EQ(d.findings[1].kind, FindingKind::kFrequencyBound);
  EXPECT_EQ(d.findings[1].node, "fusion");
  EXPECT_EQ(d.findings[1].upstream, "slow");
  EXPECT_EQ(d.findings[1].origin.kind, RateOriginKind::kCpuBound);
  EXPECT_EQ(d.findings[1].origin.where, "slow");
  EXPECT_NE(d.findings[1].message.find("upstream limit: slow is cpu_bound"),
            std::string::npos)
      << d.findings[1].message;
  EXPECT_EQ(d.findings[0].remedies,
            (std::vector<Remedy>{{RemedyKind::kHigherFrequency, "slow"},
                                 {RemedyKind::kLowerSensorRate, "/raw"}}));
  EXPECT_EQ(
      d.findings[1].remedies,
      (std::vector<Remedy>{{RemedyKind::kRaisePublisherRate, "/mid", "slow"},
                           {RemedyKind::kRelieveNode, "slow"}}));
  EXPECT_EQ(d.findings[1].remedy,
            "raise the rate of /mid's publisher (slow); relieve slow "
            "(cpu_bound)");
}

// sensor /raw (7 Hz) -> driver -> /points -> cluster -> /objects -> planner,
// which also caches a 50 Hz /pose from a timer. Nothing is cpu_bound.
runfile::RunData PipelineRun() {
  TraceBuilder b(10.0);
  const int raw = b.Topic("/raw");
  const int points = b.Topic("/points");
  const int objects = b.Topic("/objects");
  const int pose = b.Topic("/pose");
  const int plan_out = b.Topic("/plan");
  const int driver = b.Subscription("driver", "on_raw", "/raw");
  const int cluster = b.Subscription("cluster", "on_points", "/points");
  const int on_objects = b.Subscription("planner", "on_objects", "/objects");
  const int on_pose = b.Subscription("planner", "on_pose", "/pose");
  const int ekf = b.Timer("ekf", "publish", 0.02);
  b.Publishes(raw, -1, 7.0, 70);
  b.Takes(raw, driver, 7.0, 70, 0.001);
  b.Publishes(points, driver, 7.0, 70, 0.001);
  b.Takes(points, cluster, 7.0, 70, 0.001, 0.0, 0.001);
  b.Publishes(objects, cluster, 7.0, 70, 0.002);
  b.Takes(objects, on_objects, 7.0, 70, 0.001, 0.0, 0.002);
  b.Publishes(plan_out, on_objects, 7.0, 70, 0.003);
  b.Publishes(pose, ekf, 50.0, 500);
  b.Takes(pose, on_pose, 50.0, 500, 0.0001);
  return b.run();
}

TEST(DiagnosisFrequencyBoundTest, OriginIsTracedUpstreamToTheSensor) {
  const Diagnosis d = Diagnose(PipelineRun());
  ASSERT_EQ(d.findings.size(), 1u);
  const Finding& f = d.findings[0];
  EXPECT_EQ(f.kind, FindingKind::kFrequencyBound);
  EXPECT_EQ(f.node, "planner");
  EXPECT_EQ(f.topics[0], "/objects");
  EXPECT_EQ(f.upstream, "cluster");
  EXPECT_EQ(f.origin.kind, RateOriginKind::kSensor);
  EXPECT_EQ(f.origin.where, "/raw");
  EXPECT_NEAR(f.origin.rate_hz, 7.0, 1e-9);
  EXPECT_NEAR(f.rates_hz.at("origin_hz"), 7.0, 1e-9);
  EXPECT_EQ(f.remedies,
            (std::vector<Remedy>{
                {RemedyKind::kRaisePublisherRate, "/objects", "cluster"},
                {RemedyKind::kRaiseSensorRate, "/raw"}}));
  EXPECT_EQ(f.remedy,
            "raise the rate of /objects's publisher (cluster); raise the rate "
            "of sensor /raw");
}

TEST(DiagnosisFrequencyBoundTest, AnOriginThatLoopsBackIsUnknown) {
  // fusion takes /fast (20 Hz, from a timer) and /loop (10 Hz), which echo
  // publishes from /back, which relay publishes from /loop: followed
  // upstream, the chain comes back to /loop without a sensor, timer or
  // cpu_bound node.
  TraceBuilder b(10.0);
  const int fast = b.Topic("/fast");
  const int loop = b.Topic("/loop");
  const int back = b.Topic("/back");
  const int timer = b.Timer("pub", "on_timer", 0.05);
  const int on_fast = b.Subscription("fusion", "on_fast", "/fast");
  const int on_loop = b.Subscription("fusion", "on_loop", "/loop");
  const int echo = b.Subscription("echo", "on_back", "/back");
  const int relay = b.Subscription("relay", "on_loop", "/loop");
  b.Publishes(fast, timer, 20.0, 200);
  b.Takes(fast, on_fast, 20.0, 200, 0.001);
  b.Publishes(loop, echo, 10.0, 100);
  b.Takes(loop, on_loop, 10.0, 100, 0.001);
  b.Takes(loop, relay, 10.0, 100, 0.001);
  b.Publishes(back, relay, 10.0, 100);
  b.Takes(back, echo, 10.0, 100, 0.001);
  const Diagnosis d = Diagnose(b.run());
  ASSERT_EQ(d.findings.size(), 1u);
  const Finding& f = d.findings[0];
  EXPECT_EQ(f.kind, FindingKind::kFrequencyBound);
  EXPECT_EQ(f.node, "fusion");
  EXPECT_EQ(f.topics, std::vector<std::string>{"/loop"});
  EXPECT_EQ(f.origin.kind, RateOriginKind::kUnknown);
  EXPECT_EQ(f.origin.where, "");
  EXPECT_EQ(f.rates_hz.count("origin_hz"), 0u);
  // Only the publisher's remedy: nothing upstream to name.
  EXPECT_EQ(f.remedies, (std::vector<Remedy>{{RemedyKind::kRaisePublisherRate,
                                              "/loop", "echo"}}));
  EXPECT_NE(f.message.find("its origin is unknown"), std::string::npos)
      << f.message;
}

TEST(DiagnosisFrequencyBoundTest, DrivingInputsOnlyIgnoresCachedState) {
  DiagnosisOptions o;
  ASSERT_TRUE(SetOption(&o, "frequency_bound_driving_inputs_only", 1).ok());
  // The planner's /pose callback publishes nothing: one driving input left.
  EXPECT_TRUE(Diagnose(PipelineRun(), o).findings.empty());
  EXPECT_FALSE(SetOption(&o, "frequency_bound_driving_inputs_only", 0.5).ok());
}

// Node "planner": a 50 Hz pose it keeps (taken at once until `stall_s`),
// and a 0.5 s planning timer whose runs cost 1 s from `stall_s` on, back
// to back (`busy_share` of the time; 1: without a gap), to `end_s`; the
// poses that come meanwhile are dropped unread.
runfile::RunData PlannerRun(double stall_s, double end_s,
                            double busy_share = 1.0) {
  TraceBuilder b(end_s, /*cores=*/16);
  const int pose = b.Topic("/pose");
  const int sub = b.Subscription("planner", "pose", "/pose");
  const int plan = b.Timer("planner", "plan", 0.5);
  const int n = static_cast<int>(50.0 * end_s);
  b.Publishes(pose, -1, 50.0, n);
  b.Takes(pose, sub, 50.0, static_cast<int>(50.0 * stall_s), 0.0001);
  for (int i = static_cast<int>(50.0 * stall_s); i < n; ++i) {
    b.Event(TopicEvent::kDrop, pose, sub, i / 50.0);
  }
  int runs = 0;
  for (double t = stall_s; t + 1.0 <= end_s + 1e-9; t += 1.0 / busy_share) {
    b.Record(plan, t, t, 1.0);
    ++runs;
  }
  b.run().trace.timer_overruns[plan] = runs;
  return b.run();
}

TEST(DiagnosisStarvedInputTest, ATimerRunningBackToBackStarvesItsNodesInput) {
  const Diagnosis d = Diagnose(PlannerRun(20.0, 60.0));
  const Finding* f = FindKind(d, FindingKind::kStarvedInput);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->node, "planner");
  EXPECT_EQ(f->topics, std::vector<std::string>{"/pose"});
  EXPECT_EQ(f->upstream, "external");
  EXPECT_NEAR(f->rates_hz.at("starved_s"), 40.0, 0.05);
  EXPECT_NEAR(f->rates_hz.at("from_s"), 20.0, 0.05);
  // The topic's statistics show the stretch too (the LLM text agent reads
  // them): from the last take, at 19.98 s, to the end.
  ASSERT_EQ(d.topics.size(), 1u);
  ASSERT_EQ(d.topics[0].subscribers.size(), 1u);
  EXPECT_NEAR(d.topics[0].subscribers[0].longest_gap_s, 40.02, 1e-6);
  EXPECT_NEAR(f->rates_hz.at("node_busy_share"), 1.0, 0.01);
  EXPECT_EQ(f->rates_hz.at("dropped"), 2000.0);
  EXPECT_EQ(f->rates_hz.at("holder_timer_overruns"), 40.0);
  EXPECT_NEAR(f->severity, 40.0 / 60.0, 0.01);
  ASSERT_EQ(f->remedies.size(), 1u);
  EXPECT_EQ(f->remedies[0],
            (Remedy{RemedyKind::kOwnCallbackGroup, "planner/pose"}));
  EXPECT_EQ(f->remedy, "give planner/pose a callback group of its own");
  EXPECT_NE(f->message.find("planner/pose took no message of /pose for 40.0 "
                            "s from 20.0 s while its node ran its other "
                            "callbacks 100% of that time (mostly "
                            "planner/plan, a timer that skipped 40 fires in "
                            "the run, each due while the one before still "
                            "waited)"),
            std::string::npos)
      << f->message;
}

// Waiting while the node is idle is waiting for a core: a starved
// computer, which cpu_bound names, not a starved input.
TEST(DiagnosisStarvedInputTest, AnInputWaitingWhileItsNodeIsIdleIsNotStarved) {
  EXPECT_EQ(FindKind(Diagnose(PlannerRun(20.0, 60.0, /*busy_share=*/0.5)),
                     FindingKind::kStarvedInput),
            nullptr);
  // 4 s of planning back to back: under starved_input_min_s.
  EXPECT_EQ(
      FindKind(Diagnose(PlannerRun(56.0, 60.0)), FindingKind::kStarvedInput),
      nullptr);
  DiagnosisOptions shorter;
  ASSERT_TRUE(SetOption(&shorter, "starved_input_min_s", 3.0).ok());
  EXPECT_NE(FindKind(Diagnose(PlannerRun(56.0, 60.0), shorter),
                     FindingKind::kStarvedInput),
            nullptr);
  // With no share asked for, a node that ran nothing still starves nothing.
  runfile::RunData idle = PlannerRun(20.0, 60.0);
  std::erase_if(idle.trace.callbacks, [](const stack::CallbackRecord& r) {
    return r.start_s >= 20.0;
  });
  ASSERT_TRUE(SetOption(&shorter, "starved_input_busy_share", 0.0).ok());
  EXPECT_EQ(FindKind(Diagnose(idle, shorter), FindingKind::kStarvedInput),
            nullptr);
}

TEST(DiagnosisStatsTest, CallbackAndCoreUtilization) {
  TraceBuilder b(10.0, 4);
  const int a = b.Timer("a", "tick", 1.0);
  const int bb = b.Timer("b", "tick", 1.0);
  const int c = b.Timer("c", "tick", 1.0);
  b.Record(a, 0.0, 0.0, 1.0, 1, 0);   // core 0, [0, 1]
  b.Record(bb, 0.5, 0.5, 2.0, 1, 1);  // core 1, [0.5, 2.5]
  // At t = 1 the lowest free cores are 0 and 2: the executor's choice, which
  // a contiguous 0..1 reading would get wrong.
  b.Record(c, 1.0, 1.0, 2.0, 2, 0);  // cores 0 and 2, [1, 3]
  b.run().trace.timer_overruns[c] = 3;
  const Diagnosis d = Diagnose(b.run());
  ASSERT_EQ(d.callbacks.size(), 3u);
  EXPECT_EQ(d.callbacks[0].name, "a/tick");
  EXPECT_EQ(d.callbacks[0].node, "a");
  EXPECT_NEAR(d.callbacks[0].utilization, 0.1, 1e-12);
  EXPECT_NEAR(d.callbacks[1].utilization, 0.2, 1e-12);
  EXPECT_NEAR(d.callbacks[2].utilization, 0.4, 1e-12);  // 2 cores x 2 s
  EXPECT_EQ(d.callbacks[2].timer_overruns, 3);
  ASSERT_EQ(d.core_utilization.size(), 4u);
  EXPECT_NEAR(d.core_utilization[0], 0.3, 1e-12);
  EXPECT_NEAR(d.core_utilization[1], 0.2, 1e-12);
  EXPECT_NEAR(d.core_utilization[2], 0.2, 1e-12);
  EXPECT_NEAR(d.core_utilization[3], 0.0, 1e-12);

  // A record the replay cannot explain (core 0 was free) falls back to the
  // recorded contiguous range 3..3.
  b.Record(a, 5.0, 5.0, 1.0, 1, 3);
  const Diagnosis d2 = Diagnose(b.run());
  EXPECT_NEAR(d2.core_utilization[0], 0.3, 1e-12);
  EXPECT_NEAR(d2.core_utilization[3], 0.1, 1e-12);

  // A team of two started from the last executor thread (processor
  // sharing, real time) wraps round to core 0: no fifth core appears.
  b.Record(c, 6.0, 6.0, 1.0, 2, 3);
  const Diagnosis d3 = Diagnose(b.run());
  ASSERT_EQ(d3.core_utilization.size(), 4u);
  EXPECT_NEAR(d3.core_utilization[0], 0.4, 1e-12);
  EXPECT_NEAR(d3.core_utilization[3], 0.2, 1e-12);
}

TEST(DiagnosisStatsTest, LatencyPercentiles) {
  TraceBuilder b(200.0);
  const int cb = b.Timer("n", "tick", 1.0);
  // Latencies 0.00 .. 1.00 s in steps of 0.01, half of each waiting.
  for (int i = 0; i <= 100; ++i) {
    const double latency = 0.01 * ((i * 37) % 101);  // shuffled
    b.Record(cb, i, i + latency / 2, latency / 2);
  }
  for (int i = 0; i <= 100; ++i) {
    b.run().controls.push_back({i + 0.5, i + 0.5 - 0.001 * i, 0.0, 0.0});
  }
  b.run().controls.push_back({150.0, -1.0, 0.0, 0.0});  // no sensor stamp
  const Diagnosis d = Diagnose(b.run());
  const CallbackStats& s = d.callbacks[0];
  EXPECT_EQ(s.runs, 101);
  EXPECT_NEAR(s.latency_p50_s, 0.50, 1e-9);
  EXPECT_NEAR(s.latency_p99_s, 0.99, 1e-9);
  EXPECT_NEAR(s.latency_max_s, 1.00, 1e-9);
  EXPECT_NEAR(s.exec_p50_s, 0.25, 1e-9);
  EXPECT_NEAR(d.e2e_latency_p50_s, 0.050, 1e-9);
  EXPECT_NEAR(d.e2e_latency_p99_s, 0.099, 1e-9);

  // A callback that never ran has NaN statistics, not garbage.
  b.Timer("idle", "tick", 1.0);
  const Diagnosis d2 = Diagnose(b.run());
  EXPECT_EQ(d2.callbacks[1].runs, 0);
  EXPECT_TRUE(std::isnan(d2.callbacks[1].latency_p50_s));
  EXPECT_EQ(d2.callbacks[1].utilization, 0.0);
}

TEST(DiagnosisOptionsTest, SetOptionByName) {
  DiagnosisOptions o;
  EXPECT_TRUE(SetOption(&o, "cpu_bound_tighten_hz", 20.0).ok());
  EXPECT_EQ(o.cpu_bound_tighten_hz, 20.0);
  EXPECT_TRUE(SetOption(&o, "frequency_bound_fraction", 0.2).ok());
  EXPECT_EQ(o.frequency_bound_fraction, 0.2);
  EXPECT_TRUE(SetOption(&o, "end_s", -1.0).ok());
  for (const std::string& name : DiagnosisOptionNames()) {
    const bool flag = name == "frequency_bound_driving_inputs_only" ||
                      name == "cpu_bound_state_inputs_per_output";
    const double v = flag || name == "min_messages" ? 1 : 0.5;
    EXPECT_TRUE(SetOption(&o, name, v).ok()) << name;
  }

  const Status unknown = SetOption(&o, "cpu_bound_fraction", 0.1);
  EXPECT_EQ(unknown.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(unknown.message().find("cpu_bound_base_fraction"),
            std::string::npos);
  EXPECT_NE(unknown.message().find("min_messages"), std::string::npos);

  DiagnosisOptions before;
  DiagnosisOptions after;
  EXPECT_FALSE(SetOption(&after, "cpu_bound_tighten_hz", 0.0).ok());
  EXPECT_FALSE(SetOption(&after, "min_messages", -1.0).ok());
  const Status fraction = SetOption(&after, "min_messages", 1.5);
  EXPECT_FALSE(fraction.ok());
  EXPECT_NE(fraction.message().find("a whole number >= 0"), std::string::npos)
      << fraction.message();
  EXPECT_FALSE(SetOption(&after, "frequency_bound_fraction", 1.0).ok());
  EXPECT_FALSE(SetOption(&after, "start_s", std::nan("")).ok());
  EXPECT_EQ(after.cpu_bound_tighten_hz, before.cpu_bound_tighten_hz);
  EXPECT_EQ(after.min_messages, before.min_messages);
}

TEST(DiagnosisWindowTest, FindingsAndRatesFollowTheWindow) {
  // 20 s at 10 Hz: taken in full for 10 s, then only at 4 Hz.
  TraceBuilder b(20.0);
  const int in = b.Topic("/in");
  const int sub = b.Subscription("filter", "on_in", "/in");
  b.Publishes(in, -1, 10.0, 200);
  b.Takes(in, sub, 10.0, 100, 0.01);
  b.Takes(in, sub, 4.0, 40, 0.2, 0.0, 10.0);

  const Diagnosis whole = Diagnose(b.run());  // 7 Hz of 10: 30 % > 20 %
  ASSERT_EQ(whole.findings.size(), 1u);
  EXPECT_NEAR(whole.findings[0].rates_hz.at("take_hz"), 7.0, 1e-9);

  DiagnosisOptions first;
  first.end_s = 10.0;
  const Diagnosis d1 = Diagnose(b.run(), first);
  EXPECT_NEAR(d1.window_s, 10.0, 1e-12);
  EXPECT_TRUE(d1.findings.empty());
  EXPECT_EQ(d1.topics[0].publishes, 100);

  DiagnosisOptions second;
  second.start_s = 10.0;
  second.end_s = 50.0;  // clamped to the run's end
  const Diagnosis d2 = Diagnose(b.run(), second);
  EXPECT_NEAR(d2.window_start_s, 10.0, 1e-12);
  EXPECT_NEAR(d2.window_s, 10.0, 1e-12);
  ASSERT_EQ(d2.findings.size(), 1u);
  EXPECT_NEAR(d2.findings[0].rates_hz.at("take_hz"), 4.0, 1e-9);
  EXPECT_NEAR(d2.callbacks[0].exec_p50_s, 0.2, 1e-12);
  EXPECT_EQ(d2.callbacks[0].runs, 40);

  DiagnosisOptions empty;
  empty.start_s = 30.0;
  const Diagnosis d3 = Diagnose(b.run(), empty);
  EXPECT_EQ(d3.window_s, 0.0);
  EXPECT_TRUE(d3.findings.empty());
}

TEST(DiagnosisOrderTest, SeverityOrderAndDeterminism) {
  TraceBuilder b(10.0);
  const int t1 = b.Topic("/a");
  const int t2 = b.Topic("/b");
  const int s1 = b.Subscription("mild", "on_a", "/a");
  const int s2 = b.Subscription("severe", "on_b", "/b");
  b.Publishes(t1, -1, 10.0, 100);
  b.Takes(t1, s1, 7.0, 70, 0.05);
  b.Publishes(t2, -1, 10.0, 100);
  b.Takes(t2, s2, 2.0, 20, 0.5);
  const Diagnosis d = Diagnose(b.run());
  ASSERT_EQ(d.findings.size(), 2u);
  EXPECT_EQ(d.findings[0].node, "severe");
  EXPECT_EQ(d.findings[1].node, "mild");
  const Diagnosis again = Diagnose(b.run());
  for (size_t i = 0; i < d.findings.size(); ++i) {
    EXPECT_EQ(again.findings[i].message, d.findings[i].message);
    EXPECT_EQ(again.findings[i].rates_hz, d.findings[i].rates_hz);
  }
}

TEST(DiagnosisRobustnessTest, MalformedAndEmptyRunsDoNotThrow) {
  runfile::RunData empty;
  const Diagnosis d0 = Diagnose(empty);
  EXPECT_EQ(d0.window_s, 0.0);
  EXPECT_TRUE(d0.findings.empty());
  EXPECT_TRUE(std::isnan(d0.e2e_latency_p50_s));

  TraceBuilder b(10.0);
  const int in = b.Topic("/in");
  const int sub = b.Subscription("n", "on_in", "/in");
  b.Publishes(in, 7, 10.0, 100);  // publisher index out of range
  b.Event(TopicEvent::kTake, 42, sub, 1.0);
  b.Event(TopicEvent::kTake, in, -3, 1.0);
  b.Record(sub, 0.0, 0.0, 0.01);
  b.run().trace.callbacks.back().callback = 99;
  b.run().trace.callbacks.back().first_core = -1;
  b.run().callback_info.push_back(
      {"orphan/cb", 17, runfile::CallbackKind::kSubscription, 55, 0.0});
  b.run().platform["cores"] = "lots";
  const Diagnosis d = Diagnose(b.run());
  EXPECT_EQ(d.callbacks.size(), 2u);
  EXPECT_EQ(d.callbacks[1].node, "orphan");
  EXPECT_EQ(d.topics[0].publisher, "");
  ASSERT_EQ(d.findings.size(), 1u);  // never taken
  EXPECT_EQ(d.findings[0].remedies,
            (std::vector<Remedy>{{RemedyKind::kMoreCores, "n"}}));
  EXPECT_EQ(d.findings[0].remedy, "more cores");
  EXPECT_EQ(d.findings[0].rates_hz.count("core_wait_ratio"), 0u);
}

}  // namespace
}  // namespace adse::analysis
