#include "harness/campaign/replicas.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include <fmt/format.h>

#include "analysis/metrics/run_metrics.h"
#include "analysis/runfile/run_data.h"
#include "harness/spec/design_point.h"

namespace adse::campaign {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool Complete(const EvaluationRow& row) { return row.status == "complete"; }

bool Censored(const EvaluationRow& row) {
  return RowMetric(row, analysis::kCensoredMetric) == 1.0;
}

// The replica's value of `metric`: measured, or for a run stopped early on
// a constraint of it, the side of the bound the run lies on (+inf when the
// constraint fails for large values, -inf for small ones). Nothing when
// the run neither measured nor bounded it.
std::optional<double> ValueOf(const spec::Spec& spec, const EvaluationRow& row,
                              const std::string& metric) {
  if (!Complete(row)) return std::nullopt;
  const double value = RowMetric(row, metric);
  if (!std::isnan(value)) return value;
  if (!Censored(row)) return std::nullopt;
  const std::string constraint = runfile::ViolatedConstraint(row.reason);
  if (constraint.empty()) return std::nullopt;
  // Whether the constraint reads this metric, and which way it fails: it
  // is decided by the metric's value alone at the extremes.
  std::map<std::string, double> metrics = row.metrics;
  auto holds = [&](double v) -> std::optional<bool> {
    metrics[metric] = v;
    Result<bool> ok =
        spec::EvaluateConstraint(spec, constraint, metrics, row.point);
    if (!ok.ok()) return std::nullopt;
    return *ok;
  };
  const std::optional<bool> high = holds(1e12), low = holds(-1e12);
  if (!high || !low || *high == *low) return std::nullopt;
  return *high ? -kInf : kInf;
}

// The p-quantile of sorted `v` by linear interpolation; between a finite
// and an infinite value it is the infinite one (the run beyond a bound
// leaves the quantile unknown), between -inf and +inf NaN.
double Quantile(const std::vector<double>& v, double p) {
  const double at = p * static_cast<double>(v.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(at));
  const size_t hi = std::min(lo + 1, v.size() - 1);
  const double frac = at - static_cast<double>(lo);
  if (frac == 0.0 || v[lo] == v[hi]) return v[lo];
  if (std::isinf(v[lo]) && std::isinf(v[hi]))
    return std::numeric_limits<double>::quiet_NaN();
  if (std::isinf(v[lo])) return v[lo];
  if (std::isinf(v[hi])) return v[hi];
  return v[lo] + frac * (v[hi] - v[lo]);
}

std::optional<MetricSpread> Spread(const spec::Spec& spec,
                                   const std::vector<EvaluationRow>& replicas,
                                   const std::string& metric) {
  std::vector<double> values;
  for (const EvaluationRow& r : replicas) {
    if (std::optional<double> v = ValueOf(spec, r, metric)) {
      values.push_back(*v);
    }
  }
  if (values.empty()) return std::nullopt;
  std::sort(values.begin(), values.end());
  MetricSpread s;
  for (double v : values) (std::isinf(v) ? s.censored : s.measured) += 1;
  s.min = values.front();
  s.max = values.back();
  s.q1 = Quantile(values, 0.25);
  s.median = Quantile(values, 0.5);
  s.q3 = Quantile(values, 0.75);
  return s;
}

}  // namespace

EvaluationRow AggregateReplicas(const spec::Spec& spec,
                                std::vector<EvaluationRow> replicas) {
  if (replicas.size() == 1) return std::move(replicas.front());
  const int n = static_cast<int>(replicas.size());
  int complete = 0, feasible = 0, stopped = 0, attempts = 0;
  double wall_s = 0.0;
  bool simulated = false;
  std::set<std::string> names;
  for (const EvaluationRow& r : replicas) {
    complete += Complete(r);
    feasible += Complete(r) && r.feasible;
    stopped += Complete(r) && Censored(r);
    attempts += static_cast<int>(r.attempts);
    wall_s += r.wall_s;
    simulated = simulated || r.source == "simulated";
    if (Complete(r)) {
      for (const auto& [name, value] : r.metrics) names.insert(name);
    }
  }
  EvaluationRow row;
  row.feasible = 2 * feasible > n;
  row.unstable = feasible > 0 && feasible < complete;
  // Most runs stopped early: the metric they bound has no median even when
  // no run measured it.
  bool censored = 2 * stopped > n;
  for (const std::string& name : names) {
    if (name == analysis::kCensoredMetric) continue;
    const std::optional<MetricSpread> s = Spread(spec, replicas, name);
    if (!s) continue;
    if (std::isfinite(s->median)) {
      row.metrics[name] = s->median;
    } else {
      censored = true;
    }
  }
  if (names.count(analysis::kCensoredMetric) > 0) {
    row.metrics[analysis::kCensoredMetric] = censored ? 1.0 : 0.0;
  }
  // The run that stands for the point: agrees with it on feasibility and,
  // where possible, on censoring (a censored point reads its violated
  // constraint from the representative's reason).
  const EvaluationRow* representative = &replicas.front();
  int best = -1;
  for (const EvaluationRow& r : replicas) {
    if (!Complete(r)) continue;
    const int score = 1 + 2 * (r.feasible == row.feasible) +
                      (r.feasible == row.feasible && Censored(r) == censored);
    if (score > best) {
      best = score;
      representative = &r;
    }
  }
  row.index = replicas.front().index;
  row.iteration = replicas.front().iteration;
  row.point = representative->point;
  row.content_key = representative->content_key;
  row.seed = representative->seed;
  row.status = complete > 0 ? "complete" : representative->status;
  row.reason = representative->reason;
  row.bottlenecks_json = representative->bottlenecks_json;
  row.source = simulated ? "simulated" : replicas.front().source;
  row.attempts = attempts;
  row.wall_s = wall_s;
  if (complete == 0) row.metrics.clear();
  row.replicas = std::move(replicas);
  return row;
}

std::optional<MetricSpread> SpreadOf(const spec::Spec& spec,
                                     const EvaluationRow& row,
                                     const std::string& metric) {
  if (row.replicas.size() <= 1) return std::nullopt;
  return Spread(spec, row.replicas, metric);
}

std::string ReplicaSummary(const EvaluationRow& row) {
  const size_t n = std::max<size_t>(1, row.replicas.size());
  if (n == 1) return "1 run";
  size_t feasible = 0, failed = 0;
  for (const EvaluationRow& r : row.replicas) {
    feasible += Complete(r) && r.feasible;
    failed += !Complete(r);
  }
  std::string text =
      row.unstable
          ? fmt::format("unstable: feasible in {} of {} runs", feasible, n)
          : fmt::format("{} runs", n);
  if (failed > 0) text += fmt::format(", {} failed", failed);
  return text;
}

}  // namespace adse::campaign
