// `adse fidelity`: the virtual platform held against real execution. Each
// point runs on the virtual platform (deterministic: once as the scenario
// says, and a few times with every cost moved by parts in ten thousand)
// and K times on the real-time platform (noisy), with the same scenario
// and seed; the comparison says, metric by metric and callback by
// callback, how far the model is from what the host's scheduler did.
#ifndef ADSE_HARNESS_FIDELITY_FIDELITY_H_
#define ADSE_HARNESS_FIDELITY_FIDELITY_H_

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "analysis/runfile/run_data.h"
#include "harness/spec/spec.h"
#include "stack/base/status.h"

namespace adse::fidelity {

struct FidelityOptions {
  // Real-time runs per point (their median is compared), >= 1.
  int runs = 3;
  // The virtual platform's dispatches to hold against the same real-time
  // runs, one virtual run each; empty: the scenario's platform.dispatch.
  std::vector<spec::Dispatch> dispatches;
  // Virtual runs per dispatch besides the scenario's own, each with every
  // cost scaled by PerturbedCostScale(k), k = 1..n, >= 0. On a starved
  // core the closed loop answers so small a change (far below what a
  // profile can measure) by running its callbacks in another order, and
  // its control rate moves by a fifth or more: one virtual run is one draw
  // of that loop, as one real-time run is. The run metrics are compared
  // as the median of these runs and the scenario's own.
  int perturbed_runs = 4;
  // Told before each run: (point text, "virtual[ <dispatch>]" |
  // "virtual[ <dispatch>] perturbed k/n" | "real-time k/K").
  std::function<void(const std::string&, const std::string&)> on_run;
};

// The cost factor of the k-th perturbed virtual run (k >= 1): 1 + 1e-4,
// 1 - 1e-4, 1 + 2e-4, 1 - 2e-4, ...
double PerturbedCostScale(int k);

// One compared quantity: the virtual platform's value, the real-time
// runs' values, and the relative difference of their median from it.
struct Comparison {
  std::string name;
  // A run metric: the median of the virtual runs that had it (the
  // scenario's own and the perturbed ones); a callback's: of the
  // scenario's own run.
  double virtual_value = 0.0;
  // A run metric's value in each virtual run that had it, the scenario's
  // own first (only it when no run was perturbed), and how many lacked it.
  std::vector<double> virtual_runs;
  int virtual_runs_without = 0;
  std::vector<double> realtime;  // one per real-time run that had it
  // Real-time runs that lacked it (a nav time of a run that did not reach
  // the goal, a callback that never ran): the target is then missed, since
  // the median of the others hides an outcome the model did not predict;
  // so it is when a virtual run lacked it.
  int runs_without = 0;
  // For a callback: its invocations in the virtual run and in each
  // real-time run, and how many of them were compared: the first
  // `compared_count` of every run (the fewest any run made), since the
  // i-th invocation draws the same cost on both platforms. A p50 of a few
  // invocations (the scan chain on a starved core runs a dozen times) is
  // still a draw of the cost profile more than a measurement.
  int virtual_count = 0;
  std::vector<int> realtime_counts;
  int compared_count = 0;
  double realtime_median = 0.0;
  // (median - virtual) / |virtual|; NaN when either is missing or virtual
  // is 0.
  double difference = 0.0;
  // Issue 15's target for it (|difference| <= tolerance), if any.
  std::optional<double> tolerance;
  bool met() const;
};

struct PointFidelity {
  std::string point;        // FormatPoint text
  std::string dispatch;     // the virtual run's platform.dispatch
  std::string confinement;  // where the real-time runs ran
  std::string clock_by;     // what stood for the clock there
  // How each run ended (termination_reason): the virtual run's, the
  // perturbed virtual runs', then one per real-time run.
  std::string virtual_outcome;
  std::vector<std::string> perturbed_outcomes;
  std::vector<std::string> realtime_outcomes;
  // nav_time_s (only of runs that reached the goal) and ctrl_rate_hz
  // (targets 10 %), e2e_latency_p50_s, dropped_messages,
  // lidar_frames_dropped, localization_lost_s, and the sensing-to-control
  // chain's mean.
  std::vector<Comparison> metrics;
  // Per callback of at least 1 ms on the virtual platform: the p50 of its
  // execution latency, start to end (target 20 %), then its p99, each over
  // the invocations every run made (`Comparison::compared_count`).
  std::vector<Comparison> callback_p50_ms;
  std::vector<Comparison> callback_p99_ms;
  // Per callback above that reports its work (points, iterations x
  // points): the p50 of its latency per 1000 work units. A callback whose
  // work depends on the closed loop (NDT's iterations) can disagree in
  // latency only because one platform gave it more work; this tells the
  // executor model's error from that.
  std::vector<Comparison> callback_p50_ms_per_kunit;
};

// One point's runs: one virtual run per dispatch (and its perturbed
// runs), and the real-time runs.
struct PointRuns {
  std::string point;  // FormatPoint text
  std::vector<spec::Dispatch> dispatches;
  std::vector<runfile::RunData> virtual_runs;  // one per dispatch
  // Per dispatch, the runs with perturbed costs (k = 1..n in order).
  std::vector<std::vector<runfile::RunData>> perturbed_runs;
  std::vector<runfile::RunData> realtime_runs;
};

// Whether `point` can be run both ways here, said before any run: it lies
// in the space, the scenario has a cost profile (the real-time platform
// pads every callback to it), and this process may use a host CPU per
// core of the point. InvalidArgument naming what is missing; Unavailable
// naming both CPU counts.
Status CheckPointRunnable(const spec::Spec& spec,
                          const spec::DesignPoint& point);

// Runs `point` both ways. Early stop is off for these runs: a censored
// time would compare nothing. Errors: the point's or the platform's
// (InvalidArgument for a point outside the space or a scenario without a
// cost profile, Unavailable when the host has too few CPUs).
Result<PointRuns> RunPoint(const spec::Spec& spec,
                           const spec::DesignPoint& point,
                           const FidelityOptions& options);

// The runs an earlier `adse fidelity` wrote to `<dir>/runs`
// (N-virtual[-<dispatch>].h5, N-virtual[-<dispatch>]-pK.h5,
// N-realtime-K.h5), one PointRuns per N in N's order (its dispatches in
// Dispatch's order, perturbed runs by K), to compare again offline; their
// run metrics are measured again from their data (ComputeRunMetrics).
// Errors: NotFound when the folder holds no such run; InvalidArgument
// naming the file for a name not of that form, a point without a virtual
// or a real-time run, a perturbed run without its virtual run, or a
// virtual run whose dispatch is unknown; a run file's own error
// (Corruption).
Result<std::vector<PointRuns>> ReadPointRuns(const std::string& dir);

// The virtual run of `runs.dispatches[i]` held against the real-time runs.
PointFidelity ComparePoint(const PointRuns& runs, size_t i);

// The quantities of `virtual_run` (with `perturbed_runs`, its runs with
// perturbed costs) and `realtime_runs` (exposed for tests).
PointFidelity CompareRuns(
    const runfile::RunData& virtual_run,
    const std::vector<runfile::RunData>& realtime_runs,
    const std::vector<runfile::RunData>& perturbed_runs = {});

// The table `adse fidelity` prints for one point.
std::string FormatPointFidelity(const PointFidelity& fidelity);

// How often each dispatch met the targets over `points` (each point's
// comparisons for every dispatch): the control rate and nav time within
// 10 %, the callback p50s within 20 %, and the median |p50 difference|.
std::string FormatDispatchSummary(const std::vector<PointFidelity>& points);

}  // namespace adse::fidelity

#endif  // ADSE_HARNESS_FIDELITY_FIDELITY_H_
