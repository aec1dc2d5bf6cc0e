#include "harness/campaign/replicas.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "analysis/metrics/run_metrics.h"
#include "analysis/runfile/run_data.h"
#include "harness/spec/design_point.h"
#include "harness/spec/spec.h"

namespace adse::campaign {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool Censored(const EvaluationRow& row) {
  return RowMetric(row, analysis::kCensoredMetric) == 1.0;
}

// Which way `constraint` fails on `metric`, the row's other metrics and
// point held: +1 when it holds at `low` and not at `high` (a bound from
// above), -1 the other way round, 0 when it does not read the metric so
// or cannot be evaluated.
int FailingSide(const spec::Spec& spec, const std::string& constraint,
                const std::string& metric, const EvaluationRow& row, double low,
                double high) {
  std::map<std::string, double> metrics = row.metrics;
  auto holds = [&](double v) -> std::optional<bool> {
    metrics[metric] = v;
    Result<bool> ok =
        spec::EvaluateConstraint(spec, constraint, metrics, row.point);
    if (!ok.ok()) return std::nullopt;
    return *ok;
  };
  const std::optional<bool> at_high = holds(high), at_low = holds(low);
  if (!at_high || !at_low || *at_high == *at_low) return 0;
  return *at_high ? -1 : 1;
}

// The replica's value of `metric`: measured, or for a run stopped early on
// a constraint of it, the side of the bound the run lies on (+inf when the
// constraint fails for large values, -inf for small ones). Nothing when
// the run neither measured nor bounded it.
std::optional<double> ValueOf(const spec::Spec& spec, const EvaluationRow& row,
                              const std::string& metric) {
  if (!row.complete()) return std::nullopt;
  const double value = RowMetric(row, metric);
  if (!std::isnan(value)) return value;
  if (!Censored(row)) return std::nullopt;
  const std::string constraint = runfile::ViolatedConstraint(row.reason);
  if (constraint.empty()) return std::nullopt;
  const int side = FailingSide(spec, constraint, metric, row, -1e12, 1e12);
  if (side == 0) return std::nullopt;
  return side > 0 ? kInf : -kInf;
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

// The folded row's identity: the evaluation of `first`, and the run that
// stands for it (its key, seed, case, reason and diagnosis).
void TakeIdentity(const EvaluationRow& first,
                  const EvaluationRow& representative, EvaluationRow* row) {
  row->index = first.index;
  row->iteration = first.iteration;
  row->task_case = representative.task_case;
  row->point = representative.point;
  row->content_key = representative.content_key;
  row->seed = representative.seed;
  row->reason = representative.reason;
  row->bottlenecks_json = representative.bottlenecks_json;
}

// Which way `metric` gets worse as the spec judges it: +1 when larger is
// worse (a minimised objective, a constraint failing above a bound), -1
// when smaller is, 0 when no objective or constraint says. Constraints are
// probed at the metric's extremes (0 and 1 for a boolean), the other
// metrics as in `sample`; a bound that fails at both extremes (a count
// that must be `== 0`) is probed again between zero and each extreme.
int WorseDirection(const spec::Spec& spec, const std::string& metric,
                   const EvaluationRow& sample) {
  for (const spec::Objective& o : spec.objectives) {
    if (o.metric == metric) return o.minimize ? 1 : -1;
  }
  bool boolean = false;
  for (const spec::MetricInfo& m : spec::KnownMetrics()) {
    if (m.name == metric) boolean = m.boolean;
  }
  const std::vector<std::pair<double, double>> probes =
      boolean ? std::vector<std::pair<double, double>>{{0.0, 1.0}}
              : std::vector<std::pair<double, double>>{
                    {-1e12, 1e12}, {0.0, 1e12}, {-1e12, 0.0}};
  for (const auto& [low, high] : probes) {
    for (const std::string& constraint : spec.constraints) {
      const int side = FailingSide(spec, constraint, metric, sample, low, high);
      if (side != 0) return side;
    }
  }
  return 0;
}

// How many of the spec's constraints `row` fails (one that cannot be
// evaluated on it counts as failed).
int FailedConstraints(const spec::Spec& spec, const EvaluationRow& row) {
  int failed = 0;
  for (const std::string& constraint : spec.constraints) {
    Result<bool> holds =
        spec::EvaluateConstraint(spec, constraint, row.metrics, row.point);
    failed += !holds.ok() || !*holds;
  }
  return failed;
}

// The infeasible case that fails the most constraints, the first of equals:
// the one whose reason explains the point's failures (a case that parked
// but touched a car does not stand for one that also did not park).
const EvaluationRow* MostFailing(const spec::Spec& spec,
                                 const std::vector<EvaluationRow>& cases) {
  const EvaluationRow* most = nullptr;
  int most_failed = -1;
  for (const EvaluationRow& c : cases) {
    if (c.feasible) continue;
    const int failed = FailedConstraints(spec, c);
    if (failed > most_failed) {
      most = &c;
      most_failed = failed;
    }
  }
  return most;
}

// The cases' rows (one per case, in case order) folded into the point's.
EvaluationRow AggregateCases(const spec::Spec& spec,
                             std::vector<EvaluationRow> cases) {
  if (cases.size() == 1) return std::move(cases.front());
  bool complete = true, feasible = true, unstable = false, censored = false;
  bool simulated = false, has_censored_metric = false;
  int64_t attempts = 0;
  double wall_s = 0.0;
  std::set<std::string> names;
  for (const EvaluationRow& c : cases) {
    complete = complete && c.complete();
    feasible = feasible && c.complete() && c.feasible;
    unstable = unstable || c.unstable;
    censored = censored || (c.complete() && Censored(c));
    simulated = simulated || c.source == "simulated";
    attempts += c.attempts;
    wall_s += c.wall_s;
    for (const auto& [name, value] : c.metrics) names.insert(name);
  }
  has_censored_metric = names.erase(analysis::kCensoredMetric) > 0;

  EvaluationRow row;
  if (complete) {
    for (const std::string& name : names) {
      const int worse = WorseDirection(spec, name, cases.front());
      std::vector<double> values;
      for (const EvaluationRow& c : cases) {
        if (std::optional<double> v = ValueOf(spec, c, name)) {
          values.push_back(*v);
        }
      }
      if (values.empty()) continue;
      if (worse != 0) {
        const double worst =
            worse > 0 ? *std::max_element(values.begin(), values.end())
                      : *std::min_element(values.begin(), values.end());
        if (std::isfinite(worst)) {
          row.metrics[name] = worst;
        } else {
          censored = true;
        }
      } else if (values.size() == cases.size() &&
                 std::all_of(values.begin(), values.end(),
                             [](double v) { return std::isfinite(v); })) {
        double sum = 0.0;
        for (double v : values) sum += v;
        row.metrics[name] = sum / static_cast<double>(values.size());
      }
    }
    if (has_censored_metric) {
      row.metrics[analysis::kCensoredMetric] = censored ? 1.0 : 0.0;
    }
  }

  // The representative case.
  const EvaluationRow* representative = &cases.front();
  auto first = [&](auto&& pred) -> const EvaluationRow* {
    for (const EvaluationRow& c : cases) {
      if (pred(c)) return &c;
    }
    return nullptr;
  };
  if (!complete) {
    representative =
        first([](const EvaluationRow& c) { return !c.complete(); });
  } else if (!feasible) {
    const EvaluationRow* stopped = first(
        [](const EvaluationRow& c) { return !c.feasible && Censored(c); });
    representative =
        censored && stopped != nullptr ? stopped : MostFailing(spec, cases);
  } else {
    for (const spec::Objective& o : spec.objectives) {
      const EvaluationRow* worst = nullptr;
      bool differ = false;
      for (const EvaluationRow& c : cases) {
        const double v = RowMetric(c, o.metric);
        if (std::isnan(v)) continue;
        if (worst == nullptr) {
          worst = &c;
          continue;
        }
        const double w = RowMetric(*worst, o.metric);
        differ = differ || v != w;
        if (o.minimize ? v > w : v < w) worst = &c;
      }
      if (differ) {
        representative = worst;
        break;
      }
    }
  }

  TakeIdentity(cases.front(), *representative, &row);
  row.status = complete ? runfile::kRunComplete : representative->status;
  row.feasible = feasible;
  row.unstable = unstable;
  row.source = simulated ? "simulated" : cases.front().source;
  row.attempts = attempts;
  row.wall_s = wall_s;
  for (EvaluationRow& c : cases) {
    if (c.replicas.empty()) {
      row.replicas.push_back(std::move(c));
    } else {
      for (EvaluationRow& run : c.replicas) {
        row.replicas.push_back(std::move(run));
      }
    }
  }
  return row;
}

}  // namespace

EvaluationRow AggregatePoint(const spec::Spec& spec,
                             std::vector<EvaluationRow> runs) {
  std::map<int64_t, std::vector<EvaluationRow>> by_case;
  for (EvaluationRow& run : runs) {
    by_case[run.task_case].push_back(std::move(run));
  }
  std::vector<EvaluationRow> cases;
  for (auto& [task_case, replicas] : by_case) {
    cases.push_back(AggregateReplicas(spec, std::move(replicas)));
  }
  return AggregateCases(spec, std::move(cases));
}

int CaseCountOf(const EvaluationRow& row) {
  std::set<int64_t> cases;
  for (const EvaluationRow& run : row.replicas) cases.insert(run.task_case);
  return std::max<int>(1, static_cast<int>(cases.size()));
}

EvaluationRow AggregateReplicas(const spec::Spec& spec,
                                std::vector<EvaluationRow> replicas) {
  if (replicas.size() == 1) return std::move(replicas.front());
  const int n = static_cast<int>(replicas.size());
  int complete = 0, feasible = 0, stopped = 0, attempts = 0;
  double wall_s = 0.0;
  bool simulated = false;
  std::set<std::string> names;
  for (const EvaluationRow& r : replicas) {
    complete += r.complete();
    feasible += r.complete() && r.feasible;
    stopped += r.complete() && Censored(r);
    attempts += static_cast<int>(r.attempts);
    wall_s += r.wall_s;
    simulated = simulated || r.source == "simulated";
    if (r.complete()) {
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
    if (!r.complete()) continue;
    const int score = 1 + 2 * (r.feasible == row.feasible) +
                      (r.feasible == row.feasible && Censored(r) == censored);
    if (score > best) {
      best = score;
      representative = &r;
    }
  }
  TakeIdentity(replicas.front(), *representative, &row);
  row.status = complete > 0 ? runfile::kRunComplete : representative->status;
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
  if (row.replicas.size() <= 1 || CaseCountOf(row) > 1) return std::nullopt;
  return Spread(spec, row.replicas, metric);
}

std::string Instability(const spec::Spec& spec, const EvaluationRow& row) {
  if (!row.unstable) return {};
  // Per case: its runs, the complete ones and the feasible ones; a case
  // is unstable when its complete runs disagree (AggregateReplicas).
  struct Counts {
    int runs = 0, complete = 0, feasible = 0;
  };
  std::map<int64_t, Counts> by_case;
  for (const EvaluationRow& r : row.replicas) {
    Counts& counts = by_case[r.task_case];
    ++counts.runs;
    counts.complete += r.complete() ? 1 : 0;
    counts.feasible += r.complete() && r.feasible ? 1 : 0;
  }
  const bool several = by_case.size() > 1;
  std::vector<std::string> parts;
  for (const auto& [index, counts] : by_case) {
    if (counts.feasible == 0 || counts.feasible == counts.complete) continue;
    parts.push_back(
        fmt::format("{}feasible in {} of {} runs",
                    several ? spec::CaseName(spec, index) + " " : std::string(),
                    counts.feasible, counts.runs));
  }
  if (parts.empty()) return "unstable";
  return fmt::format("unstable: {}", fmt::join(parts, ", "));
}

std::string ReplicaSummary(const spec::Spec& spec, const EvaluationRow& row) {
  const size_t n = std::max<size_t>(1, row.replicas.size());
  if (n == 1) return "1 run";
  size_t failed = 0;
  for (const EvaluationRow& r : row.replicas) failed += !r.complete();
  const int cases = CaseCountOf(row);
  std::string text;
  if (cases > 1) {
    text = fmt::format("{} cases", cases);
    if (n > static_cast<size_t>(cases)) {
      text += fmt::format(" x {} runs", n / static_cast<size_t>(cases));
    }
    if (row.unstable) text += ", " + Instability(spec, row);
  } else {
    text = row.unstable ? Instability(spec, row) : fmt::format("{} runs", n);
  }
  if (failed > 0) text += fmt::format(", {} failed", failed);
  return text;
}

}  // namespace adse::campaign
