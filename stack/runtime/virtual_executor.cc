// The `virtual` platform: a discrete-event simulation of N cores at f GHz
// that runs a Graph's real callback code on the host thread and charges each
// callback a simulated cost.
//
// Semantics (the contract the tests check):
// - One simulated clock, starting at 0. Events: callback completion, external
//   arrival (PublishExternal) and timer fire. Events at equal times are
//   applied completions first, then arrivals, then timer fires, each kind in
//   insertion order; after every event at a time is applied, dispatch runs.
// - Each published message goes to every subscription of its topic. A
//   subscription keeps the last `queue_depth` messages; a full queue drops its
//   oldest (kDrop). Sinks are called synchronously at publish time, free.
// - Readiness: a subscription is ready when its queue is non-empty and it is
//   not running; its ready time is when its queue last went from empty to
//   holding a message, or, after a take that left messages, the arrival of
//   the oldest of them. A message the keep-last queue pushes out leaves its
//   wait to the newer one: otherwise a busy node's overdue timer would
//   always be older than a depth-1 subscription's newest message and
//   starve it, which rclcpp's executor, serving every handle of one wait
//   round before waiting again, does not. A timer is ready when it fired and
//   that fire has not started; a fire arriving while an earlier fire still
//   waits is skipped and counted in Trace::timer_overruns (ROS 2 timers do not
//   queue missed periods). A running timer that fires waits for its end.
// - Callbacks of one node exclude each other (ROS 2's default mutually
//   exclusive callback group).
// - Dispatch: while a core is free, start the ready callback (whose node is
//   idle) with the earliest ready time, ties to the lower callback index.
//   Non-preemptive (kRunToCompletion; with kProcessorSharing "core" reads
//   "executor thread", one per core, see below). A subscription takes its
//   OLDEST queued message (kTake). The real code runs at once; it sees now_s()
//   = start; its publications are held until its end.
// - Cost: base = host thread CPU time (kMeasured) or fixed + per_unit * units
//   (kCounted; host_cpu_s is then recorded as 0 unless
//   record_host_cpu_when_counted); k = min(max_threads, free cores at start)
//   cores are held to the end; cost = base * (1 - p + p / k) * reference_ghz /
//   freq_ghz * cost_scale, at least 1 us. With a cost profile (kCounted),
//   base = a draw from the callback's quantiles (u from the seeded stream of
//   this callback and invocation) * units / reference_units (when > 0); p
//   comes from the profile, max_threads is the smaller of the profile's and
//   the report's; the frequency factor is
//   (profile reference_ghz / freq_ghz)^freq_exponent * cost_scale. At start +
//   cost the cores are freed, held publications are released in order
//   (kPublish, per-topic seq from 0) and the CallbackRecord is appended
//   (records are in completion order).
// - kProcessorSharing: a started callback holds one executor thread; its
//   cost is base * factor as above, of which the serial part (1 - p) runs on
//   that thread and the parallel part p on k = min(max_threads, cores)
//   threads, base * p * factor / k each, whether or not cores are free. The
//   cores are shared equally among the threads with work
//   (internal/processor_sharing.h), so the end is known only when it comes;
//   CallbackRecord::cost_s is then end - start, cores k, first_core the
//   executor thread. On one core both dispatches give the same trace.
// - AdvanceTo(t) applies events strictly before t, then sets now = t.
// - Errors (a callback or sink throws, a bad topic) are sticky: AdvanceTo
//   returns the same Status from then on.
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "stack/base/platform_limits.h"
#include "stack/base/random.h"
#include "stack/runtime/executor.h"
#include "stack/runtime/internal/executor_parts.h"
#include "stack/runtime/internal/processor_sharing.h"

