#include "harness/campaign/evaluation.h"

#include <cmath>
#include <limits>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "analysis/diagnosis/remedy.h"
#include "analysis/metrics/run_metrics.h"
#include "analysis/runfile/run_data.h"
#include "harness/spec/design_point.h"
#include "stack/base/decimal.h"

namespace adse::campaign {

namespace {

// One path for live reports and stored ones: both go through the JSON.
Result<EvaluationRow> RowFromJson(const nlohmann::json& j,
                                  const std::string& path) {
  EvaluationRow row;
  try {
    row.content_key = j.at("content_key").get<std::string>();
    // The row's status says whether a run file exists: an early-stopped
    // (infeasible or stalled) run has one.
    const std::string status = j.at("status").get<std::string>();
    row.status = status == runfile::kRunComplete || runfile::EndedEarly(status)
                     ? runfile::kRunComplete
                     : runfile::kRunFailed;
    const bool censored = j.value("censored", false);
    row.reason = j.at("termination_reason").get<std::string>();
    row.seed = j.at("seed").get<uint64_t>();
    row.point = j.at("point").get<std::map<std::string, double>>();
    if (j.contains("metrics")) {
      for (const auto& [name, value] : j.at("metrics").items()) {
        // A censored run's metrics were measured up to its early stop: the
        // campaign never takes them for measurements, and leaves them out
        // as the index leaves out what a run lacks (only the point's cost,
        // the censoring itself and how far the car got are known).
        if (censored && name != "hardware_cost" &&
            name != analysis::kCensoredMetric &&
            name != analysis::kDrivenFractionMetric) {
          continue;
        }
        row.metrics[name] = value.is_number()
                                ? value.get<double>()
                                : std::numeric_limits<double>::quiet_NaN();
      }
    }
    row.feasible = j.at("feasible").get<bool>();
    nlohmann::json bottlenecks = nlohmann::json::array();
    const nlohmann::json& findings = j.at("findings");
    for (size_t i = 0; i < findings.size(); ++i) {
      const nlohmann::json& f = findings[i];
      double severity = 0.0;
      if (f.contains("rates_hz") && f["rates_hz"].contains("deficit") &&
          f["rates_hz"]["deficit"].is_number()) {
        severity = f["rates_hz"]["deficit"].get<double>();
      }
      // Strategies are told the typed kind and remedies.
      Result<analysis::FindingKind> kind =
          analysis::StringToFindingKind(f.value("kind", ""));
      if (!kind.ok()) {
        return Status::Corruption(fmt::format("{}: finding {}: {}", path, i,
                                              kind.status().message()));
      }
      if (!f.contains("remedies")) {
        return Status::Corruption(
            fmt::format("{}: finding {} has no typed remedies", path, i));
      }
      Result<std::vector<analysis::Remedy>> remedies =
          report::RemediesFromJson(f.at("remedies"));
      if (!remedies.ok()) {
        return Status::Corruption(fmt::format(
            "{}: finding {} ({} {}): {}", path, i, f.value("kind", "?"),
            f.value("node", "?"), remedies.status().message()));
      }
      bottlenecks.push_back({{"kind", analysis::FindingKindToString(*kind)},
                             {"node", f.value("node", "")},
                             {"remedy", f.value("remedy", "")},
                             {"remedies", report::RemediesToJson(*remedies)},
                             {"severity", severity}});
    }
    row.bottlenecks_json = bottlenecks.dump();
  } catch (const nlohmann::json::exception& e) {
    return Status::Corruption(path + ": not a run report: " + e.what());
  }
  return row;
}

}  // namespace

EvaluationRow RowFromReport(const report::RunReport& report) {
  // ToJson always yields every field RowFromJson reads.
  return RowFromJson(report::ToJson(report), "(report)").value();
}

Result<EvaluationRow> RowFromReportJson(const std::string& text,
                                        const std::string& path) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (!j.is_object()) {
    return Status::Corruption(path + ": not a run report (invalid JSON)");
  }
  // A report is derived data: one an older adse wrote may lack what the
  // rows now carry (a metric added since), so its run is analysed again.
  const nlohmann::json version = j.value("report_version", nlohmann::json());
  if (!version.is_number_integer() ||
      version.get<int>() < report::kReportVersion) {
    return Status::Corruption(
        fmt::format("{}: a report older than report_version {} ({})", path,
                    report::kReportVersion, version.dump()));
  }
  return RowFromJson(j, path);
}

