// RunReport: the one structured record per run that strategies, agents and
// reports read — design point, constraint status, metrics, the deviation
// fit, the diagnosis and image paths — built from a run file alone, so that
// analysing during a campaign and re-analysing later are the same code.
#ifndef ADSE_HARNESS_REPORT_RUN_REPORT_H_
#define ADSE_HARNESS_REPORT_RUN_REPORT_H_

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "analysis/diagnosis/remedy.h"
#include "analysis/metrics/standing.h"
#include "analysis/runfile/run_data.h"
#include "stack/base/env.h"
#include "stack/base/status.h"

namespace adse::report {

struct AnalyzeOptions {
  // Diagnosis thresholds by name (see analysis/diagnosis), e.g.
  // {"frequency_bound_fraction", 0.2}.
  std::map<std::string, double> thresholds;
  // Normaliser of the deviation score; 0: half the lane width.
  double deviation_normalize_by_m = 0.0;
  // Folder for pictures; empty: no pictures.
  std::string image_dir;
  // Where the pictures are written through.
  Env* env = Env::Default();
};

struct ConstraintStatus {
  std::string expression;
  bool satisfied = false;  // by the run's metrics (censored: so far)
  // The run was ended early (censored), so `satisfied` holds up to the stop
  // only; the run's termination_reason names the constraint that stopped it.
  bool censored = false;
};

struct FindingSummary {
  analysis::FindingKind kind = analysis::FindingKind::kCpuBound;
  std::string node;
  std::string remedy;  // the readable text of `remedies`
  std::string message;
  std::vector<std::string> topics;
  std::map<std::string, double> rates_hz;
  // What would relieve it, most important first (analysis::Finding).
  std::vector<analysis::Remedy> remedies;
};

// The trace in numbers, for readers that cannot open the run file (the
// deciphering agent's text part): rates and drops per topic, latency and
// load per callback.
struct TopicSummary {
  std::string name;
  std::string publisher;  // "external" for sensors
  double publish_rate_hz = 0.0;
  double slowest_take_rate_hz = 0.0;  // over its subscribers; 0 when none
  int64_t drops = 0;                  // over its subscribers
  // The longest stretch one of its subscribers went without a take
  // (analysis::SubscriberStats::longest_gap_s); 0 when none.
  double longest_take_gap_s = 0.0;
};
struct CallbackSummary {
  std::string name;  // "<node>/<callback>"
  double latency_p50_s = 0.0;
  double latency_p99_s = 0.0;
  double utilization = 0.0;  // busy core-seconds per second
};

// What a report holds, by version: 2, findings carry typed `remedies`
// beside the readable `remedy`; 3, `standing` says how long the car stood
// and for which stop reason; 4, metrics carry `localization_lost_s`; 5,
// findings may be `starved_input`; 6, topics carry `longest_take_gap_s`;
// 7, metrics carry `driven_fraction`. A campaign analyses a run again
// rather than read an older report.
inline constexpr int kReportVersion = 7;

struct RunReport {
  int report_version = kReportVersion;
  std::string run_file;
  std::string scenario_name;
  std::map<std::string, double> point;
  uint64_t seed = 0;
  std::string status;  // a run status (runfile/run_data.h)
  // Early stop ended the run: its metrics are measured up to the stop
  // (metric `censored` = 1), nav_time_s only a lower bound.
  bool censored = false;
  std::string termination_reason;
  std::string termination_detail;  // the run file's; empty for most reasons
  std::string content_key;
  std::map<std::string, double> metrics;  // run metrics + deviation metrics
  // Constraints as written in the scenario; `constraints_error` says why
  // they could not be evaluated (e.g. the stored scenario no longer parses).
  std::vector<ConstraintStatus> constraints;
  std::string constraints_error;
  bool feasible = false;
  // Deviation fit (also in metrics as deviation_score, max_deviation_m,
  // offset_m, zigzag_index, driven_fraction).
  bool deviation_complete = false;
  std::string deviation_error;
  // The diagnosis' window in sim seconds (empty when the thresholds' start_s
  // lies past the run's end) and the thresholds given in AnalyzeOptions.
  double diagnosis_start_s = 0.0;
  double diagnosis_window_s = 0.0;
  std::map<std::string, double> diagnosis_thresholds;
  std::vector<FindingSummary> findings;
  // How long the ego stood and why, longest reason first (the dominant).
  analysis::StandingSummary standing;
  std::vector<TopicSummary> topics;
  std::vector<CallbackSummary> callbacks;
  std::map<std::string, std::string> images;  // "trajectory" -> png path
};

// Analyses one run. Fails only on inputs that cannot be analysed at all.
Result<RunReport> AnalyzeRun(const runfile::RunData& run,
                             const std::string& run_file,
                             const AnalyzeOptions& options);

// JSON of the whole report. Each finding is {"kind", "node", "topics",
// "rates_hz", "remedy" (text), "remedies" (RemediesToJson), "message"}.
nlohmann::json ToJson(const RunReport& report);

// Typed remedies as JSON: [{"kind": "more_cores", "target":
// "ndt_scan_matcher"}, ...], kinds as analysis::RemedyKindToString, plus
// "publisher" where a remedy has one (raise_publisher_rate). The run report
// and the campaign's bottleneck column both use this shape.
nlohmann::json RemediesToJson(const std::vector<analysis::Remedy>& remedies);
// The inverse. An unknown kind is InvalidArgument naming it and the valid
// ones; anything else malformed (not an array, an entry without a string
// "kind" or "target") is Corruption saying which entry.
Result<std::vector<analysis::Remedy>> RemediesFromJson(const nlohmann::json& j);

// A short human summary: outcome, key metrics, why the car stood,
// constraints, findings.
std::string FormatSummary(const RunReport& report);

// One stretch of standing in words, e.g. "obstacle (track 12, static
// structure, 1.8 m ahead): 412.3 s".
std::string DescribeStanding(const analysis::StandingTime& time);

}  // namespace adse::report

#endif  // ADSE_HARNESS_REPORT_RUN_REPORT_H_
