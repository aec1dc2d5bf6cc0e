#include <fmt/format.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "analysis/runfile/run_file.h"
#include "harness/cli/cli_support.h"
#include "harness/cli/commands.h"
#include "harness/report/run_report.h"
#include "harness/sim/calibration.h"
#include "harness/sim/simulator.h"
#include "harness/spec/spec_parser.h"
#include "stack/base/hash.h"

namespace adse::cli {
namespace {

// The point from --point, or the scenario's exploration.start_from.
std::optional<spec::DesignPoint> ResolvePoint(const spec::Spec& spec,
                                              const std::string& text) {
  if (text.empty()) {
    if (!spec.exploration.start_from.empty())
      return spec.exploration.start_from;
    std::string names;
    for (const auto& p : spec.design_space.parameters) {
      names += (names.empty() ? "" : ",") + p.name + "=<value>";
    }
    std::fprintf(stderr,
                 "error: --point is required (the scenario has no "
                 "exploration.start_from): --point %s\n",
                 names.c_str());
    return std::nullopt;
  }
  Result<spec::DesignPoint> point = spec::ParsePoint(spec.design_space, text);
  if (!point.ok()) {
    std::fprintf(stderr, "error: --point: %s\n",
                 point.status().message().c_str());
    return std::nullopt;
  }
  return std::move(point).value();
}

std::string PointSlug(const spec::DesignPoint& point) {
  std::string slug;
  for (const auto& [name, value] : point) {
    slug += (slug.empty() ? "" : "_") + fmt::format("{}-{}", name, value);
  }
  return slug;
}

std::string FormatMetric(double value) {
  if (std::isnan(value)) return "n/a";
  return fmt::format("{:.4g}", value);
}

}  // namespace

int RunSimulate(const SimulateArgs& args) {
  std::optional<spec::Spec> spec =
      LoadCaseOrReport(args.scenario, args.task_case);
  if (!spec) return 2;
  std::optional<spec::DesignPoint> point = ResolvePoint(*spec, args.point);
  if (!point) return 2;
  sim::SimulateOptions options;
  options.seed = args.seed;
  const bool tty = ::isatty(STDERR_FILENO) && !args.quiet;
  if (tty) {
    options.progress = [](double t, double timeout) {
      std::fprintf(stderr, "\rsimulating: t = %6.1f s of at most %.0f s", t,
                   timeout);
      std::fflush(stderr);
    };
  }
  // A seed of its own gets a file of its own.
  const std::string out =
      args.out.empty()
          ? spec->output + "/simulate/" + PointSlug(*point) +
                (spec->task_case.empty() ? "" : "_" + spec->task_case) +
                (args.seed ? fmt::format("_seed{}", *args.seed) : "") + ".h5"
          : args.out;
  if (Status usable = CheckOutputFile(out, kRunFile); !usable.ok()) {
    std::fprintf(stderr, "error: %s\n", usable.message().c_str());
    return 2;
  }
  sim::SimulationStats stats;
  Result<runfile::RunData> run =
      sim::SimulatePoint(*spec, *point, options, &stats);
  if (tty) std::fprintf(stderr, "\r%60s\r", "");
  if (!run.ok()) {
    ReportError(*spec, run.status());
    return ExitCodeFor(run.status());
  }
  // The analysis (deviation fit, diagnosis) of the fresh run; its metrics
  // are stored with the run's own.
  Result<report::RunReport> analysed =
      report::AnalyzeRun(*run, out, report::AnalyzeOptions{});
  if (!analysed.ok()) {
    std::fprintf(stderr, "error: analysing the run: %s\n",
                 analysed.status().message().c_str());
    return 1;
  }
  for (const auto& [name, value] : analysed->metrics)
    run->metrics.emplace(name, value);
  const auto t0 = std::chrono::steady_clock::now();
  Status written = runfile::WriteRunFile(out, *run);
  const double write_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
          .count();
  if (!written.ok()) {
    std::fprintf(stderr, "error: writing %s: %s\n", out.c_str(),
                 written.message().c_str());
    return 1;
  }
  if (args.json) {
    nlohmann::json doc = report::ToJson(*analysed);
    auto number = [](double v) {
      return std::isnan(v) ? nlohmann::json(nullptr) : nlohmann::json(v);
    };
    doc["timing_s"] = {{"wall", stats.wall_s + write_s},
                       {"setup", stats.setup_s},
                       {"stack_and_executor", stats.stack_and_executor_s},
                       {"stack_cpu", number(stats.stack_cpu_s)},
                       {"executor", number(stats.executor_s)},
                       {"world", stats.world_s},
                       {"lidar", stats.lidar_s},
                       {"hdf5_write", write_s},
                       {"simulated", stats.simulated_s}};
    std::printf("%s\n", doc.dump(2).c_str());
    return 0;
  }
  std::printf("point       %s (seed %llu)\n", PointSlug(*point).c_str(),
              static_cast<unsigned long long>(run->seed));
  if (!spec->task_case.empty()) {
    std::printf("case        %s\n", spec->task_case.c_str());
  }
  std::fputs(report::FormatSummary(*analysed).c_str(), stdout);
  std::printf("run file    %s\n", out.c_str());
  std::printf(
      "wall time   %.2f s for %.1f s simulated: stack+executor %.2f s (stack "
      "%s, executor %s), "
      "world %.2f s, LiDAR %.2f s, HDF5 %.2f s\n",
      stats.wall_s + write_s, stats.simulated_s, stats.stack_and_executor_s,
      FormatMetric(stats.stack_cpu_s).c_str(),
      FormatMetric(stats.executor_s).c_str(), stats.world_s, stats.lidar_s,
      write_s);
  return 0;
}

int RunCalibrate(const CalibrateArgs& args) {
  std::optional<spec::Spec> spec =
      LoadCaseOrReport(args.scenario, args.task_case);
  if (!spec) return 2;
  std::optional<spec::DesignPoint> point = ResolvePoint(*spec, args.point);
  if (!point) return 2;
  if (Status usable = CheckOutputFile(args.out, kCalibrationFile);
      !usable.ok()) {
    std::fprintf(stderr, "error: %s\n", usable.message().c_str());
    return 2;
  }
  // Calibration measures host CPU time, whatever the scenario asked for.
  spec->platform.cost_model = spec::CostModel::kMeasured;
  std::vector<runfile::RunData> runs;
  for (int i = 0; i < args.runs; ++i) {
    sim::SimulateOptions options;
    options.seed = spec->world.traffic.seed + static_cast<uint64_t>(i);
    std::fprintf(stderr, "calibration run %d/%d...\n", i + 1, args.runs);
    Result<runfile::RunData> run = sim::SimulatePoint(*spec, *point, options);
    if (!run.ok()) {
      ReportError(*spec, run.status());
      return ExitCodeFor(run.status());
    }
    runs.push_back(std::move(run).value());
  }
  std::vector<const runfile::RunData*> pointers;
  for (const auto& r : runs) pointers.push_back(&r);
  Result<sim::Calibration> fitted = sim::FitCalibration(pointers);
  if (!fitted.ok()) {
    ReportError(*spec, fitted.status());
    return ExitCodeFor(fitted.status());
  }
  const sim::Calibration& calibration = *fitted;
  Status written =
      sim::WriteCalibration(args.out, calibration, runs.front().host);
  if (!written.ok()) {
    std::fprintf(stderr, "error: %s\n", written.message().c_str());
    return 1;
  }
  std::printf("%-45s %12s %14s\n", "callback", "fixed_ms", "per_unit_us");
  for (const auto& [name, cost] : calibration) {
    std::printf("%-45s %12.3f %14.4f\n", name.c_str(), cost.fixed_s * 1e3,
                cost.per_unit_s * 1e6);
  }
  std::printf("wrote %s (%d runs)\n", args.out.c_str(), args.runs);
  return 0;
}

int RunSchemaCheck(const SchemaCheckArgs& args) {
  int worst = 0;
  for (const std::string& file : args.files) {
    std::vector<std::string> problems;
    Status status = runfile::CheckRunFile(file, &problems);
    if (status.ok()) {
      // The schema check reads no table contents: read them all, with
      // their checksums, so that "ok" means the file can be analysed.
      Result<runfile::RunData> read = runfile::ReadRunFile(file);
      if (read.ok()) {
        std::printf("%s: ok\n", file.c_str());
      } else {
        // ReadRunFile's messages name the file.
        worst = std::max(worst, ExitCodeFor(read.status()));
        std::fprintf(stderr, "%s\n", read.status().message().c_str());
      }
      continue;
    }
    worst = std::max(worst, ExitCodeFor(status));
    if (problems.empty()) {
      std::fprintf(stderr, "%s: %s\n", file.c_str(), status.message().c_str());
    }
    for (const std::string& p : problems)
      std::fprintf(stderr, "%s: %s\n", file.c_str(), p.c_str());
  }
  return worst;
}

}  // namespace adse::cli
