#include "harness/slurm/status.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "harness/campaign/run_store.h"
#include "stack/base/files.h"

namespace adse::slurm {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

bool IsKey(const std::string& s) {
  return s.size() == 64 &&
         s.find_first_not_of("0123456789abcdef") == std::string::npos;
}

// Content keys of the complete runs and of the failure records in runs/.
void ScanRuns(const std::string& folder, std::set<std::string>* runs,
              std::set<std::string>* failures) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder + "/runs", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() == 64 + 3 && name.compare(64, 3, ".h5") == 0 &&
        IsKey(name.substr(0, 64))) {
      runs->insert(name.substr(0, 64));
    } else if (name.size() == 64 + 12 &&
               name.compare(64, 12, ".failed.json") == 0 &&
               IsKey(name.substr(0, 64))) {
      failures->insert(name.substr(0, 64));
    }
  }
}

std::string Summarise(const std::vector<JobState>& tasks) {
  std::map<std::string, int> counts;
  for (const JobState& t : tasks) ++counts[t.state];
  if (tasks.size() == 1) {
    const JobState& t = tasks[0];
    std::string text = t.state;
    if (!t.reason.empty() && t.reason != "None" && t.state == "PENDING") {
      text += " (" + t.reason + ")";
    }
    if (!t.exit_code.empty()) text += ", exit " + t.exit_code;
    return text;
  }
  std::vector<std::string> parts;
  for (const auto& [state, n] : counts) {
    parts.push_back(fmt::format("{} {}", n, state));
  }
  return fmt::format("{} tasks: {}", tasks.size(), fmt::join(parts, ", "));
}

// Whether the lock holder's text ("pid N on HOST ...") names a process on
// this host that is gone, or no holder is left (the lock file is emptied
// when a campaign ends). A holder on another host cannot be checked.
bool HolderIsGone(const std::string& holder) {
  if (holder.empty()) return true;
  unsigned long pid = 0;
  char host[256] = {};
  if (std::sscanf(holder.c_str(), "pid %lu on %255s", &pid, host) != 2) {
    return false;
  }
  char here[256] = {};
  ::gethostname(here, sizeof(here) - 1);
  if (std::string(host) != here) return false;
  return ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH;
}

// What the views in summary.json `j` are; a stopped campaign's reason.
ViewsState ViewsOf(const json& j, const std::string& lock_holder,
                   std::string* stopped_because) {
  if (j.value("in_progress", false)) {
    return HolderIsGone(lock_holder) ? ViewsState::kAbandoned
                                     : ViewsState::kInProgress;
  }
  if (j.value("complete", false)) return ViewsState::kComplete;
  *stopped_because = j.value("stopped_because", "");
  const int signal = j.value("interrupted_by_signal", 0);
  const int unfinished = j.value("unfinished", 0);
  if (stopped_because->empty() && signal != 0) {
    *stopped_because = fmt::format("stopped by signal {}", signal);
  } else if (stopped_because->empty() && unfinished > 0) {
    *stopped_because =
        fmt::format("{} planned point(s) have no result yet", unfinished);
  }
  return ViewsState::kStopped;
}

// The content keys of the runs summary.json's evaluations stand on, or
// nullopt when it lists none (views from before it did).
std::optional<std::set<std::string>> KeysOf(const json& j) {
  if (!j.contains("evaluations") || !j["evaluations"].is_array()) {
    return std::nullopt;
  }
  std::set<std::string> keys;
  for (const json& e : j["evaluations"]) {
    if (!e.is_object()) continue;
    if (e.contains("runs") && e["runs"].is_array()) {
      for (const json& run : e["runs"]) {
        if (run.is_object()) keys.insert(run.value("content_key", ""));
      }
    } else {
      keys.insert(e.value("content_key", ""));
    }
  }
  keys.erase("");
  return keys;
}

}  // namespace

const char* ViewsStateToString(ViewsState state) {
  switch (state) {
    case ViewsState::kNone:
      return "none";
    case ViewsState::kInProgress:
      return "in_progress";
    case ViewsState::kAbandoned:
      return "abandoned";
    case ViewsState::kStopped:
      return "stopped";
    case ViewsState::kComplete:
      return "complete";
    case ViewsState::kUnreadable:
      return "unreadable";
  }
  return "unknown";
}

