#include "analysis/diagnosis/diagnosis.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <set>
#include <tuple>
#include <utility>

#include <fmt/format.h>

#include "analysis/diagnosis/internal/starved_input.h"
#include "analysis/metrics/run_metrics.h"

namespace adse::analysis {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr char kExternal[] = "external";

// ---- Options ---------------------------------------------------------------

enum class Range { kAny, kNonNegative, kCount, kPositive, kFraction, kFlag };

struct OptionSpec {
  const char* name;
  double DiagnosisOptions::*field;
  Range range;
};

constexpr OptionSpec kOptionSpecs[] = {
    {"cpu_bound_base_fraction", &DiagnosisOptions::cpu_bound_base_fraction,
     Range::kNonNegative},
    {"cpu_bound_tighten_hz", &DiagnosisOptions::cpu_bound_tighten_hz,
     Range::kPositive},
    {"cpu_bound_floor_fraction", &DiagnosisOptions::cpu_bound_floor_fraction,
     Range::kNonNegative},
    {"cpu_bound_state_inputs_per_output",
     &DiagnosisOptions::cpu_bound_state_inputs_per_output, Range::kFlag},
    {"frequency_bound_fraction", &DiagnosisOptions::frequency_bound_fraction,
     Range::kFraction},
    {"frequency_bound_driving_inputs_only",
     &DiagnosisOptions::frequency_bound_driving_inputs_only, Range::kFlag},
    {"min_messages", &DiagnosisOptions::min_messages, Range::kCount},
    {"start_s", &DiagnosisOptions::start_s, Range::kNonNegative},
    {"end_s", &DiagnosisOptions::end_s, Range::kAny},
    {"remedy_exec_load", &DiagnosisOptions::remedy_exec_load, Range::kPositive},
    {"remedy_wait_ratio", &DiagnosisOptions::remedy_wait_ratio,
     Range::kPositive},
    {"starved_input_min_s", &DiagnosisOptions::starved_input_min_s,
     Range::kPositive},
    {"starved_input_busy_share", &DiagnosisOptions::starved_input_busy_share,
     Range::kFraction},
};

bool InRange(Range range, double v) {
  switch (range) {
    case Range::kAny:
      return true;
    case Range::kNonNegative:
      return v >= 0.0;
    case Range::kCount:
      return v >= 0.0 && v == std::floor(v);
    case Range::kPositive:
      return v > 0.0;
    case Range::kFraction:
      return v >= 0.0 && v < 1.0;
    case Range::kFlag:
      return v == 0.0 || v == 1.0;
  }
  return false;
}

const char* RangeText(Range range) {
  switch (range) {
    case Range::kAny:
      return "finite";
    case Range::kNonNegative:
      return ">= 0";
    case Range::kCount:
      return "a whole number >= 0";
    case Range::kPositive:
      return "> 0";
    case Range::kFraction:
      return "in [0, 1)";
    case Range::kFlag:
      return "0 or 1";
  }
  return "";
}

// ---- Helpers ---------------------------------------------------------------

// Length of [a0, a1] ∩ [b0, b1] (0 when disjoint or degenerate).
double Overlap(double a0, double a1, double b0, double b1) {
  return std::max(0.0, std::min(a1, b1) - std::max(a0, b0));
}

std::string Join(const std::vector<std::string>& parts, const char* sep) {
  std::string out;
  for (size_t i = 0; i < parts.size(); ++i) {
    if (i > 0) out += sep;
    out += parts[i];
  }
  return out;
}

double RunEnd(const runfile::RunData& run) {
  if (!run.ego.empty()) return run.ego.back().t_s;
  // No trajectory (a failed run): the last thing the trace saw.
  double end = 0.0;
  for (const auto& r : run.trace.callbacks) end = std::max(end, r.end_s);
  for (const auto& e : run.trace.topic_events) end = std::max(end, e.t_s);
  for (const auto& c : run.controls) end = std::max(end, c.t_s);
  return end;
}

int ParseCores(const runfile::RunData& run) {
  auto it = run.platform.find("cores");
  if (it == run.platform.end()) return 0;
  char* end = nullptr;
  const long v = std::strtol(it->second.c_str(), &end, 10);
  if (end == it->second.c_str() || v < 0 || v > 1 << 20) return 0;
  return static_cast<int>(v);
}

// Everything Diagnose needs indexed once, defensively against bad indices.
class TraceView {
 public:
  TraceView(const runfile::RunData& run, const DiagnosisOptions& options)
      : run_(run) {
    const double run_end = RunEnd(run);
    start_s_ =
        std::isfinite(options.start_s) ? std::max(0.0, options.start_s) : 0.0;
    end_s_ = (options.end_s < 0.0 || !std::isfinite(options.end_s))
                 ? run_end
                 : std::min(options.end_s, run_end);
    window_s_ = std::max(0.0, end_s_ - start_s_);
    for (const runfile::NamedCallback& info : run.callback_info) {
      if (info.node >= 0 &&
          info.node < static_cast<int>(run.node_names.size())) {
        node_of_.push_back(run.node_names[info.node]);
      } else {
        const size_t slash = info.name.rfind('/');
        node_of_.push_back(slash == std::string::npos
                               ? info.name
                               : info.name.substr(0, slash));
      }
    }
  }

