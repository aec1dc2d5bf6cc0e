// The real-time platform (realtime_executor.h). One mutex guards all of
// the executor's state; the executor threads hold it only to choose, take
// and finish callbacks, never while a callback runs. A clock thread
// applies the timed events (external arrivals, timer fires) when they fall
// due. Sinks are queued and run on the caller's thread in AdvanceTo, so the
// world's state is only ever touched by its own thread.
#include "stack/runtime/realtime_executor.h"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <exception>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "stack/base/random.h"
#include "stack/runtime/internal/executor_parts.h"
#include "stack/runtime/internal/padding_team.h"

namespace adse::stack {
namespace {

using internal::HeldPublication;
using internal::QueuedMessage;
using internal::ThreadCpuSeconds;

using Clock = std::chrono::steady_clock;

constexpr int kMaxRealTimeCores = 256;

struct Arrival {
  double t_s;
  uint64_t order;  // ties: in the order published
  int topic;
  MessagePtr message;
  double stamp_s;
  bool operator<(const Arrival& o) const {
    return t_s != o.t_s ? t_s < o.t_s : order < o.order;
  }
};

struct SinkCall {
  int sink;
  MessagePtr message;
  double t_s;
};

struct CallbackState {
  const CallbackSpec* spec = nullptr;
  bool is_timer = false;
  bool running = false;
  std::deque<QueuedMessage> queue;  // keep-last, oldest first
  // Since when the queue has held a message not yet taken (see the
  // virtual executor: a message pushed out leaves its wait to the next).
  double waiting_since_s = 0.0;
  bool fire_pending = false;
  double fire_s = 0.0;
  int64_t next_fire = 0;
  const CallbackCost* cost = nullptr;
  double factor = 1.0;  // frequency factor * time dilation
  uint64_t draw_seed = 0;
  uint64_t draws = 0;
};

class RealTimeContext final : public CallbackContext {
 public:
  RealTimeContext(double now_s, int num_topics,
                  std::vector<HeldPublication>* held)
      : now_s_(now_s), num_topics_(num_topics), held_(held) {}
  double now_s() const override { return now_s_; }
  void ReportWork(const WorkReport& work) override { work_ = work; }
  const WorkReport& work() const { return work_; }
  int bad_topic() const { return bad_topic_; }

 protected:
  void PublishErased(int topic, MessagePtr message, double stamp_s) override {
    if (topic < 0 || topic >= num_topics_ || message == nullptr) {
      if (bad_topic_ == kNone) bad_topic_ = topic;
      return;
    }
    held_->push_back({topic, std::move(message), stamp_s});
  }

 public:
  static constexpr int kNone = std::numeric_limits<int>::min();

 private:
  double now_s_;
  int num_topics_;
  std::vector<HeldPublication>* held_;
  WorkReport work_;
  int bad_topic_ = kNone;
};

class RealTimeExecutor final : public Executor {
 public:
  RealTimeExecutor(const Graph* graph, const RealTimeOptions& options);
  ~RealTimeExecutor() override { Stop(); }

  void PublishExternal(int topic, MessagePtr message, double stamp_s,
                       double t_s) override;
  Status AdvanceTo(double t_s) override;
  double now_s() const override { return now_; }
  const Trace& trace() const override { return trace_; }
  void Stop() override;

  // Starts the threads; false (and error_ set) when pinning fails.
  Status Start();

 private:
  double SimNow() const {
    return std::chrono::duration<double>(Clock::now() - t0_).count() /
           dilation_;
  }
  Clock::time_point WallAt(double t_s) const {
    return t0_ + std::chrono::duration_cast<Clock::duration>(
                     std::chrono::duration<double>(t_s * dilation_));
  }
  void Fail(Status status) {
    if (error_.ok()) error_ = std::move(status);
  }
  void ClockLoop();
  void WorkerLoop(int thread);
  // The next timed event's sim time (arrival or timer fire), or +inf.
  double NextDue() const;
  void ApplyDue(double now);
  // With mu_ held: traces the publication and queues it.
  void Deliver(int topic, const MessagePtr& message, double stamp_s,
               int publisher, double now);
  // With mu_ held: the ready callback to run next, or -1.
  int Choose() const;
  bool Ready(const CallbackState& st) const {
    return !st.running && !node_busy_[st.spec->node] &&
           (st.is_timer ? st.fire_pending : !st.queue.empty());
  }
  void RunOne(int c, int thread, std::unique_lock<std::mutex>* lock);
  // Pins a thread to options_.host_cpus (when given).
  Status Pin(pthread_t thread) const;
  // First step of a padding helper: the executor threads' CPUs and
  // enter_thread.
  Status EnterHelper();

