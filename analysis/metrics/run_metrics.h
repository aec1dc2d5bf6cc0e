// The per-run metrics every strategy and report reads, computed from a
// run's stored data (never from the simulator), so re-analysis offline is
// the same code as online.
#ifndef ADSE_ANALYSIS_METRICS_RUN_METRICS_H_
#define ADSE_ANALYSIS_METRICS_RUN_METRICS_H_

#include <map>
#include <string>

#include "analysis/runfile/run_data.h"

namespace adse::analysis {

struct RunMetricsOptions {
  // Topic whose publish rate is the control-command rate.
  std::string control_topic = "/control/command";
  // Topic of the raw LiDAR scans (for drop counts).
  std::string lidar_topic = "/sensing/lidar/points_raw";
};

// 1 when early stop ended the run (status infeasible): every other run
// metric is then measured up to the stop, so censored, and nav_time_s is
// only a lower bound.
inline constexpr char kCensoredMetric[] = "censored";

// The share of the ideal path's length driven by the end of the run (0-1;
// harness/report sets it from the deviation fit). Of a run stopped early it
// is the one metric not censored: how far the car got says how far from
// arriving in time it was.
inline constexpr char kDrivenFractionMetric[] = "driven_fraction";

// Metrics by name: completed (0/1), censored (0/1), nav_time_s (time to the
// goal; when not completed, the time the run ended), ctrl_rate_hz (control
// commands per second over the navigation), e2e_latency_p50_s /
// e2e_latency_p99_s (control command publish time minus the stamp of the LiDAR
// scan it derives from), dropped_messages (all topics), lidar_frames_dropped,
// collisions, ego_collisions (those the ego caused, or not known not to
// have), callbacks (executions), cpu_utilization (busy core-seconds /
// cores x nav time; an execution holds `cores` threads from start to end,
// and no more cores than the platform has are busy at once),
// localization_lost_s (time the planner had no valid pose to drive by:
// its newest stop reason localization_lost; NaN without stop reasons).
std::map<std::string, double> ComputeRunMetrics(
    const runfile::RunData& run, const RunMetricsOptions& options = {});

// Linear-interpolated percentile (q in [0, 1]) of unsorted values; NaN
// when empty.
double Percentile(std::vector<double> values, double q);

}  // namespace adse::analysis

#endif  // ADSE_ANALYSIS_METRICS_RUN_METRICS_H_