  double start_s() const { return start_s_; }
  double end_s() const { return end_s_; }
  double window_s() const { return window_s_; }
  bool InWindow(double t) const { return t >= start_s_ && t < end_s_; }
  double Clip(double a, double b) const {
    return Overlap(a, b, start_s_, end_s_);
  }
  double Rate(int64_t count) const {
    return window_s_ > 0.0 ? static_cast<double>(count) / window_s_ : 0.0;
  }

  int num_callbacks() const {
    return static_cast<int>(run_.callback_info.size());
  }
  int num_topics() const { return static_cast<int>(run_.topic_names.size()); }
  bool ValidCallback(int c) const { return c >= 0 && c < num_callbacks(); }
  bool ValidTopic(int t) const { return t >= 0 && t < num_topics(); }

  std::string CallbackName(int c) const {
    return ValidCallback(c) ? run_.callback_info[c].name
                            : fmt::format("callback#{}", c);
  }
  // The node's name from callback_info, else the "<node>/" prefix of the
  // callback's name; "" for an unknown callback.
  const std::string& NodeOfCallback(int c) const {
    static const std::string kNone;
    return ValidCallback(c) ? node_of_[c] : kNone;
  }
  const std::vector<std::string>& node_of() const { return node_of_; }

 private:
  const runfile::RunData& run_;
  double start_s_ = 0.0, end_s_ = 0.0, window_s_ = 0.0;
  std::vector<std::string> node_of_;  // by callback index
};

// ---- Per-core utilisation --------------------------------------------------

// The trace keeps only each execution's lowest core and core count. The
// virtual executor gives a starting callback the lowest-numbered free cores,
// so replaying starts in time order recovers the exact cores held; where the
// replay disagrees with the recorded first_core (the real-time platform,
// processor sharing: first_core is the executor thread, and a team may
// run on any core), the range first_core..first_core+cores-1 is assumed,
// wrapped round the platform's cores. Executions there may overlap on a
// core (the OS shares it), so a core's utilisation is capped at 1.
std::vector<double> CoreUtilization(const runfile::RunData& run,
                                    const TraceView& view) {
  const auto& records = run.trace.callbacks;
  const int platform_cores = ParseCores(run);
  int num_cores = platform_cores;
  if (platform_cores == 0) {  // unknown: as many as the records name
    for (const auto& r : records) {
      if (r.first_core >= 0 && r.cores > 0) {
        num_cores = std::max(num_cores, r.first_core + r.cores);
      }
    }
  }
  std::vector<double> busy_s(num_cores, 0.0);
  std::vector<size_t> order(records.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return std::tie(records[a].start_s, records[a].first_core, a) <
           std::tie(records[b].start_s, records[b].first_core, b);
  });
  // End of the execution holding each core (-inf: free).
  std::vector<double> held_until(num_cores,
                                 -std::numeric_limits<double>::infinity());
  std::vector<int> cores;
  for (size_t i : order) {
    const stack::CallbackRecord& r = records[i];
    if (r.first_core < 0 || r.first_core >= num_cores || r.cores <= 0 ||
        r.cores > num_cores) {
      continue;
    }
    cores.clear();
    for (int c = 0; c < num_cores && static_cast<int>(cores.size()) < r.cores;
         ++c) {
      if (held_until[c] <= r.start_s) cores.push_back(c);
    }
    if (static_cast<int>(cores.size()) != r.cores ||
        cores.front() != r.first_core) {
      cores.clear();
      for (int c = r.first_core; c < r.first_core + r.cores; ++c) {
        cores.push_back(c % num_cores);
      }
    }
    const double busy = view.Clip(r.start_s, r.end_s);
    for (int c : cores) {
      held_until[c] = std::max(held_until[c], r.end_s);
      busy_s[c] += busy;
    }
  }
  std::vector<double> utilization(num_cores, 0.0);
  if (view.window_s() > 0.0) {
    for (int c = 0; c < num_cores; ++c) {
      utilization[c] = std::min(1.0, busy_s[c] / view.window_s());
    }
  }
  return utilization;
}

