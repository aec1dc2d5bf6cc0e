#include "harness/slurm/records.h"

#include <algorithm>
#include <filesystem>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "stack/base/files.h"
#include "stack/base/vocabulary.h"

namespace adse::slurm {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {
const std::vector<Term<JobKind>>& JobKindTerms() {
  static const std::vector<Term<JobKind>> kTerms = {
      {JobKind::kCoordinator, "coordinator"},
      {JobKind::kArray, "array"},
      {JobKind::kIndex, "index"},
  };
  return kTerms;
}
}  // namespace

const char* JobKindToString(JobKind kind) {
  return NameOf(JobKindTerms(), kind);
}
bool StringToJobKind(std::string_view name, JobKind* kind) {
  return ValueOf(JobKindTerms(), name, kind);
}
std::vector<std::string> JobKindNames() { return NamesOf(JobKindTerms()); }

namespace {

std::string PlanPath(const std::string& dir) {
  return SlurmDir(dir) + "/plan.json";
}
std::string JobLogPath(const std::string& dir) {
  return SlurmDir(dir) + "/jobs.json";
}
std::string ShardPath(const std::string& dir, int task) {
  return fmt::format("{}/shards/{}.json", SlurmDir(dir), task);
}

Status WriteJson(const std::string& path, const json& j) {
  return WriteFileAtomic(
      path, j.dump(2, ' ', false, json::error_handler_t::replace) + "\n");
}

Result<json> ReadJson(const std::string& path) {
  Result<std::string> text = ReadFile(path, 256u << 20);
  if (!text.ok()) return text.status();
  json j = json::parse(*text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    return Status::Corruption(path + ": not a JSON object");
  }
  return j;
}

}  // namespace

std::string SlurmDir(const std::string& campaign_dir) {
  return campaign_dir + "/slurm";
}

int SweepPlan::shards() const {
  if (points.empty() || shard_size < 1) return 0;
  return static_cast<int>((points.size() + shard_size - 1) / shard_size);
}

std::pair<size_t, size_t> SweepPlan::ShardRange(int shard) const {
  if (shard < 0 || shard >= shards()) return {0, 0};
  const size_t begin = static_cast<size_t>(shard) * shard_size;
  return {begin, std::min(points.size(), begin + shard_size)};
}

Status WriteSweepPlan(const std::string& campaign_dir, const SweepPlan& plan) {
  json points = json::array();
  for (const PlannedPoint& p : plan.points) {
    json point = {{"index", p.index}, {"point", p.point}, {"key", p.key}};
    if (p.replica_keys.size() > 1) point["replica_keys"] = p.replica_keys;
    points.push_back(point);
  }
  return WriteJson(PlanPath(campaign_dir),
                   {{"kind", "adse-sweep-plan"},
                    {"scenario", plan.scenario},
                    {"strategy", plan.strategy},
                    {"seed", plan.seed},
                    {"budget", plan.budget},
                    {"shard_size", plan.shard_size},
                    {"steps_per_task", plan.steps_per_task},
                    {"use_cache", plan.use_cache},
                    {"cache_dir", plan.cache_dir},
                    {"points", points}});
}

Result<SweepPlan> ReadSweepPlan(const std::string& campaign_dir) {
  const std::string path = PlanPath(campaign_dir);
  std::error_code ec;
  if (!fs::exists(path, ec)) {
    return Status::NotFound(fmt::format(
        "{}: no sweep plan (written by adse submit for a static sweep)", path));
  }
  Result<json> j = ReadJson(path);
  if (!j.ok()) return j.status();
  SweepPlan plan;
  try {
    if (j->value("kind", "") != "adse-sweep-plan") {
      return Status::Corruption(path + ": not an adse sweep plan");
    }
    plan.scenario = j->at("scenario").get<std::string>();
    plan.strategy = j->value("strategy", "");
    plan.seed = j->value("seed", uint64_t{0});
    plan.budget = j->value("budget", 0);
    plan.shard_size = j->at("shard_size").get<int>();
    plan.steps_per_task = j->value("steps_per_task", 1);
    plan.use_cache = j->value("use_cache", true);
    plan.cache_dir = j->value("cache_dir", "");
    for (const json& p : j->at("points")) {
      PlannedPoint planned{p.at("index").get<int64_t>(),
                           p.at("point").get<std::string>(),
                           p.at("key").get<std::string>(),
                           {}};
      planned.replica_keys =
          p.value("replica_keys", std::vector<std::string>{planned.key});
      if (planned.replica_keys.empty() ||
          planned.replica_keys.front() != planned.key) {
        return Status::Corruption(
            fmt::format("{}: point {}: replica_keys must start with its key",
                        path, planned.index));
      }
      plan.points.push_back(std::move(planned));
    }
  } catch (const json::exception& e) {
    return Status::Corruption(path + ": " + e.what());
  }
  if (plan.shard_size < 1) {
    return Status::Corruption(path + ": shard_size must be >= 1");
  }
  return plan;
}

int JobLog::last_submission() const {
  int last = 0;
  for (const SubmittedJob& job : jobs) last = std::max(last, job.submission);
  return last;
}

Result<JobLog> ReadJobLog(const std::string& campaign_dir) {
  const std::string path = JobLogPath(campaign_dir);
  JobLog log;
  std::error_code ec;
  if (!fs::exists(path, ec)) return log;
  Result<json> j = ReadJson(path);
  if (!j.ok()) return j.status();
  try {
    log.scenario = j->value("scenario", "");
    log.strategy = j->value("strategy", "");
    log.budget = j->value("budget", 0);
    for (const json& e : j->at("jobs")) {
      SubmittedJob job;
      job.submission = e.value("submission", 0);
      job.time = e.value("time", "");
      const std::string kind = e.at("kind").get<std::string>();
      if (!StringToJobKind(kind, &job.kind)) {
        return Status::Corruption(
            fmt::format("{}: job {}: {}", path, log.jobs.size(),
                        UnknownTermMessage("kind", kind, JobKindNames())));
      }
      job.job_id = e.value("job_id", "");
      job.script = e.value("script", "");
      job.shards = e.value("shards", std::vector<int>{});
      log.jobs.push_back(job);
    }
  } catch (const json::exception& e) {
    return Status::Corruption(path + ": " + e.what());
  }
  return log;
}

Status WriteJobLog(const std::string& campaign_dir, const JobLog& log) {
  json jobs = json::array();
  for (const SubmittedJob& job : log.jobs) {
    jobs.push_back({{"submission", job.submission},
                    {"time", job.time},
                    {"kind", JobKindToString(job.kind)},
                    {"job_id", job.job_id},
                    {"script", job.script},
                    {"shards", job.shards}});
  }
  return WriteJson(JobLogPath(campaign_dir), {{"scenario", log.scenario},
                                              {"strategy", log.strategy},
                                              {"budget", log.budget},
                                              {"jobs", jobs}});
}

std::map<std::string, ShardResult> ReadShardResults(
    const std::string& campaign_dir, int task) {
  std::map<std::string, ShardResult> results;
  Result<json> j = ReadJson(ShardPath(campaign_dir, task));
  if (!j.ok()) return results;
  try {
    for (const auto& [key, r] : j->at("results").items()) {
      results[key] = {r.value("source", ""), r.value("attempts", 0),
                      r.value("wall_s", 0.0)};
    }
  } catch (const json::exception&) {
    // A damaged record only costs the index its sources and wall times.
  }
  return results;
}

Status WriteShardResults(const std::string& campaign_dir, int task,
                         const std::map<std::string, ShardResult>& results) {
  std::map<std::string, ShardResult> merged =
      ReadShardResults(campaign_dir, task);
  for (const auto& [key, r] : results) {
    // A later session that only found the run keeps how it was made.
    auto it = merged.find(key);
    if (it != merged.end() && it->second.source == "simulated" &&
        r.source == "campaign") {
      continue;
    }
    merged[key] = r;
  }
  json out = json::object();
  for (const auto& [key, r] : merged) {
    out[key] = {
        {"source", r.source}, {"attempts", r.attempts}, {"wall_s", r.wall_s}};
  }
  return WriteJson(ShardPath(campaign_dir, task),
                   {{"task", task}, {"results", out}});
}

}  // namespace adse::slurm
