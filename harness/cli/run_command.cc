// `adse run`: a campaign, with a progress bar on a terminal and plain log
// lines otherwise. Exit 0 when the campaign finished (failed runs are in
// the report), 2 for bad input, 1 for other errors, 128 + signal when
// stopped by Ctrl-C / SIGTERM (run the same command again to resume).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <limits>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "analysis/metrics/run_metrics.h"
#include "harness/campaign/campaign.h"
#include "harness/campaign/headline.h"
#include "harness/cli/cli_support.h"
#include "harness/cli/commands.h"
#include "harness/slurm/allocation.h"
#include "harness/slurm/step_pool.h"
#include "harness/spec/design_point.h"
#include "harness/spec/spec_parser.h"
#include "harness/spec/text_util.h"
#include "stack/base/files.h"

namespace adse::cli {
namespace {

using Clock = std::chrono::steady_clock;

std::string Eta(double s) {
  if (!std::isfinite(s) || s < 0) return "--";
  const int total = static_cast<int>(std::lround(s));
  if (total < 60) return fmt::format("{}s", total);
  if (total < 3600) return fmt::format("{}m{:02d}s", total / 60, total % 60);
  return fmt::format("{}h{:02d}m", total / 3600, (total / 60) % 60);
}

// Progress of a campaign on stderr: a redrawn bar on a terminal, one line
// per event otherwise. Failures are always printed as they happen.
class Progress : public campaign::ExplorerListener {
 public:
  // `confirm_runs`: exploration.confirm_runs, the runs at most after the
  // budget's.
  Progress(const spec::Spec& spec, int budget, int confirm_runs, bool tty,
           bool quiet)
      : spec_(spec),
        budget_(budget),
        confirm_runs_(confirm_runs),
        tty_(tty),
        quiet_(quiet) {}

  void set_workers(int workers) { workers_ = workers; }

  void OnProposed(const runfile::IterationRow& it,
                  const std::vector<spec::DesignPoint>& points,
                  bool fell_back) override {
    proposed_ += static_cast<int>(points.size());
    if (it.strategy == campaign::kConfirmPhase && confirm_from_ < 0) {
      confirm_from_ = done_;  // every run of the budget has come back
    }
    // An llm iteration the built-in agent had to take over is shown even
    // under the bar: a model server that is down should not go unnoticed;
    // so is every confirm run, a run past the budget.
    const bool shown = fell_back || it.strategy == campaign::kConfirmPhase;
    if (!quiet_ && !it.rationale.empty() && (!tty_ || shown)) {
      if (tty_) std::fprintf(stderr, "\r\033[K");
      std::fprintf(stderr, "iteration %lld (%s): %s\n",
                   static_cast<long long>(it.iteration), it.strategy.c_str(),
                   it.rationale.c_str());
    }
    Draw();
  }

  void OnEvaluated(const campaign::EvaluationRow& row) override {
    ++done_;
    const bool failed = !row.complete();
    if (failed) ++failed_;
    if (row.source == "simulated") {
      simulated_wall_s_ += row.wall_s;
      ++simulated_;
    }
    auto cost = row.metrics.find("hardware_cost");
    if (row.feasible && cost != row.metrics.end() &&
        cost->second < best_cost_) {
      best_cost_ = cost->second;
      best_point_ = spec::FormatPoint(spec_.design_space, row.point);
    }
    const std::string point = spec::FormatPoint(spec_.design_space, row.point);
    const std::string count = Count();
    std::string line;
    if (failed) {
      line = fmt::format(
          "[{}] #{} FAILED {}: {} ({} attempt(s); see "
          "runs/{}.failed.json)",
          count, row.index, point, row.reason, row.attempts, row.content_key);
    } else if (!quiet_ && !tty_) {
      // An early-stopped run has no measured nav time or rate: its reason
      // says which bound stopped it.
      const bool censored =
          campaign::RowMetric(row, analysis::kCensoredMetric) == 1.0;
      // A point of several cases: its reason is its representative case's.
      const std::string reason =
          spec_.cases.empty()
              ? row.reason
              : fmt::format("{} in case {} (the worst of {})", row.reason,
                            spec::CaseName(spec_, row.task_case),
                            spec_.cases.size());
      line = fmt::format(
          "[{}] #{} {}: {}{}, cost {:.3g}, {} "
          "({}{})",
          count, row.index, point, reason,
          censored ? std::string(" (stopped early, metrics censored)")
                   : fmt::format(", nav {:.1f} s, ctrl {:.1f} Hz",
                                 campaign::RowMetric(row, "nav_time_s"),
                                 campaign::RowMetric(row, "ctrl_rate_hz")),
          campaign::RowMetric(row, "hardware_cost"), Feasibility(row, censored),
          row.source,
          row.source == "simulated" ? fmt::format(" in {:.1f} s", row.wall_s)
                                    : "");
    }
    if (!line.empty() && (failed || !quiet_)) {
      if (tty_) std::fprintf(stderr, "\r\033[K");
      std::fprintf(stderr, "%s\n", line.c_str());
    }
    Draw();
  }

