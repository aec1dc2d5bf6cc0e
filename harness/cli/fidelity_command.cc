// `adse fidelity <scenario> --points P1 P2 ... [--runs K] [--perturbed-runs
// P]`: each point on the virtual platform (1 + P times) and K times on the
// real-time one, compared (harness/fidelity); `adse fidelity --compare DIR`
// compares an earlier call's runs again. Exit 0 ok, 2 bad input (a point
// outside the space, a scenario without a cost profile, more cores than the
// host gives, a folder without such runs), 1 otherwise.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "analysis/pictures/pictures.h"
#include "analysis/runfile/run_file.h"
#include "harness/cli/cli_support.h"
#include "harness/cli/commands.h"
#include "harness/fidelity/fidelity.h"
#include "harness/spec/design_point.h"
#include "harness/spec/types.h"
#include "stack/base/files.h"

namespace adse::cli {
namespace {

nlohmann::json ComparisonsJson(
    const std::vector<fidelity::Comparison>& comparisons) {
  auto number = [](double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
  };
  nlohmann::json out = nlohmann::json::array();
  for (const fidelity::Comparison& c : comparisons) {
    nlohmann::json runs = nlohmann::json::array();
    for (double v : c.realtime) runs.push_back(number(v));
    nlohmann::json virtual_runs = nlohmann::json::array();
    for (double v : c.virtual_runs) virtual_runs.push_back(number(v));
    out.push_back(
        {{"name", c.name},
         {"virtual", number(c.virtual_value)},
         {"virtual_runs", virtual_runs},
         {"virtual_runs_without", c.virtual_runs_without},
         {"realtime_median", number(c.realtime_median)},
         {"realtime_runs", runs},
         {"realtime_runs_without", c.runs_without},
         {"invocations", c.virtual_count > 0
                             ? nlohmann::json{{"virtual", c.virtual_count},
                                              {"realtime", c.realtime_counts},
                                              {"compared", c.compared_count}}
                             : nlohmann::json()},
         {"difference", number(c.difference)},
         {"tolerance",
          c.tolerance ? nlohmann::json(*c.tolerance) : nlohmann::json()},
         {"met", c.tolerance ? nlohmann::json(c.met()) : nlohmann::json()}});
  }
  return out;
}

nlohmann::json PointJson(const fidelity::PointFidelity& f) {
  return {{"point", f.point},
          {"dispatch", f.dispatch},
          {"confinement", f.confinement},
          {"clock_by", f.clock_by},
          {"perturbed_runs", f.perturbed_outcomes.size()},
          {"ended",
           {{"virtual", f.virtual_outcome},
            {"virtual_perturbed", f.perturbed_outcomes},
            {"realtime", f.realtime_outcomes}}},
          {"metrics", ComparisonsJson(f.metrics)},
          {"callback_p50_ms", ComparisonsJson(f.callback_p50_ms)},
          {"callback_p99_ms", ComparisonsJson(f.callback_p99_ms)},
          {"callback_p50_ms_per_kunit",
           ComparisonsJson(f.callback_p50_ms_per_kunit)}};
}

// The point's callback p50s, virtual above real time, as a PNG at `png`
// (nothing when no callback ran).
Status DrawPoint(const fidelity::PointFidelity& f, size_t realtime_runs,
                 const std::string& task_case, const std::string& png) {
  std::vector<analysis::ComparisonRow> rows;
  for (const fidelity::Comparison& c : f.callback_p50_ms) {
    std::optional<double> real;
    if (std::isfinite(c.realtime_median)) real = c.realtime_median;
    rows.push_back({c.name, c.virtual_value, real});
  }
  if (rows.empty()) return Status::Ok();
  analysis::ComparisonChartOptions o;
  o.title =
      fmt::format("p50 callback latency at {}{}: virtual vs real time", f.point,
                  task_case.empty() ? "" : ", case " + task_case);
  o.adse_name = fmt::format("virtual platform ({})", f.dispatch);
  o.reference_name =
      realtime_runs == 1
          ? std::string("real time (1 run)")
          : fmt::format("real time (median of {} runs)", realtime_runs);
  return analysis::RenderComparisonChart(rows, o, png);
}

// With several dispatches each file names its own.
std::string DispatchSuffix(const fidelity::PointRuns& runs, size_t d) {
  return runs.dispatches.size() > 1
             ? fmt::format("-{}", spec::DispatchToString(runs.dispatches[d]))
             : std::string();
}

// The comparison as it grows, point by point: the text printed, the JSON,
// and each dispatch's comparisons for the summary.
struct Comparisons {
  std::string dir;
  std::string text;
  nlohmann::json json;
  std::vector<fidelity::PointFidelity> compared;
  bool several_dispatches = false;