  const Graph* graph_;
  RealTimeOptions options_;
  double dilation_;
  std::shared_ptr<const CostProfile> profile_;

  std::mutex mu_;
  std::condition_variable work_cv_;   // executor threads wait here
  std::condition_variable clock_cv_;  // the clock thread waits here
  bool started_ = false;              // the clock runs (first AdvanceTo)
  bool stopping_ = false;
  Clock::time_point t0_;
  double now_ = 0.0;  // the caller's view: the last AdvanceTo target

  std::vector<CallbackState> states_;
  std::vector<std::vector<int>> topic_subs_;
  std::vector<std::vector<int>> topic_sinks_;
  std::vector<uint64_t> topic_seq_;
  std::vector<char> node_busy_;
  std::multiset<Arrival> arrivals_;
  uint64_t next_order_ = 0;
  std::vector<SinkCall> sink_calls_;
  Trace trace_;
  Status error_;

  std::vector<std::thread> threads_;
  std::thread clock_thread_;
  // Helper threads of data-parallel callbacks; they enter like the
  // executor's threads and are pinned to the same CPUs.
  internal::PaddingTeam team_;
};

RealTimeExecutor::RealTimeExecutor(const Graph* graph,
                                   const RealTimeOptions& options)
    : graph_(graph),
      options_(options),
      dilation_(options.time_dilation),
      profile_(options.profile),
      team_([this] { return EnterHelper(); }) {
  const auto& callbacks = graph->callbacks();
  topic_subs_.resize(graph->topics().size());
  topic_sinks_.resize(graph->topics().size());
  topic_seq_.assign(graph->topics().size(), 0);
  node_busy_.assign(graph->nodes().size(), 0);
  states_.resize(callbacks.size());
  for (size_t c = 0; c < callbacks.size(); ++c) {
    CallbackState& st = states_[c];
    st.spec = &callbacks[c];
    st.is_timer = st.spec->kind == CallbackSpec::Kind::kTimer;
    st.cost = &profile_->callbacks.at(st.spec->name);
    st.factor = FrequencyFactor(*st.cost, profile_->reference_ghz,
                                options.freq_ghz, options.cost_scale) *
                dilation_ * options.cpu_share;
    st.draw_seed = Random::DeriveSeed(options.profile_seed, st.spec->name);
    if (!st.is_timer)
      topic_subs_[st.spec->topic].push_back(static_cast<int>(c));
  }
  for (size_t s = 0; s < graph->sinks().size(); ++s) {
    topic_sinks_[graph->sinks()[s].topic].push_back(static_cast<int>(s));
  }
  trace_.timer_overruns.assign(callbacks.size(), 0);
}

Status RealTimeExecutor::Pin(pthread_t thread) const {
  if (options_.host_cpus.empty()) return Status::Ok();
  cpu_set_t set;
  CPU_ZERO(&set);
  for (int cpu : options_.host_cpus) CPU_SET(cpu, &set);
  const int rc = pthread_setaffinity_np(thread, sizeof(set), &set);
  if (rc != 0) {
    return Status::Unavailable(
        fmt::format("cannot pin the stack's threads to host CPUs {}: {}",
                    fmt::join(options_.host_cpus, ","), std::strerror(rc)));
  }
  return Status::Ok();
}

Status RealTimeExecutor::Start() {
  auto pin = [this](std::thread& t) { return Pin(t.native_handle()); };
  // Each thread enters (options_.enter_thread) before it does anything
  // else; Start returns once all have, or with the first failure.
  int entered = 0;
  std::condition_variable entered_cv;
  auto enter = [this, &entered, &entered_cv] {
    Status status =
        options_.enter_thread ? options_.enter_thread() : Status::Ok();
    std::lock_guard<std::mutex> lock(mu_);
    if (!status.ok()) Fail(std::move(status));
    ++entered;
    entered_cv.notify_all();
  };
  clock_thread_ = std::thread([this, enter] {
    enter();
    ClockLoop();
  });
  Status pinned = pin(clock_thread_);
  int started = 1;
  for (int i = 0; i < options_.cores && pinned.ok(); ++i) {
    threads_.emplace_back([this, i, enter] {
      enter();
      WorkerLoop(i);
    });
    ++started;
    pinned = pin(threads_.back());
  }
  Status status = pinned;
  {
    std::unique_lock<std::mutex> lock(mu_);
    entered_cv.wait(lock, [&] { return entered == started; });
    if (status.ok()) status = error_;
  }
  if (!status.ok()) Stop();
  return status;
}

void RealTimeExecutor::Stop() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (stopping_ && threads_.empty() && !clock_thread_.joinable()) return;
    stopping_ = true;
  }
  work_cv_.notify_all();
  clock_cv_.notify_all();
  for (std::thread& t : threads_) {
    if (t.joinable()) t.join();
  }
  threads_.clear();
  if (clock_thread_.joinable()) clock_thread_.join();
  team_.Stop();  // after the workers, whose callbacks may still use it
}