// ---- Remedy evidence for a cpu_bound subscription --------------------------

struct RemedyEvidence {
  double exec_load = 0.0;
  bool has_wait_ratio = false;
  double core_wait_ratio = 0.0;
  double core_wait_mean_s = 0.0;  // per run, for the message
  double cost_mean_s = 0.0;
};

// exec_load = p50(cost of the subscription's runs) x needed_hz
//           + sum over the node's other callbacks of their busy time / window,
// needed_hz being the rate it must take (the publish rate, or its node's
// output rate for a state input). Callbacks of one node exclude each other,
// so this is the share of time the node alone would need to take what it
// must: >= 1 means no number of cores helps, only faster ones.
// core_wait_ratio = sum over the subscription's runs of the part of
// [ready, start] during which no callback of its node was running (so it
// waited for a core, not for its own node) / sum of their costs.
RemedyEvidence ComputeRemedyEvidence(const runfile::RunData& run,
                                     const TraceView& view, int callback,
                                     double needed_hz) {
  RemedyEvidence ev;
  const std::string node = view.NodeOfCallback(callback);
  std::vector<std::pair<double, double>> node_busy;  // [start, end]
  std::vector<double> costs;
  double other_busy_s = 0.0;
  for (const auto& r : run.trace.callbacks) {
    if (!view.ValidCallback(r.callback) ||
        view.NodeOfCallback(r.callback) != node) {
      continue;
    }
    node_busy.emplace_back(r.start_s, r.end_s);
    if (r.callback == callback) {
      if (view.InWindow(r.ready_s)) costs.push_back(r.cost_s);
    } else {
      other_busy_s += view.Clip(r.start_s, r.end_s);
    }
  }
  const double other_load =
      view.window_s() > 0.0 ? other_busy_s / view.window_s() : 0.0;
  const double exec_p50 = costs.empty() ? 0.0 : Percentile(costs, 0.5);
  ev.exec_load = exec_p50 * needed_hz + other_load;

  std::sort(node_busy.begin(), node_busy.end());
  double wait_s = 0.0, cost_s = 0.0;
  int runs = 0;
  for (const auto& r : run.trace.callbacks) {
    if (r.callback != callback || !view.InWindow(r.ready_s)) continue;
    ++runs;
    double node_busy_s = 0.0;
    // Intervals of one node are disjoint; only those before r.start_s can
    // overlap its wait.
    auto it = std::lower_bound(node_busy.begin(), node_busy.end(), r.ready_s,
                               [](const std::pair<double, double>& iv,
                                  double t) { return iv.second <= t; });
    for (; it != node_busy.end() && it->first < r.start_s; ++it) {
      node_busy_s += Overlap(it->first, it->second, r.ready_s, r.start_s);
    }
    wait_s += std::max(0.0, (r.start_s - r.ready_s) - node_busy_s);
    cost_s += r.cost_s;
  }
  if (cost_s > 0.0) {
    ev.has_wait_ratio = true;
    ev.core_wait_ratio = wait_s / cost_s;
    ev.core_wait_mean_s = wait_s / runs;
    ev.cost_mean_s = cost_s / runs;
  }
  return ev;
}

bool FindingLess(const Finding& a, const Finding& b) {
  if (a.severity != b.severity) return a.severity > b.severity;
  const std::string& ta = a.topics.empty() ? std::string() : a.topics[0];
  const std::string& tb = b.topics.empty() ? std::string() : b.topics[0];
  return std::tie(a.kind, a.node, ta, a.message) <
         std::tie(b.kind, b.node, tb, b.message);
}

}  // namespace

