#include "harness/fidelity/fidelity.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <numeric>
#include <regex>
#include <sstream>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "analysis/metrics/run_metrics.h"
#include "analysis/runfile/run_file.h"
#include "harness/profile/profile_check.h"
#include "harness/sim/simulator.h"
#include "harness/spec/design_point.h"
#include "harness/spec/spec_parser.h"
#include "harness/spec/types.h"

namespace adse::fidelity {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Issue 15's targets.
constexpr double kRunTolerance = 0.10;       // nav time, control rate
constexpr double kCallbackTolerance = 0.20;  // per-callback p50
// Callbacks cheaper than this on the virtual platform are left out: their
// latency is the executor's bookkeeping, not the model.
constexpr double kMinCallbackMs = 1.0;
// The step of the perturbed runs' cost factors (PerturbedCostScale).
constexpr double kPerturbation = 1e-4;

// Nearest-rank quantile of `v` (sorted in place).
double Quantile(std::vector<double>& v, double q) {
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const size_t rank =
      static_cast<size_t>(std::ceil(q * static_cast<double>(v.size())));
  return v[std::max<size_t>(rank, 1) - 1];
}

// The values that are not NaN into `present`; how many were, returned.
int SplitMissing(const std::vector<double>& values,
                 std::vector<double>* present) {
  int missing = 0;
  for (double v : values) {
    if (std::isnan(v)) {
      ++missing;
    } else {
      present->push_back(v);
    }
  }
  return missing;
}

// `virtual_values`: one per virtual run, `realtime` one per real-time run,
// NaN where a run lacked it.
Comparison Compare(const std::string& name,
                   const std::vector<double>& virtual_values,
                   const std::vector<double>& realtime,
                   std::optional<double> tolerance) {
  Comparison c;
  c.name = name;
  c.virtual_runs_without = SplitMissing(virtual_values, &c.virtual_runs);
  c.runs_without = SplitMissing(realtime, &c.realtime);
  c.virtual_value = analysis::Percentile(c.virtual_runs, 0.5);
  c.realtime_median = analysis::Percentile(c.realtime, 0.5);
  c.difference =
      std::isfinite(c.virtual_value) && c.virtual_value != 0.0 &&
              std::isfinite(c.realtime_median)
          ? (c.realtime_median - c.virtual_value) / std::abs(c.virtual_value)
          : kNaN;
  c.tolerance = tolerance;
  return c;
}

double Metric(const runfile::RunData& run, const std::string& name) {
  const auto it = run.metrics.find(name);
  return it == run.metrics.end() ? kNaN : it->second;
}

double SensingToControlMs(const runfile::RunData& run) {
  std::map<std::string, std::vector<double>> chains =
      profile::ChainLatencies(run);
  const std::vector<double>& v = chains["sensing_to_control"];
  if (v.empty()) return kNaN;
  return 1000.0 * std::accumulate(v.begin(), v.end(), 0.0) /
         static_cast<double>(v.size());
}

// One invocation's execution latency (start to end, ms) and work units.
struct Invocation {
  double start_s;
  double ms;
  double work_units;
};

// Per callback name: its invocations in the order they started, which is
// the order they drew their costs from the callback's seeded stream.
std::map<std::string, std::vector<Invocation>> CallbackInvocations(
    const runfile::RunData& run) {
  std::map<std::string, std::vector<Invocation>> out;
  for (const stack::CallbackRecord& r : run.trace.callbacks) {
    if (r.callback < 0 ||
        r.callback >= static_cast<int>(run.callback_info.size())) {
      continue;
    }
    out[run.callback_info[r.callback].name].push_back(
        {r.start_s, 1000.0 * (r.end_s - r.start_s), r.work_units});
  }
  for (auto& [name, invocations] : out) {
    std::stable_sort(invocations.begin(), invocations.end(),
                     [](const Invocation& a, const Invocation& b) {
                       return a.start_s < b.start_s;
                     });
  }
  return out;
}

// The `q` quantile of the first `n` invocations' latencies; with
// `per_kunit`, per 1000 of the work units each reported (those that
// reported none left out).
double InvocationQuantile(const std::vector<Invocation>& invocations, size_t n,
                          double q, bool per_kunit = false) {
  std::vector<double> v;
  for (size_t i = 0; i < n && i < invocations.size(); ++i) {
    const Invocation& c = invocations[i];
    if (!per_kunit) {
      v.push_back(c.ms);
    } else if (c.work_units > 0.0) {
      v.push_back(c.ms / (c.work_units / 1000.0));
    }
  }
  return Quantile(v, q);
}

std::string Number(double v) {
  return std::isfinite(v) ? fmt::format("{:.4g}", v) : "—";
}

}  // namespace