  // "feasible", or "infeasible: " and the constraints it breaks, which a
  // reason such as goal_reached does not say. A censored run's reason
  // already names the bound that stopped it, and its withheld metrics
  // would name every constraint.
  std::string Feasibility(const campaign::EvaluationRow& row,
                          bool censored) const {
    if (row.feasible) return "feasible";
    if (censored) return "infeasible";
    const std::vector<std::string> broken =
        spec::ViolatedConstraints(spec_, row.metrics, row.point);
    if (broken.empty()) return "infeasible";
    return fmt::format("infeasible: {}", fmt::join(broken, ", "));
  }

  void AttemptFailed(const campaign::EvalRequest& request, int attempt,
                     const std::string& detail) {
    if (tty_) std::fprintf(stderr, "\r\033[K");
    std::fprintf(stderr, "attempt %d of %s failed: %s; retrying\n", attempt,
                 spec::FormatPoint(spec_.design_space, request.point).c_str(),
                 detail.c_str());
    Draw();
  }

  void Finish() {
    if (tty_ && !quiet_) std::fprintf(stderr, "\r\033[K");
  }

 private:
  // "3/15", or "confirm 1/3" past the budget.
  std::string Count() const {
    if (confirm_from_ < 0) return fmt::format("{}/{}", done_, budget_);
    return fmt::format("confirm {}/{}", done_ - confirm_from_, confirm_runs_);
  }

  void Draw() {
    if (!tty_ || quiet_) return;
    const int running = std::max(0, std::min(workers_, proposed_ - done_));
    constexpr int kWidth = 24;
    const int filled =
        budget_ > 0 ? std::min(kWidth, done_ * kWidth / budget_) : 0;
    const double per_run =
        simulated_ > 0 ? simulated_wall_s_ / simulated_ : NAN;
    // Past the budget: the confirm runs left, at most.
    const int left = confirm_from_ < 0
                         ? budget_ - done_
                         : confirm_runs_ - (done_ - confirm_from_);
    const double eta = per_run * std::max(0, left) / std::max(1, workers_);
    std::fprintf(
        stderr,
        "\r\033[K[%s%s] %s done, %d running, %d failed, ETA %s, best "
        "feasible %s",
        std::string(filled, '#').c_str(),
        std::string(kWidth - filled, '.').c_str(), Count().c_str(), running,
        failed_, Eta(eta).c_str(),
        std::isfinite(best_cost_)
            ? fmt::format("cost {:.3g} ({})", best_cost_, best_point_).c_str()
            : "none yet");
    std::fflush(stderr);
  }

