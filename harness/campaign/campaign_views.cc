// The campaign folder's views, all rebuilt from the evaluation rows:
// campaign.h5 (index), summary.json, report.md and pareto.png.
#include <algorithm>
#include <cmath>
#include <csignal>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "analysis/runfile/campaign_file.h"
#include "harness/campaign/campaign.h"
#include "harness/campaign/headline.h"
#include "harness/campaign/replicas.h"
#include "harness/campaign/run_store.h"
#include "harness/llm/exchange_log.h"
#include "harness/llm/llm_strategy.h"
#include "harness/spec/design_point.h"
#include "harness/spec/spec_parser.h"
#include "harness/spec/text_util.h"
#include "stack/base/files.h"

namespace adse::campaign {
namespace {

// What the LLM agents did (strategy llm), from the folder's llm/ records.
struct LlmRecords {
  std::vector<llm::ExchangeRecord> exchanges;
  std::vector<llm::LlmEvent> events;
  std::string problem;  // why a record could not be read
};

LlmRecords LoadLlmRecords(const std::string& folder) {
  LlmRecords r;
  Result<std::vector<llm::ExchangeRecord>> exchanges =
      llm::LoadExchanges(llm::ExchangesPath(folder));
  if (exchanges.ok()) {
    r.exchanges = std::move(*exchanges);
  } else {
    r.problem = exchanges.status().message();
  }
  Result<std::vector<llm::LlmEvent>> events =
      llm::LoadEvents(llm::EventsPath(folder));
  if (events.ok()) {
    r.events = std::move(*events);
  } else {
    r.problem += (r.problem.empty() ? "" : "; ") + events.status().message();
  }
  return r;
}

std::string Number(double v) {
  if (std::isnan(v)) return "—";
  return fmt::format("{:.4g}", v);
}

// The metrics the report's tables show: the objectives', the constraints',
// then cost, nav time and control rate, which every study reads.
std::vector<std::string> MetricColumns(const spec::Spec& spec) {
  std::vector<std::string> columns;
  auto add = [&columns](const std::string& metric) {
    if (std::find(columns.begin(), columns.end(), metric) == columns.end()) {
      columns.push_back(metric);
    }
  };
  for (const spec::Objective& o : spec.objectives) add(o.metric);
  for (const std::string& metric : spec::ConstraintMetrics(spec)) add(metric);
  for (const char* metric : {"hardware_cost", "nav_time_s", "ctrl_rate_hz"}) {
    add(metric);
  }
  return columns;
}

// With replicas: each point's metrics as median [min–max] over its runs,
// and the unstable points. Empty when every point ran once.
std::string ReplicaSection(const spec::Spec& spec,
                           const std::vector<EvaluationRow>& rows,
                           const std::vector<std::string>& columns) {
  std::ostringstream md;
  bool any = false;
  // Points of several cases have their own section (CaseSection).
  auto replicated = [](const EvaluationRow& row) {
    return row.replicas.size() > 1 && CaseCountOf(row) == 1;
  };
  for (const EvaluationRow& row : rows) any = any || replicated(row);
  if (!any) return "";
  auto value = [](double v) {
    return std::isinf(v) ? std::string(v > 0 ? "stopped↑" : "stopped↓")
                         : Number(v);
  };
  md << "\n## Replicas\n\nEach point ran several times, each run with its "
        "own seed (traffic, cost sampling, sensor noise). Metrics are the "
        "median over the runs, [min – max] beside it; a run stopped early "
        "ranks beyond the bound it broke (stopped↑ above it, stopped↓ "
        "below). A point is feasible when more than half its runs are, and "
        "**unstable** when they disagree.\n\n| # | point | runs | "
     << fmt::format("{}", fmt::join(columns, " | ")) << " |\n|---|---|---|";
  for (size_t i = 0; i < columns.size(); ++i) md << "---|";
  md << "\n";
  for (const EvaluationRow& row : rows) {
    if (!replicated(row)) continue;
    md << "| " << row.index << " | "
       << spec::FormatPoint(spec.design_space, row.point) << " | "
       << (row.unstable ? "**" + ReplicaSummary(spec, row) + "**"
                        : ReplicaSummary(spec, row));
    for (const std::string& c : columns) {
      std::optional<MetricSpread> m = SpreadOf(spec, row, c);
      md << " | "
         << (m ? fmt::format("{} [{} – {}]", value(m->median), value(m->min),
                             value(m->max))
               : std::string("—"));
    }
    md << " |\n";
  }
  return md.str();
}

nlohmann::json RowJson(const spec::Spec& spec, const EvaluationRow& row) {
  nlohmann::json metrics = nlohmann::json::object();
  for (const auto& [name, value] : row.metrics) {
    metrics[name] =
        std::isfinite(value) ? nlohmann::json(value) : nlohmann::json();
  }
  nlohmann::json j = {
      {"index", row.index},
      {"iteration", row.iteration},
      {"point", row.point},
      {"point_text", spec::FormatPoint(spec.design_space, row.point)},
      {"content_key", row.content_key},
      {"status", row.status},
      {"reason", row.reason},
      {"source", row.source},
      {"attempts", row.attempts},
      {"wall_s", row.wall_s},
      {"feasible", row.feasible},
      {"metrics", metrics}};
  j["bottlenecks"] =
      nlohmann::json::parse(row.bottlenecks_json, nullptr, false);
  if (j["bottlenecks"].is_discarded())
    j["bottlenecks"] = nlohmann::json::array();
  j["replicas"] = std::max<size_t>(1, row.replicas.size());
  j["cases"] = CaseCountOf(row);
  j["unstable"] = row.unstable;
  if (row.replicas.size() > 1) {
    // Infinite quantiles (runs stopped beyond a bound) are null; `censored`
    // counts those runs.
    auto number = [](double v) {
      return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
    };
    nlohmann::json spread = nlohmann::json::object();
    std::set<std::string> names;
    for (const EvaluationRow& run : row.replicas) {
      for (const auto& [name, value] : run.metrics) names.insert(name);
    }
    for (const std::string& name : names) {
      if (std::optional<MetricSpread> m = SpreadOf(spec, row, name)) {
        spread[name] = {
            {"median", number(m->median)}, {"min", number(m->min)},
            {"max", number(m->max)},       {"q1", number(m->q1)},
            {"q3", number(m->q3)},         {"measured", m->measured},
            {"censored", m->censored}};
      }
    }
    j["spread"] = spread;
    nlohmann::json runs = nlohmann::json::array();
    for (const EvaluationRow& run : row.replicas) {
      nlohmann::json run_metrics = nlohmann::json::object();
      for (const auto& [name, value] : run.metrics)
        run_metrics[name] = number(value);
      runs.push_back({{"replica", run.replica},
                      {"task_case", run.task_case},
                      {"content_key", run.content_key},
                      {"seed", run.seed},
                      {"status", run.status},
                      {"reason", run.reason},
                      {"source", run.source},
                      {"feasible", run.feasible},
                      {"metrics", run_metrics}});
    }
    j["runs"] = runs;
  }
  return j;
}

std::string Duration(double s) {
  if (s < 60) return fmt::format("{:.1f} s", s);
  const int total = static_cast<int>(std::lround(s));
  if (total < 3600) return fmt::format("{}m{:02d}s", total / 60, total % 60);
  return fmt::format("{}h{:02d}m", total / 3600, (total / 60) % 60);
}

// One line per row: a markdown table cell must not hold a newline or |.
std::string Cell(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  std::string out;
  for (char c : text) {
    if (c == '|') out += "\\";
    out += c;
  }
  return out;
}

// With task.cases: every run of each point, case by case, with its own
// picture. Empty without cases.
std::string CaseSection(const spec::Spec& spec,
                        const std::vector<EvaluationRow>& rows,
                        const std::vector<std::string>& columns,
                        const std::string& image_dir) {
  if (spec.cases.empty()) return "";
  std::ostringstream md;
  md << "\n## Cases\n\nEach point ran once per case of `task.cases` ("
     << spec::CaseNames(spec)
     << "). A point is feasible only when it is feasible in every case; a "
        "metric an objective or constraint judges is its worst over the "
        "cases, any other the mean.\n\n| # | point | case | outcome | "
     << fmt::format("{}", fmt::join(columns, " | "))
     << " | feasible | picture |\n|---|---|---|---|";
  for (size_t i = 0; i < columns.size(); ++i) md << "---|";
  md << "---|---|\n";
  for (const EvaluationRow& row : rows) {
    for (const EvaluationRow& run : row.replicas.empty()
                                        ? std::vector<EvaluationRow>{row}
                                        : row.replicas) {
      std::string name = spec::CaseName(spec, run.task_case);
      if (spec.harness.replicas > 1) {
        name += fmt::format(" (run {})", run.replica);
      }
      md << "| " << row.index << " | "
         << spec::FormatPoint(spec.design_space, row.point) << " | " << name
         << " | " << Cell(run.complete() ? run.reason : run.status) << " | ";
      for (const std::string& col : columns) {
        md << Number(RowMetric(run, col)) << " | ";
      }
      md << (run.feasible ? "yes" : "no") << " | [png](" << image_dir << "/"
         << run.content_key << "/trajectory.png) |\n";
    }
  }
  return md.str();
}

std::string LlmMarkdown(const LlmRecords& llm) {
  std::ostringstream md;
  md << "\n## LLM agents\n\n";
  if (!llm.problem.empty())
    md << "Records could not be read: " << llm.problem << "\n\n";
  std::map<std::string, int> asked, failed;
  int64_t prompt_tokens = 0, answer_tokens = 0;
  double latency = 0.0;
  int answered = 0;
  for (const llm::ExchangeRecord& e : llm.exchanges) {
    ++asked[e.agent];
    if (!e.ok) ++failed[e.agent];
    if (e.ok) {
      ++answered;
      latency += e.latency_s;
    }
    prompt_tokens += std::max<int64_t>(e.prompt_tokens, 0);
    answer_tokens += std::max<int64_t>(e.completion_tokens, 0);
  }
  md << fmt::format(
      "{} exchanges ({} answered, mean latency {} s), {} prompt and {} answer "
      "tokens; "
      "every exchange is in `llm/exchanges.jsonl` and `campaign.h5` "
      "(/llm_exchanges).\n\n",
      llm.exchanges.size(), answered,
      Number(answered ? latency / answered : NAN), prompt_tokens,
      answer_tokens);
  md << "| agent | requests | failed |\n|---|---|---|\n";
  for (const auto& [agent, n] : asked) {
    md << fmt::format("| {} | {} | {} |\n", agent, n, failed[agent]);
  }
  std::map<llm::LlmEventKind, int> kinds;
  for (const llm::LlmEvent& e : llm.events) ++kinds[e.kind];
  md << fmt::format(
      "\nEvents: {} answers rejected (each got one corrective follow-up), {} "
      "iterations "
      "proposed by the built-in agent instead, {} disagreements with the "
      "deterministic "
      "analysis (the deterministic values were used), {} errors{}.\n\n",
      kinds[llm::LlmEventKind::kRejected], kinds[llm::LlmEventKind::kFallback],
      kinds[llm::LlmEventKind::kDisagreement], kinds[llm::LlmEventKind::kError],
      kinds[llm::LlmEventKind::kConverged] ? ", convergence declared" : "");
  if (!llm.events.empty()) {
    md << "| iteration | agent | event | detail |\n|---|---|---|---|\n";
    for (const llm::LlmEvent& e : llm.events) {
      md << fmt::format("| {} | {} | {} | {} |\n", e.iteration, e.agent,
                        llm::LlmEventKindToString(e.kind), Cell(e.detail));
    }
  }
  return md.str();
}

std::string ReportMarkdown(const spec::Spec& spec, const CampaignSummary& s,
                           const Headline& headline,
                           const std::string& image_dir,
                           const LlmRecords* llm) {
  const auto& rows = s.exploration.evaluations;
  std::ostringstream md;
  md << "# Campaign: " << spec.name << "\n\n";
  if (!s.stopped_because.empty()) {
    md << fmt::format(
        "> **Stopped: {}.** No answer: mend the scenario and run again; "
        "runs that finished are kept.\n\n",
        s.stopped_because);
  } else if (s.in_progress) {
    std::vector<std::string> running;
    for (const spec::DesignPoint& p : s.running) {
      running.push_back("`" + spec::FormatPoint(spec.design_space, p) + "`");
    }
    md << fmt::format(
        "> **In progress:** {} of {}{} so far{}; the answer comes "
        "when the campaign ends.\n\n",
        rows.size(), spec::Counted(spec.exploration.budget, "evaluation"),
        spec.exploration.confirm_runs > 0
            ? fmt::format(" and up to {} confirm runs",
                          spec.exploration.confirm_runs)
            : std::string(),
        running.empty()
            ? std::string()
            : fmt::format(", running {}", fmt::join(running, ", ")));
  }
  if (s.stopped_because.empty()) {
    md << HeadlineMarkdown(spec, rows, headline, image_dir);
  }
  md << "## Campaign\n\n";
  md << fmt::format("- scenario: `{}`\n", spec.source_path);
  std::string confirm;
  if (spec.exploration.confirm_runs > 0) {
    confirm = fmt::format(" and up to {} confirm runs ({} used)",
                          spec.exploration.confirm_runs,
                          ConfirmEvaluations(s.exploration));
  }
  md << fmt::format(
      "- strategy: `{}` (exploration.seed {}), budget {}{}: {}, {} "
      "simulated, {} reused (this folder or the shared cache), {} failed\n",
      spec.exploration.strategy, spec.exploration.seed, spec.exploration.budget,
      confirm, spec::Counted(rows.size(), "evaluation"), s.simulated, s.reused,
      s.failed);
  md << fmt::format("- workers: {}, {}\n", s.workers, s.isolation);
  if (!s.isolation_note.empty()) md << "- note: " << s.isolation_note << "\n";
  for (const std::string& note : s.notes) md << "- note: " << note << "\n";
  if (s.finished_unknown) {
    md << "- whether the campaign finished is not recorded (its folder has "
          "no summary.json it can read)\n";
  }
  md << fmt::format("- wall time: {}\n", Duration(s.wall_s));
  if (s.interrupted_by != 0) {
    md << fmt::format(
        "- **stopped early by signal {}{}**: run the same command again "
        "(`adse run`, or `adse submit` on Slurm) to resume; finished runs "
        "are kept and not repeated\n",
        s.interrupted_by,
        s.interrupted_by == SIGUSR1 ? " (Slurm's time-limit warning)" : "");
  }
  if (s.unfinished > 0) {
    md << fmt::format(
        "- **incomplete: {} planned point(s) have no result yet** (array "
        "tasks unfinished or cancelled): `adse submit` again runs only "
        "those\n",
        s.unfinished);
  }
  std::vector<std::string> objectives;
  for (const spec::Objective& o : spec.objectives) {
    objectives.push_back((o.minimize ? "minimize " : "maximize ") + o.metric);
  }
  md << fmt::format("- objectives: {}\n", fmt::join(objectives, ", "));
  md << fmt::format(
      "- constraints: {}\n\n",
      spec.constraints.empty()
          ? std::string("none")
          : fmt::format("`{}`", fmt::join(spec.constraints, "`, `")));

  const std::vector<std::string> columns = MetricColumns(spec);
  const std::set<int> front(s.pareto_front.begin(), s.pareto_front.end());
  md << fmt::format("## Pareto front over {} ({})\n\n",
                    fmt::join(objectives, ", "),
                    spec::Counted(front.size(), "point"));
  md << "Constraint-aware and non-dominated over the objectives; infeasible "
        "points appear only when nothing is feasible.\n\n";
  md << "| # | point | " << fmt::format("{}", fmt::join(columns, " | "))
     << " | feasible | picture |\n|---|---|";
  for (size_t i = 0; i < columns.size(); ++i) md << "---|";
  md << "---|---|\n";
  for (int i : CheapestFirst(rows, s.pareto_front)) {
    const EvaluationRow& row = rows[static_cast<size_t>(i)];
    md << "| " << row.index << " | "
       << spec::FormatPoint(spec.design_space, row.point) << " | ";
    for (const std::string& c : columns)
      md << Number(RowMetric(row, c)) << " | ";
    md << (row.feasible ? "yes" : "no") << " | [png](" << image_dir << "/"
       << row.content_key << "/trajectory.png) |\n";
  }
  md << CaseSection(spec, rows, columns, image_dir);
  md << ReplicaSection(spec, rows, columns);

  md << "\n## Iterations\n\nEach round's proposal and the strategy's "
        "reasoning.\n\n| iteration | proposed | rationale |\n|---|---|---|\n";
  std::map<int64_t, std::vector<std::string>> proposed;
  for (const EvaluationRow& row : rows) {
    proposed[row.iteration].push_back(
        spec::FormatPoint(spec.design_space, row.point));
  }
  for (const runfile::IterationRow& it : s.exploration.iterations) {
    md << "| " << it.iteration << " | "
       << Cell(fmt::format("{}", fmt::join(proposed[it.iteration], "; ")))
       << " | " << Cell(it.rationale.empty() ? "—" : it.rationale) << " |\n";
  }

  md << "\n## All evaluations\n\n| # | point | status | reason | source | "
     << fmt::format("{}", fmt::join(columns, " | "))
     << " | feasible |\n|---|---|---|---|---|";
  for (size_t i = 0; i < columns.size(); ++i) md << "---|";
  md << "---|\n";
  for (const EvaluationRow& row : rows) {
    md << fmt::format("| {} | {} | {} | {} | {} | ", row.index,
                      spec::FormatPoint(spec.design_space, row.point),
                      row.status, Cell(row.reason), row.source);
    for (const std::string& c : columns)
      md << Number(RowMetric(row, c)) << " | ";
    md << (row.replicas.size() > 1
               ? fmt::format("{} ({})", row.feasible ? "yes" : "no",
                             ReplicaSummary(spec, row))
               : std::string(row.feasible ? "yes" : "no"))
       << " |\n";
  }

  md << "\n## Failures\n\n";
  bool any = false;
  for (const EvaluationRow& row : rows) {
    if (row.complete()) continue;
    any = true;
    md << fmt::format("- #{} {} (run `{}`, {} attempt(s)): {}\n", row.index,
                      spec::FormatPoint(spec.design_space, row.point),
                      row.content_key.substr(0, 12), row.attempts, row.reason);
    md << fmt::format(
        "  record: `runs/{}.failed.json`, logs: `logs/{}.*.log`\n",
        row.content_key, row.content_key);
  }
  if (!any) md << "None.\n";
  if (llm) md << LlmMarkdown(*llm);
  return md.str();
}

}  // namespace

Status WriteCampaignViews(const spec::Spec& spec,
                          const CampaignSummary& summary, Env* env) {
  const CampaignFolder folder(summary.output_dir, env);
  const auto& rows = summary.exploration.evaluations;

  runfile::CampaignIndex index;
  index.scenario_name = spec.name;
  index.scenario_text = spec.source_text;
  index.strategy = spec.exploration.strategy;
  index.exploration_seed = spec.exploration.seed;
  index.budget = spec.exploration.budget;
  index.isolation = summary.isolation;
  index.adse_version = ADSE_VERSION;
  index.parameters = spec.design_space.Names();
  std::set<std::string> metric_names;
  for (const EvaluationRow& row : rows) {
    for (const auto& [name, value] : row.metrics) metric_names.insert(name);
    for (const EvaluationRow& run : row.replicas) {
      for (const auto& [name, value] : run.metrics) metric_names.insert(name);
    }
  }
  index.metrics.assign(metric_names.begin(), metric_names.end());
  index.evaluations = rows;
  index.iterations = summary.exploration.iterations;
  std::optional<LlmRecords> llm;
  if (spec.exploration.strategy == "llm") {
    llm = LoadLlmRecords(folder.root());
    for (const llm::ExchangeRecord& e : llm->exchanges) {
      runfile::LlmExchangeRow row;
      row.seq = e.seq;
      row.iteration = e.iteration;
      row.agent = e.agent;
      row.model = e.model;
      row.backend = e.backend;
      row.request_sha256 = e.request_sha256;
      row.prompt = e.prompt;
      for (const std::string& h : e.image_sha256) {
        row.image_sha256 += (row.image_sha256.empty() ? "" : ",") + h;
      }
      row.ok = e.ok;
      row.answer = e.answer;
      row.error = e.ok ? "" : e.error_code + ": " + e.error;
      row.prompt_tokens = e.prompt_tokens;
      row.completion_tokens = e.completion_tokens;
      row.latency_s = e.latency_s;
      row.attempts = e.attempts;
      index.llm_exchanges.push_back(std::move(row));
    }
  }
  ADSE_RETURN_IF_ERROR(
      runfile::WriteCampaignIndex(folder.Path("campaign.h5"), index, env));

  return WriteAnswerViews(spec, summary, folder.root(), "images", env);
}

nlohmann::json AnswerJson(const spec::Spec& spec,
                          const std::vector<EvaluationRow>& rows,
                          const Headline& headline) {
  auto row_or_null = [&](int i) {
    return i < 0 ? nlohmann::json() : RowJson(spec, rows[i]);
  };
  nlohmann::json ties = nlohmann::json::array();
  for (int i : headline.cheapest_ties) ties.push_back(RowJson(spec, rows[i]));
  const CheaperDesigns& c = headline.cheaper;
  nlohmann::json cheaper;  // null: no feasible design, or not counted
  if (c.counted) {
    auto designs = [&](const std::vector<spec::DesignPoint>& points,
                       const std::vector<double>& costs) {
      nlohmann::json out = nlohmann::json::array();
      for (size_t k = 0; k < points.size(); ++k) {
        out.push_back(
            {{"point", spec::FormatPoint(spec.design_space, points[k])},
             {"hardware_cost", costs[k]}});
      }
      return out;
    };
    cheaper = {{"in_space", c.cheaper},
               {"run", c.run},
               {"ruled_out_by_capacity", c.ruled_out},
               {"untried_count", c.untried_count},
               {"untried", designs(c.untried, c.untried_cost)},
               {"to_settle_count", c.to_settle_count},
               {"to_settle", designs(c.to_settle, c.to_settle_cost)}};
  }
  return {{"cheapest_feasible", row_or_null(headline.cheapest)},
          {"tied_with_cheapest", ties},
          {"cheaper_designs", cheaper},
          {"fastest_feasible", row_or_null(headline.fastest)},
          {"knee", row_or_null(headline.knee)},
          {"cost_time_front", headline.cost_time_front}};
}

Status WriteAnswerViews(const spec::Spec& spec, const CampaignSummary& summary,
                        const std::string& dir, const std::string& image_dir,
                        Env* env) {
  const CampaignFolder folder(dir, env);
  const auto& rows = summary.exploration.evaluations;
  std::optional<LlmRecords> llm;
  if (spec.exploration.strategy == "llm") {
    llm = LoadLlmRecords(summary.output_dir);
  }
  // The front is recomputed so that views written mid-campaign are right.
  const Headline headline = ComputeHeadline(spec, rows);
  const std::vector<int>& front = headline.front;
  CampaignSummary current = summary;
  current.pareto_front = front;

  nlohmann::json j;
  j["scenario"] = spec.name;
  j["scenario_file"] = spec.source_path;
  j["strategy"] = spec.exploration.strategy;
  j["exploration_seed"] = spec.exploration.seed;
  j["budget"] = spec.exploration.budget;
  j["confirm_runs"] = spec.exploration.confirm_runs;
  j["replicas"] = spec.harness.replicas;
  j["cases"] = spec::CaseCount(spec);
  j["workers"] = summary.workers;
  j["isolation"] = summary.isolation;
  j["isolation_note"] = summary.isolation_note;
  j["wall_s"] = summary.wall_s;
  j["interrupted_by_signal"] = summary.interrupted_by;
  j["unfinished"] = summary.unfinished;
  j["in_progress"] = summary.in_progress;
  j["running"] = nlohmann::json::array();
  for (const spec::DesignPoint& p : summary.running) {
    j["running"].push_back(spec::FormatPoint(spec.design_space, p));
  }
  if (!summary.stopped_because.empty()) {
    j["stopped_because"] = summary.stopped_because;
  }
  j["complete"] = !summary.in_progress && !summary.finished_unknown &&
                  summary.interrupted_by == 0 && summary.unfinished == 0 &&
                  summary.stopped_because.empty();
  j["notes"] = summary.notes;
  j["counts"] = {{"evaluations", rows.size()},
                 {"simulated", summary.simulated},
                 {"reused", summary.reused},
                 {"failed", summary.failed}};
  j["objectives"] = nlohmann::json::array();
  for (const spec::Objective& o : spec.objectives) {
    j["objectives"].push_back({{"metric", o.metric}, {"minimize", o.minimize}});
  }
  j["constraints"] = spec.constraints;
  j["answer"] = AnswerJson(spec, rows, headline);
  j["pareto_front"] = nlohmann::json::array();
  for (int i : front) j["pareto_front"].push_back(RowJson(spec, rows[i]));
  j["evaluations"] = nlohmann::json::array();
  for (const EvaluationRow& row : rows)
    j["evaluations"].push_back(RowJson(spec, row));
  j["iterations"] = nlohmann::json::array();
  for (const runfile::IterationRow& it : summary.exploration.iterations) {
    j["iterations"].push_back({{"iteration", it.iteration},
                               {"strategy", it.strategy},
                               {"rationale", it.rationale},
                               {"content_keys", it.content_keys}});
  }
  if (llm) {
    int fallbacks = 0, rejected = 0, disagreements = 0;
    for (const llm::LlmEvent& e : llm->events) {
      fallbacks += e.kind == llm::LlmEventKind::kFallback;
      rejected += e.kind == llm::LlmEventKind::kRejected;
      disagreements += e.kind == llm::LlmEventKind::kDisagreement;
    }
    j["llm"] = {
        {"exchanges", llm->exchanges.size()},
        {"rejected_answers", rejected},
        {"fallback_iterations", fallbacks},
        {"disagreements", disagreements},
        {"records", "llm/exchanges.jsonl, llm/memory.jsonl, llm/events.jsonl"}};
  }
  ADSE_RETURN_IF_ERROR(WriteFileAtomic(
      folder.Path("summary.json"),
      j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n",
      env));
  ADSE_RETURN_IF_ERROR(WriteFileAtomic(
      folder.Path("report.md"),
      ReportMarkdown(spec, current, headline, image_dir, llm ? &*llm : nullptr),
      env));

  // The picture is a convenience: a plot that cannot be drawn (e.g. no
  // finite point) leaves the other views intact.
  (void)RenderFrontPicture(
      spec, rows, headline,
      fmt::format("{}: {}, {} on the cost-time front ({})", spec.name,
                  spec::Counted(rows.size(), "evaluation"),
                  headline.cost_time_front.size(), spec.exploration.strategy),
      folder.Path("pareto.png"), env);
  return Status::Ok();
}

}  // namespace adse::campaign