  // Point `n`'s runs held against each other per dispatch: printed, kept,
  // and drawn as fidelity-n[-dispatch].png. Kept only once every picture
  // is drawn, so that a failed one leaves no part of the point behind.
  Status Add(size_t n, const fidelity::PointRuns& runs,
             const std::string& task_case) {
    std::vector<fidelity::PointFidelity> point;
    for (size_t d = 0; d < runs.dispatches.size(); ++d) {
      point.push_back(fidelity::ComparePoint(runs, d));
      ADSE_RETURN_IF_ERROR(DrawPoint(point.back(), runs.realtime_runs.size(),
                                     task_case,
                                     fmt::format("{}/fidelity-{}{}.png", dir, n,
                                                 DispatchSuffix(runs, d))));
    }
    several_dispatches = several_dispatches || runs.dispatches.size() > 1;
    for (const fidelity::PointFidelity& f : point) {
      const std::string table = fidelity::FormatPointFidelity(f);
      std::printf("%s\n", table.c_str());
      text += table + "\n";
      json["points"].push_back(PointJson(f));
      compared.push_back(f);
    }
    return Status::Ok();
  }

  // The summary (over more than one point or dispatch), then fidelity.txt
  // (ending with `tail`) and fidelity.json.
  Status Finish(size_t points, const std::string& tail = "") {
    if (points > 1 || several_dispatches) {
      const std::string summary = fidelity::FormatDispatchSummary(compared);
      std::printf("%s", summary.c_str());
      text += summary;
    }
    text += tail;
    ADSE_RETURN_IF_ERROR(WriteFileAtomic(dir + "/fidelity.txt", text));
    return WriteFileAtomic(dir + "/fidelity.json", json.dump(1) + "\n");
  }

  // A call that failed (or was interrupted) at point `n` of `total`: what
  // was compared before it is kept, and both files say where it stopped,
  // so that they never pass for the whole comparison.
  Status Stop(size_t n, size_t total, const std::string& point,
              const Status& why) {
    const std::string before =
        n == 2 ? "point 1 is compared above; its"
               : fmt::format("points 1-{} are compared above; their", n - 1);
    const std::string note = fmt::format(
        "stopped at point {} of {} ({}): {}\n{} runs are in {}/runs\n", n,
        total, point, why.message(), before, dir);
    json["stopped"] = {{"at_point", n},
                       {"of", total},
                       {"point", point},
                       {"error", why.message()}};
    std::fprintf(stderr, "%s", note.c_str());
    return Finish(n - 1, note);
  }
};

// The point's runs themselves, for adse analyze, h5py and --compare:
// runs/N-virtual[-<dispatch>] (one per dispatch), its perturbed runs
// N-virtual[-<dispatch>]-pK, and runs/N-realtime-R.
Status WritePointRuns(const std::string& dir, size_t n,
                      const fidelity::PointRuns& runs) {
  Status written = MakeDirs(dir + "/runs");
  for (size_t d = 0; d < runs.virtual_runs.size() && written.ok(); ++d) {
    const std::string stem =
        fmt::format("{}/runs/{}-virtual{}", dir, n, DispatchSuffix(runs, d));
    written = runfile::WriteRunFile(stem + ".h5", runs.virtual_runs[d]);
    for (size_t k = 0; d < runs.perturbed_runs.size() &&
                       k < runs.perturbed_runs[d].size() && written.ok();
         ++k) {
      written = runfile::WriteRunFile(fmt::format("{}-p{}.h5", stem, k + 1),
                                      runs.perturbed_runs[d][k]);
    }
  }
  for (size_t r = 0; r < runs.realtime_runs.size() && written.ok(); ++r) {
    written = runfile::WriteRunFile(
        fmt::format("{}/runs/{}-realtime-{}.h5", dir, n, r + 1),
        runs.realtime_runs[r]);
  }
  return written;
}

// A file of an earlier call's comparison in `dir` (its text, or a run
// file in runs/), or nullopt.
std::optional<std::string> EarlierComparison(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(dir + "/fidelity.txt", ec)) return dir + "/fidelity.txt";
  for (const auto& e : fs::directory_iterator(dir + "/runs", ec)) {
    if (e.is_regular_file(ec) && e.path().extension() == ".h5") {
      return e.path().string();
    }
  }
  return std::nullopt;
}

// `adse fidelity --compare DIR`: the runs an earlier call wrote, compared
// again (after a change to the comparison, or to read them with another
// binary); the run files are left as they are.
int CompareAgain(const FidelityArgs& args) {
  Result<std::vector<fidelity::PointRuns>> runs =
      fidelity::ReadPointRuns(args.compare);
  if (!runs.ok()) {
    std::fprintf(stderr, "error: --compare %s: %s\n", args.compare.c_str(),
                 runs.status().message().c_str());
    return ExitCodeFor(runs.status());
  }
  const runfile::RunData& first = runs->front().virtual_runs.front();
  Comparisons c;
  c.dir = args.out.empty() ? args.compare : args.out;
  if (Status made = MakeDirs(c.dir); !made.ok()) {
    std::fprintf(stderr, "error: %s\n", made.message().c_str());
    return 1;
  }
  c.json = {{"scenario", first.scenario_name},
            {"runs", runs->front().realtime_runs.size()},
            {"points", nlohmann::json::array()}};
  if (!first.task_case.empty()) c.json["task_case"] = first.task_case;
  for (size_t i = 0; i < runs->size(); ++i) {
    const fidelity::PointRuns& point = (*runs)[i];
    if (Status added =
            c.Add(i + 1, point, point.virtual_runs.front().task_case);
        !added.ok()) {
      std::fprintf(stderr, "error: %s\n", added.message().c_str());
      return 1;
    }
  }
  if (Status saved = c.Finish(runs->size()); !saved.ok()) {
    std::fprintf(stderr, "error: %s\n", saved.message().c_str());
    return 1;
  }
  std::printf("wrote %s/fidelity.txt, fidelity.json and fidelity-N.png\n",
              c.dir.c_str());
  return 0;
}

}  // namespace

