// adse analyze: recompute metrics, deviation, diagnosis, pictures and the
// answer (headline and front) from stored run files, into a new analysis
// version (a campaign's under <campaign>/analysis/vN, a single run file's
// next to it); or compare two campaigns or analysis versions.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>

#include "analysis/diagnosis/diagnosis.h"
#include "analysis/runfile/campaign_file.h"
#include "analysis/runfile/run_file.h"
#include "harness/campaign/campaign.h"
#include "harness/campaign/evaluation.h"
#include "harness/campaign/headline.h"
#include "harness/campaign/replay.h"
#include "harness/campaign/replicas.h"
#include "harness/campaign/run_store.h"
#include "harness/cli/cli_support.h"
#include "harness/cli/commands.h"
#include "harness/report/run_report.h"
#include "harness/spec/spec_parser.h"
#include "harness/spec/text_util.h"
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

// An analysis version is written into a private folder and renamed to
// its number whole at the end, so that a stopped analysis never leaves a
// version that looks complete.
struct VersionFolder {
  std::string final_path;  // <root>/vN
  std::string tmp_path;    // written into until Commit
};

VersionFolder StartVersion(const fs::path& root) {
  VersionFolder v;
  // Versions of analyses killed before their end (SIGKILL, SIGTERM).
  RemoveAbandonedTemporaries(root.string());
  v.final_path = NextVersion(root);
  v.tmp_path = TemporaryPathFor(v.final_path);
  std::error_code ec;
  fs::remove_all(v.tmp_path, ec);
  return v;
}

Status CommitVersion(const VersionFolder& v) {
  ADSE_RETURN_IF_ERROR(Env::Default()->RenameFile(v.tmp_path, v.final_path));
  return Env::Default()->SyncDir(fs::path(v.final_path).parent_path());
}

// Prints why the analysis stopped and removes its unfinished version;
// returns `exit_code`.
int Abandon(const VersionFolder& v, const std::string& message, int exit_code) {
  std::error_code ec;
  fs::remove_all(v.tmp_path, ec);
  std::fprintf(stderr, "error: %s\n", message.c_str());
  return exit_code;
}