const char* CampaignKindToString(CampaignKind kind) {
  switch (kind) {
    case CampaignKind::kLocal:
      return "local";
    case CampaignKind::kCoordinator:
      return "coordinator";
    case CampaignKind::kSweep:
      return "sweep";
  }
  return "unknown";
}

Result<CampaignStatus> ReadCampaignStatus(const std::string& folder_in) {
  std::error_code ec;
  const std::string folder =
      fs::absolute(folder_in, ec).lexically_normal().string();
  CampaignStatus st;
  st.folder = folder;
  if (!fs::is_directory(folder + "/runs", ec) &&
      !fs::is_directory(SlurmDir(folder), ec)) {
    return Status::NotFound(fmt::format(
        "{}: not a campaign folder (no runs/ or slurm/ in it)", folder_in));
  }
  std::set<std::string> runs, failures;
  ScanRuns(folder, &runs, &failures);

  Result<JobLog> log = ReadJobLog(folder);
  if (!log.ok()) return log.status();
  Result<SweepPlan> plan = ReadSweepPlan(folder);
  if (!plan.ok() && plan.status().code() != Status::Code::kNotFound) {
    return plan.status();
  }
  st.scenario = log->scenario;
  st.strategy = log->strategy;
  st.total = log->budget;
  st.kind =
      log->jobs.empty() ? CampaignKind::kLocal : CampaignKind::kCoordinator;
  if (plan.ok()) {
    st.kind = CampaignKind::kSweep;
    st.scenario = plan->scenario;
    st.strategy = plan->strategy;
    st.total = static_cast<int>(plan->points.size());
  }
  Result<std::string> holder = ReadFile(folder + "/.lock", 4096);
  if (holder.ok()) {
    st.lock_holder = *holder;
    while (!st.lock_holder.empty() && st.lock_holder.back() == '\n') {
      st.lock_holder.pop_back();
    }
  }
  // This campaign's runs, as its views list them (one key per replica and
  // case): runs/ may hold others' too.
  std::optional<std::set<std::string>> campaign_keys;
  int runs_per_point = 1;
  Result<std::string> summary_text = ReadFile(folder + "/summary.json");
  if (summary_text.ok()) {
    const json j = json::parse(*summary_text, nullptr, false);
    if (!j.is_object()) {
      st.views = ViewsState::kUnreadable;
      st.unreadable_because = "summary.json is no JSON object (damaged?)";
    }
    if (j.is_object()) {
      if (st.strategy.empty()) st.strategy = j.value("strategy", "");
      if (st.scenario.empty()) st.scenario = j.value("scenario_file", "");
      if (st.total == 0) st.total = j.value("budget", 0);
      st.confirm_runs = j.value("confirm_runs", 0);
      runs_per_point = std::max(1, j.value("replicas", 1)) *
                       std::max(1, j.value("cases", 1));
      // Without a plan, status counts run files: a point has one per
      // case and replica.
      if (!plan.ok()) {
        st.total *= runs_per_point;
        st.confirm_runs *= runs_per_point;
      }
      st.views = ViewsOf(j, st.lock_holder, &st.stopped_because);
      campaign_keys = KeysOf(j);
      if (st.views == ViewsState::kInProgress && j["running"].is_array()) {
        for (const json& point : j["running"]) {
          if (point.is_string()) st.running_points.push_back(point);
        }
      }
    }
  }

  // Jobs and their steps, from Slurm.
  std::vector<std::string> ids;
  for (const SubmittedJob& job : log->jobs) ids.push_back(job.job_id);
  std::vector<StepState> steps;
  if (!ids.empty()) {
    Result<std::vector<JobState>> states = QueryJobs(ids);
    if (!states.ok()) {
      st.notes.push_back("job states unknown: " + states.status().message());
    }
    for (const SubmittedJob& job : log->jobs) {
      JobStatus js;
      js.job = job;
      if (states.ok()) {
        for (const JobState& s : *states) {
          if (s.id == job.job_id || s.id.rfind(job.job_id + "_", 0) == 0) {
            js.tasks.push_back(s);
            js.active = js.active || IsActiveState(s.state);
          }
        }
      }
      js.summary = !states.ok()       ? "unknown"
                   : js.tasks.empty() ? "not known to Slurm any more "
                                        "(finished; no accounting to say "
                                        "how)"
                                      : Summarise(js.tasks);
      st.jobs.push_back(js);
    }
    Result<std::vector<StepState>> found = QuerySteps(ids);
    if (found.ok()) {
      steps = *found;
    } else if (states.ok()) {
      st.notes.push_back("running steps unknown: " + found.status().message());
    }
  }
  std::map<std::string, std::string> point_of;  // key -> point text
  if (plan.ok()) {
    for (const PlannedPoint& p : plan->points) {
      for (const std::string& key : p.replica_keys) point_of[key] = p.point;
    }
  }
  std::set<std::string> running_keys;
  for (const StepState& step : steps) {
    const std::string prefix = StepKeyPrefix(step);
    if (prefix.empty()) continue;
    RunningStep r{step.id, prefix, "", step.elapsed, step.nodes};
    for (const auto& [key, point] : point_of) {
      if (!r.key.empty() && key.rfind(r.key, 0) == 0) {
        r.point = point;
        running_keys.insert(key);
      }
    }
    st.running_steps.push_back(r);
  }

  if (plan.ok()) {
    // A point is done when each of its runs (replicas) has a result, and
    // failed when every one failed.
    for (const PlannedPoint& p : plan->points) {
      size_t ran = 0, failed = 0, running = 0;
      for (const std::string& key : p.replica_keys) {
        if (runs.count(key)) {
          ++ran;
        } else if (failures.count(key)) {
          ++failed;
        } else if (running_keys.count(key)) {
          ++running;
        }
      }
      if (failed == p.replica_keys.size()) {
        ++st.failed;
      } else if (ran + failed == p.replica_keys.size()) {
        ++st.done;
      } else if (running > 0) {
        ++st.running;
      } else {
        ++st.pending;
      }
    }
  } else {
    const std::set<std::string>& counted =
        campaign_keys ? *campaign_keys : runs;
    int others = 0;
    for (const std::string& key : runs) others += counted.count(key) == 0;
    for (const std::string& key : failures) {
      others += counted.count(key) == 0 && runs.count(key) == 0;
    }
    for (const std::string& key : counted) {
      if (runs.count(key)) {
        ++st.done;
      } else if (failures.count(key)) {
        ++st.failed;
      }
    }
    st.running =
        !st.running_steps.empty()
            ? static_cast<int>(st.running_steps.size())
            : static_cast<int>(st.running_points.size()) * runs_per_point;
    st.pending = std::max(0, st.total - st.done - st.failed - st.running);
    // While the campaign runs, runs that landed after its views were
    // written are not in them yet; once it ended, others are others'.
    if (others > 0 && (st.views == ViewsState::kComplete ||
                       st.views == ViewsState::kStopped)) {
      st.notes.push_back(fmt::format(
          "runs/ also holds {} run file(s) that no evaluation of this "
          "campaign uses (another scenario, or another version of this one, "
          "run into this folder); they are not counted",
          others));
    }
  }
  return st;
}