int RunFidelity(const FidelityArgs& args) {
  if (!args.compare.empty()) return CompareAgain(args);
  if (args.scenario.empty() || args.points.empty()) {
    std::fprintf(stderr,
                 "error: adse fidelity: expected a scenario and --points, or "
                 "--compare DIR\n");
    return 2;
  }
  std::optional<spec::Spec> spec =
      LoadCaseOrReport(args.scenario, args.task_case);
  if (!spec) return 2;
  if (!args.clock_by.empty()) {
    spec::StringToClockBy(args.clock_by, &spec->platform.clock_by);
  }
  std::vector<spec::DesignPoint> points;
  for (const std::string& text : args.points) {
    Result<spec::DesignPoint> point =
        spec::ParsePoint(spec->design_space, text);
    if (!point.ok()) {
      std::fprintf(stderr, "error: --points %s: %s\n", text.c_str(),
                   point.status().message().c_str());
      return 2;
    }
    points.push_back(*point);
  }
  // Every point runnable in real time here, said before hours of runs.
  for (size_t i = 0; i < points.size(); ++i) {
    if (Status runnable = fidelity::CheckPointRunnable(*spec, points[i]);
        !runnable.ok()) {
      std::fprintf(stderr, "--points %s: ", args.points[i].c_str());
      ReportError(*spec, runnable);
      return 2;
    }
  }
  Comparisons c;
  c.dir = args.out.empty() ? spec->ResolvedOutput() + "/fidelity" : args.out;
  // An earlier call's runs are worth keeping (real-time runs take long),
  // and mixed with this call's they would be compared as one point's.
  if (std::optional<std::string> earlier = EarlierComparison(c.dir)) {
    std::fprintf(stderr,
                 "error: %s holds an earlier adse fidelity's comparison (%s): "
                 "give another folder with -o, or remove it; `adse fidelity "
                 "--compare %s` compares its runs again\n",
                 c.dir.c_str(), earlier->c_str(), c.dir.c_str());
    return 2;
  }
  if (Status made = MakeDirs(c.dir); !made.ok()) {
    std::fprintf(stderr, "error: %s\n", made.message().c_str());
    return 1;
  }
  fidelity::FidelityOptions options;
  options.runs = args.runs;
  options.perturbed_runs = args.perturbed_runs;
  for (const std::string& name : args.dispatch) {
    spec::Dispatch d;
    spec::StringToDispatch(name, &d);  // CLI11 checked the name
    if (std::find(options.dispatches.begin(), options.dispatches.end(), d) ==
        options.dispatches.end()) {
      options.dispatches.push_back(d);
    }
  }
  options.on_run = [](const std::string& point, const std::string& what) {
    std::fprintf(stderr, "%s: %s run ...\n", point.c_str(), what.c_str());
  };
  c.json = {{"scenario", spec->name},
            {"runs", args.runs},
            {"points", nlohmann::json::array()}};
  if (!args.task_case.empty()) c.json["task_case"] = args.task_case;
  for (size_t i = 0; i < points.size(); ++i) {
    Result<fidelity::PointRuns> runs =
        fidelity::RunPoint(*spec, points[i], options);
    Status kept = runs.status();
    if (runs.ok()) {
      // The runs first: a failed picture loses no run.
      kept = WritePointRuns(c.dir, i + 1, *runs);
      if (kept.ok()) kept = c.Add(i + 1, *runs, args.task_case);
      if (!kept.ok()) {
        std::fprintf(stderr, "error: %s\n", kept.message().c_str());
      }
    } else {
      ReportError(*spec, kept);
    }
    if (!kept.ok()) {
      // What was compared so far stays on disk, saying where it stopped.
      if (i > 0) (void)c.Stop(i + 1, points.size(), args.points[i], kept);
      return runs.ok() ? 1 : ExitCodeFor(kept);
    }
  }
  if (Status saved = c.Finish(points.size()); !saved.ok()) {
    std::fprintf(stderr, "error: %s\n", saved.message().c_str());
    return 1;
  }
  std::printf(
      "wrote %s/fidelity.txt, fidelity.json, fidelity-N.png and runs/\n",
      c.dir.c_str());
  return 0;
}

}  // namespace adse::cli