double PerturbedCostScale(int k) {
  const double step = kPerturbation * static_cast<double>((k + 1) / 2);
  return k % 2 == 1 ? 1.0 + step : 1.0 - step;
}

bool Comparison::met() const {
  return tolerance && runs_without == 0 && virtual_runs_without == 0 &&
         std::isfinite(difference) && std::abs(difference) <= *tolerance;
}

PointFidelity CompareRuns(const runfile::RunData& virtual_run,
                          const std::vector<runfile::RunData>& realtime_runs,
                          const std::vector<runfile::RunData>& perturbed_runs) {
  PointFidelity f;
  f.virtual_outcome = virtual_run.termination_reason;
  for (const runfile::RunData& r : perturbed_runs) {
    f.perturbed_outcomes.push_back(r.termination_reason);
  }
  for (const runfile::RunData& r : realtime_runs) {
    f.realtime_outcomes.push_back(r.termination_reason);
  }
  std::vector<const runfile::RunData*> virtual_runs = {&virtual_run};
  for (const runfile::RunData& r : perturbed_runs) virtual_runs.push_back(&r);
  struct Quantity {
    const char* name;
    std::optional<double> tolerance;
  };
  // A nav time is compared only between runs that reached the goal: a
  // timeout's is the timeout on both platforms.
  auto reached = [](const runfile::RunData& r) {
    return r.termination_reason == "goal_reached";
  };
  for (const Quantity& q : {Quantity{"nav_time_s", kRunTolerance},
                            Quantity{"ctrl_rate_hz", kRunTolerance},
                            Quantity{"e2e_latency_p50_s", std::nullopt},
                            Quantity{"dropped_messages", std::nullopt},
                            Quantity{"lidar_frames_dropped", std::nullopt},
                            Quantity{"localization_lost_s", std::nullopt}}) {
    const bool time = std::string(q.name) == "nav_time_s";
    auto value = [&](const runfile::RunData& r) {
      return time && !reached(r) ? kNaN : Metric(r, q.name);
    };
    std::vector<double> v, rt;
    for (const runfile::RunData* r : virtual_runs) v.push_back(value(*r));
    for (const runfile::RunData& r : realtime_runs) rt.push_back(value(r));
    f.metrics.push_back(Compare(q.name, v, rt, q.tolerance));
  }
  std::vector<double> v_chain, chain;
  for (const runfile::RunData* r : virtual_runs) {
    v_chain.push_back(SensingToControlMs(*r));
  }
  for (const runfile::RunData& r : realtime_runs) {
    chain.push_back(SensingToControlMs(r));
  }
  f.metrics.push_back(
      Compare("sensing_to_control_ms", v_chain, chain, std::nullopt));

  // Both platforms draw a callback's i-th cost from the same seeded
  // stream, so its latencies are compared over the invocations every run
  // made (the first n of each): a run that made more invocations adds
  // draws of a wide cost distribution, which move a p50 of a dozen
  // invocations by a quarter with no difference in the executor.
  const std::map<std::string, std::vector<Invocation>> v =
      CallbackInvocations(virtual_run);
  std::vector<std::map<std::string, std::vector<Invocation>>> rts;
  for (const runfile::RunData& r : realtime_runs) {
    rts.push_back(CallbackInvocations(r));
  }
  for (const auto& [name, invocations] : v) {
    if (!(InvocationQuantile(invocations, invocations.size(), 0.5) >=
          kMinCallbackMs)) {
      continue;
    }
    size_t n = invocations.size();
    std::vector<int> counts;
    for (const auto& run : rts) {
      auto it = run.find(name);
      counts.push_back(it == run.end() ? 0
                                       : static_cast<int>(it->second.size()));
      if (it != run.end()) n = std::min(n, it->second.size());
    }
    // Each real-time run's quantile over the first n; NaN where it never
    // ran.
    auto realtime = [&](double q, bool per_kunit) {
      std::vector<double> out;
      for (const auto& run : rts) {
        auto it = run.find(name);
        out.push_back(it == run.end()
                          ? kNaN
                          : InvocationQuantile(it->second, n, q, per_kunit));
      }
      return out;
    };
    auto compare = [&](double q, bool per_kunit,
                       std::optional<double> tolerance) {
      Comparison c =
          Compare(name, {InvocationQuantile(invocations, n, q, per_kunit)},
                  realtime(q, per_kunit), tolerance);
      c.virtual_count = static_cast<int>(invocations.size());
      c.realtime_counts = counts;
      c.compared_count = static_cast<int>(n);
      return c;
    };
    f.callback_p50_ms.push_back(compare(0.5, false, kCallbackTolerance));
    f.callback_p99_ms.push_back(compare(0.99, false, std::nullopt));
    Comparison unit = compare(0.5, true, std::nullopt);
    if (std::isfinite(unit.virtual_value)) {
      f.callback_p50_ms_per_kunit.push_back(std::move(unit));
    }
  }
  return f;
}