std::string FormatStatus(const CampaignStatus& st) {
  std::string out;
  const std::string what =
      st.kind == CampaignKind::kSweep ? fmt::format(
                                            "a static sweep ({}) of {} points "
                                            "as a Slurm job array",
                                            st.strategy, st.total)
      : st.kind == CampaignKind::kCoordinator
          ? fmt::format(
                "strategy {} with a "
                "coordinator on Slurm",
                st.strategy)
          : fmt::format("a local campaign{}",
                        st.strategy.empty() ? "" : " (" + st.strategy + ")");
  out += fmt::format("campaign: {}\n  {}\n", st.folder, what);
  if (!st.scenario.empty()) out += fmt::format("  scenario: {}\n", st.scenario);
  out += fmt::format(
      "runs: {} done, {} failed, {} running, {} pending{}\n", st.done,
      st.failed, st.running, st.pending,
      st.total > 0
          ? fmt::format(" (of {}{})", st.total,
                        st.confirm_runs > 0
                            ? fmt::format(", and up to {} confirm runs",
                                          st.confirm_runs)
                            : "")
          : "");
  if (!st.running_steps.empty()) {
    out += "running steps:\n";
    for (const RunningStep& r : st.running_steps) {
      out += fmt::format("  {:<12} {:<36} {} on {}\n", r.step_id,
                         r.point.empty() ? "run " + r.key : r.point, r.elapsed,
                         r.nodes);
    }
  }
  if (!st.jobs.empty()) {
    out += "Slurm jobs:\n";
    for (const JobStatus& j : st.jobs) {
      std::string shards;
      if (!j.job.shards.empty()) {
        shards = fmt::format(", {} shard(s)", j.job.shards.size());
      }
      out +=
          fmt::format("  {} job {} ({}{}): {}\n", JobKindToString(j.job.kind),
                      j.job.job_id, j.job.script, shards, j.summary);
    }
  }
  if (!st.running_points.empty()) {
    out += "running points:\n";
    for (const std::string& point : st.running_points) {
      out += "  " + point + "\n";
    }
  }
  if (!st.lock_holder.empty() && st.views != ViewsState::kAbandoned) {
    out += fmt::format("campaign lock: {}\n", st.lock_holder);
  }
  switch (st.views) {
    case ViewsState::kNone:
      out += "views: none yet\n";
      break;
    case ViewsState::kUnreadable:
      out += fmt::format(
          "views: unreadable in {}: {}; `adse run` again writes the views "
          "anew from the run files\n",
          st.folder, st.unreadable_because);
      break;
    case ViewsState::kInProgress:
      out +=
          "views: in progress (report.md, campaign.h5; rewritten as runs "
          "come in)\n";
      break;
    case ViewsState::kAbandoned:
      out += fmt::format(
          "views: left in progress by a campaign that is no longer running "
          "({}{}): run `adse run` again to resume it\n",
          st.lock_holder.empty() ? "its lock was released" : st.lock_holder,
          st.lock_holder.empty() ? "" : ", gone");
      break;
    case ViewsState::kStopped:
      out += fmt::format(
          "views: of a campaign that stopped before its end{} (report.md, "
          "campaign.h5)\n",
          st.stopped_because.empty() ? "" : ": " + st.stopped_because);
      break;
    case ViewsState::kComplete:
      out += "views: complete (report.md, campaign.h5)\n";
      break;
  }
  for (const std::string& note : st.notes) out += "note: " + note + "\n";
  return out;
}

