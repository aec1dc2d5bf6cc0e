// adse analyze: recompute metrics, deviation, diagnosis, pictures and the
// Pareto front from stored run files, into a new analysis version next to
// them; or compare two analysis versions.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "analysis/pareto/pareto.h"
#include "analysis/pictures/pictures.h"
#include "analysis/runfile/run_file.h"
#include "harness/cli/commands.h"
#include "harness/report/run_report.h"
#include "harness/spec/spec_parser.h"
#include "stack/base/files.h"

namespace adse::cli {
namespace {

namespace fs = std::filesystem;

// The next free "v<N>" folder under `root`.
std::string NextVersion(const fs::path& root) {
  int last = 0;
  std::error_code ec;
  if (fs::is_directory(root, ec)) {
    for (const auto& e : fs::directory_iterator(root, ec)) {
      const std::string name = e.path().filename().string();
      if (name.size() > 1 && name[0] == 'v')
        last = std::max(last, std::atoi(name.c_str() + 1));
    }
  }
  return (root / fmt::format("v{}", last + 1)).string();
}

std::vector<std::string> RunFilesIn(const fs::path& folder) {
  std::vector<std::string> out;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(folder, ec);
       it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (ec) break;
    const std::string name = it->path().filename().string();
    if (it->is_directory() &&
        (name == "analysis" || name.ends_with(".analysis"))) {
      it.disable_recursion_pending();
      continue;
    }
    if (it->is_regular_file() && it->path().extension() == ".h5" &&
        name.find(".tmp.") == std::string::npos) {
      out.push_back(it->path().string());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Objectives in minimisation form from the scenario stored in the runs.
struct ObjectiveSet {
  std::vector<std::string> names;
  std::vector<bool> maximize;
};

ObjectiveSet ObjectivesOf(const runfile::RunData& run) {
  ObjectiveSet set;
  Result<spec::Spec> spec =
      spec::ParseSpec(run.scenario_text, "stored scenario", ".");
  if (spec.ok()) {
    for (const spec::Objective& o : spec->objectives) {
      set.names.push_back(o.metric);
      set.maximize.push_back(!o.minimize);
    }
  }
  if (set.names.empty())
    set = {{"hardware_cost", "nav_time_s"}, {false, false}};
  return set;
}

Status WriteJson(const std::string& path, const nlohmann::json& doc) {
  return WriteFileAtomic(path, doc.dump(2) + "\n");
}

int Diff(const std::string& a_path, const std::string& b_path, bool json) {
  auto load = [](const std::string& dir) -> std::optional<nlohmann::json> {
    for (const char* name : {"summary.json", "report.json"}) {
      const fs::path p = fs::path(dir) / name;
      Result<std::string> text = ReadFile(p.string());
      if (!text.ok()) continue;
      nlohmann::json doc = nlohmann::json::parse(*text, nullptr, false);
      if (doc.is_discarded()) {
        std::fprintf(stderr, "error: %s: not valid JSON\n", p.string().c_str());
        return std::nullopt;
      }
      if (doc.contains("runs")) return doc;
      return nlohmann::json{{"runs", nlohmann::json::array({doc})}};
    }
    std::fprintf(stderr,
                 "error: %s: no summary.json or report.json (expected an "
                 "analysis version folder)\n",
                 dir.c_str());
    return std::nullopt;
  };
  std::optional<nlohmann::json> a = load(a_path), b = load(b_path);
  if (!a || !b) return 2;
  auto key = [](const nlohmann::json& r) {
    std::string k;
    for (const auto& [name, value] : r["point"].items())
      k += fmt::format("{}={} ", name, value.dump());
    return k + "seed=" + r["seed"].dump();
  };
  std::map<std::string, nlohmann::json> in_a, in_b;
  for (const auto& r : (*a)["runs"]) in_a[key(r)] = r;
  for (const auto& r : (*b)["runs"]) in_b[key(r)] = r;
  nlohmann::json changes = nlohmann::json::array();
  std::set<std::string> keys;
  for (const auto& [k, _] : in_a) keys.insert(k);
  for (const auto& [k, _] : in_b) keys.insert(k);
  for (const std::string& k : keys) {
    nlohmann::json change = {{"point", k}};
    if (!in_a.count(k))
      change["change"] = "only in B";
    else if (!in_b.count(k))
      change["change"] = "only in A";
    else {
      const auto& ra = in_a[k];
      const auto& rb = in_b[k];
      if (ra["feasible"] != rb["feasible"])
        change["feasible"] = {ra["feasible"], rb["feasible"]};
      if (ra.value("on_front", false) != rb.value("on_front", false)) {
        change["on_front"] = {ra.value("on_front", false),
                              rb.value("on_front", false)};
      }
      for (const auto& [m, va] : ra["metrics"].items()) {
        const auto vb = rb["metrics"].value(m, nlohmann::json(nullptr));
        if (va.is_number() && vb.is_number()) {
          const double x = va.get<double>(), y = vb.get<double>();
          if (std::abs(x - y) > 1e-9 * std::max(1.0, std::abs(x)))
            change["metrics"][m] = {x, y};
        } else if (va != vb) {
          change["metrics"][m] = {va, vb};
        }
      }
      if (change.size() == 1) continue;
    }
    changes.push_back(change);
  }
  if (json) {
    std::printf(
        "%s\n",
        nlohmann::json{{"a", a_path}, {"b", b_path}, {"changes", changes}}
            .dump(2)
            .c_str());
    return 0;
  }
  std::printf("A = %s\nB = %s\n%zu of %zu points changed\n", a_path.c_str(),
              b_path.c_str(), changes.size(), keys.size());
  for (const auto& c : changes) std::printf("  %s\n", c.dump().c_str());
  return 0;
}

}  // namespace

int RunAnalyze(const AnalyzeArgs& args) {
  if (!args.diff.empty()) {
    if (args.diff.size() != 2) {
      std::fprintf(stderr,
                   "error: --diff takes two analysis folders: --diff A B\n");
      return 2;
    }
    return Diff(args.diff[0], args.diff[1], args.json);
  }
  report::AnalyzeOptions options;
  for (const std::string& t : args.thresholds) {
    const size_t eq = t.find('=');
    char* end = nullptr;
    const double value =
        eq == std::string::npos ? 0.0 : std::strtod(t.c_str() + eq + 1, &end);
    if (eq == std::string::npos || end == nullptr || *end != '\0' ||
        eq + 1 == t.size()) {
      std::fprintf(stderr,
                   "error: --threshold %s: expected NAME=VALUE with a number\n",
                   t.c_str());
      return 2;
    }
    options.thresholds[t.substr(0, eq)] = value;
  }
  int exit_code = 0;
  for (const std::string& target : args.targets) {
    std::error_code ec;
    const bool folder = fs::is_directory(target, ec);
    if (!folder && !fs::exists(target, ec)) {
      std::fprintf(stderr, "error: %s: no such file or folder\n",
                   target.c_str());
      exit_code = 2;
      continue;
    }
    const std::vector<std::string> files =
        folder ? RunFilesIn(target) : std::vector<std::string>{target};
    if (files.empty()) {
      std::fprintf(stderr, "error: %s: no run files (*.h5) in it\n",
                   target.c_str());
      exit_code = 2;
      continue;
    }
    nlohmann::json summary = {{"analysis_of", target},
                              {"runs", nlohmann::json::array()}};
    std::vector<analysis::Evaluation> evals;
    std::vector<nlohmann::json*> rows;
    std::optional<ObjectiveSet> objectives;
    for (const std::string& file : files) {
      Result<runfile::RunData> run = runfile::ReadRunFile(file);
      if (!run.ok()) {
        // A broken file never stops the rest.
        std::fprintf(stderr, "skipped %s: %s\n", file.c_str(),
                     run.status().message().c_str());
        exit_code = 2;
        continue;
      }
      const std::string version =
          NextVersion(file.substr(0, file.size() - 3) + ".analysis");
      options.image_dir = version;
      if (Status s = MakeDirs(version); !s.ok()) {
        std::fprintf(stderr, "error: %s\n", s.message().c_str());
        return 1;
      }
      Result<report::RunReport> report =
          report::AnalyzeRun(*run, file, options);
      if (!report.ok()) {
        std::fprintf(stderr, "error: %s: %s\n", file.c_str(),
                     report.status().message().c_str());
        fs::remove_all(version, ec);
        return ExitCodeFor(report.status());
      }
      const nlohmann::json doc = report::ToJson(*report);
      if (Status s = WriteJson(version + "/report.json", doc); !s.ok()) {
        std::fprintf(stderr, "error: %s\n", s.message().c_str());
        return 1;
      }
      if (!folder) {
        if (args.json) {
          std::printf("%s\n", doc.dump(2).c_str());
        } else {
          std::printf("%s\n%swrote %s\n", file.c_str(),
                      report::FormatSummary(*report).c_str(), version.c_str());
        }
        continue;
      }
      if (!objectives) objectives = ObjectivesOf(*run);
      analysis::Evaluation e;
      e.point = report->point;
      e.feasible = report->feasible;
      for (size_t i = 0; i < objectives->names.size(); ++i) {
        auto it = report->metrics.find(objectives->names[i]);
        double v = it == report->metrics.end() ? NAN : it->second;
        if (!std::isfinite(v)) e.feasible = false, v = 1e300;
        e.objectives.push_back(objectives->maximize[i] ? -v : v);
      }
      evals.push_back(e);
      summary["runs"].push_back(doc);
    }
    if (!folder || evals.empty()) continue;
    const std::vector<int> front = analysis::ParetoFront(evals);
    std::set<int> on_front(front.begin(), front.end());
    std::vector<analysis::ParetoPlotPoint> plot;
    for (size_t i = 0; i < evals.size(); ++i) {
      nlohmann::json& r = summary["runs"][i];
      r["on_front"] = on_front.count(static_cast<int>(i)) > 0;
      const auto& m = r["metrics"];
      if (m.value("hardware_cost", nlohmann::json()).is_number() &&
          m.value("nav_time_s", nlohmann::json()).is_number()) {
        plot.push_back(
            {m["hardware_cost"].get<double>(), m["nav_time_s"].get<double>(),
             r["feasible"].get<bool>(), r["on_front"].get<bool>(), ""});
      }
    }
    summary["objectives"] = objectives->names;
    summary["pareto_front_size"] = front.size();
    const std::string version = NextVersion(fs::path(target) / "analysis");
    if (Status s = MakeDirs(version); !s.ok()) {
      std::fprintf(stderr, "error: %s\n", s.message().c_str());
      return 1;
    }
    if (!plot.empty()) {
      analysis::ParetoPlotOptions plot_options;
      plot_options.title =
          fmt::format("{} runs, {} on the front", evals.size(), front.size());
      if (analysis::RenderParetoPlot(plot, version + "/pareto.png",
                                     plot_options)
              .ok()) {
        summary["images"]["pareto"] = version + "/pareto.png";
      }
    }
    if (Status s = WriteJson(version + "/summary.json", summary); !s.ok()) {
      std::fprintf(stderr, "error: %s\n", s.message().c_str());
      return 1;
    }
    if (args.json) {
      std::printf("%s\n", summary.dump(2).c_str());
    } else {
      std::printf(
          "%s: %zu runs analysed, %zu on the Pareto front (%s)\nwrote %s\n",
          target.c_str(), evals.size(), front.size(),
          fmt::format("{}", fmt::join(objectives->names, ", ")).c_str(),
          version.c_str());
    }
  }
  return exit_code;
}

}  // namespace adse::cli