  const spec::Spec& spec_;
  int budget_;
  int confirm_runs_;
  int confirm_from_ = -1;  // runs done when the confirm phase began
  bool tty_, quiet_;
  int workers_ = 1;
  int proposed_ = 0, done_ = 0, failed_ = 0, simulated_ = 0;
  double simulated_wall_s_ = 0.0;
  double best_cost_ = std::numeric_limits<double>::infinity();
  std::string best_point_;
};

}  // namespace

int RunRun(const RunArgs& args) {
  std::optional<spec::Spec> spec = LoadScenarioOrReport(args.scenario);
  if (!spec) return 2;
  if (!args.executor.empty()) spec->harness.executor = args.executor;
  campaign::CampaignOptions options;
  if (spec->harness.executor == "slurm") {
    // Checked before the campaign folder is touched.
    Result<std::optional<slurm::Allocation>> allocation =
        slurm::CurrentAllocation();
    if (!allocation.ok() || !allocation->has_value()) {
      std::fprintf(
          stderr, "error: %s\n",
          allocation.ok()
              ? (std::string(args.executor.empty()
                                 ? spec->Where("harness.executor") +
                                       "harness.executor: 'slurm'"
                                 : "--executor slurm") +
                 " runs each design point as a Slurm job step (srun) and "
                 "needs an allocation, but SLURM_JOB_ID is not set: submit "
                 "the campaign with `adse submit` from a login node, run "
                 "adse run inside salloc or sbatch, or use --executor local")
                    .c_str()
              : allocation.status().message().c_str());
      return 2;
    }
    options.make_pool = slurm::CreateAllocationPool;
    // Slurm's warning before the time limit (sbatch --signal=B:USR1@<s>).
    options.drain_signal = SIGUSR1;
    options.drain_grace_s = std::max(0, spec->harness.slurm.signal_lead_s - 30);
  }
  // A campaign folder resumes whatever it holds; a file where it or a
  // folder above it goes, or a folder that is no campaign's, is bad input,
  // said before any worker starts.
  if (Status usable =
          CheckCampaignFolders(*spec, args.out, !args.no_cache, args.cache_dir);
      !usable.ok()) {
    std::fprintf(stderr, "error: %s\n", usable.message().c_str());
    return 2;
  }
  options.output_dir = args.out;
  options.strategy = args.strategy;
  options.budget = args.budget;
  options.confirm_runs = args.confirm_runs;
  options.workers = args.workers;
  options.isolation = args.isolation;
  options.use_cache = !args.no_cache;
  options.cache_dir = args.cache_dir;
  options.retry_failed = args.retry_failed;

  const int budget = args.budget >= 0 ? args.budget : spec->exploration.budget;
  const uint64_t space = spec->design_space.Size();
  Progress progress(*spec, static_cast<int>(std::min<uint64_t>(budget, space)),
                    args.confirm_runs >= 0 ? args.confirm_runs
                                           : spec->exploration.confirm_runs,
                    ::isatty(STDERR_FILENO) != 0, args.quiet);
  options.listener = &progress;
  options.on_attempt_failed = [&progress](const campaign::EvalRequest& r,
                                          int attempt,
                                          const std::string& detail) {
    progress.AttemptFailed(r, attempt, detail);
  };
  options.on_pool_ready = [&](int workers, const std::string& isolation,
                              const std::string& fallback) {
    progress.set_workers(workers);
    if (!fallback.empty()) std::fprintf(stderr, "note: %s\n", fallback.c_str());
    if (!args.quiet)
      std::fprintf(stderr, "%d worker(s): %s\n", workers, isolation.c_str());
  };

  Result<campaign::CampaignSummary> summary =
      campaign::RunCampaign(*spec, options);
  progress.Finish();
  if (!summary.ok()) {
    std::fprintf(stderr, "error: %s\n", summary.status().message().c_str());
    return ExitCodeFor(summary.status());
  }
  const campaign::CampaignSummary& s = *summary;
  if (args.json) {
    Result<std::string> text = ReadFile(s.output_dir + "/summary.json");
    std::printf("%s", text.ok() ? text->c_str() : "{}\n");
  } else {
    std::printf(
        "%s: %s (%d simulated, %d reused, %d failed) in %s with %s\n",
        spec->name.c_str(),
        spec::Counted(s.exploration.evaluations.size(), "evaluation").c_str(),
        s.simulated, s.reused, s.failed, Eta(s.wall_s).c_str(),
        spec::Counted(s.workers, "worker").c_str());
    const auto& rows = s.exploration.evaluations;
    std::printf("%s", campaign::HeadlineText(
                          *spec, rows, campaign::ComputeHeadline(*spec, rows))
                          .c_str());
    std::printf("report: %s/report.md\n", s.output_dir.c_str());
  }
  if (s.interrupted_by != 0) {
    std::fprintf(
        stderr,
        "stopped by signal %d: %s kept; run the same command "
        "again to resume\n",
        s.interrupted_by,
        spec::Counted(s.exploration.evaluations.size(), "evaluation").c_str());
    return 128 + s.interrupted_by;
  }
  return 0;
}

}  // namespace adse::cli