std::string StatusJson(const CampaignStatus& st) {
  json running = json::array();
  for (const RunningStep& r : st.running_steps) {
    running.push_back({{"step", r.step_id},
                       {"key_prefix", r.key},
                       {"point", r.point},
                       {"elapsed", r.elapsed},
                       {"nodes", r.nodes}});
  }
  json jobs = json::array();
  for (const JobStatus& j : st.jobs) {
    json tasks = json::array();
    for (const JobState& t : j.tasks) {
      tasks.push_back({{"id", t.id},
                       {"job_id", t.job_id},
                       {"state", t.state},
                       {"reason", t.reason},
                       {"elapsed", t.elapsed},
                       {"exit_code", t.exit_code}});
    }
    jobs.push_back({{"submission", j.job.submission},
                    {"time", j.job.time},
                    {"kind", JobKindToString(j.job.kind)},
                    {"job_id", j.job.job_id},
                    {"script", j.job.script},
                    {"shards", j.job.shards},
                    {"state", j.summary},
                    {"active", j.active},
                    {"tasks", tasks}});
  }
  const json j = {{"folder", st.folder},
                  {"scenario", st.scenario},
                  {"strategy", st.strategy},
                  {"kind", CampaignKindToString(st.kind)},
                  {"total", st.total},
                  {"confirm_runs", st.confirm_runs},
                  {"counts",
                   {{"done", st.done},
                    {"failed", st.failed},
                    {"running", st.running},
                    {"pending", st.pending}}},
                  {"running", running},
                  {"running_points", st.running_points},
                  {"jobs", jobs},
                  {"lock_holder", st.lock_holder},
                  {"views", ViewsStateToString(st.views)},
                  {"stopped_because", st.stopped_because},
                  {"unreadable_because", st.unreadable_because},
                  {"notes", st.notes}};
  return j.dump(2, ' ', false, json::error_handler_t::replace) + "\n";
}

}  // namespace adse::slurm
