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

// `metric` across the row's replicas; nullopt when the row ran once or no
// replica measured or bounded the metric.
std::optional<MetricSpread> SpreadOf(const spec::Spec& spec,
                                     const EvaluationRow& row,
                                     const std::string& metric);

// "feasible in 2 of 3 runs" for an unstable row, "3 runs" for a stable one,
// "1 run" for a point run once.
std::string ReplicaSummary(const EvaluationRow& row);

}  // namespace adse::campaign

#endif  // ADSE_HARNESS_CAMPAIGN_REPLICAS_H_