bool RowFeasible(const spec::Spec& spec, const EvaluationRow& row) {
  if (row.status != runfile::kRunComplete ||
      RowMetric(row, analysis::kCensoredMetric) == 1.0) {
    return false;
  }
  return spec::ViolatedConstraintCount(spec, row.metrics, row.point) == 0;
}

double RowMetric(const EvaluationRow& row, const std::string& name) {
  auto it = row.metrics.find(name);
  return it == row.metrics.end() ? std::numeric_limits<double>::quiet_NaN()
                                 : it->second;
}

explore::Observation ObservationFromRow(const EvaluationRow& row) {
  explore::Observation o;
  o.point = row.point;
  o.key = row.content_key;
  o.failed = !row.complete();
  if (o.failed) return o;
  for (const auto& [name, value] : row.metrics) {
    if (!std::isnan(value)) o.metrics[name] = value;
  }
  o.feasible = row.feasible;
  o.censored = RowMetric(row, analysis::kCensoredMetric) == 1.0;
  if (o.censored) {
    o.violated_constraint = runfile::ViolatedConstraint(row.reason);
    o.stalled =
        !runfile::ReasonAfter(row.reason, runfile::kStalledPrefix).empty();
  }
  // The diagnosis is advisory: a row whose JSON does not parse (written by
  // hand, or damaged) is simply told without it.
  const nlohmann::json j =
      nlohmann::json::parse(row.bottlenecks_json, nullptr, false);
  if (j.is_array()) {
    for (const nlohmann::json& b : j) {
      if (!b.is_object()) continue;
      // A kind outside the vocabulary (a row damaged or written by hand)
      // leaves the hint out, as unreadable JSON leaves them all out.
      Result<analysis::FindingKind> kind =
          analysis::StringToFindingKind(b.value("kind", ""));
      if (!kind.ok()) continue;
      explore::BottleneckHint hint;
      hint.kind = *kind;
      hint.node = b.value("node", "");
      hint.remedy = b.value("remedy", "");
      hint.severity = b.value("severity", 0.0);
      if (b.contains("remedies")) {
        // Unreadable typed remedies leave only the text, like a row that
        // predates them.
        Result<std::vector<analysis::Remedy>> remedies =
            report::RemediesFromJson(b["remedies"]);
        if (remedies.ok()) hint.remedies = std::move(remedies).value();
      }
      o.bottlenecks.push_back(hint);
    }
  }
  return o;
}

analysis::Evaluation ParetoEvaluation(const spec::Spec& spec,
                                      const EvaluationRow& row) {
  return explore::ParetoEvaluationOf(spec, ObservationFromRow(row));
}

std::vector<int> ParetoFrontOf(const spec::Spec& spec,
                               const std::vector<EvaluationRow>& rows) {
  std::vector<explore::Observation> observations;
  observations.reserve(rows.size());
  for (const EvaluationRow& row : rows) {
    observations.push_back(ObservationFromRow(row));
  }
  return explore::ParetoFrontOf(spec, observations);
}

namespace {
void RoundDecimalMetrics(EvaluationRow* row) {
  for (const spec::MetricInfo& info : spec::KnownMetrics()) {
    if (!info.decimal) continue;
    auto it = row->metrics.find(info.name);
    if (it != row->metrics.end()) {
      it->second = RoundToSignificantDigits(it->second, kDecimalDigits);
    }
  }
  for (EvaluationRow& replica : row->replicas) RoundDecimalMetrics(&replica);
}
}  // namespace

Result<runfile::CampaignIndex> ReadIndex(const std::string& path) {
  Result<runfile::CampaignIndex> index = runfile::ReadCampaignIndex(path);
  if (!index.ok()) return index;
  for (EvaluationRow& row : index->evaluations) RoundDecimalMetrics(&row);
  return index;
}

}  // namespace adse::campaign
