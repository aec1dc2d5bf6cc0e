// One evaluation of a campaign as every part sees it: the row of the
// campaign index. A live run's RunReport and a recorded index row become
// the same row, and strategies are told the same Observation from it, so a
// replay over recorded results behaves exactly like the live campaign.
#ifndef ADSE_HARNESS_CAMPAIGN_EVALUATION_H_
#define ADSE_HARNESS_CAMPAIGN_EVALUATION_H_

#include <string>
#include <vector>

#include "analysis/pareto/pareto.h"
#include "analysis/runfile/campaign_file.h"
#include "harness/explore/strategy.h"
#include "harness/report/run_report.h"
#include "harness/spec/spec.h"

namespace adse::campaign {

using runfile::EvaluationRow;

// The row for a complete run: metrics, feasibility, termination reason and
// the diagnosis from its report. Index, iteration, source, attempts and
// wall time are the caller's. bottlenecks_json holds one object per
// finding: {"kind", "node", "remedy" (text), "remedies" (typed, as
// report::RemediesToJson), "severity"}.
EvaluationRow RowFromReport(const report::RunReport& report);

// The same row from a report's JSON (report::ToJson), as a worker writes it
// next to its run file (runs/<key>.report.json): the coordinator then need
// not analyse the run again. Corruption naming `path` when the text is not
// such a report, when it is older than report::kReportVersion (stale: the
// run is analysed again), when a finding has no typed remedies or names an
// unknown remedy kind (the message names it).
Result<EvaluationRow> RowFromReportJson(const std::string& text,
                                        const std::string& path);

// Whether the row's run satisfies every constraint of `spec` on its metrics
// and point; a failed run, or one stopped early, never does.
bool RowFeasible(const spec::Spec& spec, const EvaluationRow& row);

// A row's metric, NaN when the run has none (failed runs have none).
double RowMetric(const EvaluationRow& row, const std::string& name);

// What a strategy is told about a row (failed rows: failed = true). The
// diagnosis is advisory: a bottleneck whose typed remedies are missing (an
// index written before them) or unreadable keeps only its text.
explore::Observation ObservationFromRow(const EvaluationRow& row);

// The row in the form analysis/pareto ranks: the spec's objectives in
// minimisation form; a failed row or a missing objective is infeasible.
analysis::Evaluation ParetoEvaluation(const spec::Spec& spec,
                                      const EvaluationRow& row);

// The campaign index at `path` as every command reads it: an index
// written before some metrics were rounded where a run makes them
// (spec::MetricInfo::decimal, 2026-12-07) reads them rounded, as an old
// run file's cost is (report::AnalyzeRun), so that every command gives
// one number (89.85 s, not 89.84999999999704 s).
Result<runfile::CampaignIndex> ReadIndex(const std::string& path);

// Indices (into `rows`) of the constraint-aware Pareto front.
std::vector<int> ParetoFrontOf(const spec::Spec& spec,
                               const std::vector<EvaluationRow>& rows);

}  // namespace adse::campaign

#endif  // ADSE_HARNESS_CAMPAIGN_EVALUATION_H_