Status SetOption(DiagnosisOptions* options, const std::string& name,
                 double value) {
  if (options == nullptr) return Status::Internal("SetOption: null options");
  for (const OptionSpec& spec : kOptionSpecs) {
    if (name != spec.name) continue;
    if (!std::isfinite(value) || !InRange(spec.range, value)) {
      return Status::InvalidArgument(
          fmt::format("diagnosis threshold {}={} out of range (must be {})",
                      name, value, RangeText(spec.range)));
    }
    options->*spec.field = value;
    return Status::Ok();
  }
  return Status::InvalidArgument(
      fmt::format("unknown diagnosis threshold '{}'; valid names: {}", name,
                  Join(DiagnosisOptionNames(), ", ")));
}

std::vector<std::string> DiagnosisOptionNames() {
  std::vector<std::string> names;
  for (const OptionSpec& spec : kOptionSpecs) names.emplace_back(spec.name);
  return names;
}

double AllowedDeficit(const DiagnosisOptions& options, double rate_hz) {
  return options.cpu_bound_base_fraction /
             (1.0 + std::max(0.0, rate_hz) / options.cpu_bound_tighten_hz) +
         options.cpu_bound_floor_fraction;
}

Diagnosis Diagnose(const runfile::RunData& run,
                   const DiagnosisOptions& options) {
  const TraceView view(run, options);
  Diagnosis d;
  d.window_start_s = view.start_s();
  d.window_s = view.window_s();
  const int num_topics = view.num_topics();
  const int num_callbacks = view.num_callbacks();

  // ---- Topic statistics ----
  std::vector<std::set<std::string>> publishers(num_topics);
  std::vector<int64_t> publishes(num_topics, 0);
  // Publishes per publisher callback (-1: external): in the window, and over
  // the whole run (for topics silent in the window).
  std::vector<std::map<int, int64_t>> window_pubs(num_topics);
  std::vector<std::map<int, int64_t>> run_pubs(num_topics);
  std::vector<bool> published_in_window(num_callbacks, false);
  // Per (topic, subscriber callback): takes and drops in the window.
  std::map<std::pair<int, int>, std::pair<int64_t, int64_t>> subs;
  std::map<std::pair<int, int>, std::vector<double>> take_times;
  for (int c = 0; c < num_callbacks; ++c) {
    const runfile::NamedCallback& info = run.callback_info[c];
    if (info.kind == runfile::CallbackKind::kSubscription &&
        view.ValidTopic(info.topic)) {
      subs[{info.topic, c}];
    }
  }
  for (const stack::TopicEvent& e : run.trace.topic_events) {
    if (!view.ValidTopic(e.topic)) continue;
    if (e.kind == stack::TopicEvent::kPublish) {
      const std::string& node = view.NodeOfCallback(e.callback);
      if (e.callback < 0) {
        publishers[e.topic].insert(kExternal);
      } else if (!node.empty()) {
        publishers[e.topic].insert(node);
      }
      const int publisher = e.callback < 0 ? -1 : e.callback;
      ++run_pubs[e.topic][publisher];
      if (view.InWindow(e.t_s)) {
        ++publishes[e.topic];
        ++window_pubs[e.topic][publisher];
        if (view.ValidCallback(publisher)) {
          published_in_window[publisher] = true;
        }
      }
      continue;
    }
    if (!view.InWindow(e.t_s) || !view.ValidCallback(e.callback)) continue;
    auto& counts = subs[{e.topic, e.callback}];
    if (e.kind == stack::TopicEvent::kTake) {
      ++counts.first;
      take_times[{e.topic, e.callback}].push_back(e.t_s);
    }
    if (e.kind == stack::TopicEvent::kDrop) ++counts.second;
  }
  d.topics.resize(num_topics);
  for (int t = 0; t < num_topics; ++t) {
    TopicStats& ts = d.topics[t];
    ts.name = run.topic_names[t];
    ts.publisher = Join({publishers[t].begin(), publishers[t].end()}, ", ");
    ts.publishes = publishes[t];
    ts.publish_rate_hz = view.Rate(publishes[t]);
  }
  for (const auto& [key, counts] : subs) {  // ordered by (topic, callback)
    SubscriberStats s;
    s.callback = view.CallbackName(key.second);
    s.takes = counts.first;
    s.drops = counts.second;
    s.take_rate_hz = view.Rate(counts.first);
    std::vector<double>& takes = take_times[key];
    std::sort(takes.begin(), takes.end());
    double last_s = view.start_s();
    for (double t : takes) {
      s.longest_gap_s = std::max(s.longest_gap_s, t - last_s);
      last_s = t;
    }
    s.longest_gap_s = std::max(s.longest_gap_s, view.end_s() - last_s);
    d.topics[key.first].subscribers.push_back(std::move(s));
  }

  // ---- Callback statistics ----
  std::vector<std::vector<double>> latencies(num_callbacks),
      costs(num_callbacks);
  std::vector<double> busy_core_s(num_callbacks, 0.0);
  for (const stack::CallbackRecord& r : run.trace.callbacks) {
    if (!view.ValidCallback(r.callback)) continue;
    busy_core_s[r.callback] +=
        view.Clip(r.start_s, r.end_s) * std::max(1, r.cores);
    if (!view.InWindow(r.ready_s)) continue;
    latencies[r.callback].push_back(r.end_s - r.ready_s);
    costs[r.callback].push_back(r.cost_s);
  }
  d.callbacks.resize(num_callbacks);
  for (int c = 0; c < num_callbacks; ++c) {
    CallbackStats& cs = d.callbacks[c];
    cs.name = run.callback_info[c].name;
    cs.node = view.NodeOfCallback(c);
    cs.runs = static_cast<int64_t>(latencies[c].size());
    cs.latency_p50_s = Percentile(latencies[c], 0.5);
    cs.latency_p99_s = Percentile(latencies[c], 0.99);
    cs.latency_max_s = Percentile(latencies[c], 1.0);
    cs.exec_p50_s = Percentile(costs[c], 0.5);
    cs.utilization =
        view.window_s() > 0.0 ? busy_core_s[c] / view.window_s() : 0.0;
    if (c < static_cast<int>(run.trace.timer_overruns.size())) {
      cs.timer_overruns = run.trace.timer_overruns[c];
    }
  }

  d.core_utilization = CoreUtilization(run, view);

  std::vector<double> e2e;
  for (const runfile::ControlSample& c : run.controls) {
    if (view.InWindow(c.t_s) && c.stamp_s >= 0.0) {
      e2e.push_back(c.t_s - c.stamp_s);
    }
  }
  d.e2e_latency_p50_s = Percentile(e2e, 0.5);
  d.e2e_latency_p99_s = Percentile(e2e, 0.99);

  if (view.window_s() <= 0.0) return d;  // no rates, nothing to diagnose
  auto enough = [&](int t) {
    return static_cast<double>(publishes[t]) >= options.min_messages &&
           publishes[t] > 0;
  };

  // ---- CPU-bound: a subscription taking fewer messages than published ----
  // (or, for a state input, than its node's outputs need; see the option)
  std::map<int32_t, double> node_output_hz;
  for (int c = 0; c < num_callbacks; ++c) {
    if (!published_in_window[c]) continue;
    double& hz = node_output_hz[run.callback_info[c].node];
    hz = std::max(hz, view.Rate(d.callbacks[c].runs));
  }
  std::set<std::string> cpu_bound_nodes;
  for (const auto& [key, counts] : subs) {
    const auto [topic, callback] = key;
    if (run.callback_info[callback].kind !=
            runfile::CallbackKind::kSubscription ||
        run.callback_info[callback].topic != topic || !enough(topic)) {
      continue;
    }
    const double publish_hz = view.Rate(publishes[topic]);
    const double take_hz = view.Rate(counts.first);
    const auto output = node_output_hz.find(run.callback_info[callback].node);
    const bool state_input =
        options.cpu_bound_state_inputs_per_output != 0 &&
        !published_in_window[callback] && output != node_output_hz.end() &&
        output->second > 0.0 && output->second < publish_hz;
    const double needed_hz = state_input ? output->second : publish_hz;
    const double deficit = 1.0 - take_hz / needed_hz;
    const double allowed = AllowedDeficit(options, needed_hz);
    if (!(deficit > allowed)) continue;

    Finding f;
    f.kind = FindingKind::kCpuBound;
    f.node = view.NodeOfCallback(callback);
    f.topics = {run.topic_names[topic]};
    f.upstream = d.topics[topic].publisher;
    f.severity = deficit;
    const RemedyEvidence ev =
        ComputeRemedyEvidence(run, view, callback, needed_hz);
    f.rates_hz = {{"publish_hz", publish_hz},
                  {"take_hz", take_hz},
                  {"deficit", deficit},
                  {"allowed_deficit", allowed},
                  {"exec_load", ev.exec_load}};
    if (state_input) f.rates_hz["needed_hz"] = needed_hz;
    if (ev.has_wait_ratio) f.rates_hz["core_wait_ratio"] = ev.core_wait_ratio;

    const bool exec_limited = ev.exec_load >= options.remedy_exec_load;
    const bool core_limited =
        !ev.has_wait_ratio || ev.core_wait_ratio >= options.remedy_wait_ratio;
    if (exec_limited)
      f.remedies.push_back({RemedyKind::kHigherFrequency, f.node});
    if (core_limited) f.remedies.push_back({RemedyKind::kMoreCores, f.node});
    if (f.remedies.empty()) {  // neither alone: the one nearer its threshold
      f.remedies.push_back(
          {ev.exec_load / options.remedy_exec_load >=
                   ev.core_wait_ratio / options.remedy_wait_ratio
               ? RemedyKind::kHigherFrequency
               : RemedyKind::kMoreCores,
           f.node});
    }
    const bool from_sensor = publishers[topic].size() == 1 &&
                             *publishers[topic].begin() == kExternal;
    if (from_sensor) {
      f.remedies.push_back({RemedyKind::kLowerSensorRate, f.topics[0]});
    }
    f.remedy = RemediesText(f.remedies);

    const std::string wait_text =
        ev.has_wait_ratio ? fmt::format(
                                "waits for a core {:.2f}x its execution time "
                                "({:.3g} ms against {:.3g} ms a run)",
                                ev.core_wait_ratio, 1e3 * ev.core_wait_mean_s,
                                1e3 * ev.cost_mean_s)
                          : std::string("never ran in the window");
    const std::string needed_text =
        state_input ? fmt::format(
                          ", needing {:.2f} Hz (a state input: one message "
                          "per output of the node)",
                          needed_hz)
                    : std::string();
    f.message = fmt::format(
        "{} cannot keep up with {}: takes {:.2f} Hz of {:.2f} Hz published{} "
        "(deficit {:.1f}% > allowed {:.1f}% = {:g}/(1+{:.2f}/{:g})+{:g}); "
        "execution load {:.2f} (>= {:g} needs faster cores), {} "
        "(>= {:g} needs more cores) -> {}",
        f.node, f.topics[0], take_hz, publish_hz, needed_text, 100.0 * deficit,
        100.0 * allowed, options.cpu_bound_base_fraction, needed_hz,
        options.cpu_bound_tighten_hz, options.cpu_bound_floor_fraction,
        ev.exec_load, options.remedy_exec_load, wait_text,
        options.remedy_wait_ratio, f.remedy);
    cpu_bound_nodes.insert(f.node);
    d.findings.push_back(std::move(f));
  }

  // ---- Frequency-bound: one input much slower than the node's others ----
  // Where a topic's rate comes from: follow its main publisher upstream
  // (subscription -> its input topic) to a sensor, a timer or a cpu_bound
  // node, whichever comes first.
  auto main_publisher = [&](int topic) {
    const auto& counts =
        window_pubs[topic].empty() ? run_pubs[topic] : window_pubs[topic];
    int best = -2;  // none
    int64_t best_count = 0;
    for (const auto& [callback, count] : counts) {  // ascending: ties low
      if (count > best_count) {
        best = callback;
        best_count = count;
      }
    }
    return best;
  };
  auto trace_origin = [&](int topic) {
    std::set<int> seen;
    while (view.ValidTopic(topic) && seen.insert(topic).second) {
      const int p = main_publisher(topic);
      if (p == -1) {
        return RateOrigin{RateOriginKind::kSensor, run.topic_names[topic],
                          view.Rate(publishes[topic])};
      }
      if (!view.ValidCallback(p)) break;
      const runfile::NamedCallback& info = run.callback_info[p];
      if (cpu_bound_nodes.count(view.NodeOfCallback(p)) > 0) {
        return RateOrigin{RateOriginKind::kCpuBound, view.NodeOfCallback(p),
                          0.0};
      }
      if (info.kind == runfile::CallbackKind::kTimer) {
        return RateOrigin{RateOriginKind::kTimer, info.name,
                          info.period_s > 0.0 ? 1.0 / info.period_s : 0.0};
      }
      topic = info.topic;
    }
    return RateOrigin{RateOriginKind::kUnknown, "", 0.0};
  };

  // Inputs per node: distinct subscribed topics with enough publishes (and,
  // if asked, only those whose callback publishes: the node's outputs follow
  // them, unlike state kept for later).
  const bool driving_only = options.frequency_bound_driving_inputs_only != 0;
  std::map<std::string, std::set<int>> inputs;
  for (int c = 0; c < num_callbacks; ++c) {
    const runfile::NamedCallback& info = run.callback_info[c];
    if (info.kind == runfile::CallbackKind::kSubscription &&
        view.ValidTopic(info.topic) && enough(info.topic) &&
        (!driving_only || published_in_window[c])) {
      inputs[view.NodeOfCallback(c)].insert(info.topic);
    }
  }
  for (const auto& [node, topics] : inputs) {
    if (topics.size() < 2) continue;
    int slowest = -1;
    for (int t : topics) {  // ascending index: ties go to the lower index
      if (slowest < 0 || publishes[t] < publishes[slowest]) slowest = t;
    }
    std::vector<double> others;
    for (int t : topics) {
      if (t != slowest) others.push_back(view.Rate(publishes[t]));
    }
    const double slow_hz = view.Rate(publishes[slowest]);
    const double median_hz = Percentile(others, 0.5);
    if (!(median_hz > 0.0)) continue;
    const double deficit = 1.0 - slow_hz / median_hz;
    if (!(deficit > options.frequency_bound_fraction)) continue;

    Finding f;
    f.kind = FindingKind::kFrequencyBound;
    f.node = node;
    f.topics = {run.topic_names[slowest]};
    f.upstream = d.topics[slowest].publisher;
    f.severity = deficit;
    f.rates_hz = {{"slowest_hz", slow_hz},
                  {"others_median_hz", median_hz},
                  {"deficit", deficit},
                  {"allowed_fraction", options.frequency_bound_fraction}};
    for (int t : topics) {
      f.rates_hz["input_hz:" + run.topic_names[t]] = view.Rate(publishes[t]);
    }
    f.origin = trace_origin(slowest);
    const RateOrigin& origin = f.origin;
    if (origin.rate_hz > 0.0) f.rates_hz["origin_hz"] = origin.rate_hz;
    const std::string upstream =
        f.upstream.empty() ? std::string("unknown") : f.upstream;
    f.remedies.push_back(
        {RemedyKind::kRaisePublisherRate, f.topics[0], upstream});
    std::string cause;
    switch (origin.kind) {
      case RateOriginKind::kCpuBound:
        cause = fmt::format("upstream limit: {} is cpu_bound", origin.where);
        f.remedies.push_back({RemedyKind::kRelieveNode, origin.where});
        break;
      case RateOriginKind::kSensor:
        cause =
            fmt::format("its rate is set by the sensor topic {} ({:.2f} Hz)",
                        origin.where, origin.rate_hz);
        f.remedies.push_back({RemedyKind::kRaiseSensorRate, origin.where});
        break;
      case RateOriginKind::kTimer:
        cause = fmt::format(
            "its rate is set by the timer {} ({:.2f} Hz): a configuration "
            "choice",
            origin.where, origin.rate_hz);
        f.remedies.push_back({RemedyKind::kShortenTimerPeriod, origin.where});
        break;
      case RateOriginKind::kNone:
      case RateOriginKind::kUnknown:
        cause = "its origin is unknown";
        break;
    }
    f.remedy = RemediesText(f.remedies);
    f.message = fmt::format(
        "{} is limited by its input {} at {:.2f} Hz, {:.1f}% below the "
        "{:.2f} Hz median of its other inputs (> {:.1f}%); {} -> {}",
        node, f.topics[0], slow_hz, 100.0 * deficit, median_hz,
        100.0 * options.frequency_bound_fraction, cause, f.remedy);
    d.findings.push_back(std::move(f));
  }

  // ---- Starved input: a subscription its own node starves ----
  for (Finding& f :
       internal::FindStarvedInputs(run, view.start_s(), view.end_s(), options,
                                   view.node_of(), d.topics)) {
    d.findings.push_back(std::move(f));
  }

  std::sort(d.findings.begin(), d.findings.end(), FindingLess);
  return d;
}

}  // namespace adse::analysis