namespace adse::stack {
namespace {

using internal::HeldPublication;
using internal::QueuedMessage;
using internal::ThreadCpuSeconds;

// Nothing is instantaneous: keeps the clock moving and ends after starts.
constexpr double kMinCostS = 1e-6;
// PublishExternal slightly in the past (rounding in the caller's time
// arithmetic) is moved to now; further back is a caller bug.
constexpr double kPastToleranceS = 1e-9;

bool IsFinitePositive(double v) { return std::isfinite(v) && v > 0.0; }

Status ValidateCountedCost(const CountedCost& cost, const std::string& field) {
  if (!std::isfinite(cost.fixed_s) || cost.fixed_s < 0.0) {
    return Status::InvalidArgument(fmt::format(
        "{}.fixed_s must be finite and >= 0, got {}", field, cost.fixed_s));
  }
  if (!std::isfinite(cost.per_unit_s) || cost.per_unit_s < 0.0) {
    return Status::InvalidArgument(
        fmt::format("{}.per_unit_s must be finite and >= 0, got {}", field,
                    cost.per_unit_s));
  }
  return Status::Ok();
}

// Event kinds double as the tie-break rank at equal times.
enum EventKind : uint64_t { kCompletion = 0, kArrival = 1, kTimerFire = 2 };
constexpr int kKindShift = 62;

struct Event {
  double t;
  uint64_t key;   // kind << 62 | insertion sequence
  int32_t index;  // completion, timer: callback; arrival: slot in arrivals_;
                  // kSharedEnd: a part ends under processor sharing
};
constexpr int32_t kSharedEnd = -1;

// std::push_heap builds a max-heap; this order puts the earliest on top.
struct EventLater {
  bool operator()(const Event& a, const Event& b) const {
    if (a.t != b.t) return a.t > b.t;
    return a.key > b.key;
  }
};

struct Arrival {
  int32_t topic = -1;
  MessagePtr message;
  double stamp_s = 0.0;
};

struct CallbackState {
  const CallbackSpec* spec = nullptr;
  bool is_timer = false;
  bool running = false;
  bool in_ready = false;
  // Subscriptions: keep-last ring buffer of capacity queue_depth.
  std::vector<QueuedMessage> ring;
  int head = 0;
  int size = 0;
  // Since when the queue has held a message not yet taken: a message a
  // newer one pushed out leaves its wait to it, as rclcpp's wait set keeps
  // a subscription ready however often its queue turned over.
  double waiting_since_s = 0.0;
  // Timers.
  bool fire_pending = false;
  double fire_s = 0.0;
  int64_t next_fire = 0;  // k of the fire at phase + k * period in the heap
  CountedCost counted;
  // With a cost profile: this callback's entry, its frequency factor, the
  // seed of its draws and how many it has taken.
  const CallbackCost* profiled = nullptr;
  double profile_factor = 1.0;
  uint64_t draw_seed = 0;
  uint64_t draws = 0;
  CallbackRecord record;              // the run in progress
  std::vector<HeldPublication> held;  // its publications, until its end
};

// The context handed to callbacks; one instance, reused for every run since
// callbacks execute one at a time on the host thread.
class VirtualContext final : public CallbackContext {
 public:
  explicit VirtualContext(int num_topics) : num_topics_(num_topics) {}

  void Begin(double now_s, std::vector<HeldPublication>* held) {
    now_s_ = now_s;
    held_ = held;
    work_ = WorkReport{};
    bad_topic_ = false;
  }
  double now_s() const override { return now_s_; }
  void ReportWork(const WorkReport& work) override { work_ = work; }
  const WorkReport& work() const { return work_; }
  // The first publication to a topic index the graph does not have.
  bool bad_topic() const { return bad_topic_; }
  int bad_topic_index() const { return bad_topic_index_; }

 protected:
  void PublishErased(int topic, MessagePtr message, double stamp_s) override {
    if (topic < 0 || topic >= num_topics_ || message == nullptr) {
      if (!bad_topic_) bad_topic_index_ = topic;
      bad_topic_ = true;
      return;
    }
    held_->push_back({topic, std::move(message), stamp_s});
  }

 private:
  int num_topics_;
  double now_s_ = 0.0;
  std::vector<HeldPublication>* held_ = nullptr;
  WorkReport work_;
  bool bad_topic_ = false;
  int bad_topic_index_ = -1;
};

class VirtualExecutor final : public Executor {
 public:
  VirtualExecutor(const Graph* graph, const VirtualPlatformOptions& options);

  void PublishExternal(int topic, MessagePtr message, double stamp_s,
                       double t_s) override;
  Status AdvanceTo(double t_s) override;
  double now_s() const override { return now_; }
  const Trace& trace() const override { return trace_; }