Status RealTimeExecutor::EnterHelper() {
  ADSE_RETURN_IF_ERROR(Pin(pthread_self()));
  return options_.enter_thread ? options_.enter_thread() : Status::Ok();
}

void RealTimeExecutor::PublishExternal(int topic, MessagePtr message,
                                       double stamp_s, double t_s) {
  std::lock_guard<std::mutex> lock(mu_);
  if (topic < 0 || topic >= static_cast<int>(topic_subs_.size())) {
    Fail(Status::InvalidArgument(
        fmt::format("PublishExternal: no topic with index {}", topic)));
    return;
  }
  if (message == nullptr || !std::isfinite(t_s)) {
    Fail(Status::InvalidArgument(
        fmt::format("PublishExternal on topic '{}': null message or "
                    "non-finite time",
                    graph_->topics()[topic].name)));
    return;
  }
  arrivals_.insert({t_s, next_order_++, topic, std::move(message), stamp_s});
  clock_cv_.notify_one();
}

Status RealTimeExecutor::AdvanceTo(double t_s) {
  if (!std::isfinite(t_s) || t_s < now_) {
    return Status::InvalidArgument(
        fmt::format("AdvanceTo({}) must be finite and >= now ({})", t_s, now_));
  }
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (!started_) {
      started_ = true;
      t0_ = Clock::now() - std::chrono::duration_cast<Clock::duration>(
                               std::chrono::duration<double>(now_ * dilation_));
    }
  }
  clock_cv_.notify_all();
  std::this_thread::sleep_until(WallAt(t_s));
  std::vector<SinkCall> calls;
  {
    std::lock_guard<std::mutex> lock(mu_);
    calls.swap(sink_calls_);
    if (!error_.ok()) return error_;
  }
  for (const SinkCall& call : calls) {
    const SinkSpec& sink = graph_->sinks()[call.sink];
    try {
      sink.fn(call.message, call.t_s);
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mu_);
      Fail(Status::Internal(
          fmt::format("sink #{} on topic '{}' threw: {}", call.sink,
                      graph_->topics()[sink.topic].name, e.what())));
      return error_;
    }
  }
  now_ = t_s;
  return Status::Ok();
}

double RealTimeExecutor::NextDue() const {
  double due = std::numeric_limits<double>::infinity();
  if (!arrivals_.empty()) due = arrivals_.begin()->t_s;
  for (const CallbackState& st : states_) {
    if (!st.is_timer) continue;
    due = std::min(due, st.spec->phase_s + static_cast<double>(st.next_fire) *
                                               st.spec->period_s);
  }
  return due;
}

void RealTimeExecutor::ApplyDue(double now) {
  while (!arrivals_.empty() && arrivals_.begin()->t_s <= now) {
    auto node = arrivals_.extract(arrivals_.begin());
    Arrival& a = node.value();
    Deliver(a.topic, a.message, a.stamp_s, -1, now);
  }
  for (size_t c = 0; c < states_.size(); ++c) {
    CallbackState& st = states_[c];
    if (!st.is_timer) continue;
    while (st.spec->phase_s +
               static_cast<double>(st.next_fire) * st.spec->period_s <=
           now) {
      const double fire = st.spec->phase_s +
                          static_cast<double>(st.next_fire) * st.spec->period_s;
      ++st.next_fire;
      if (st.fire_pending) {
        ++trace_.timer_overruns[c];  // the earlier fire still waits
        continue;
      }
      st.fire_pending = true;
      st.fire_s = fire;
    }
  }
}