Status CheckPointRunnable(const spec::Spec& spec,
                          const spec::DesignPoint& point) {
  ADSE_RETURN_IF_ERROR(spec.design_space.Check(point));
  Result<spec::PointConfig> config = spec::ApplyPoint(spec, point);
  if (!config.ok()) return config.status();
  return sim::CheckRealTimePlatform(config->platform);
}

Result<PointRuns> RunPoint(const spec::Spec& input,
                           const spec::DesignPoint& point,
                           const FidelityOptions& options) {
  if (options.runs < 1) {
    return Status::InvalidArgument(
        fmt::format("runs: expected at least 1, found {}", options.runs));
  }
  if (options.perturbed_runs < 0) {
    return Status::InvalidArgument(
        fmt::format("perturbed_runs: expected at least 0, found {}",
                    options.perturbed_runs));
  }
  ADSE_RETURN_IF_ERROR(input.design_space.Check(point));
  spec::Spec spec = input;
  spec.harness.early_stop = false;
  PointRuns runs;
  runs.point = spec::FormatPoint(spec.design_space, point);
  runs.dispatches = options.dispatches;
  if (runs.dispatches.empty()) runs.dispatches = {spec.platform.dispatch};

  spec.platform.kind = spec::PlatformKind::kVirtual;
  const double cost_scale = spec.platform.cost_scale;
  for (spec::Dispatch dispatch : runs.dispatches) {
    spec.platform.dispatch = dispatch;
    const std::string what =
        runs.dispatches.size() == 1
            ? std::string("virtual")
            : fmt::format("virtual {}", spec::DispatchToString(dispatch));
    runs.perturbed_runs.emplace_back();
    for (int k = 0; k <= options.perturbed_runs; ++k) {
      if (options.on_run) {
        options.on_run(runs.point,
                       k == 0 ? what
                              : fmt::format("{} perturbed {}/{}", what, k,
                                            options.perturbed_runs));
      }
      spec.platform.cost_scale =
          k == 0 ? cost_scale : cost_scale * PerturbedCostScale(k);
      Result<runfile::RunData> run = sim::SimulatePoint(spec, point);
      if (!run.ok()) return run.status();
      (k == 0 ? runs.virtual_runs : runs.perturbed_runs.back())
          .push_back(std::move(run).value());
    }
  }
  spec.platform.cost_scale = cost_scale;

  spec.platform.kind = spec::PlatformKind::kCgroup;
  spec.platform.dispatch = spec::Dispatch::kRunToCompletion;
  for (int k = 0; k < options.runs; ++k) {
    if (options.on_run) {
      options.on_run(runs.point,
                     fmt::format("real-time {}/{}", k + 1, options.runs));
    }
    Result<runfile::RunData> run = sim::SimulatePoint(spec, point);
    if (!run.ok()) return run.status();
    runs.realtime_runs.push_back(std::move(run).value());
  }
  return runs;
}

