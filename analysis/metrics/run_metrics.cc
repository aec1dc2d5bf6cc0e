#include "analysis/metrics/run_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "analysis/metrics/parking_metrics.h"
#include "stack/algorithms/stop_reason.h"
#include "stack/base/decimal.h"

namespace adse::analysis {
namespace {

// Core-seconds during which the executions of `records` that start by
// `end_s` held more threads than `cores`: under processor sharing and in
// real time threads beyond the cores wait for one, so those are not busy
// cores. Run to completion never holds more (0 exactly).
double OversubscribedCoreS(const std::vector<stack::CallbackRecord>& records,
                           double end_s, int cores) {
  std::vector<std::pair<double, int>> steps;  // (time, threads added)
  for (const stack::CallbackRecord& r : records) {
    if (r.start_s > end_s || r.cores <= 0) continue;
    steps.push_back({r.start_s, r.cores});
    steps.push_back({r.end_s, -r.cores});
  }
  // Ends before starts at equal times: a core freed is taken at once.
  std::sort(steps.begin(), steps.end());
  double excess_s = 0.0;
  int threads = 0;
  for (size_t i = 0; i < steps.size(); ++i) {
    threads += steps[i].second;
    if (threads > cores && i + 1 < steps.size()) {
      excess_s += (threads - cores) * (steps[i + 1].first - steps[i].first);
    }
  }
  return excess_s;
}

// Seconds up to `end_s` that the planner's newest stop reason said
// localization_lost: each stop sample holds until the next one (a starved
// planner that publishes seldom still has no pose in between). NaN when
// the run file has no stop reasons (written before they were recorded).
double LocalizationLostS(const std::vector<runfile::StopSample>& stops,
                         double end_s) {
  if (stops.empty()) return std::numeric_limits<double>::quiet_NaN();
  double lost_s = 0.0;
  for (size_t i = 0; i < stops.size() && stops[i].t_s < end_s; ++i) {
    if (stops[i].reason != StopReason::kLocalizationLost) continue;
    const double until =
        i + 1 < stops.size() ? std::min(stops[i + 1].t_s, end_s) : end_s;
    lost_s += std::max(0.0, until - stops[i].t_s);
  }
  return lost_s;
}

}  // namespace

double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  const double pos =
      std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(lo + 1, values.size() - 1);
  return values[lo] +
         (pos - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

std::map<std::string, double> ComputeRunMetrics(
    const runfile::RunData& run, const RunMetricsOptions& options) {
  std::map<std::string, double> m;
  const bool completed = run.status == runfile::kRunComplete &&
                         run.termination_reason == "goal_reached";
  const double end_s = run.ego.empty() ? 0.0 : run.ego.back().t_s;
  m["completed"] = completed ? 1.0 : 0.0;
  m[kCensoredMetric] = runfile::EndedEarly(run.status) ? 1.0 : 0.0;
  // The world's clock is a sum of fixed steps, whose float error reaches
  // the last digits (41 s as 40.99999999999981); the time is a whole
  // number of steps, so those digits are noise.
  m["nav_time_s"] = RoundToSignificantDigits(end_s, kDecimalDigits);

  auto topic_index = [&](const std::string& name) {
    for (size_t i = 0; i < run.topic_names.size(); ++i) {
      if (run.topic_names[i] == name) return static_cast<int>(i);
    }
    return -1;
  };
  const int control = topic_index(options.control_topic);
  const int lidar = topic_index(options.lidar_topic);
  int64_t control_count = 0, drops = 0, lidar_drops = 0;
  for (const stack::TopicEvent& e : run.trace.topic_events) {
    if (e.t_s > end_s) continue;
    if (e.kind == stack::TopicEvent::kPublish && e.topic == control)
      ++control_count;
    if (e.kind == stack::TopicEvent::kDrop) {
      ++drops;
      if (e.topic == lidar) ++lidar_drops;
    }
  }
  m["ctrl_rate_hz"] =
      end_s > 0 ? static_cast<double>(control_count) / end_s : 0.0;
  m["dropped_messages"] = static_cast<double>(drops);
  m["lidar_frames_dropped"] = static_cast<double>(lidar_drops);

  std::vector<double> latencies;
  latencies.reserve(run.controls.size());
  for (const runfile::ControlSample& c : run.controls) {
    if (c.t_s <= end_s && c.stamp_s >= 0.0)
      latencies.push_back(c.t_s - c.stamp_s);
  }
  m["e2e_latency_p50_s"] = Percentile(latencies, 0.5);
  m["e2e_latency_p99_s"] = Percentile(latencies, 0.99);
  m["collisions"] = static_cast<double>(run.collisions.size());
  // Contacts not known to be the other's doing count against the ego.
  m["ego_collisions"] = static_cast<double>(std::count_if(
      run.collisions.begin(), run.collisions.end(),
      [](const runfile::CollisionEvent& c) { return c.ego_caused != 0; }));

  double busy_core_s = 0.0;
  for (const stack::CallbackRecord& r : run.trace.callbacks) {
    if (r.start_s <= end_s) busy_core_s += r.cost_s * r.cores;
  }
  m["callbacks"] = static_cast<double>(run.trace.callbacks.size());
  double cores = 0.0;
  if (auto it = run.platform.find("cores"); it != run.platform.end()) {
    cores = std::atof(it->second.c_str());
  }
  if (cores >= 1) {
    busy_core_s -= OversubscribedCoreS(run.trace.callbacks, end_s,
                                       static_cast<int>(cores));
  }
  m["cpu_utilization"] =
      (cores > 0 && end_s > 0) ? busy_core_s / (cores * end_s) : 0.0;
  m["localization_lost_s"] = LocalizationLostS(run.stop_reasons, end_s);
  AddParkingMetrics(run, &m);
  return m;
}

}  // namespace adse::analysis
