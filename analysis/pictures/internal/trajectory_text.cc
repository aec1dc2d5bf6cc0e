#include "analysis/pictures/internal/trajectory_text.h"

#include <fmt/format.h>

#include <algorithm>

#include "analysis/pictures/internal/drawing_impl.h"

namespace adse::analysis::internal {

std::string TrajectoryTitle(const runfile::RunData& run) {
  std::string point;
  for (const auto& [name, value] : run.design_point) {
    point += (point.empty() ? "" : ", ") + name + "=" + FormatNumber(value);
  }
  std::string reason = run.termination_reason;
  reason = reason.substr(0, reason.find('\n'));
  std::string outcome =
      run.status == runfile::kRunFailed ? "FAILED: " + reason : reason;
  if (auto it = run.metrics.find("nav_time_s"); it != run.metrics.end()) {
    // A censored run stopped early: its nav time is only a lower bound.
    outcome +=
        runfile::EndedEarly(run.status)
            ? ", nav >= " + FormatNumber(it->second) + " s (stopped early)"
            : ", nav " + FormatNumber(it->second) + " s";
  }
  // Contacts with traffic (valet parking's with the lot are drawn).
  if (!run.collisions.empty()) {
    const auto ego_caused = std::count_if(
        run.collisions.begin(), run.collisions.end(),
        [](const runfile::CollisionEvent& c) { return c.ego_caused == 1; });
    outcome += fmt::format(", {} collision{} ({} caused by the ego)",
                           run.collisions.size(),
                           run.collisions.size() == 1 ? "" : "s", ego_caused);
  }
  // The picture shows the last plan in colour; say when there were others.
  if (run.parking.replans > 0) {
    outcome += fmt::format(", re-planned {}x", run.parking.replans);
  }
  // A run of one of the scenario's task.cases names it.
  const std::string scenario =
      (run.scenario_name.empty() ? "(no scenario)" : run.scenario_name) +
      (run.task_case.empty() ? "" : " (" + run.task_case + ")");
  return fmt::format("{} | {} | {}", scenario,
                     point.empty() ? "(no design point)" : point,
                     outcome.empty() ? "(no outcome)" : outcome);
}

std::string EndText(const runfile::RunData& run, double t_s) {
  const std::string& reason = run.termination_reason;
  if (reason == "goal_reached") return "";
  std::string what;
  if (!runfile::ViolatedConstraint(reason).empty()) {
    what = "stopped early";  // the title names the constraint
  } else if (const std::string held =
                 runfile::ReasonAfter(reason, runfile::kStalledPrefix);
             !held.empty()) {
    what = "stalled (" + held + ")";
  } else if (reason == "timeout" || reason == "no_path" ||
             reason == "parked_out_of_tolerance") {
    what = reason == "no_path"   ? "no path"
           : reason == "timeout" ? "timeout"
                                 : "parked out of tolerance";
  } else {
    what = "ended";
  }
  return fmt::format("{} {:.0f} s", what, t_s);
}

}  // namespace adse::analysis::internal
