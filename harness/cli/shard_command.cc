// `adse shard`: one task of a static sweep's job array — evaluates its
// shard of the planned points as job steps in the task's allocation
// (harness/slurm/sweep.h). Exit 0 when every point of the shard has a
// result (failed runs included), 2 bad input, 1 other errors, 128 + signal
// when stopped (138: Slurm's time-limit warning; the task requeues itself).
#include <cstdio>

#include <fmt/format.h>

#include "harness/cli/commands.h"
#include "harness/slurm/sweep.h"

namespace adse::cli {
namespace {

// One line per evaluated point on stderr.
class ShardProgress : public campaign::ExplorerListener {
 public:
  explicit ShardProgress(bool quiet) : quiet_(quiet) {}
  void OnEvaluated(const campaign::EvaluationRow& row) override {
    ++done_;
    const bool failed = !row.complete();
    if (quiet_ && !failed) return;
    std::string point;
    for (const auto& [name, value] : row.point) {
      point += fmt::format("{}{}={:g}", point.empty() ? "" : ",", name, value);
    }
    std::fprintf(
        stderr, "[%d] %s%s: %s (%s%s)\n", done_, failed ? "FAILED " : "",
        point.c_str(), row.reason.c_str(), row.source.c_str(),
        row.source == "simulated" ? fmt::format(" {:.1f} s", row.wall_s).c_str()
                                  : "");
  }

 private:
  bool quiet_;
  int done_ = 0;
};

}  // namespace

int RunShard(const ShardArgs& args) {
  slurm::ShardOptions options;
  options.campaign_dir = args.campaign;
  options.task = args.task;
  options.local = args.local;
  ShardProgress progress(args.quiet);
  options.on_pool_ready = [&args](int workers, const std::string& isolation,
                                  const std::string& fallback) {
    if (!fallback.empty()) std::fprintf(stderr, "note: %s\n", fallback.c_str());
    if (!args.quiet) {
      std::fprintf(stderr, "%d worker(s): %s\n", workers, isolation.c_str());
    }
  };
  options.on_attempt_failed = [](const campaign::EvalRequest& r, int attempt,
                                 const std::string& detail) {
    std::string point;
    for (const auto& [name, value] : r.point) {
      point += fmt::format("{}{}={:g}", point.empty() ? "" : ",", name, value);
    }
    std::fprintf(stderr, "attempt %d of %s failed: %s; retrying\n", attempt,
                 point.c_str(), detail.c_str());
  };
  options.listener = &progress;
  Result<slurm::ShardSummary> summary = slurm::RunShard(options);
  if (!summary.ok()) {
    std::fprintf(stderr, "error: %s\n", summary.status().message().c_str());
    return ExitCodeFor(summary.status());
  }
  const campaign::CampaignSummary& c = summary->campaign;
  std::fprintf(stderr,
               "shard %d of %d: %zu of %zu points have a result (%d "
               "simulated, %d reused, %d failed) in %.1f s\n",
               summary->task, summary->shards, c.exploration.evaluations.size(),
               summary->points.size(), c.simulated, c.reused, c.failed,
               c.wall_s);
  if (c.interrupted_by != 0) {
    std::fprintf(stderr,
                 "stopped by signal %d: unfinished points run again when the "
                 "task is requeued or the campaign submitted again\n",
                 c.interrupted_by);
    return 128 + c.interrupted_by;
  }
  return 0;
}

}  // namespace adse::cli
