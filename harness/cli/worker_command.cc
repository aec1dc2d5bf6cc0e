// `adse worker`: one run in this process, as the campaign's pool starts it
// (libsumo allows one simulation per process). Simulates the point,
// analyses it and writes the run file atomically. Exit 0 ok, 2 bad input
// (including a scenario changed under the campaign), 3 out of memory, 1
// anything else.
#include <cstdio>
#include <new>

#include "analysis/runfile/run_file.h"
#include "stack/base/files.h"

#include <nlohmann/json.hpp>
#include "harness/cli/cli_support.h"
#include "harness/cli/commands.h"
#include "harness/pool/worker_pool.h"
#include "harness/report/run_report.h"
#include "harness/sim/run_key.h"
#include "harness/sim/simulator.h"
#include "harness/spec/spec_parser.h"

namespace adse::cli {
namespace {

int Work(const WorkerArgs& args) {
  std::optional<spec::Spec> spec =
      LoadWorkerCaseOrReport(args.scenario, args.task_case);
  if (!spec) return 2;
  Result<spec::DesignPoint> point =
      spec::ParsePoint(spec->design_space, args.point);
  if (!point.ok()) {
    std::fprintf(stderr, "error: --point: %s\n",
                 point.status().message().c_str());
    return 2;
  }
  const uint64_t seed = args.seed.value_or(spec->world.traffic.seed);
  if (!args.expect_key.empty()) {
    Result<std::string> key = sim::RunKey(*spec, *point, seed);
    if (!key.ok()) {
      ReportError(*spec, key.status());
      return ExitCodeFor(key.status());
    }
    if (*key != args.expect_key) {
      std::fprintf(stderr,
                   "error: %s changed since the campaign started (run key %s "
                   "expected, %s "
                   "now); start a new campaign or restore the file\n",
                   args.scenario.c_str(), args.expect_key.substr(0, 12).c_str(),
                   key->substr(0, 12).c_str());
      return 2;
    }
  }
  sim::SimulateOptions options;
  options.seed = seed;
  Result<runfile::RunData> run = sim::SimulatePoint(*spec, *point, options);
  if (!run.ok()) {
    ReportError(*spec, run.status());
    return ExitCodeFor(run.status());
  }
  // The analysis' metrics (deviation fit) travel with the run's own.
  report::AnalyzeOptions analyze;
  if (!args.image_dir.empty()) {
    if (Status s = MakeDirs(args.image_dir); !s.ok()) {
      std::fprintf(stderr, "error: %s\n", s.message().c_str());
      return 1;
    }
    analyze.image_dir = args.image_dir;
  }
  Result<report::RunReport> analysed =
      report::AnalyzeRun(*run, args.out, analyze);
  if (!analysed.ok()) {
    std::fprintf(stderr, "error: analysing the run: %s\n",
                 analysed.status().message().c_str());
    return 1;
  }
  for (const auto& [name, value] : analysed->metrics)
    run->metrics.emplace(name, value);
  if (Status s = runfile::WriteRunFile(args.out, *run); !s.ok()) {
    std::fprintf(stderr, "error: writing %s: %s\n", args.out.c_str(),
                 s.message().c_str());
    return 1;
  }
  // The coordinator takes the worker's analysis instead of redoing it;
  // written after the run file, which stays the truth (a missing or stale
  // report only costs the coordinator that analysis again).
  if (!args.report.empty()) {
    analysed->content_key = run->content_key;
    if (Status s = WriteFileAtomic(args.report,
                                   report::ToJson(*analysed).dump(1) + "\n");
        !s.ok()) {
      std::fprintf(stderr, "warning: writing %s: %s\n", args.report.c_str(),
                   s.message().c_str());
    }
  }
  std::fprintf(stderr, "wrote %s (%s)\n", args.out.c_str(),
               run->termination_reason.c_str());
  return 0;
}

}  // namespace

int RunWorker(const WorkerArgs& args) {
  try {
    return Work(args);
  } catch (const std::bad_alloc&) {
    // Under RLIMIT_AS an allocation fails instead of the OOM killer
    // striking; the pool reads this status as out of memory.
    std::fputs("error: out of memory\n", stderr);
    return pool::kExitOutOfMemory;
  }
}

}  // namespace adse::cli