 private:
  uint64_t PushEvent(double t, EventKind kind, int32_t index) {
    const uint64_t key =
        (static_cast<uint64_t>(kind) << kKindShift) | next_seq_++;
    heap_.push_back({t, key, index});
    std::push_heap(heap_.begin(), heap_.end(), EventLater());
    return key;
  }
  Event PopEvent() {
    std::pop_heap(heap_.begin(), heap_.end(), EventLater());
    Event e = heap_.back();
    heap_.pop_back();
    return e;
  }
  void PushTimerFire(int c) {
    CallbackState& st = states_[c];
    const double t = st.spec->phase_s +
                     static_cast<double>(st.next_fire) * st.spec->period_s;
    PushEvent(t, kTimerFire, c);
  }

  void ApplyEvent(const Event& e);
  void OnArrival(int32_t slot);
  void OnTimerFire(int c);
  void OnCompletion(int c);
  // Processor sharing: the parts that end now; those that end a callback
  // complete it. Events pushed before the sharing last changed are stale.
  void OnSharedEnd(uint64_t key);
  // Processor sharing: the event of the next part's end at the new rates.
  void PushSharedEnd();
  // Publishes `message` on `topic` now: traces it, queues it for every
  // subscription and calls the sinks.
  void Deliver(int topic, const MessagePtr& message, double stamp_s,
               int publisher);
  void Enqueue(int c, const MessagePtr& message, uint64_t seq, double stamp_s);
  void MakeReady(int c) {
    CallbackState& st = states_[c];
    if (st.in_ready) return;
    st.in_ready = true;
    ready_.push_back(c);
  }
  double ReadyTime(const CallbackState& st) const {
    return st.is_timer ? st.fire_s : st.waiting_since_s;
  }
  void Dispatch();
  void Start(int c);
  void Fail(Status status) {
    if (error_.ok()) error_ = std::move(status);
  }

  const Graph* graph_;
  double freq_factor_;  // reference_ghz / freq_ghz * cost_scale
  bool measured_;
  bool read_clock_;  // host CPU time is measured around each callback

  double now_ = 0.0;
  uint64_t next_seq_ = 0;
  std::vector<Event> heap_;
  std::vector<Arrival> arrivals_;       // payloads of pending arrivals
  std::vector<int32_t> free_arrivals_;  // reusable slots in arrivals_

  std::vector<CallbackState> states_;
  std::vector<int> ready_;                     // ready callbacks, unordered
  std::vector<std::vector<int>> topic_subs_;   // per topic: subscriptions
  std::vector<std::vector<int>> topic_sinks_;  // per topic: sink indices
  std::vector<uint64_t> topic_seq_;            // per topic: next seq
  std::vector<char> node_busy_;
  std::vector<int32_t> core_owner_;  // callback holding each core, or -1
  int free_cores_;
  int cores_;
  std::shared_ptr<const CostProfile> profile_;  // keeps `profiled` valid
  // kProcessorSharing only: the work in progress, whether it changed since
  // its next end was pushed, and that event's key.
  std::optional<internal::ProcessorSharing> sharing_;
  bool sharing_changed_ = false;
  uint64_t shared_end_key_ = 0;
  std::vector<int> ended_;  // scratch for OnSharedEnd

