#include "harness/campaign/pool_evaluator.h"

#include <algorithm>
#include <csignal>
#include <cstring>
#include <filesystem>

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "analysis/runfile/run_file.h"
#include "harness/campaign/replicas.h"
#include "harness/report/run_report.h"
#include "harness/sim/run_key.h"
#include "harness/spec/spec_parser.h"
#include "stack/base/files.h"

namespace adse::campaign {
namespace fs = std::filesystem;

namespace {

// The last non-empty line of a worker's output, for one-line messages.
std::string LastLine(const std::string& text) {
  size_t end = text.find_last_not_of(" \n\r\t");
  if (end == std::string::npos) return "";
  const size_t begin = text.rfind('\n', end);
  return text.substr(begin == std::string::npos ? 0 : begin + 1,
                     end + 1 - (begin == std::string::npos ? 0 : begin + 1));
}

std::string Describe(const pool::JobResult& r, double timeout_s,
                     int memory_mb) {
  switch (r.outcome) {
    case pool::Outcome::kOk:
      return "ok";
    case pool::Outcome::kTimeout:
      return fmt::format("killed after run_timeout_s = {:g} s", timeout_s);
    case pool::Outcome::kOutOfMemory:
      return fmt::format("out of memory (limit memory_mb = {})", memory_mb);
    case pool::Outcome::kCrashed:
      return fmt::format("crashed: killed by signal {} ({})", r.signal,
                         strsignal(r.signal));
    case pool::Outcome::kExitError: {
      const std::string line = LastLine(r.stderr_tail);
      return fmt::format("worker exited with status {}{}{}", r.exit_code,
                         line.empty() ? "" : ": ", line);
    }
    case pool::Outcome::kCancelled:
      return "cancelled";
  }
  return "unknown";
}

}  // namespace

PoolEvaluator::PoolEvaluator(const spec::Spec& spec,
                             const CampaignFolder& folder,
                             pool::WorkerPool* pool,
                             PoolEvaluatorOptions options)
    : spec_(spec),
      folder_(folder),
      pool_(pool),
      options_(std::move(options)),
      runs_(sim::PointRuns(spec)) {
  for (int c = 0; c < spec::CaseCount(spec); ++c) {
    case_specs_.push_back(sim::CaseSpec(spec, c));
  }
}

int PoolEvaluator::capacity() const {
  // In points: each takes a run per case and replica.
  return std::max(1, pool_->slots() / static_cast<int>(runs_.size()));
}

int PoolEvaluator::outstanding() const {
  return static_cast<int>(points_.size() + ready_.size());
}

bool PoolEvaluator::interrupted() const {
  return pool::InterruptRequested() != 0 || pool::DrainRequested() != 0 ||
         refused_.has_value();
}

std::optional<EvaluationRow> PoolEvaluator::LoadRun(const Pending& p,
                                                    const std::string& source) {
  const std::string path = folder_.RunPath(p.key);
  std::error_code ec;
  std::optional<EvaluationRow> row;
  // The run file, read back whole once: one cut short or damaged since, or
  // a folder in its place, is found unusable below and run again.
  Result<runfile::RunData> run = runfile::ReadRunFile(path);
  // The worker's own analysis, when it left one for this very run.
  if (run.ok()) {
    Result<std::string> text = ReadFile(folder_.ReportPath(p.key), 16 << 20);
    if (text.ok()) {
      Result<EvaluationRow> stored =
          RowFromReportJson(*text, folder_.ReportPath(p.key));
      if (stored.ok() && stored->content_key == p.key) row = *stored;
    }
  }
  if (!row) {
    if (run.ok() && run->content_key != p.key) {
      run = Status::Corruption(fmt::format(
          "{}: holds run {} (renamed by hand?)", path, run->content_key));
    }
    report::AnalyzeOptions analyze;
    const std::string image_dir = folder_.ImageDir(p.key);
    // Pictures are drawn once; a resumed campaign reuses them.
    if (!fs::exists(folder_.TrajectoryImagePath(p.key), ec)) {
      if (MakeDirs(image_dir, folder_.env()).ok())
        analyze.image_dir = image_dir;
      analyze.env = folder_.env();
    }
    Result<report::RunReport> report =
        run.ok() ? report::AnalyzeRun(*run, path, analyze)
                 : Result<report::RunReport>(run.status());
    if (!report.ok()) {
      // Keep the evidence, out of the way of the content-keyed name.
      (void)folder_.env()->RenameFile(path, path + ".unreadable");
      std::fprintf(stderr, "warning: %s is unusable (%s); running it again\n",
                   path.c_str(), report.status().message().c_str());
      return std::nullopt;
    }
    row = RowFromReport(*report);
    // Derived data: losing it only costs this analysis again.
    (void)WriteFileAtomic(folder_.ReportPath(p.key),
                          report::ToJson(*report).dump(1) + "\n",
                          folder_.env());
  }
  row->index = p.request.index;
  row->iteration = p.request.iteration;
  row->replica = p.replica;
  row->task_case = p.task_case;
  // Feasibility under this campaign's constraints: a run reused from the
  // cache was analysed under the scenario that ran it, whose constraints
  // that do not stop runs early may differ.
  row->feasible = RowFeasible(spec_, *row);
  row->content_key = p.key;
  row->source = source;
  row->attempts = p.attempt;
  if (p.attempt == 0) {
    // Taken over from an earlier sitting: what the run took then.
    Result<RunCost> cost = ReadRunCost(folder_.CostPath(p.key));
    if (cost.ok() && cost->content_key == p.key) {
      row->attempts = cost->attempts;
      row->wall_s = cost->wall_s;
    }
  }
  return row;
}

std::optional<EvaluationRow> PoolEvaluator::LoadSimulated(const Pending& p,
                                                          double wall_s) {
  std::optional<EvaluationRow> row = LoadRun(p, "simulated");
  if (!row) return row;
  row->wall_s = wall_s;
  // Bookkeeping only: losing it costs a resumed index the wall time.
  if (Status s = WriteRunCost(folder_.CostPath(p.key),
                              {p.key, p.attempt, wall_s}, folder_.env());
      !s.ok()) {
    std::fprintf(stderr, "warning: %s\n", s.message().c_str());
  }
  return row;
}

EvaluationRow PoolEvaluator::FailedRow(const Pending& p,
                                       const FailureRecord& record,
                                       const std::string& source) const {
  EvaluationRow row;
  row.index = p.request.index;
  row.iteration = p.request.iteration;
  row.replica = p.replica;
  row.task_case = p.task_case;
  row.content_key = p.key;
  row.status = runfile::kRunFailed;
  row.reason = record.outcome + ": " + record.detail;
  row.source = source;
  row.attempts = record.attempts;
  row.wall_s = record.wall_s;
  row.seed = p.seed;
  row.point = p.request.point;
  row.bottlenecks_json = "[]";
  return row;
}

std::optional<EvaluationRow> PoolEvaluator::Prepare(const EvalRequest& request,
                                                    int run, Pending* p) {
  p->request = request;
  p->run = run;
  p->task_case = runs_[run].task_case;
  p->replica = runs_[run].replica;
  p->seed = sim::ReplicaSeed(spec_, p->replica);
  Result<std::string> key =
      sim::RunKey(case_specs_[p->task_case], request.point, p->seed);
  if (!key.ok()) {
    // Only an unreadable input file makes this fail; no run can help.
    FailureRecord record;
    record.outcome = "input_error";
    record.detail = key.status().message();
    return FailedRow(*p, record, "campaign");
  }
  p->key = *key;
  std::error_code ec;
  if (fs::exists(folder_.RunPath(p->key), ec)) {
    if (auto row = LoadRun(*p, "campaign")) return row;
  }
  if (!options_.retry_failed && fs::exists(folder_.FailurePath(p->key), ec)) {
    Result<FailureRecord> record =
        ReadFailureRecord(folder_.FailurePath(p->key));
    if (record.ok()) return FailedRow(*p, *record, "campaign");
  }
  return std::nullopt;
}

std::optional<EvaluationRow> PoolEvaluator::Recorded(
    const EvalRequest& request) {
  std::vector<EvaluationRow> runs;
  for (int r = 0; r < static_cast<int>(runs_.size()); ++r) {
    Pending p;
    std::optional<EvaluationRow> row = Prepare(request, r, &p);
    if (!row) return std::nullopt;
    runs.push_back(*std::move(row));
  }
  return AggregatePoint(spec_, std::move(runs));
}

void PoolEvaluator::Start(const EvalRequest& request) {
  points_[request.index].assign(runs_.size(), std::nullopt);
  for (int r = 0; r < static_cast<int>(runs_.size()); ++r) {
    Pending p;
    if (std::optional<EvaluationRow> known = Prepare(request, r, &p)) {
      Deliver(p, *std::move(known));
      continue;
    }
    if (options_.cache != nullptr && options_.cache->Find(p.key)) {
      if (options_.cache->CopyOut(p.key, folder_.RunPath(p.key)).ok()) {
        if (auto row = LoadRun(p, "cache")) {
          Deliver(p, *std::move(row));
          continue;
        }
      }
    }
    queued_.push_back(p);
  }
  Dispatch();
}

void PoolEvaluator::Deliver(const Pending& p, EvaluationRow row) {
  if (row.status != runfile::kRunFailed) any_run_came_through_ = true;
  auto point = points_.find(p.request.index);
  if (point == points_.end()) return;
  point->second[p.run] = std::move(row);
  for (const std::optional<EvaluationRow>& run : point->second) {
    if (!run) return;  // runs still to come
  }
  std::vector<EvaluationRow> runs;
  for (std::optional<EvaluationRow>& run : point->second) {
    runs.push_back(*std::move(run));
  }
  points_.erase(point);
  ready_.push_back(AggregatePoint(spec_, std::move(runs)));
}

void PoolEvaluator::Dispatch() {
  while (!queued_.empty() && pool_->idle_slots() > 0 && !interrupted()) {
    Pending p = queued_.front();
    queued_.pop_front();
    ++p.attempt;
    pool::Job job;
    job.id = next_job_++;
    job.argv = options_.worker_command;
    for (const std::string& arg :
         {options_.scenario_path, std::string("--point"),
          spec::FormatPoint(spec_.design_space, p.request.point),
          std::string("--seed"), std::to_string(p.seed), std::string("--out"),
          folder_.RunPath(p.key), std::string("--expect-key"), p.key,
          std::string("--report"), folder_.ReportPath(p.key),
          std::string("--image-dir"), folder_.ImageDir(p.key)}) {
      job.argv.push_back(arg);
    }
    if (!spec_.cases.empty()) {
      job.argv.push_back("--case");
      job.argv.push_back(spec_.cases[p.task_case].name);
    }
    job.log_path = folder_.LogPath(p.key, p.attempt);
    job.timeout_s = options_.run_timeout_s;
    // Enough of the key to find the run from the scheduler's queue.
    job.name = "adse-" + p.key.substr(0, 16);
    if (Status s = pool_->Submit(job); !s.ok()) {
      pool::JobResult failed;
      failed.id = job.id;
      failed.outcome = pool::Outcome::kExitError;
      failed.stderr_tail = s.message();
      running_[job.id] = p;
      Finish(failed);
      continue;
    }
    running_[job.id] = p;
  }
}

void PoolEvaluator::Finish(const pool::JobResult& result) {
  auto it = running_.find(result.id);
  if (it == running_.end()) return;
  Pending p = it->second;
  running_.erase(it);
  if (result.outcome == pool::Outcome::kCancelled) return;
  // A run that fails while the campaign is being stopped may have failed
  // because of the stop (its job step killed with the allocation): it is
  // left unevaluated, to run again on resume, not retried or recorded.
  if (result.outcome != pool::Outcome::kOk && pool::InterruptRequested() != 0) {
    return;
  }
  std::string detail;
  if (result.outcome == pool::Outcome::kOk) {
    if (auto row = LoadSimulated(p, result.wall_s)) {
      if (options_.cache != nullptr) {
        // A cache that cannot be written costs reuse, not the result.
        if (Status s = options_.cache->Insert(p.key, folder_.RunPath(p.key));
            !s.ok()) {
          std::fprintf(stderr, "warning: cache: %s\n", s.message().c_str());
        }
      }
      Deliver(p, *std::move(row));
      return;
    }
    detail = "the worker succeeded but its run file is unusable";
  } else {
    detail = Describe(result, options_.run_timeout_s, options_.memory_mb);
  }
  // Bad input (exit 2: the scenario changed under the campaign, a point
  // outside the space) fails the same way every time: no retry.
  const bool hopeless =
      result.outcome == pool::Outcome::kExitError && result.exit_code == 2;
  if (hopeless && !any_run_came_through_) {
    // The campaign stops (refused()); the point stays unevaluated, as
    // after an interrupt, so that the mended scenario runs it.
    if (!refused_) refused_ = detail;
    return;
  }
  if (!hopeless && p.attempt <= options_.retries) {
    if (options_.on_attempt_failed) {
      options_.on_attempt_failed(p.request, p.attempt, detail);
    }
    queued_.push_front(p);
    return;
  }
  FailureRecord record;
  record.content_key = p.key;
  record.point = spec::FormatPoint(spec_.design_space, p.request.point);
  record.seed = p.seed;
  record.outcome = result.outcome == pool::Outcome::kOk
                       ? "unusable_output"
                       : pool::OutcomeName(result.outcome);
  record.exit_code = result.exit_code;
  record.signal = result.signal;
  record.attempts = p.attempt;
  record.wall_s = result.wall_s;
  record.detail = detail;
  record.stderr_tail = result.stderr_tail;
  if (Status s =
          WriteFailureRecord(folder_.FailurePath(p.key), record, folder_.env());
      !s.ok()) {
    std::fprintf(stderr, "warning: %s\n", s.message().c_str());
  }
  Deliver(p, FailedRow(p, record, "simulated"));
}

std::vector<EvaluationRow> PoolEvaluator::Wait() {
  while (ready_.empty() && !(queued_.empty() && running_.empty())) {
    if (pool::InterruptRequested() != 0 || refused_) break;
    if (pool::DrainRequested() != 0) {
      // Start nothing more; what runs may finish within the grace period.
      queued_.clear();
      const auto now = std::chrono::steady_clock::now();
      if (!drain_deadline_) {
        drain_deadline_ =
            now +
            std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                std::chrono::duration<double>(
                    std::max(0.0, options_.drain_grace_s)));
      }
      if (running_.empty() || now >= *drain_deadline_) break;
    }
    for (const pool::JobResult& r : pool_->Wait(1.0)) Finish(r);
    Dispatch();
  }
  std::vector<EvaluationRow> rows;
  rows.swap(ready_);
  return rows;
}

std::vector<EvaluationRow> PoolEvaluator::Cancel() {
  for (const pool::JobResult& r : pool_->CancelAll()) {
    auto it = running_.find(r.id);
    if (it == running_.end()) continue;
    // A run whose file landed just before the stop is kept, not redone.
    std::error_code ec;
    if (fs::exists(folder_.RunPath(it->second.key), ec)) {
      if (auto row = LoadSimulated(it->second, r.wall_s)) {
        Deliver(it->second, *std::move(row));
      }
    }
  }
  // A point with runs still to go stays unevaluated; the runs it has
  // are in runs/, and a resumed campaign takes them from there.
  points_.clear();
  running_.clear();
  queued_.clear();
  std::vector<EvaluationRow> rows;
  rows.swap(ready_);
  return rows;
}

}  // namespace adse::campaign
