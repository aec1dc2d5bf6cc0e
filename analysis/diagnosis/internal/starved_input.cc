#include "analysis/diagnosis/internal/starved_input.h"

#include <algorithm>
#include <cstdint>
#include <map>

#include <fmt/format.h>

namespace adse::analysis::internal {
namespace {

// Takes and drops of one subscription, in time order.
struct QueueEvents {
  std::vector<double> takes_s;
  std::vector<double> drops_s;
};

// The node's other callbacks' executions, in start order (callbacks of one
// node exclude each other, so they do not overlap).
struct Execution {
  double start_s, end_s;
  int callback;
};

}  // namespace

std::vector<Finding> FindStarvedInputs(const runfile::RunData& run,
                                       double start_s, double end_s,
                                       const DiagnosisOptions& options,
                                       const std::vector<std::string>& node_of,
                                       const std::vector<TopicStats>& topics) {
  std::vector<Finding> out;
  const int num_callbacks = static_cast<int>(run.callback_info.size());
  const int num_topics = static_cast<int>(run.topic_names.size());
  const double window_s = end_s - start_s;
  if (!(window_s > 0.0) || static_cast<int>(node_of.size()) != num_callbacks) {
    return out;
  }
  std::map<int, QueueEvents> queues;  // by subscription callback
  for (int c = 0; c < num_callbacks; ++c) {
    const runfile::NamedCallback& info = run.callback_info[c];
    if (info.kind == runfile::CallbackKind::kSubscription && info.topic >= 0 &&
        info.topic < num_topics) {
      queues[c];
    }
  }
  for (const stack::TopicEvent& e : run.trace.topic_events) {
    auto it = queues.find(e.callback);
    if (it == queues.end() || e.t_s < start_s || e.t_s >= end_s) continue;
    if (e.kind == stack::TopicEvent::kTake) it->second.takes_s.push_back(e.t_s);
    if (e.kind == stack::TopicEvent::kDrop) it->second.drops_s.push_back(e.t_s);
  }
  std::map<std::string, std::vector<Execution>> by_node;
  for (const stack::CallbackRecord& r : run.trace.callbacks) {
    if (r.callback < 0 || r.callback >= num_callbacks || r.end_s <= start_s ||
        r.start_s >= end_s) {
      continue;
    }
    by_node[node_of[r.callback]].push_back({r.start_s, r.end_s, r.callback});
  }
  for (auto& [node, executions] : by_node) {
    std::sort(executions.begin(), executions.end(),
              [](const Execution& a, const Execution& b) {
                return a.start_s < b.start_s;
              });
  }

  for (auto& [c, q] : queues) {
    std::sort(q.takes_s.begin(), q.takes_s.end());
    std::sort(q.drops_s.begin(), q.drops_s.end());
    const std::vector<Execution>& executions = by_node[node_of[c]];
    // Stretches between takes (and the window's ends).
    std::vector<double> bounds = {start_s};
    bounds.insert(bounds.end(), q.takes_s.begin(), q.takes_s.end());
    bounds.push_back(end_s);
    double best_s = 0.0, best_from = 0.0, best_share = 0.0;
    int64_t best_drops = 0;
    std::map<int, double> best_busy;  // by other callback, in the stretch
    for (size_t i = 0; i + 1 < bounds.size(); ++i) {
      const double a = bounds[i], b = bounds[i + 1];
      if (b - a < options.starved_input_min_s || b - a <= best_s) continue;
      const int64_t drops =
          std::lower_bound(q.drops_s.begin(), q.drops_s.end(), b) -
          std::upper_bound(q.drops_s.begin(), q.drops_s.end(), a);
      if (drops < options.min_messages) continue;
      std::map<int, double> busy;
      double busy_s = 0.0;
      // From the last execution starting before `a` (the only one that can
      // reach into the stretch: they do not overlap).
      auto from = std::lower_bound(
          executions.begin(), executions.end(), a,
          [](const Execution& x, double t) { return x.start_s < t; });
      if (from != executions.begin()) --from;
      for (auto x_it = from; x_it != executions.end(); ++x_it) {
        const Execution& x = *x_it;
        if (x.start_s >= b) break;
        if (x.callback == c || x.end_s <= a) continue;
        const double s = std::min(x.end_s, b) - std::max(x.start_s, a);
        busy[x.callback] += s;
        busy_s += s;
      }
      // Some of the node's own work, whatever the share asked for: an idle
      // node starves nothing.
      const double share = busy_s / (b - a);
      if (!(busy_s > 0.0) || share < options.starved_input_busy_share) {
        continue;
      }
      best_s = b - a;
      best_from = a;
      best_share = share;
      best_drops = drops;
      best_busy = std::move(busy);
    }
    if (best_s <= 0.0) continue;

    const runfile::NamedCallback& info = run.callback_info[c];
    // The callback that held the node most of that time, and how many of
    // its fires (a timer's) were skipped, each due while one still waited.
    int holder = -1;
    double holder_s = -1.0;
    for (const auto& [other, s] : best_busy) {
      if (s > holder_s) {
        holder = other;
        holder_s = s;
      }
    }
    const int64_t overruns =
        holder < static_cast<int>(run.trace.timer_overruns.size())
            ? run.trace.timer_overruns[holder]
            : 0;
    Finding f;
    f.kind = FindingKind::kStarvedInput;
    f.node = node_of[c];
    f.topics = {run.topic_names[info.topic]};
    if (info.topic < static_cast<int>(topics.size())) {
      f.upstream = topics[info.topic].publisher;
    }
    f.severity = best_s / window_s;
    f.rates_hz = {{"starved_s", best_s},
                  {"from_s", best_from},
                  {"node_busy_share", best_share},
                  {"dropped", static_cast<double>(best_drops)},
                  {"holder_timer_overruns", static_cast<double>(overruns)}};
    f.remedies.push_back({RemedyKind::kOwnCallbackGroup, info.name});
    f.remedy = RemediesText(f.remedies);
    const std::string overrun_text =
        overruns > 0 ? fmt::format(
                           ", a timer that skipped {} fires in the "
                           "run, each due while the one before "
                           "still waited",
                           overruns)
                     : std::string();
    f.message = fmt::format(
        "{} took no message of {} for {:.1f} s from {:.1f} s while its node "
        "ran its other callbacks {:.0f}% of that time (mostly {}{}); {} "
        "messages dropped unread -> {}",
        info.name, f.topics[0], best_s, best_from, 100.0 * best_share,
        run.callback_info[holder].name, overrun_text, best_drops, f.remedy);
    out.push_back(std::move(f));
  }
  return out;
}

}  // namespace adse::analysis::internal
