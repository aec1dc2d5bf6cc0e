#include "harness/spec/spec.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "harness/spec/text_util.h"

namespace adse::spec {
namespace fs = std::filesystem;

int DesignParameter::IndexOf(double value) const {
  if (!std::isfinite(value)) return -1;
  // Values are sorted: find the nearest by binary search.
  auto it = std::lower_bound(values.begin(), values.end(), value);
  const double tolerance = 1e-9 * std::max(1.0, std::fabs(value));
  if (it != values.end() && std::fabs(*it - value) <= tolerance) {
    return static_cast<int>(it - values.begin());
  }
  if (it != values.begin() && std::fabs(*(it - 1) - value) <= tolerance) {
    return static_cast<int>(it - values.begin() - 1);
  }
  return -1;
}

std::string DesignParameter::DescribeValues() const {
  constexpr size_t kListAll = 12;
  std::vector<std::string> parts;
  if (values.size() <= kListAll) {
    for (double v : values) parts.push_back(FormatNumber(v));
    return JoinList(parts);
  }
  // Long lists: first values, an ellipsis, the last; the count says the
  // rest.
  for (size_t i = 0; i < 3; ++i) parts.push_back(FormatNumber(values[i]));
  parts.push_back("...");
  parts.push_back(FormatNumber(values.back()));
  return JoinList(parts) + " (" + std::to_string(values.size()) + " values)";
}

uint64_t DesignSpace::Size() const {
  if (parameters.empty()) return 0;
  uint64_t size = 1;
  for (const DesignParameter& p : parameters) {
    const uint64_t n = p.values.size();
    if (n == 0) return 0;
    if (size > std::numeric_limits<uint64_t>::max() / n) {
      return std::numeric_limits<uint64_t>::max();
    }
    size *= n;
  }
  return size;
}

const DesignParameter* DesignSpace::Find(const std::string& name) const {
  for (const DesignParameter& p : parameters) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

const DesignParameter* DesignSpace::FindByBind(
    const std::string& target) const {
  for (const DesignParameter& p : parameters) {
    if (p.bind == target) return &p;
  }
  return nullptr;
}

std::vector<std::string> DesignSpace::Names() const {
  std::vector<std::string> names;
  for (const DesignParameter& p : parameters) names.push_back(p.name);
  return names;
}

Status DesignSpace::Check(const DesignPoint& point) const {
  std::vector<std::string> errors;
  const std::vector<std::string> names = Names();
  for (const auto& [name, value] : point) {
    const DesignParameter* p = Find(name);
    if (p == nullptr) {
      errors.push_back("unknown parameter '" + name + "'" +
                       DidYouMean(name, names) +
                       "; parameters: " + JoinList(names));
    } else if (p->IndexOf(value) < 0) {
      errors.push_back(name + ": expected one of " + p->DescribeValues() +
                       ", found " + FormatNumber(value));
    }
  }
  std::vector<std::string> missing;
  for (const DesignParameter& p : parameters) {
    if (point.count(p.name) == 0) missing.push_back(p.name);
  }
  if (!missing.empty()) {
    errors.push_back("missing parameter" +
                     std::string(missing.size() > 1 ? "s " : " ") +
                     JoinList(missing));
  }
  if (errors.empty()) return Status::Ok();
  std::string message;
  for (const std::string& e : errors) {
    if (!message.empty()) message += "\n";
    message += e;
  }
  return Status::InvalidArgument(message);
}

const std::vector<MetricInfo>& KnownMetrics() {
  static const std::vector<MetricInfo> kMetrics = {
      {"completed", "the ego reached the goal before the timeout (0 or 1)",
       true},
      {.name = "nav_time_s",
       .doc = "time from the start event to reaching the goal, s",
       .decimal = true},
      {"deviation_score",
       "normalised distance between actual and ideal trajectory, in [0, 1]",
       /*boolean=*/false, /*count=*/false, /*precision=*/true},
      {"max_deviation_m", "largest lateral error from the ideal path, m",
       /*boolean=*/false, /*count=*/false, /*precision=*/true},
      {"zigzag_index", "jitter of the lateral error around its smooth fit",
       /*boolean=*/false, /*count=*/false, /*precision=*/true},
      {"ctrl_rate_hz", "control-command rate over the navigation, Hz"},
      {.name = "hardware_cost",
       .doc = "value of the scenario's cost expression",
       .decimal = true},
      {"e2e_latency_p50_s", "median LiDAR-to-control latency, s"},
      {"e2e_latency_p99_s", "99th percentile LiDAR-to-control latency, s"},
      {"dropped_messages", "messages dropped by keep-last queues, count", false,
       true},
      {"collisions", "collisions of the ego with vehicles or obstacles, count",
       false, true},
      {"ego_collisions",
       "collisions the ego caused: at the contact it moved towards the other "
       "vehicle at least as fast as that one moved towards it, count",
       false, true},
      {"driven_fraction",
       "share of the ideal path's length driven by the end of the run, 0-1 "
       "(on arrival a little under 1, the goal's tolerance short of the "
       "path's end; of a run stopped early, how far it got)"},
      {"localization_lost_s",
       "time the planner had no valid pose to drive by (its stop reason "
       "localization_lost), s"},
      // valet_parking runs only (analysis/metrics/parking_metrics.h).
      {"parked",
       "valet_parking: the run ended standing in the slot within the goal's "
       "position and heading tolerances (0 or 1)",
       /*boolean=*/true, /*count=*/false, /*precision=*/false,
       /*valet_parking_only=*/true},
      {"parking_position_error_m",
       "valet_parking: parked body centre's distance from the slot's "
       "target at the end, m",
       /*boolean=*/false, /*count=*/false, /*precision=*/true,
       /*valet_parking_only=*/true},
      {"parking_yaw_error_deg",
       "valet_parking: heading error from the parked heading at the end, "
       "degrees",
       /*boolean=*/false, /*count=*/false, /*precision=*/true,
       /*valet_parking_only=*/true},
      {"parking_time_s",
       "valet_parking: from the manoeuvre's first plan to the end of the "
       "run, s",
       /*boolean=*/false, /*count=*/false, /*precision=*/false,
       /*valet_parking_only=*/true},
      {"parking_replans",
       "valet_parking: paths found after the first, each planned where the "
       "car stood off the course of the one before or at its end outside "
       "the goal's tolerances, count",
       /*boolean=*/false, /*count=*/true, /*precision=*/false,
       /*valet_parking_only=*/true},
      {"parking_path_deviation_m",
       "valet_parking: mean distance of the rear axle from the planned "
       "manoeuvre while driving it, m",
       /*boolean=*/false, /*count=*/false, /*precision=*/true,
       /*valet_parking_only=*/true},
      {"min_clearance_m",
       "valet_parking: smallest gap between the ego's body and a wall, pole "
       "or parked car, m",
       /*boolean=*/false, /*count=*/false, /*precision=*/false,
       /*valet_parking_only=*/true},
      {"obstacle_collisions",
       "valet_parking: contacts of the ego's body with walls, poles or "
       "parked cars, count",
       /*boolean=*/false, /*count=*/true, /*precision=*/false,
       /*valet_parking_only=*/true},
      {"gear_changes",
       "valet_parking: reversals of the direction of motion, count",
       /*boolean=*/false, /*count=*/true, /*precision=*/false,
       /*valet_parking_only=*/true},
      {"censored",
       "early stop ended the run (status infeasible): its other metrics are "
       "measured up to the stop (0 or 1)",
       true},
  };
  return kMetrics;
}

std::string Spec::Where(const std::string& field_path) const {
  std::string path = field_path;
  while (!path.empty()) {
    if (auto it = marks.find(path); it != marks.end() && it->second.line > 0) {
      return source_path + ":" + std::to_string(it->second.line) + ":" +
             std::to_string(it->second.column) + ": ";
    }
    // Climb to the parent: "a.b[2]" -> "a.b", "a.b" -> "a".
    const size_t cut = path.find_last_of(".[");
    if (cut == std::string::npos) break;
    path.resize(cut);
  }
  return source_path + ": ";
}

int CaseCount(const Spec& spec) {
  return std::max<int>(1, static_cast<int>(spec.cases.size()));
}

std::string CaseNames(const Spec& spec) {
  std::string names;
  for (const TaskCase& c : spec.cases) {
    names += (names.empty() ? "" : ", ") + c.name;
  }
  return names;
}

std::string CaseName(const Spec& spec, int64_t index) {
  return index >= 0 && static_cast<size_t>(index) < spec.cases.size()
             ? spec.cases[static_cast<size_t>(index)].name
             : "case " + std::to_string(index);
}

int FindCase(const Spec& spec, const std::string& name) {
  for (size_t i = 0; i < spec.cases.size(); ++i) {
    if (spec.cases[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

Spec ForCase(const Spec& spec, int index) {
  Spec out = spec;
  const TaskCase& c = spec.cases.at(static_cast<size_t>(index));
  out.task = c.task;
  out.task_case = c.name;
  out.cases.clear();
  const std::string prefix = "task.cases[" + std::to_string(index) + "].";
  for (const auto& [path, mark] : spec.marks) {
    if (path.compare(0, prefix.size(), prefix) == 0) {
      out.marks["task." + path.substr(prefix.size())] = mark;
    }
  }
  return out;
}

std::string Spec::ResolvedOutput() const {
  fs::path path(output);
  if (path.is_relative()) {
    std::error_code ec;
    path = fs::current_path(ec) / path;
  }
  return path.lexically_normal().string();
}

}  // namespace adse::spec