namespace {

// A virtual run file, and the dispatch its platform record names.
struct VirtualRun {
  runfile::RunData data;
  spec::Dispatch dispatch;
};

// A run file read back, its run metrics measured again from its data (as
// `adse analyze` does): a comparison of older runs shows metrics added
// since they were written.
Result<runfile::RunData> ReadRun(const std::string& path) {
  Result<runfile::RunData> run = runfile::ReadRunFile(path);
  if (!run.ok()) return run.status();
  for (const auto& [name, value] : analysis::ComputeRunMetrics(*run)) {
    run->metrics[name] = value;
  }
  return run;
}

Result<VirtualRun> ReadVirtualRun(const std::string& path) {
  Result<runfile::RunData> run = ReadRun(path);
  if (!run.ok()) return run.status();
  VirtualRun out;
  const auto it = run->platform.find("dispatch");
  if (it == run->platform.end() ||
      !spec::StringToDispatch(it->second, &out.dispatch)) {
    return Status::InvalidArgument(fmt::format(
        "{}: platform.dispatch: expected one of the dispatches, found '{}'",
        path, it == run->platform.end() ? "" : it->second));
  }
  out.data = std::move(run).value();
  return out;
}

}  // namespace

Result<std::vector<PointRuns>> ReadPointRuns(const std::string& dir) {
  const std::filesystem::path folder = std::filesystem::path(dir) / "runs";
  std::error_code error;
  if (!std::filesystem::is_directory(folder, error)) {
    return Status::NotFound(
        fmt::format("{}: no such folder (adse fidelity writes its runs there)",
                    folder.string()));
  }
  // By N: the virtual runs' paths, then the real-time runs' by K.
  struct Files {
    std::vector<std::string> virtual_runs;
    // By the name's dispatch part and K.
    std::map<std::pair<std::string, int>, std::string> perturbed_runs;
    std::map<int, std::string> realtime_runs;
  };
  std::map<int, Files> by_point;
  const std::regex name(
      R"((\d{1,6})-(virtual(-[a-z_]+)?(-p(\d{1,6}))?|realtime-(\d{1,6}))\.h5)");
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    const std::string file = entry.path().filename().string();
    if (entry.path().extension() != ".h5") continue;
    std::smatch m;
    if (!std::regex_match(file, m, name)) {
      return Status::InvalidArgument(fmt::format(
          "{}: expected run files named N-virtual[-<dispatch>][-pK].h5 or "
          "N-realtime-K.h5",
          entry.path().string()));
    }
    Files& files = by_point[std::stoi(m[1].str())];
    if (m[6].matched) {
      files.realtime_runs[std::stoi(m[6].str())] = entry.path().string();
    } else if (m[5].matched) {
      files.perturbed_runs[{m[3].str(), std::stoi(m[5].str())}] =
          entry.path().string();
    } else {
      files.virtual_runs.push_back(entry.path().string());
    }
  }
  if (error) {
    return Status::IoError(
        fmt::format("{}: {}", folder.string(), error.message()));
  }
  if (by_point.empty()) {
    return Status::NotFound(
        fmt::format("{}: holds no run of adse fidelity", folder.string()));
  }
  std::vector<PointRuns> out;
  for (auto& [n, files] : by_point) {
    if (files.virtual_runs.empty() || files.realtime_runs.empty()) {
      return Status::InvalidArgument(fmt::format(
          "{}: point {} has {} virtual and {} real-time run files; both are "
          "needed",
          folder.string(), n, files.virtual_runs.size(),
          files.realtime_runs.size()));
    }
    PointRuns runs;
    std::string first_path;  // of the first dispatch's virtual run
    for (const std::string& path : files.virtual_runs) {
      Result<VirtualRun> run = ReadVirtualRun(path);
      if (!run.ok()) return run.status();
      // In the vocabulary's order (run to completion first), whatever
      // order the folder lists them in.
      const auto at = std::upper_bound(runs.dispatches.begin(),
                                       runs.dispatches.end(), run->dispatch);
      if (at == runs.dispatches.begin()) first_path = path;
      runs.virtual_runs.insert(
          runs.virtual_runs.begin() + (at - runs.dispatches.begin()),
          std::move(run->data));
      runs.dispatches.insert(at, run->dispatch);
    }
    runs.perturbed_runs.resize(runs.dispatches.size());
    for (const auto& [key, path] : files.perturbed_runs) {
      Result<VirtualRun> run = ReadVirtualRun(path);
      if (!run.ok()) return run.status();
      const auto at = std::find(runs.dispatches.begin(), runs.dispatches.end(),
                                run->dispatch);
      if (at == runs.dispatches.end()) {
        return Status::InvalidArgument(fmt::format(
            "{}: a perturbed run of point {} with the {} dispatch, but no "
            "virtual run of that dispatch beside it",
            path, n, spec::DispatchToString(run->dispatch)));
      }
      runs.perturbed_runs[at - runs.dispatches.begin()].push_back(
          std::move(run->data));
    }
    for (const auto& [k, path] : files.realtime_runs) {
      Result<runfile::RunData> run = ReadRun(path);
      if (!run.ok()) return run.status();
      runs.realtime_runs.push_back(std::move(run).value());
    }
    // The point as the scenario's space writes it.
    const runfile::RunData& first = runs.virtual_runs.front();
    spec::ParseOptions parse;
    parse.check_files = false;  // only the space is read
    Result<spec::Spec> stored = spec::ParseSpec(
        first.scenario_text, first_path + ": scenario/yaml", "", parse);
    if (!stored.ok()) return stored.status();
    runs.point = spec::FormatPoint(stored->design_space, first.design_point);
    // A point's files from two calls into one folder would be compared as
    // one point's.
    std::vector<const runfile::RunData*> all;
    for (const runfile::RunData& r : runs.virtual_runs) all.push_back(&r);
    for (const auto& per_dispatch : runs.perturbed_runs) {
      for (const runfile::RunData& r : per_dispatch) all.push_back(&r);
    }
    for (const runfile::RunData& r : runs.realtime_runs) all.push_back(&r);
    for (const runfile::RunData* r : all) {
      if (r->design_point != first.design_point) {
        return Status::InvalidArgument(fmt::format(
            "{}: point {}'s run files are of different design points ({} and "
            "{}): the folder mixes the runs of several adse fidelity calls",
            folder.string(), n, runs.point,
            spec::FormatPoint(stored->design_space, r->design_point)));
      }
    }
    out.push_back(std::move(runs));
  }
  return out;
}