  VirtualContext context_;
  Trace trace_;
  Status error_;
  bool in_advance_ = false;
};

VirtualExecutor::VirtualExecutor(const Graph* graph,
                                 const VirtualPlatformOptions& options)
    : graph_(graph),
      freq_factor_(options.reference_ghz / options.freq_ghz *
                   options.cost_scale),
      measured_(options.cost_model == CostModelKind::kMeasured),
      read_clock_(measured_ || options.record_host_cpu_when_counted),
      free_cores_(options.cores),
      cores_(options.cores),
      profile_(options.profile),
      context_(static_cast<int>(graph->topics().size())) {
  const auto& callbacks = graph->callbacks();
  const size_t num_topics = graph->topics().size();
  topic_subs_.resize(num_topics);
  topic_sinks_.resize(num_topics);
  topic_seq_.assign(num_topics, 0);
  node_busy_.assign(graph->nodes().size(), 0);
  core_owner_.assign(options.cores, -1);
  if (options.dispatch == DispatchKind::kProcessorSharing) {
    sharing_.emplace(options.cores);
  }

  states_.resize(callbacks.size());
  for (size_t c = 0; c < callbacks.size(); ++c) {
    const CallbackSpec& spec = callbacks[c];
    CallbackState& st = states_[c];
    st.spec = &spec;
    st.is_timer = spec.kind == CallbackSpec::Kind::kTimer;
    auto it = options.counted.find(spec.name);
    st.counted =
        it != options.counted.end() ? it->second : options.default_counted;
    if (profile_ != nullptr && !measured_) {
      // CreateVirtualExecutor checked that every callback has an entry.
      st.profiled = &profile_->callbacks.at(spec.name);
      st.profile_factor = FrequencyFactor(*st.profiled, profile_->reference_ghz,
                                          options.freq_ghz, options.cost_scale);
      st.draw_seed = Random::DeriveSeed(options.profile_seed, spec.name);
    }
    if (st.is_timer) {
      PushTimerFire(static_cast<int>(c));
    } else {
      st.ring.resize(spec.queue_depth);
      topic_subs_[spec.topic].push_back(static_cast<int>(c));
    }
    st.held.reserve(4);
  }
  for (size_t s = 0; s < graph->sinks().size(); ++s) {
    topic_sinks_[graph->sinks()[s].topic].push_back(static_cast<int>(s));
  }
  ready_.reserve(callbacks.size());
  heap_.reserve(callbacks.size() + 64);
  trace_.timer_overruns.assign(callbacks.size(), 0);
  // Amortised growth would do; reserving skips the first few copies.
  trace_.callbacks.reserve(4096);
  trace_.topic_events.reserve(16384);
}

void VirtualExecutor::PublishExternal(int topic, MessagePtr message,
                                      double stamp_s, double t_s) {
  if (topic < 0 || topic >= static_cast<int>(topic_subs_.size())) {
    Fail(Status::InvalidArgument(
        fmt::format("PublishExternal: no topic with index {}", topic)));
    return;
  }
  if (message == nullptr) {
    Fail(Status::InvalidArgument(
        fmt::format("PublishExternal: null message on topic '{}'",
                    graph_->topics()[topic].name)));
    return;
  }
  if (!std::isfinite(t_s) || t_s < now_ - kPastToleranceS) {
    Fail(Status::InvalidArgument(
        fmt::format("PublishExternal on topic '{}' at t={} before now={}",
                    graph_->topics()[topic].name, t_s, now_)));
    return;
  }
  t_s = std::max(t_s, now_);
  int32_t slot;
  if (!free_arrivals_.empty()) {
    slot = free_arrivals_.back();
    free_arrivals_.pop_back();
  } else {
    slot = static_cast<int32_t>(arrivals_.size());
    arrivals_.emplace_back();
  }
  Arrival& a = arrivals_[slot];
  a.topic = topic;
  a.message = std::move(message);
  a.stamp_s = stamp_s;
  PushEvent(t_s, kArrival, slot);
}

Status VirtualExecutor::AdvanceTo(double t_s) {
  if (!error_.ok()) return error_;
  if (in_advance_) {
    return Status::Internal("AdvanceTo called from inside a callback or sink");
  }
  if (!std::isfinite(t_s) || t_s < now_) {
    return Status::InvalidArgument(
        fmt::format("AdvanceTo({}) must be finite and >= now ({})", t_s, now_));
  }
  in_advance_ = true;
  while (error_.ok() && !heap_.empty() && heap_.front().t < t_s) {
    const double batch_t = heap_.front().t;
    now_ = batch_t;
    // Every event at this time, in (kind, sequence) order, before dispatch.
    while (error_.ok() && !heap_.empty() && heap_.front().t == batch_t) {
      ApplyEvent(PopEvent());
    }
    if (error_.ok()) Dispatch();
    if (error_.ok() && sharing_changed_) PushSharedEnd();
  }
  in_advance_ = false;
  if (!error_.ok()) return error_;
  now_ = t_s;
  return Status::Ok();
}

void VirtualExecutor::ApplyEvent(const Event& e) {
  switch (static_cast<EventKind>(e.key >> kKindShift)) {
    case kCompletion:
      if (e.index == kSharedEnd) {
        OnSharedEnd(e.key);
      } else {
        OnCompletion(e.index);
      }
      break;
    case kArrival:
      OnArrival(e.index);
      break;
    case kTimerFire:
      OnTimerFire(e.index);
      break;
  }
}

void VirtualExecutor::OnArrival(int32_t slot) {
  // Move out first: a sink may call PublishExternal and grow arrivals_.
  Arrival& a = arrivals_[slot];
  const int topic = a.topic;
  const double stamp_s = a.stamp_s;
  MessagePtr message = std::move(a.message);
  free_arrivals_.push_back(slot);
  Deliver(topic, message, stamp_s, -1);
}

void VirtualExecutor::OnTimerFire(int c) {
  CallbackState& st = states_[c];
  ++st.next_fire;
  PushTimerFire(c);
  if (st.fire_pending) {
    ++trace_.timer_overruns[c];  // the earlier fire still waits: skip this
    return;
  }
  st.fire_pending = true;
  st.fire_s = now_;
  if (!st.running) MakeReady(c);
}

void VirtualExecutor::OnSharedEnd(uint64_t key) {
  if (key != shared_end_key_) return;
  ended_.clear();
  sharing_->AdvanceTo(now_, &ended_);
  sharing_changed_ = true;
  for (size_t i = 0; i < ended_.size() && error_.ok(); ++i) {
    OnCompletion(ended_[i]);
  }
}

void VirtualExecutor::PushSharedEnd() {
  sharing_changed_ = false;
  if (sharing_->empty()) return;
  shared_end_key_ = PushEvent(sharing_->NextEndS(), kCompletion, kSharedEnd);
}

void VirtualExecutor::OnCompletion(int c) {
  CallbackState& st = states_[c];
  CallbackRecord& rec = st.record;
  // Under processor sharing a callback holds one executor thread, and its
  // end is now.
  const int held = sharing_ ? 1 : rec.cores;
  if (sharing_) {
    rec.end_s = now_;
    rec.cost_s = now_ - rec.start_s;
  }
  for (int i = rec.first_core, left = held; left > 0; ++i) {
    if (core_owner_[i] == c) {
      core_owner_[i] = -1;
      --left;
    }
  }
  free_cores_ += held;
  node_busy_[st.spec->node] = 0;
  st.running = false;
  trace_.callbacks.push_back(rec);
  // Index loop: a sink may publish externally, which does not touch `held`,
  // but keep no iterator across user code anyway.
  for (size_t i = 0; i < st.held.size() && error_.ok(); ++i) {
    HeldPublication& p = st.held[i];
    Deliver(p.topic, p.message, p.stamp_s, c);
  }
  st.held.clear();
  if (st.is_timer ? st.fire_pending : st.size > 0) MakeReady(c);
}

void VirtualExecutor::Deliver(int topic, const MessagePtr& message,
                              double stamp_s, int publisher) {
  const uint64_t seq = topic_seq_[topic]++;
  trace_.topic_events.push_back(
      {TopicEvent::kPublish, topic, publisher, now_, seq, stamp_s});
  for (int c : topic_subs_[topic]) Enqueue(c, message, seq, stamp_s);
  for (int s : topic_sinks_[topic]) {
    const SinkSpec& sink = graph_->sinks()[s];
    try {
      sink.fn(message, now_);
    } catch (const std::exception& e) {
      Fail(Status::Internal(fmt::format("sink #{} on topic '{}' threw: {}", s,
                                        graph_->topics()[topic].name,
                                        e.what())));
      return;
    } catch (...) {
      Fail(Status::Internal(fmt::format("sink #{} on topic '{}' threw", s,
                                        graph_->topics()[topic].name)));
      return;
    }
  }
}

void VirtualExecutor::Enqueue(int c, const MessagePtr& message, uint64_t seq,
                              double stamp_s) {
  CallbackState& st = states_[c];
  const int depth = static_cast<int>(st.ring.size());
  if (st.size == 0) st.waiting_since_s = now_;
  if (st.size == depth) {
    // Keep-last: the oldest message makes room.
    QueuedMessage& old = st.ring[st.head];
    trace_.topic_events.push_back(
        {TopicEvent::kDrop, st.spec->topic, c, now_, old.seq, old.stamp_s});
    old.message.reset();
    st.head = st.head + 1 == depth ? 0 : st.head + 1;
    --st.size;
  }
  int tail = st.head + st.size;
  if (tail >= depth) tail -= depth;
  st.ring[tail] = {message, seq, stamp_s, now_};
  ++st.size;
  if (!st.running) MakeReady(c);
}

void VirtualExecutor::Dispatch() {
  // The ready set is small (at most one entry per callback), so a scan is
  // cheaper than keeping it ordered as drops move ready times.
  while (free_cores_ > 0 && error_.ok()) {
    int best_pos = -1;
    int best_c = 0;
    double best_t = 0.0;
    for (size_t i = 0; i < ready_.size(); ++i) {
      const int c = ready_[i];
      const CallbackState& st = states_[c];
      if (node_busy_[st.spec->node]) continue;
      const double t = ReadyTime(st);
      if (best_pos < 0 || t < best_t || (t == best_t && c < best_c)) {
        best_pos = static_cast<int>(i);
        best_c = c;
        best_t = t;
      }
    }
    if (best_pos < 0) return;
    ready_[best_pos] = ready_.back();
    ready_.pop_back();
    Start(best_c);
  }
}

void VirtualExecutor::Start(int c) {
  CallbackState& st = states_[c];
  const CallbackSpec& spec = *st.spec;
  st.in_ready = false;
  st.running = true;
  node_busy_[spec.node] = 1;

  CallbackRecord& rec = st.record;
  rec.callback = c;
  rec.node = spec.node;
  rec.start_s = now_;
  MessagePtr message;
  if (st.is_timer) {
    rec.ready_s = st.fire_s;
    st.fire_pending = false;
  } else {
    QueuedMessage& q = st.ring[st.head];
    rec.ready_s = q.arrival_s;
    message = std::move(q.message);
    trace_.topic_events.push_back(
        {TopicEvent::kTake, spec.topic, c, now_, q.seq, q.stamp_s});
    st.head = st.head + 1 == static_cast<int>(st.ring.size()) ? 0 : st.head + 1;
    --st.size;
    if (st.size > 0) st.waiting_since_s = st.ring[st.head].arrival_s;
  }

  context_.Begin(now_, &st.held);
  // Counted runs skip the clock unless asked: host time differs run to run and
  // would break bit-identical traces (and costs two syscalls).
  const double cpu0 = read_clock_ ? ThreadCpuSeconds() : 0.0;
  try {
    if (st.is_timer) {
      spec.on_timer(context_);
    } else {
      spec.on_message(message, context_);
    }
  } catch (const std::exception& e) {
    Fail(Status::Internal(
        fmt::format("callback '{}' threw: {}", spec.name, e.what())));
  } catch (...) {
    Fail(Status::Internal(fmt::format("callback '{}' threw", spec.name)));
  }
  const double host_cpu_s = read_clock_ ? ThreadCpuSeconds() - cpu0 : 0.0;
  message.reset();
  if (context_.bad_topic()) {
    Fail(Status::Internal(fmt::format(
        "callback '{}' published to topic index {}, which does not exist",
        spec.name, context_.bad_topic_index())));
  }

  // Sanitise the report: a bad value must not yield a NaN clock.
  const WorkReport& work = context_.work();
  const double units = std::isfinite(work.units) ? work.units : 0.0;
  double p =
      std::isfinite(work.parallel_fraction) ? work.parallel_fraction : 0.0;
  int max_threads = work.max_threads;
  double base_s = 0.0;
  double factor = freq_factor_;
  if (measured_) {
    base_s = host_cpu_s;
  } else if (st.profiled != nullptr) {
    const CallbackCost& cost = *st.profiled;
    base_s =
        DrawnCostS(cost, InvocationUniform(st.draw_seed, st.draws++), units);
    // The source's parallel part, on at most the threads both it scales to
    // and the callback runs with (e.g. the localization.ndt_threads knob).
    p = cost.parallel_fraction;
    max_threads = std::min(cost.max_threads, work.max_threads);
    factor = st.profile_factor;
  } else {
    base_s = st.counted.fixed_s + st.counted.per_unit_s * units;
  }
  // Run to completion: k free cores, held to the end. Processor sharing:
  // one executor thread, and a team of k whatever is free.
  const int k =
      std::max(1, std::min(max_threads, sharing_ ? cores_ : free_cores_));
  const int held = sharing_ ? 1 : k;
  double cost_s = AmdahlS(base_s, p, k) * factor;
  if (!(cost_s >= kMinCostS)) cost_s = kMinCostS;  // also catches NaN

  int first_core = -1;
  for (int i = 0, taken = 0; taken < held; ++i) {
    if (core_owner_[i] >= 0) continue;
    core_owner_[i] = c;
    if (first_core < 0) first_core = i;
    ++taken;
  }
  free_cores_ -= held;

  rec.host_cpu_s = host_cpu_s;
  rec.work_units = units;
  rec.cores = k;
  rec.first_core = first_core;
  if (sharing_) {
    // One team's thread does the serial part, then each its share; with no
    // team the whole cost is serial, computed as above so that one core
    // gives the same trace under both dispatches.
    double serial_s = cost_s;
    double share_s = 0.0;
    if (k > 1) {
      const double pc = std::clamp(p, 0.0, 1.0);
      serial_s = base_s * (1.0 - pc) * factor;
      share_s = base_s * pc * factor / k;
      if (!(serial_s + share_s >= kMinCostS)) {  // also catches NaN
        serial_s = kMinCostS;
        share_s = 0.0;
      }
    }
    sharing_->Add(c, now_, serial_s, share_s, k);
    sharing_changed_ = true;
    return;
  }
  rec.end_s = now_ + cost_s;
  rec.cost_s = cost_s;
  PushEvent(rec.end_s, kCompletion, c);
}

}  // namespace

Status ValidateVirtualPlatformOptions(const VirtualPlatformOptions& options) {
  if (options.cores < 1 || options.cores > kMaxPlatformCores) {
    return Status::InvalidArgument(fmt::format(
        "cores must be in [1, {}], got {}", kMaxPlatformCores, options.cores));
  }
  if (!IsFinitePositive(options.freq_ghz)) {
    return Status::InvalidArgument(fmt::format(
        "freq_ghz must be finite and > 0, got {}", options.freq_ghz));
  }
  if (!IsFinitePositive(options.reference_ghz)) {
    return Status::InvalidArgument(fmt::format(
        "reference_ghz must be finite and > 0, got {}", options.reference_ghz));
  }
  if (!IsFinitePositive(options.cost_scale)) {
    return Status::InvalidArgument(fmt::format(
        "cost_scale must be finite and > 0, got {}", options.cost_scale));
  }
  if (options.cost_model != CostModelKind::kMeasured &&
      options.cost_model != CostModelKind::kCounted) {
    return Status::InvalidArgument("cost_model: unknown kind");
  }
  if (options.dispatch != DispatchKind::kRunToCompletion &&
      options.dispatch != DispatchKind::kProcessorSharing) {
    return Status::InvalidArgument("dispatch: unknown kind");
  }
  if (options.profile != nullptr) {
    ADSE_RETURN_IF_ERROR(ValidateCostProfile(*options.profile));
  }
  for (const auto& [name, cost] : options.counted) {
    ADSE_RETURN_IF_ERROR(
        ValidateCountedCost(cost, fmt::format("counted[{}]", name)));
  }
  return ValidateCountedCost(options.default_counted, "default_counted");
}

Result<std::unique_ptr<Executor>> CreateVirtualExecutor(
    const Graph* graph, const VirtualPlatformOptions& options) {
  if (graph == nullptr) return Status::InvalidArgument("graph is null");
  ADSE_RETURN_IF_ERROR(ValidateVirtualPlatformOptions(options));
  ADSE_RETURN_IF_ERROR(ValidateGraph(*graph));
  if (options.profile != nullptr &&
      options.cost_model == CostModelKind::kCounted) {
    // A callback the profile does not cost would be charged nothing: refuse.
    ADSE_RETURN_IF_ERROR(CheckProfileCovers(*options.profile, *graph));
  }
  return std::unique_ptr<Executor>(new VirtualExecutor(graph, options));
}

}  // namespace adse::stack