void RealTimeExecutor::ClockLoop() {
  std::unique_lock<std::mutex> lock(mu_);
  while (!stopping_) {
    if (!started_) {
      clock_cv_.wait(lock);
      continue;
    }
    const double due = NextDue();
    if (std::isfinite(due) && SimNow() < due) {
      clock_cv_.wait_until(lock, WallAt(due));
      continue;  // woken early by a new arrival, or due now: look again
    }
    if (!std::isfinite(due)) {
      clock_cv_.wait(lock);
      continue;
    }
    ApplyDue(SimNow());
    work_cv_.notify_all();
  }
}

void RealTimeExecutor::Deliver(int topic, const MessagePtr& message,
                               double stamp_s, int publisher, double now) {
  const uint64_t seq = topic_seq_[topic]++;
  trace_.topic_events.push_back(
      {TopicEvent::kPublish, topic, publisher, now, seq, stamp_s});
  for (int c : topic_subs_[topic]) {
    CallbackState& st = states_[c];
    if (st.queue.empty()) st.waiting_since_s = now;
    if (static_cast<int>(st.queue.size()) == st.spec->queue_depth) {
      const QueuedMessage& old = st.queue.front();
      trace_.topic_events.push_back(
          {TopicEvent::kDrop, topic, c, now, old.seq, old.stamp_s});
      st.queue.pop_front();
    }
    st.queue.push_back({message, seq, stamp_s, now});
  }
  for (int s : topic_sinks_[topic]) sink_calls_.push_back({s, message, now});
}

int RealTimeExecutor::Choose() const {
  int best = -1;
  double best_t = 0.0;
  for (size_t c = 0; c < states_.size(); ++c) {
    const CallbackState& st = states_[c];
    if (!Ready(st)) continue;
    const double t = st.is_timer ? st.fire_s : st.waiting_since_s;
    if (best < 0 || t < best_t) {
      best = static_cast<int>(c);
      best_t = t;
    }
  }
  return best;
}

void RealTimeExecutor::WorkerLoop(int thread) {
  std::unique_lock<std::mutex> lock(mu_);
  while (!stopping_) {
    const int c = error_.ok() ? Choose() : -1;
    if (c < 0) {
      work_cv_.wait(lock);
      continue;
    }
    RunOne(c, thread, &lock);
  }
}

void RealTimeExecutor::RunOne(int c, int thread,
                              std::unique_lock<std::mutex>* lock) {
  CallbackState& st = states_[c];
  const CallbackSpec& spec = *st.spec;
  st.running = true;
  node_busy_[spec.node] = 1;
  CallbackRecord rec;
  rec.callback = c;
  rec.node = spec.node;
  rec.first_core = thread;
  rec.start_s = SimNow();
  MessagePtr message;
  if (st.is_timer) {
    rec.ready_s = st.fire_s;
    st.fire_pending = false;
  } else {
    QueuedMessage q = std::move(st.queue.front());
    st.queue.pop_front();
    if (!st.queue.empty()) st.waiting_since_s = st.queue.front().arrival_s;
    rec.ready_s = q.arrival_s;
    message = std::move(q.message);
    trace_.topic_events.push_back(
        {TopicEvent::kTake, spec.topic, c, rec.start_s, q.seq, q.stamp_s});
  }
  const double u = InvocationUniform(st.draw_seed, st.draws++);
  std::vector<HeldPublication> held;
  RealTimeContext context(rec.start_s,
                          static_cast<int>(graph_->topics().size()), &held);
  lock->unlock();

  Status failure;
  const double cpu0 = ThreadCpuSeconds();
  try {
    if (st.is_timer) {
      spec.on_timer(context);
    } else {
      spec.on_message(message, context);
    }
  } catch (const std::exception& e) {
    failure = Status::Internal(
        fmt::format("callback '{}' threw: {}", spec.name, e.what()));
  } catch (...) {
    failure = Status::Internal(fmt::format("callback '{}' threw", spec.name));
  }
  const double host_cpu_s = ThreadCpuSeconds() - cpu0;
  message.reset();
  // Busy-work to the profile's cost at the point's clock: a real callback
  // of that cost keeps its core this busy, and the OS may preempt it. A
  // data-parallel callback's parallel part is split over k threads that
  // all busy-work at once, as its OpenMP team would, so it occupies k CPUs
  // whether or not they are free.
  const WorkReport& work = context.work();
  const int k = std::max(
      1, std::min({st.cost->max_threads, work.max_threads, options_.cores}));
  const double total_s = DrawnCostS(*st.cost, u, work.units) * st.factor;
  const double p = k > 1 ? st.cost->parallel_fraction : 0.0;
  const double serial_s = total_s * (1.0 - p);
  const double share_s = total_s * p / k;
  internal::BusyUntilThreadCpu(cpu0, serial_s);  // all of it when k = 1
  if (k > 1) {
    Status team = team_.Run(k - 1, share_s, [&] {
      internal::BusyUntilThreadCpu(cpu0, serial_s + share_s);
    });
    if (!team.ok() && failure.ok()) failure = std::move(team);
  }

  lock->lock();
  if (!failure.ok()) Fail(failure);
  if (context.bad_topic() != RealTimeContext::kNone) {
    Fail(Status::Internal(fmt::format(
        "callback '{}' published to topic index {}, which does not exist",
        spec.name, context.bad_topic())));
  }
  rec.end_s = SimNow();
  rec.cost_s = rec.end_s - rec.start_s;
  rec.host_cpu_s = host_cpu_s;
  rec.work_units = std::isfinite(work.units) ? work.units : 0.0;
  rec.cores = k;
  trace_.callbacks.push_back(rec);
  for (const HeldPublication& p : held) {
    Deliver(p.topic, p.message, p.stamp_s, c, rec.end_s);
  }
  node_busy_[spec.node] = 0;
  st.running = false;
  work_cv_.notify_all();
}

}  // namespace