PointFidelity ComparePoint(const PointRuns& runs, size_t i) {
  static const std::vector<runfile::RunData> kNone;
  const std::vector<runfile::RunData>& perturbed =
      i < runs.perturbed_runs.size() ? runs.perturbed_runs[i] : kNone;
  PointFidelity f =
      CompareRuns(runs.virtual_runs.at(i), runs.realtime_runs, perturbed);
  f.point = runs.point;
  f.dispatch = spec::DispatchToString(runs.dispatches.at(i));
  if (!runs.realtime_runs.empty()) {
    const std::map<std::string, std::string>& notes =
        runs.realtime_runs.front().platform;
    if (notes.count("confinement")) f.confinement = notes.at("confinement");
    if (notes.count("clock_by")) f.clock_by = notes.at("clock_by");
  }
  return f;
}

std::string FormatPointFidelity(const PointFidelity& f) {
  std::ostringstream out;
  const size_t k = f.realtime_outcomes.size();
  const size_t p = f.perturbed_outcomes.size();
  // The last perturbed run's factor is the farthest from 1.
  const std::string perturbed =
      p == 0 ? std::string()
             : fmt::format(
                   "; median of {} runs, costs x (1 ± {:g})", p + 1,
                   std::abs(PerturbedCostScale(static_cast<int>(p)) - 1.0));
  out << fmt::format(
      "{}: virtual ({}{}) vs real-time (median of {} run{}; {}; clock by "
      "{})\n",
      f.point, f.dispatch, perturbed, k, k == 1 ? "" : "s", f.confinement,
      f.clock_by);
  // How the runs ended leads: a run that ended otherwise than the virtual
  // one is a disagreement no median shows.
  auto same_as_virtual = [&](const std::vector<std::string>& outcomes) {
    return std::all_of(
        outcomes.begin(), outcomes.end(),
        [&](const std::string& o) { return o == f.virtual_outcome; });
  };
  out << fmt::format(
      "  ended: virtual {}{}; real-time {}{}\n", f.virtual_outcome,
      p == 0 ? std::string()
             : fmt::format(" (perturbed: {})",
                           fmt::join(f.perturbed_outcomes, ", ")),
      fmt::join(f.realtime_outcomes, ", "),
      same_as_virtual(f.realtime_outcomes) &&
              same_as_virtual(f.perturbed_outcomes)
          ? ""
          : "  (differ)");
  // "min–max" of a run's values, "(n without)" when some runs lacked it.
  auto range = [](const std::vector<double>& values, int without) {
    std::string text;
    if (!values.empty()) {
      text = Number(*std::min_element(values.begin(), values.end())) + "–" +
             Number(*std::max_element(values.begin(), values.end()));
    }
    if (without > 0 && !values.empty()) {
      text = fmt::format("{} ({} without)", text, without);
    }
    return text;
  };
  auto table = [&](const char* what, const std::vector<Comparison>& rows) {
    // The virtual runs' column only when there were several.
    auto column = [p](const std::string& text) {
      return p == 0 ? std::string() : fmt::format(" {:>22}", text);
    };
    out << fmt::format("  {:<44}{} {:>10} {:>10} {:>22} {:>8}  {}\n", what,
                       column("virtual runs"), "virtual", "real-time",
                       "real-time runs", "diff", "target");
    for (const Comparison& c : rows) {
      const std::string virtual_runs =
          column(c.virtual_runs.size() + c.virtual_runs_without > 1
                     ? range(c.virtual_runs, c.virtual_runs_without)
                     : std::string());
      const std::string runs = range(c.realtime, c.runs_without);
      const std::string diff =
          std::isfinite(c.difference)
              ? fmt::format("{:+.1f}%", 100.0 * c.difference)
              : std::string("—");
      const std::string target =
          c.tolerance ? fmt::format("±{:.0f}% {}", 100.0 * *c.tolerance,
                                    c.met() ? "met" : "missed")
                      : std::string();
      std::string count;
      if (c.virtual_count > 0) {
        count =
            fmt::format("  n {} / {}, first {} compared", c.virtual_count,
                        fmt::join(c.realtime_counts, ", "), c.compared_count);
      }
      out << fmt::format("  {:<44}{} {:>10} {:>10} {:>22} {:>8}  {}{}\n",
                         c.name, virtual_runs, Number(c.virtual_value),
                         Number(c.realtime_median), runs, diff, target, count);
    }
  };
  table("run", f.metrics);
  table("callback p50 latency, start to end (ms)", f.callback_p50_ms);
  table("callback p99 latency (ms)", f.callback_p99_ms);
  table("callback p50 latency per 1000 work units (ms)",
        f.callback_p50_ms_per_kunit);
  return out.str();
}

