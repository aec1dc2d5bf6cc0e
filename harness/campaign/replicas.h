// A point run several times (harness.replicas), each run with its own seed:
// its runs' rows folded into the one row that strategies, fronts, the
// headline and the index read, with the runs kept beside it.
#ifndef ADSE_HARNESS_CAMPAIGN_REPLICAS_H_
#define ADSE_HARNESS_CAMPAIGN_REPLICAS_H_

#include <optional>
#include <string>
#include <vector>

#include "harness/campaign/evaluation.h"
#include "harness/spec/spec.h"

namespace adse::campaign {

// What one metric did across a point's replicas. A run stopped early on a
// constraint of the metric has no value; it ranks beyond that constraint's
// bound (+inf above a time limit, -inf below a rate floor), so quantiles
// that fall on such runs are infinite.
struct MetricSpread {
  double median = 0.0;
  double min = 0.0, max = 0.0;
  double q1 = 0.0, q3 = 0.0;  // interquartile range (linear interpolation)
  int measured = 0;           // replicas with a measured value
  int censored = 0;           // replicas stopped early on this metric
};

// The point's row from its replicas' rows (replica order, at least one).
// One replica: its row unchanged. More:
// - metrics: each the median over the replicas (MetricSpread::median); a
//   median that is not finite (it falls on stopped runs) is left out, and
//   the row is censored then and when most runs were stopped early;
// - feasible when more than half the replicas are; unstable when the
//   complete replicas disagree on feasibility;
// - complete when any replica completed, failed when all failed;
// - content_key, seed, reason and diagnosis: the representative replica's,
//   the first complete one that agrees with the point on feasibility and
//   censoring (its run is the point's picture);
// - source: simulated when any replica was; attempts and wall_s summed.
EvaluationRow AggregateReplicas(const spec::Spec& spec,
                                std::vector<EvaluationRow> replicas);

// The point's row from all its runs (any order; each run's task_case set):
// each case's replicas folded by AggregateReplicas, then the cases, when
// the scenario has task.cases, folded into one row:
// - complete when every case is, else failed (the first failed case's
//   reason); feasible only when feasible in every case; unstable when any
//   case is;
// - a metric an objective or constraint judges: its worst over the cases
//   (a case stopped early on it ranks beyond the bound, and the row is
//   then censored); any other metric: the mean over the cases;
// - content_key, seed, reason, task_case and diagnosis: the representative
//   case's: the first case that made the point fail, then the first
//   infeasible one (stopped early where the point is censored), else the
//   case worst in the first objective the cases differ in;
// - replicas: every run, case by case.
EvaluationRow AggregatePoint(const spec::Spec& spec,
                             std::vector<EvaluationRow> runs);

// How many of the scenario's cases the row's runs drove (1 without cases).
int CaseCountOf(const EvaluationRow& row);

// `metric` across the row's replicas; nullopt when the row ran once, ran
// several cases, or no replica measured or bounded the metric.
std::optional<MetricSpread> SpreadOf(const spec::Spec& spec,
                                     const EvaluationRow& row,
                                     const std::string& metric);

// "unstable: feasible in 2 of 3 runs" for an unstable row, "3 runs" for a
// stable one, "1 run" for a point run once; "2 cases" or "2 cases x 3 runs"
// for a scenario with task.cases, followed for an unstable row by the
// cases whose runs disagree ("unstable: backing_in feasible in 2 of 3
// runs"); ", 1 failed" when runs failed.
std::string ReplicaSummary(const spec::Spec& spec, const EvaluationRow& row);

// The instability alone: "" for a stable row, else "unstable: feasible in
// 2 of 3 runs", naming each case whose runs disagree when there are cases.
std::string Instability(const spec::Spec& spec, const EvaluationRow& row);

}  // namespace adse::campaign

#endif  // ADSE_HARNESS_CAMPAIGN_REPLICAS_H_