Status ValidateRealTimeOptions(const RealTimeOptions& options) {
  if (options.cores < 1 || options.cores > kMaxRealTimeCores) {
    return Status::InvalidArgument(fmt::format(
        "cores must be in [1, {}], got {}", kMaxRealTimeCores, options.cores));
  }
  if (!std::isfinite(options.freq_ghz) || options.freq_ghz <= 0.0) {
    return Status::InvalidArgument(fmt::format(
        "freq_ghz must be finite and > 0, got {}", options.freq_ghz));
  }
  if (!std::isfinite(options.cost_scale) || options.cost_scale <= 0.0) {
    return Status::InvalidArgument(fmt::format(
        "cost_scale must be finite and > 0, got {}", options.cost_scale));
  }
  if (!std::isfinite(options.time_dilation) || options.time_dilation < 1.0) {
    return Status::InvalidArgument(
        fmt::format("time_dilation must be finite and >= 1, got {}",
                    options.time_dilation));
  }
  if (options.profile == nullptr) {
    return Status::InvalidArgument(
        "profile: the real-time platform pads every callback to its profile "
        "cost and needs a cost profile");
  }
  if (!(options.cpu_share > 0.0 && options.cpu_share <= 1.0)) {
    return Status::InvalidArgument(
        fmt::format("cpu_share must be in (0, 1], got {}", options.cpu_share));
  }
  ADSE_RETURN_IF_ERROR(ValidateCostProfile(*options.profile));
  std::set<int> seen;
  for (int cpu : options.host_cpus) {
    if (cpu < 0 || cpu >= CPU_SETSIZE || !seen.insert(cpu).second) {
      return Status::InvalidArgument(fmt::format(
          "host_cpus: {} is negative, too large or listed twice", cpu));
    }
  }
  return Status::Ok();
}

Result<std::unique_ptr<Executor>> CreateRealTimeExecutor(
    const Graph* graph, const RealTimeOptions& options) {
  if (graph == nullptr) return Status::InvalidArgument("graph is null");
  ADSE_RETURN_IF_ERROR(ValidateRealTimeOptions(options));
  ADSE_RETURN_IF_ERROR(ValidateGraph(*graph));
  ADSE_RETURN_IF_ERROR(CheckProfileCovers(*options.profile, *graph));
  auto executor = std::make_unique<RealTimeExecutor>(graph, options);
  ADSE_RETURN_IF_ERROR(executor->Start());
  return std::unique_ptr<Executor>(std::move(executor));
}

}  // namespace adse::stack