std::string FormatDispatchSummary(const std::vector<PointFidelity>& points) {
  struct Tally {
    int points = 0, rate_met = 0, nav = 0, nav_met = 0;
    int callbacks = 0, callbacks_met = 0;
    std::vector<double> abs_p50;
  };
  std::vector<std::string> order;
  std::map<std::string, Tally> by;
  for (const PointFidelity& f : points) {
    if (by.count(f.dispatch) == 0) order.push_back(f.dispatch);
    Tally& t = by[f.dispatch];
    ++t.points;
    for (const Comparison& c : f.metrics) {
      if (c.name == "ctrl_rate_hz") t.rate_met += c.met();
      // Compared where some run arrived: a nav time no run has is no test.
      if (c.name == "nav_time_s" &&
          (std::isfinite(c.virtual_value) || !c.realtime.empty())) {
        ++t.nav;
        t.nav_met += c.met();
      }
    }
    for (const Comparison& c : f.callback_p50_ms) {
      ++t.callbacks;
      t.callbacks_met += c.met();
      if (std::isfinite(c.difference)) {
        t.abs_p50.push_back(std::abs(c.difference));
      }
    }
  }
  std::ostringstream out;
  out << fmt::format("{:<20} {:>16} {:>16} {:>20} {:>18}\n", "dispatch",
                     "ctrl rate ±10%", "nav time ±10%", "callback p50 ±20%",
                     "median |p50 diff|");
  for (const std::string& d : order) {
    Tally& t = by[d];
    out << fmt::format(
        "{:<20} {:>16} {:>16} {:>20} {:>18}\n", d,
        fmt::format("{} of {}", t.rate_met, t.points),
        fmt::format("{} of {}", t.nav_met, t.nav),
        fmt::format("{} of {}", t.callbacks_met, t.callbacks),
        t.abs_p50.empty()
            ? std::string("—")
            : fmt::format("{:.1f}%", 100.0 * Quantile(t.abs_p50, 0.5)));
  }
  return out.str();
}

}  // namespace adse::fidelity