// A report's picture paths, written into the private folder, as they are
// once it is renamed.
void MoveImagePaths(const VersionFolder& v, report::RunReport* report) {
  for (auto& [name, path] : report->images) {
    if (path.rfind(v.tmp_path, 0) == 0) {
      path = v.final_path + path.substr(v.tmp_path.size());
    }
  }
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

Status WriteJson(const std::string& path, const nlohmann::json& doc) {
  return WriteFileAtomic(path, doc.dump(2) + "\n");
}

int Diff(const std::string& a_path, const std::string& b_path, bool json) {
  // A campaign root or an analysis version: its summary.json, whose
  // evaluations are the runs and pareto_front says which are on the front;
  // a single run's version: its report.json.
  auto load = [](const std::string& dir) -> std::optional<nlohmann::json> {
    for (const char* name : {"summary.json", "report.json"}) {
      const fs::path p = fs::path(dir) / name;
      Result<std::string> text = ReadFile(p.string());
      if (!text.ok()) continue;
      nlohmann::json doc = nlohmann::json::parse(*text, nullptr, false);
      if (doc.is_discarded() || !doc.is_object()) {
        std::fprintf(stderr, "error: %s: not valid JSON\n", p.string().c_str());
        return std::nullopt;
      }
      // Every entry an object with a point, or the file is not ours.
      auto malformed = [&](const std::string& what) {
        std::fprintf(stderr, "error: %s: %s\n", p.string().c_str(),
                     what.c_str());
        return std::nullopt;
      };
      auto has_point = [](const nlohmann::json& r) {
        return r.is_object() && r.contains("point") && r["point"].is_object();
      };
      if (doc.contains("evaluations") && doc["evaluations"].is_array()) {
        const nlohmann::json front_rows =
            doc.value("pareto_front", nlohmann::json::array());
        if (!front_rows.is_array()) {
          return malformed("pareto_front: expected a list of evaluations");
        }
        std::set<std::string> front;
        for (const auto& r : front_rows) {
          if (!has_point(r)) {
            return malformed(
                "pareto_front: expected evaluations, each an "
                "object with a point");
          }
          front.insert(r.value("content_key", ""));
        }
        nlohmann::json runs = nlohmann::json::array();
        for (nlohmann::json r : doc["evaluations"]) {
          if (!has_point(r)) {
            return malformed(
                fmt::format("evaluations[{}]: expected an object with a point",
                            runs.size()));
          }
          r["on_front"] = front.count(r.value("content_key", "")) > 0;
          runs.push_back(r);
        }
        return nlohmann::json{{"runs", runs}};
      }
      if (has_point(doc)) {
        return nlohmann::json{{"runs", nlohmann::json::array({doc})}};
      }
      std::fprintf(stderr,
                   "error: %s: neither a campaign summary (evaluations) nor "
                   "a run report (point)\n",
                   p.string().c_str());
      return std::nullopt;
    }
    std::fprintf(stderr,
                 "error: %s: no summary.json or report.json (expected a "
                 "campaign folder or an analysis version folder)\n",
                 dir.c_str());
    return std::nullopt;
  };
  std::optional<nlohmann::json> a = load(a_path), b = load(b_path);
  if (!a || !b) return 2;
  // "cores=16,freq_ghz=2.1,lidar_hz=7", as points are written elsewhere.
  auto key = [](const nlohmann::json& r) {
    std::vector<std::string> parts;
    for (const auto& [name, value] : r["point"].items()) {
      parts.push_back(value.is_number()
                          ? fmt::format("{}={}", name,
                                        spec::FormatNumber(value.get<double>()))
                          : fmt::format("{}={}", name, value.dump()));
    }
    return fmt::format("{}", fmt::join(parts, ","));
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
      const nlohmann::json none = nlohmann::json::object();
      const nlohmann::json& ma = ra.contains("metrics") ? ra["metrics"] : none;
      const nlohmann::json& mb = rb.contains("metrics") ? rb["metrics"] : none;
      for (const auto& [m, va] : ma.items()) {
        const auto vb = mb.value(m, nlohmann::json(nullptr));
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
  // One line per point: what changed, A -> B.
  auto text = [](const nlohmann::json& v) -> std::string {
    if (v.is_boolean()) return v.get<bool>() ? "yes" : "no";
    if (v.is_number()) return fmt::format("{:.6g}", v.get<double>());
    if (v.is_null()) return "n/a";
    return v.is_string() ? v.get<std::string>() : v.dump();
  };
  for (const auto& c : changes) {
    std::vector<std::string> what;
    if (c.contains("change")) what.push_back(c["change"].get<std::string>());
    for (const auto& [field, label] :
         {std::pair{"feasible", "feasible"}, {"on_front", "on the front"}}) {
      if (!c.contains(field)) continue;
      what.push_back(fmt::format("{} {} -> {}", label, text(c[field][0]),
                                 text(c[field][1])));
    }
    if (c.contains("metrics")) {
      for (const auto& [m, v] : c["metrics"].items()) {
        what.push_back(fmt::format("{} {} -> {}", m, text(v[0]), text(v[1])));
      }
    }
    std::printf("  %s: %s\n", c["point"].get<std::string>().c_str(),
                fmt::format("{}", fmt::join(what, "; ")).c_str());
  }
  return 0;
}

// What the campaign's own summary.json says of how it ended (stopped by a
// signal, still running, ...), carried into the analysis' views: an
// analysis does not make a campaign complete.
void CarryCampaignState(const campaign::CampaignFolder& folder,
                        campaign::CampaignSummary* summary) {
  Result<std::string> text = ReadFile(folder.Path("summary.json"));
  const nlohmann::json j = text.ok()
                               ? nlohmann::json::parse(*text, nullptr, false)
                               : nlohmann::json();
  if (!j.is_object()) {
    summary->finished_unknown = true;
    if (text.ok()) {
      summary->notes.push_back(folder.Path("summary.json") +
                               " is no JSON object: how the campaign ended "
                               "is not known");
    }
    return;
  }
  auto number = [&](const char* key) {
    return j.contains(key) && j[key].is_number_integer() ? j[key].get<int>()
                                                         : 0;
  };
  summary->interrupted_by = number("interrupted_by_signal");
  summary->unfinished = number("unfinished");
  summary->in_progress = j.contains("in_progress") &&
                         j["in_progress"].is_boolean() &&
                         j["in_progress"].get<bool>();
  if (j.contains("stopped_because") && j["stopped_because"].is_string()) {
    summary->stopped_because = j["stopped_because"];
  }
  if (j.contains("wall_s") && j["wall_s"].is_number()) {
    summary->wall_s = j["wall_s"];
  }
  if (j.contains("workers") && j["workers"].is_number_integer()) {
    summary->workers = j["workers"];
  }
}

// A folder: a campaign (its campaign.h5 names the runs and holds the
// scenario) or loose run files of one scenario. Every run is analysed
// again and the answer views are written by the code adse run uses, into
// <folder>/analysis/vN; the run files are never touched.
int AnalyzeFolder(const std::string& target,
                  const report::AnalyzeOptions& base_options,
                  const campaign::Recording* reference, bool json) {
  const campaign::CampaignFolder folder(target);
  std::optional<runfile::CampaignIndex> index;
  std::error_code ec;
  if (fs::exists(folder.Path("campaign.h5"), ec)) {
    Result<runfile::CampaignIndex> read =
        campaign::ReadIndex(folder.Path("campaign.h5"));
    if (!read.ok()) {
      std::fprintf(stderr,
                   "error: %s: %s (adse run or adse index rebuilds it from "
                   "the run files)\n",
                   folder.Path("campaign.h5").c_str(),
                   read.status().message().c_str());
      return 2;
    }
    index = std::move(*read);
  }
  // The runs to analyse, each with the row it had (bookkeeping kept). A
  // point of several runs (replicas, task.cases) has an item per run and
  // is folded again from them below, as the campaign folded it.
  struct Item {
    campaign::EvaluationRow row;
    std::string file;  // empty: a failed run, kept as recorded
  };
  std::vector<Item> items;
  std::string scenario_text, scenario_source;
  if (index) {
    scenario_text = index->scenario_text;
    scenario_source = folder.Path("campaign.h5") + " (stored scenario)";
    for (const campaign::EvaluationRow& row : index->evaluations) {
      for (const campaign::EvaluationRow& run :
           row.replicas.empty() ? std::vector<campaign::EvaluationRow>{row}
                                : row.replicas) {
        items.push_back({run, run.complete() ? folder.RunPath(run.content_key)
                                             : std::string()});
      }
    }
  } else {
    for (const std::string& file : RunFilesIn(target)) {
      campaign::EvaluationRow row;
      row.index = static_cast<int64_t>(items.size());
      row.source = "recorded";
      items.push_back({row, file});
    }
  }
  if (items.empty()) {
    std::fprintf(stderr, "error: %s: no run files (*.h5) in it\n",
                 target.c_str());
    return 2;
  }
  int exit_code = 0;
  std::vector<std::pair<Item, runfile::RunData>> loaded;
  // Rows taken as the campaign recorded them: failed runs, and runs whose
  // file cannot be read (so the campaign's front stays whole).
  std::vector<campaign::EvaluationRow> recorded_rows;
  int unreadable = 0;
  for (Item& item : items) {
    if (item.file.empty()) {
      recorded_rows.push_back(item.row);
      continue;
    }
    Result<runfile::RunData> run = runfile::ReadRunFile(item.file);
    if (!run.ok()) {
      // A broken file never stops the rest. (ReadRunFile's errors name
      // the file.)
      std::fprintf(stderr, "skipped %s\n", run.status().message().c_str());
      exit_code = 2;
      ++unreadable;
      if (index) recorded_rows.push_back(item.row);
      continue;
    }
    if (scenario_text.empty()) {
      scenario_text = run->scenario_text;
      scenario_source = item.file + " (stored scenario)";
    } else if (!index && run->scenario_text != scenario_text) {
      std::fprintf(stderr,
                   "skipped %s: a different scenario than %s; analyse "
                   "the folders of different scenarios separately\n",
                   item.file.c_str(), scenario_source.c_str());
      exit_code = 2;
      continue;
    }
    loaded.emplace_back(std::move(item), std::move(*run));
  }
  if (loaded.empty() && !index) {
    std::fprintf(stderr, "error: %s: none of its %zu run files could be read\n",
                 target.c_str(), items.size());
    return 2;
  }
  spec::ParseOptions parse;
  parse.check_files = false;  // the front needs only the stored text
  Result<spec::Spec> spec =
      spec::ParseSpec(scenario_text, scenario_source, ".", parse);
  if (!spec.ok()) {
    std::fprintf(stderr, "error: %s: the stored scenario does not parse:\n%s\n",
                 scenario_source.c_str(), spec.status().message().c_str());
    return 2;
  }
  // The campaign as it ran: its budget and strategy (--budget, --strategy)
  // rather than the stored scenario's.
  if (index) {
    spec->exploration.budget = static_cast<int>(index->budget);
    spec->exploration.strategy = index->strategy;
  }
  // One study's runs over another's would be read as a comparison.
  if (reference != nullptr && reference->spec.name != spec->name) {
    std::fprintf(stderr,
                 "error: --reference: %s is the study of scenario '%s', not "
                 "of '%s' (%s): give a reference recorded from the same "
                 "scenario\n",
                 reference->folder.c_str(), reference->spec.name.c_str(),
                 spec->name.c_str(), scenario_source.c_str());
    return 2;
  }
  const VersionFolder v = StartVersion(fs::path(target) / "analysis");
  const std::string& version = v.tmp_path;
  // Whatever stops the analysis leaves no version behind.
  auto fail = [&](const std::string& message, int code) {
    return Abandon(v, message, code);
  };
  if (Status s = MakeDirs(version + "/reports"); !s.ok()) {
    return fail(s.message(), 1);
  }
  std::vector<campaign::EvaluationRow> rows;
  size_t undiagnosed = 0;  // runs that end before the window starts
  for (auto& [item, run] : loaded) {
    report::AnalyzeOptions options = base_options;
    const std::string key = run.content_key.empty()
                                ? fs::path(item.file).stem().string()
                                : run.content_key;
    options.image_dir = version + "/images/" + key;
    if (Status s = MakeDirs(options.image_dir); !s.ok()) {
      return fail(s.message(), 1);
    }
    Result<report::RunReport> report =
        report::AnalyzeRun(run, item.file, options);
    if (!report.ok()) {
      return fail(item.file + ": " + report.status().message(),
                  ExitCodeFor(report.status()));
    }
    MoveImagePaths(v, &*report);
    if (report->diagnosis_window_s <= 0.0 && report->diagnosis_start_s > 0.0) {
      ++undiagnosed;
    }
    if (Status s = WriteJson(version + "/reports/" + key + ".json",
                             report::ToJson(*report));
        !s.ok()) {
      return fail(s.message(), 1);
    }
    campaign::EvaluationRow row = campaign::RowFromReport(*report);
    row.index = item.row.index;
    row.iteration = item.row.iteration;
    row.replica = item.row.replica;
    row.task_case = item.row.task_case;
    row.source = item.row.source;
    row.attempts = item.row.attempts;
    row.wall_s = item.row.wall_s;
    rows.push_back(std::move(row));
  }
  if (undiagnosed > 0) {
    std::fprintf(stderr,
                 "warning: %s of %zu end before the diagnosis' window starts "
                 "(--threshold start_s=%g): they have no diagnosis\n",
                 spec::Counted(undiagnosed, "run").c_str(), loaded.size(),
                 base_options.thresholds.count("start_s")
                     ? base_options.thresholds.at("start_s")
                     : 0.0);
  }
  rows.insert(rows.end(), recorded_rows.begin(), recorded_rows.end());
  {
    // Each point's runs folded into its row (one run: itself).
    std::map<int64_t, std::vector<campaign::EvaluationRow>> runs_of;
    for (campaign::EvaluationRow& run : rows) {
      runs_of[run.index].push_back(std::move(run));
    }
    rows.clear();
    for (auto& [point_index, runs] : runs_of) {
      rows.push_back(campaign::AggregatePoint(*spec, std::move(runs)));
    }
  }

  campaign::CampaignSummary summary;
  summary.output_dir = target;
  summary.strategy = index ? index->strategy : spec->exploration.strategy;
  summary.isolation = index ? index->isolation : std::string();
  summary.exploration.evaluations = rows;
  if (index) summary.exploration.iterations = index->iterations;
  // As the campaign got them (loose run files are all found).
  campaign::CountSources(&summary);
  if (index) CarryCampaignState(folder, &summary);
  if (unreadable > 0) {
    summary.notes.push_back(fmt::format(
        "{} run file(s) could not be read: {}", unreadable,
        index ? "their points are kept as campaign.h5 recorded them, not "
                "analysed again"
              : "they are left out"));
  }
  if (Status s = campaign::WriteAnswerViews(*spec, summary, version, "images");
      !s.ok()) {
    return fail(s.message(), 1);
  }
  if (reference != nullptr) {
    const std::string png = version + "/pareto.png";
    if (Status s = campaign::RenderStudyPicture(
            *spec, rows, reference->spec, reference->rows,
            fmt::format("{}: {} ({}) over {} ({} points)", spec->name,
                        spec::Counted(rows.size(), "evaluation"),
                        summary.strategy, reference->spec.name,
                        reference->rows.size()),
            png);
        !s.ok()) {
      return fail(png + ": " + s.message(), 1);
    }
  }
  if (Status s = CommitVersion(v); !s.ok()) return fail(s.message(), 1);
  if (json) {
    Result<std::string> text = ReadFile(v.final_path + "/summary.json");
    std::printf("%s", text.ok() ? text->c_str() : "{}\n");
  } else {
    std::printf("%s: %s analysed", target.c_str(),
                spec::Counted(loaded.size(), "run").c_str());
    if (unreadable > 0 && index) {
      std::printf(
          ", %d kept as campaign.h5 recorded them (run file unreadable)",
          unreadable);
    }
    std::printf("\n");
    std::printf("%s", campaign::HeadlineText(
                          *spec, rows, campaign::ComputeHeadline(*spec, rows))
                          .c_str());
    std::printf("wrote %s (report.md, summary.json, pareto.png%s)\n",
                v.final_path.c_str(),
                reference != nullptr
                    ? (" in the study's form over " + reference->folder).c_str()
                    : "");
  }
  return exit_code;
}

}  // namespace

int RunAnalyze(const AnalyzeArgs& args) {
  if (!args.diff.empty()) {
    if (args.diff.size() != 2) {
      std::fprintf(stderr,
                   "error: --diff takes two analysis folders: --diff A B\n");
      return 2;
    }
    return Diff(CampaignOfRunsFolder(args.diff[0]),
                CampaignOfRunsFolder(args.diff[1]), args.json);
  }
  report::AnalyzeOptions options;
  for (const std::string& t : args.thresholds) {
    const size_t eq = t.find('=');
    double value = 0.0;
    if (eq == std::string::npos ||
        !spec::ParseNumber(std::string_view(t).substr(eq + 1), &value)) {
      std::fprintf(stderr,
                   "error: --threshold %s: expected NAME=VALUE with a decimal "
                   "number\n",
                   t.c_str());
      return 2;
    }
    const std::string name = t.substr(0, eq);
    // Name and range checked now, before anything is written.
    analysis::DiagnosisOptions scratch;
    if (Status s = analysis::SetOption(&scratch, name, value); !s.ok()) {
      std::fprintf(stderr, "error: --threshold %s: %s\n", t.c_str(),
                   s.message().c_str());
      return 2;
    }
    options.thresholds[name] = value;
  }
  if (options.thresholds.count("start_s") &&
      options.thresholds.count("end_s") && options.thresholds["end_s"] >= 0.0 &&
      options.thresholds["end_s"] <= options.thresholds["start_s"]) {
    std::fprintf(stderr,
                 "error: --threshold end_s=%g: not after start_s=%g; the "
                 "diagnosis' window would be empty\n",
                 options.thresholds["end_s"], options.thresholds["start_s"]);
    return 2;
  }
  // The reference is read before anything is written.
  std::optional<campaign::Recording> reference;
  if (!args.reference.empty()) {
    Result<campaign::Recording> loaded =
        campaign::LoadRecording(args.reference);
    if (!loaded.ok()) {
      std::fprintf(stderr, "error: --reference: %s\n",
                   loaded.status().message().c_str());
      return 2;
    }
    reference = std::move(*loaded);
    for (const std::string& target : args.targets) {
      std::error_code ec;
      if (!fs::is_directory(target, ec)) {
        std::fprintf(stderr,
                     "error: --reference: %s is not a campaign folder (the "
                     "study's picture is a campaign's)\n",
                     target.c_str());
        return 2;
      }
    }
  }
  int exit_code = 0;
  for (const std::string& target : args.targets) {
    std::error_code ec;
    if (fs::is_directory(target, ec)) {
      const std::string folder = CampaignOfRunsFolder(target);
      if (folder != target) {
        std::fprintf(stderr,
                     "%s: the run files of the campaign %s, which is analysed "
                     "(into %s/analysis)\n",
                     target.c_str(), folder.c_str(), folder.c_str());
      }
      exit_code =
          std::max(exit_code,
                   AnalyzeFolder(folder, options,
                                 reference ? &*reference : nullptr, args.json));
      continue;
    }
    if (!fs::exists(target, ec)) {
      std::fprintf(stderr, "error: %s: no such file or folder\n",
                   target.c_str());
      exit_code = 2;
      continue;
    }
    const std::string& file = target;
    Result<runfile::RunData> run = runfile::ReadRunFile(file);
    if (!run.ok()) {  // its errors name the file
      std::fprintf(stderr, "error: %s\n", run.status().message().c_str());
      exit_code = 2;
      continue;
    }
    // run.h5 -> run.analysis; a name without ".h5" keeps all of it.
    const fs::path as_path(file);
    const std::string base =
        as_path.extension() == ".h5"
            ? (as_path.parent_path() / as_path.stem()).string()
            : file;
    const VersionFolder v = StartVersion(base + ".analysis");
    auto fail = [&](const std::string& message, int code) {
      return Abandon(v, message, code);
    };
    options.image_dir = v.tmp_path;
    if (Status s = MakeDirs(v.tmp_path); !s.ok()) return fail(s.message(), 1);
    Result<report::RunReport> report = report::AnalyzeRun(*run, file, options);
    if (!report.ok()) {
      return fail(file + ": " + report.status().message(),
                  ExitCodeFor(report.status()));
    }
    MoveImagePaths(v, &*report);
    const nlohmann::json doc = report::ToJson(*report);
    if (Status s = WriteJson(v.tmp_path + "/report.json", doc); !s.ok()) {
      return fail(s.message(), 1);
    }
    if (Status s = CommitVersion(v); !s.ok()) return fail(s.message(), 1);
    const std::string& version = v.final_path;
    if (args.json) {
      std::printf("%s\n", doc.dump(2).c_str());
    } else {
      std::printf("%s\n%swrote %s\n", file.c_str(),
                  report::FormatSummary(*report).c_str(), version.c_str());
    }
  }
  return exit_code;
}

}  // namespace adse::cli
