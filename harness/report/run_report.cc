#include "harness/report/run_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "analysis/deviation/deviation.h"
#include "analysis/diagnosis/diagnosis.h"
#include "analysis/metrics/run_metrics.h"
#include "analysis/pictures/pictures.h"
#include "harness/spec/spec_parser.h"
#include "stack/base/decimal.h"
#include "stack/base/files.h"

namespace adse::report {
namespace {

nlohmann::json Number(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

// The share of the path driven, 0 when the deviation fit failed.
double DrivenFraction(const RunReport& r) {
  auto it = r.metrics.find(analysis::kDrivenFractionMetric);
  return it != r.metrics.end() && std::isfinite(it->second) ? it->second : 0.0;
}

}  // namespace

Result<RunReport> AnalyzeRun(const runfile::RunData& run,
                             const std::string& run_file,
                             const AnalyzeOptions& options) {
  RunReport r;
  r.run_file = run_file;
  r.scenario_name = run.scenario_name;
  r.point = run.design_point;
  r.seed = run.seed;
  r.status = run.status;
  r.censored = runfile::EndedEarly(run.status);
  r.termination_reason = run.termination_reason;
  r.termination_detail = run.termination_detail;
  r.content_key = run.content_key;
  // Metrics are recomputed from the trace, never copied, so a changed
  // metric definition reaches old runs too; hardware_cost comes from the
  // scenario's cost expression as stored, rounded as the expression's value
  // now is (runs stored before 2026-12-07 carry its float noise).
  r.metrics = analysis::ComputeRunMetrics(run);
  if (auto it = run.metrics.find("hardware_cost"); it != run.metrics.end()) {
    r.metrics["hardware_cost"] =
        RoundToSignificantDigits(it->second, kDecimalDigits);
  }

  // Deviation from the ideal path.
  std::vector<Eigen::Vector2d> ideal;
  ideal.reserve(run.ideal_path.size());
  for (const runfile::PathPoint& p : run.ideal_path)
    ideal.emplace_back(p.x_m, p.y_m);
  std::vector<analysis::TimedXy> actual;
  actual.reserve(run.ego.size());
  for (const runfile::EgoSample& s : run.ego)
    actual.push_back({s.t_s, s.x_m, s.y_m});
  analysis::DeviationOptions deviation_options;
  deviation_options.normalize_by_m = options.deviation_normalize_by_m;
  Result<analysis::DeviationResult> deviation = analysis::FitDeviation(
      ideal, actual, run.lane_width_m, deviation_options);
  if (deviation.ok()) {
    r.metrics["deviation_score"] = deviation->deviation_score;
    r.metrics["max_deviation_m"] = deviation->max_deviation_m;
    r.metrics["offset_m"] = deviation->offset_m;
    r.metrics["zigzag_index"] = deviation->zigzag_index;
    r.metrics[analysis::kDrivenFractionMetric] = deviation->driven_fraction;
    r.deviation_complete = deviation->complete;
  } else {
    r.deviation_error = deviation.status().message();
    r.metrics["deviation_score"] = std::nan("");
    r.metrics[analysis::kDrivenFractionMetric] = std::nan("");
  }

  // Bottlenecks.
  analysis::DiagnosisOptions diagnosis_options;
  // The stack's nodes cache a 50 Hz pose next to their 7-14 Hz data: as
  // inputs those would make every healthy node look frequency-bound.
  diagnosis_options.frequency_bound_driving_inputs_only = 1;
  for (const auto& [name, value] : options.thresholds) {
    ADSE_RETURN_IF_ERROR(analysis::SetOption(&diagnosis_options, name, value));
  }
  const analysis::Diagnosis diagnosis =
      analysis::Diagnose(run, diagnosis_options);
  r.diagnosis_start_s = diagnosis.window_start_s;
  r.diagnosis_window_s = diagnosis.window_s;
  r.diagnosis_thresholds = options.thresholds;
  for (const analysis::Finding& f : diagnosis.findings) {
    r.findings.push_back({f.kind, f.node, f.remedy, f.message, f.topics,
                          f.rates_hz, f.remedies});
  }
  for (const analysis::TopicStats& t : diagnosis.topics) {
    TopicSummary summary{t.name, t.publisher, t.publish_rate_hz, 0.0, 0};
    for (size_t i = 0; i < t.subscribers.size(); ++i) {
      const analysis::SubscriberStats& sub = t.subscribers[i];
      summary.slowest_take_rate_hz =
          i == 0 ? sub.take_rate_hz
                 : std::min(summary.slowest_take_rate_hz, sub.take_rate_hz);
      summary.drops += sub.drops;
      summary.longest_take_gap_s =
          std::max(summary.longest_take_gap_s, sub.longest_gap_s);
    }
    r.topics.push_back(summary);
  }
  for (const analysis::CallbackStats& c : diagnosis.callbacks) {
    r.callbacks.push_back(
        {c.name, c.latency_p50_s, c.latency_p99_s, c.utilization});
  }

  r.standing = analysis::SummarizeStanding(run);

  // Constraints, from the scenario stored in the run. The files it names
  // (a calibration, a net) need not exist where the run is re-analysed.
  spec::ParseOptions parse_options;
  parse_options.check_files = false;
  Result<spec::Spec> spec = spec::ParseSpec(
      run.scenario_text, run.scenario_name + ".yaml (stored in the run)", ".",
      parse_options);
  if (spec.ok()) {
    // A censored run is infeasible whatever its metrics so far say.
    r.feasible = run.status == runfile::kRunComplete;
    for (const std::string& c : spec->constraints) {
      Result<bool> ok =
          spec::EvaluateConstraint(*spec, c, r.metrics, run.design_point);
      const bool satisfied = ok.ok() && *ok;
      r.constraints.push_back({c, satisfied, r.censored});
      r.feasible = r.feasible && satisfied;
    }
  } else {
    r.constraints_error = spec.status().message();
  }

  if (!options.image_dir.empty()) {
    const std::string png = options.image_dir + "/trajectory.png";
    Result<std::string> bytes = analysis::TrajectoryImagePng(run);
    if (bytes.ok() && WriteFileAtomic(png, *bytes, options.env).ok()) {
      r.images["trajectory"] = png;
    }
  }
  return r;
}

nlohmann::json ToJson(const RunReport& r) {
  nlohmann::json j;
  j["report_version"] = r.report_version;
  j["run_file"] = r.run_file;
  j["scenario"] = r.scenario_name;
  j["point"] = r.point;
  j["seed"] = r.seed;
  j["status"] = r.status;
  j["censored"] = r.censored;
  j["termination_reason"] = r.termination_reason;
  if (!r.termination_detail.empty()) {
    j["termination_detail"] = r.termination_detail;
  }
  j["content_key"] = r.content_key;
  for (const auto& [name, value] : r.metrics)
    j["metrics"][name] = Number(value);
  j["constraints"] = nlohmann::json::array();
  for (const ConstraintStatus& c : r.constraints) {
    j["constraints"].push_back({{"expression", c.expression},
                                {"satisfied", c.satisfied},
                                {"censored", c.censored}});
  }
  if (!r.constraints_error.empty())
    j["constraints_error"] = r.constraints_error;
  j["feasible"] = r.feasible;
  j["deviation"] = {{"complete", r.deviation_complete},
                    {"driven_fraction", DrivenFraction(r)}};
  if (!r.deviation_error.empty()) j["deviation"]["error"] = r.deviation_error;
  j["diagnosis"] = {{"window_start_s", Number(r.diagnosis_start_s)},
                    {"window_s", Number(r.diagnosis_window_s)},
                    {"thresholds", r.diagnosis_thresholds}};
  j["findings"] = nlohmann::json::array();
  for (const FindingSummary& f : r.findings) {
    j["findings"].push_back({{"kind", analysis::FindingKindToString(f.kind)},
                             {"node", f.node},
                             {"topics", f.topics},
                             {"rates_hz", f.rates_hz},
                             {"remedy", f.remedy},
                             {"remedies", RemediesToJson(f.remedies)},
                             {"message", f.message}});
  }
  nlohmann::json standing = {{"standing_s", Number(r.standing.standing_s)},
                             {"has_reasons", r.standing.has_reasons},
                             {"by_reason", nlohmann::json::array()}};
  for (const analysis::StandingTime& t : r.standing.by_reason) {
    nlohmann::json entry = {{"reason", StopReasonToString(t.reason)},
                            {"standing_s", Number(t.standing_s)}};
    if (StopReasonNamesTrack(t.reason)) {
      entry["track_id"] = t.track_id;
      entry["obstacle_gap_m"] = Number(t.obstacle_gap_m);
      entry["static_structure"] = t.static_structure;
    }
    standing["by_reason"].push_back(std::move(entry));
  }
  j["standing"] = std::move(standing);
  j["trace"]["topics"] = nlohmann::json::array();
  for (const TopicSummary& t : r.topics) {
    j["trace"]["topics"].push_back(
        {{"name", t.name},
         {"publisher", t.publisher},
         {"publish_rate_hz", Number(t.publish_rate_hz)},
         {"slowest_take_rate_hz", Number(t.slowest_take_rate_hz)},
         {"drops", t.drops},
         {"longest_take_gap_s", Number(t.longest_take_gap_s)}});
  }
  j["trace"]["callbacks"] = nlohmann::json::array();
  for (const CallbackSummary& c : r.callbacks) {
    j["trace"]["callbacks"].push_back(
        {{"name", c.name},
         {"latency_p50_s", Number(c.latency_p50_s)},
         {"latency_p99_s", Number(c.latency_p99_s)},
         {"utilization", Number(c.utilization)}});
  }
  j["images"] = r.images;
  return j;
}

nlohmann::json RemediesToJson(const std::vector<analysis::Remedy>& remedies) {
  nlohmann::json j = nlohmann::json::array();
  for (const analysis::Remedy& remedy : remedies) {
    nlohmann::json entry = {{"kind", analysis::RemedyKindToString(remedy.kind)},
                            {"target", remedy.target}};
    if (!remedy.publisher.empty()) entry["publisher"] = remedy.publisher;
    j.push_back(std::move(entry));
  }
  return j;
}

Result<std::vector<analysis::Remedy>> RemediesFromJson(
    const nlohmann::json& j) {
  if (!j.is_array()) {
    return Status::Corruption("remedies are not a JSON array");
  }
  std::vector<analysis::Remedy> remedies;
  for (size_t i = 0; i < j.size(); ++i) {
    const nlohmann::json& entry = j[i];
    auto text = [&](const char* key) -> const nlohmann::json* {
      if (!entry.is_object() || !entry.contains(key)) return nullptr;
      const nlohmann::json& v = entry.at(key);
      return v.is_string() ? &v : nullptr;
    };
    const nlohmann::json* kind = text("kind");
    const nlohmann::json* target = text("target");
    if (kind == nullptr || target == nullptr) {
      return Status::Corruption(
          fmt::format("remedy {} has no string \"kind\" and \"target\": {}", i,
                      entry.dump()));
    }
    Result<analysis::RemedyKind> parsed =
        analysis::StringToRemedyKind(kind->get<std::string>());
    if (!parsed.ok()) {
      return parsed.status().WithContext(fmt::format("remedy {}", i));
    }
    analysis::Remedy remedy{*parsed, target->get<std::string>()};
    if (entry.contains("publisher")) {
      const nlohmann::json* publisher = text("publisher");
      if (publisher == nullptr) {
        return Status::Corruption(
            fmt::format("remedy {}: \"publisher\" is not a string", i));
      }
      remedy.publisher = publisher->get<std::string>();
    }
    remedies.push_back(std::move(remedy));
  }
  return remedies;
}

std::string DescribeStanding(const analysis::StandingTime& t) {
  std::string what = StopReasonToString(t.reason);
  if (t.reason == StopReason::kLaneChange) {
    // The gap runs from the nearer bumper, ahead or behind; negative, the
    // object is beside the car.
    what += fmt::format(" (track {}, {} in the target lane)", t.track_id,
                        t.obstacle_gap_m >= 0
                            ? fmt::format("{:.1f} m away", t.obstacle_gap_m)
                            : std::string("beside the car"));
  } else if (StopReasonNamesTrack(t.reason)) {
    // A negative gap: the object's near edge is behind the front bumper
    // (it cut in beside the car).
    what += fmt::format(
        " (track {}{}, {})", t.track_id,
        t.static_structure ? ", static structure" : "",
        t.obstacle_gap_m >= 0
            ? fmt::format("{:.1f} m ahead", t.obstacle_gap_m)
            : fmt::format("beside the car, {:.1f} m behind its front",
                          -t.obstacle_gap_m));
  } else if (t.reason == StopReason::kNone) {
    what += " (the plan did not stop: held outside the planner)";
  }
  return fmt::format("{}: {:.1f} s", what, t.standing_s);
}

std::string FormatSummary(const RunReport& r) {
  std::string out;
  auto metric = [&](const char* name) {
    auto it = r.metrics.find(name);
    return it == r.metrics.end() || !std::isfinite(it->second)
               ? std::string("n/a")
               : fmt::format("{:.4g}", it->second);
  };
  if (r.status == runfile::kRunStalled) {
    // An obstacle stalls the car by either bound: static structure by the
    // stall timeout, another road user by the traffic one (the stood line
    // below says which it was).
    const std::string held_by =
        runfile::ReasonAfter(r.termination_reason, runfile::kStalledPrefix);
    StopReason reason = StopReason::kNone;
    const bool obstacle =
        StringToStopReason(held_by, &reason) && StopReasonNamesTrack(reason);
    out += fmt::format(
        "ended       stalled: the car stood still until {} s, held by {} "
        "({})\n",
        metric("nav_time_s"), held_by,
        obstacle ? "task.stall_timeout_s on map structure, "
                   "task.traffic_stall_timeout_s behind a road user"
                 : "task.stall_timeout_s");
    out +=
        "censored    the metrics below are measured up to then; nav_time_s "
        "is a lower bound\n";
  } else {
    out += fmt::format("ended       {} ({})\n", r.termination_reason, r.status);
    if (!r.termination_detail.empty()) {
      out += fmt::format("            {}\n", r.termination_detail);
    }
    if (r.censored) {
      out += fmt::format(
          "censored    early stop at {} s: the metrics below are measured up "
          "to it; nav_time_s is a lower bound\n",
          metric("nav_time_s"));
    }
  }
  for (const char* name :
       {"completed", "nav_time_s", "ctrl_rate_hz", "hardware_cost",
        "deviation_score", "max_deviation_m", "offset_m", "zigzag_index",
        "e2e_latency_p50_s", "e2e_latency_p99_s", "dropped_messages",
        "lidar_frames_dropped", "collisions", "cpu_utilization",
        "localization_lost_s"}) {
    out += fmt::format("{:<20} {}\n", name, metric(name));
  }
  // valet_parking runs: the manoeuvre's own metrics.
  if (r.metrics.count("parked")) {
    for (const char* name :
         {"parked", "parking_position_error_m", "parking_yaw_error_deg",
          "parking_time_s", "parking_path_deviation_m",
          "parking_path_deviation_max_m", "min_clearance_m",
          "obstacle_collisions", "gear_changes"}) {
      out += fmt::format("{:<28} {}\n", name, metric(name));
    }
  }
  if (!r.deviation_complete && r.deviation_error.empty()) {
    out += fmt::format(
        "deviation   scored on the driven part ({:.0f} % of the path)\n",
        100 * DrivenFraction(r));
  }
  if (r.standing.by_reason.empty()) {
    out += fmt::format("stood       {:.1f} s{}\n", r.standing.standing_s,
                       r.standing.has_reasons || r.standing.standing_s == 0
                           ? ""
                           : " (no stop reasons recorded in this run file)");
  } else {
    out += fmt::format("stood       {:.1f} s, mostly for {}\n",
                       r.standing.standing_s,
                       DescribeStanding(r.standing.by_reason.front()));
    for (size_t i = 1; i < r.standing.by_reason.size(); ++i) {
      out += fmt::format("            also {}\n",
                         DescribeStanding(r.standing.by_reason[i]));
    }
  }
  for (const ConstraintStatus& c : r.constraints) {
    out += fmt::format("constraint  {:<24} {}{}\n", c.expression,
                       c.satisfied ? "ok" : "VIOLATED",
                       c.censored ? " (so far: censored)" : "");
  }
  if (!r.constraints_error.empty())
    out += "constraints n/a: " + r.constraints_error + "\n";
  out += fmt::format("feasible    {}\n", r.feasible ? "yes" : "no");
  if (!r.diagnosis_thresholds.empty()) {
    std::vector<std::string> given;
    for (const auto& [name, value] : r.diagnosis_thresholds) {
      given.push_back(fmt::format("{}={:g}", name, value));
    }
    out += fmt::format(
        "diagnosis   window {:g}-{:g} s, thresholds {}\n", r.diagnosis_start_s,
        r.diagnosis_start_s + r.diagnosis_window_s, fmt::join(given, ", "));
  }
  if (r.diagnosis_window_s <= 0.0 && r.diagnosis_start_s > 0.0) {
    out +=
        "diagnosis   none: its window is empty (start_s at or past the "
        "run's end)\n";
  } else if (r.findings.empty()) {
    out += "diagnosis   no bottleneck found\n";
  }
  for (const FindingSummary& f : r.findings) {
    out +=
        fmt::format("diagnosis   {}: {} (remedy: {})\n",
                    analysis::FindingKindToString(f.kind), f.message, f.remedy);
  }
  return out;
}

}  // namespace adse::report
