#include "harness/campaign/headline.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <tuple>

#include "analysis/metrics/run_metrics.h"
#include "analysis/pareto/pareto.h"
#include "analysis/pictures/pictures.h"
#include "harness/campaign/replicas.h"
#include "harness/spec/design_point.h"
#include "harness/spec/spec_parser.h"
#include "harness/spec/text_util.h"
#include "stack/base/files.h"

namespace adse::campaign {
namespace {

bool Placed(const EvaluationRow& row) {
  return std::isfinite(RowMetric(row, kCostMetric)) &&
         std::isfinite(RowMetric(row, kTimeMetric));
}

// Runs behind the rows at row i's design point: each row's replicas.
int RunsAt(const std::vector<EvaluationRow>& rows, int i) {
  if (i < 0) return 0;
  int n = 0;
  for (const EvaluationRow& row : rows) {
    if (!row.complete() || row.point != rows[i].point) continue;
    n += static_cast<int>(std::max<size_t>(1, row.replicas.size()));
  }
  return n;
}

// The point's values in space order, "2/1.2/7": short enough to label a
// plot; the legend names the parameters.
std::string ShortPoint(const spec::Spec& spec, const EvaluationRow& row) {
  std::vector<std::string> values;
  for (const spec::DesignParameter& p : spec.design_space.parameters) {
    auto it = row.point.find(p.name);
    if (it != row.point.end())
      values.push_back(fmt::format("{:g}", it->second));
  }
  return fmt::format("{}", fmt::join(values, "/"));
}

std::string Value(double v, const char* unit) {
  if (!std::isfinite(v)) return "—";
  return fmt::format("{:.4g}{}", v, unit);
}

// "cost 2.4, nav 150.2 s, ctrl 9.8 Hz (1 run, no replicas)"; with
// replicas "(median of 3 runs, nav 148.1–152.0 s)", and how sure: an
// unstable point says in how many runs it was feasible.
std::string Facts(const spec::Spec& spec,
                  const std::vector<EvaluationRow>& rows, int i, int runs) {
  const EvaluationRow& row = rows[i];
  std::string sureness;
  const int cases = CaseCountOf(row);
  if (cases > 1) {
    const size_t per_case = row.replicas.size() / static_cast<size_t>(cases);
    sureness = fmt::format("worst of {} cases", cases);
    if (per_case > 1) {
      sureness += fmt::format(", each the median of {} runs", per_case);
    }
    if (row.unstable) sureness += ", " + Instability(spec, row);
  } else if (row.replicas.size() > 1) {
    sureness = fmt::format("median of {} runs", row.replicas.size());
    if (std::optional<MetricSpread> nav = SpreadOf(spec, row, kTimeMetric)) {
      sureness += fmt::format(", nav {}–{}", Value(nav->min, ""),
                              Value(nav->max, " s"));
    }
    if (row.unstable) sureness += ", " + ReplicaSummary(spec, row);
  } else {
    sureness = runs <= 1 ? std::string("1 run, no replicas")
                         : fmt::format("{} runs at this point", runs);
  }
  return fmt::format("cost {}, nav {}, ctrl {} ({})",
                     Value(RowMetric(row, kCostMetric), ""),
                     Value(RowMetric(row, kTimeMetric), " s"),
                     Value(RowMetric(row, "ctrl_rate_hz"), " Hz"), sureness);
}

struct Line {
  const char* what;
  int row;
  int runs;
};

std::vector<Line> Lines(const std::vector<EvaluationRow>& rows,
                        const Headline& h) {
  std::vector<Line> lines = {
      {"cheapest feasible", h.cheapest, h.cheapest_runs}};
  for (int i : h.cheapest_ties) {
    lines.push_back({"tied with cheapest", i, RunsAt(rows, i)});
  }
  lines.push_back({"fastest feasible", h.fastest, h.fastest_runs});
  if (h.knee >= 0) lines.push_back({"knee of cost-time", h.knee, h.knee_runs});
  return lines;
}

}  // namespace

bool SimpleBound(const std::string& constraint, const std::string& metric,
                 double* bound) {
  static const std::regex kNameFirst(
      R"(^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(<=|>=|<|>)\s*([-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?)\s*$)");
  static const std::regex kNumberFirst(
      R"(^\s*([-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?)\s*(<=|>=|<|>)\s*([A-Za-z_][A-Za-z0-9_]*)\s*$)");
  std::smatch m;
  if (std::regex_match(constraint, m, kNameFirst) && m[1] == metric) {
    *bound = std::stod(m[3]);
    return true;
  }
  if (std::regex_match(constraint, m, kNumberFirst) && m[3] == metric) {
    *bound = std::stod(m[1]);
    return true;
  }
  return false;
}

std::vector<std::string> UndrawnFailures(
    const spec::Spec& spec, const std::vector<EvaluationRow>& rows) {
  std::set<std::string> failed;
  for (const EvaluationRow& row : rows) {
    if (row.feasible || !Placed(row) ||
        RowMetric(row, analysis::kCensoredMetric) == 1.0) {
      continue;
    }
    const std::vector<std::string> violated =
        spec::ViolatedConstraints(spec, row.metrics, row.point);
    const bool drawn =
        std::any_of(violated.begin(), violated.end(), [](const auto& c) {
          double bound = 0.0;
          return SimpleBound(c, kTimeMetric, &bound) ||
                 SimpleBound(c, kCostMetric, &bound);
        });
    if (!drawn) failed.insert(violated.begin(), violated.end());
  }
  std::vector<std::string> out;
  for (const std::string& c : spec.constraints) {
    if (failed.count(c) > 0) out.push_back(c);
  }
  return out;
}

std::vector<int> CheapestFirst(const std::vector<EvaluationRow>& rows,
                               std::vector<int> indices) {
  // A missing value (a censored run's time) sorts last.
  auto key = [&](int i) {
    auto last = [](double v) {
      return std::isnan(v) ? std::numeric_limits<double>::infinity() : v;
    };
    return std::make_tuple(
        last(analysis::TieKey(RowMetric(rows[i], kCostMetric))),
        last(RowMetric(rows[i], kTimeMetric)), i);
  };
  std::sort(indices.begin(), indices.end(),
            [&](int a, int b) { return key(a) < key(b); });
  return indices;
}

Headline ComputeHeadline(const spec::Spec& spec,
                         const std::vector<EvaluationRow>& rows) {
  Headline h;
  h.front = ParetoFrontOf(spec, rows);
  std::vector<int> feasible;
  for (size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].complete() && rows[i].feasible && Placed(rows[i])) {
      feasible.push_back(static_cast<int>(i));
    }
  }
  // 3 x 1.2 (3.5999999999999996) and 2 x 1.8 cost the same, and the
  // faster of them is the cheapest design: costs compare as the front does.
  auto cost = [&](int i) {
    return analysis::TieKey(RowMetric(rows[i], kCostMetric));
  };
  auto time = [&](int i) { return RowMetric(rows[i], kTimeMetric); };
  auto by_cost = [&](int a, int b) {
    return cost(a) != cost(b)   ? cost(a) < cost(b)
           : time(a) != time(b) ? time(a) < time(b)
                                : a < b;
  };
  std::sort(feasible.begin(), feasible.end(), by_cost);
  if (feasible.empty()) return h;
  h.cheapest = feasible.front();
  h.fastest =
      *std::min_element(feasible.begin(), feasible.end(), [&](int a, int b) {
        return time(a) != time(b) ? time(a) < time(b) : by_cost(a, b);
      });
  // Sorted by cost, a row is on the 2-D front when it is strictly faster
  // than every cheaper-or-equal row before it, or ties the last one in
  // both (4 cores at 3 GHz and 6 at 2 GHz: two answers, as on the n-D
  // front, neither hidden under the other).
  double best_time = std::numeric_limits<double>::infinity();
  for (int i : feasible) {
    const double t = analysis::TieKey(time(i));
    const bool ties_last = !h.cost_time_front.empty() &&
                           cost(i) == cost(h.cost_time_front.back()) &&
                           t == best_time;
    if (t < best_time || ties_last) {
      h.cost_time_front.push_back(i);
      best_time = t;
    }
  }
  const std::vector<int>& f = h.cost_time_front;
  // The cheapest leads the front; the designs tied with it follow.
  for (size_t k = 1;
       k < f.size() && cost(f[k]) == cost(f[0]) &&
       analysis::TieKey(time(f[k])) == analysis::TieKey(time(f[0]));
       ++k) {
    h.cheapest_ties.push_back(f[k]);
  }
  if (f.size() >= 3) {
    const double c0 = cost(f.front()), c1 = cost(f.back());
    const double t0 = time(f.back()), t1 = time(f.front());
    double best = 0.0;
    for (size_t k = 1; k + 1 < f.size(); ++k) {
      // Scaled, the chord is x + y = 1; the knee bulges farthest below it.
      const double x = (cost(f[k]) - c0) / (c1 - c0);
      const double y = (time(f[k]) - t0) / (t1 - t0);
      if (1.0 - x - y > best) {
        best = 1.0 - x - y;
        h.knee = f[k];
      }
    }
  }
  h.cheaper =
      CountCheaper(spec, rows, RowMetric(rows[h.cheapest], kCostMetric));
  h.cheapest_runs = RunsAt(rows, h.cheapest);
  h.fastest_runs = RunsAt(rows, h.fastest);
  h.knee_runs = RunsAt(rows, h.knee);
  return h;
}

std::string HeadlineText(const spec::Spec& spec,
                         const std::vector<EvaluationRow>& rows,
                         const Headline& h) {
  std::ostringstream out;
  if (rows.empty()) return "no evaluation has a result yet\n";
  if (h.cheapest < 0) {
    out << fmt::format(
        "no feasible design among {}: every one violates a "
        "constraint ({})\n",
        spec::Counted(rows.size(), "evaluation"),
        fmt::join(spec.constraints, ", "));
  }
  for (const Line& line : Lines(rows, h)) {
    if (line.row < 0) continue;
    out << fmt::format(
        "{:<19} {}  {}\n", line.what,
        spec::FormatPoint(spec.design_space, rows[line.row].point),
        Facts(spec, rows, line.row, line.runs));
  }
  if (const std::string cheaper = CheaperText(spec, h.cheaper);
      !cheaper.empty()) {
    out << fmt::format("{:<19} {}\n", "cheaper designs", cheaper);
  }
  std::vector<std::string> objectives;
  for (const spec::Objective& o : spec.objectives)
    objectives.push_back(o.metric);
  // With nothing feasible the constraint-aware front holds the designs
  // that violate least; say so, as report.md does.
  out << fmt::format("Pareto front over {} ({} of {}{}):\n",
                     fmt::join(objectives, ", "), h.front.size(),
                     spec::Counted(rows.size(), "evaluation"),
                     h.cheapest < 0 ? "; nothing is feasible, so these are "
                                      "the designs that violate least"
                                    : "");
  for (int i : CheapestFirst(rows, h.front)) {
    const EvaluationRow& row = rows[i];
    out << fmt::format("  {:<36} cost {:>7}  nav {:>9}  ctrl {:>8}{}\n",
                       spec::FormatPoint(spec.design_space, row.point),
                       Value(RowMetric(row, kCostMetric), ""),
                       Value(RowMetric(row, kTimeMetric), " s"),
                       Value(RowMetric(row, "ctrl_rate_hz"), " Hz"),
                       row.feasible ? "" : "  (infeasible)");
  }
  return out.str();
}

namespace {

// "[trajectory](...)"; with task.cases one picture per case, named by it
// (each case's first run).
std::string PictureLinks(const spec::Spec& spec, const EvaluationRow& row,
                         const std::string& image_dir) {
  if (CaseCountOf(row) <= 1) {
    return fmt::format("[trajectory]({}/{}/trajectory.png)", image_dir,
                       row.content_key);
  }
  std::vector<std::string> links;
  std::set<int64_t> seen;
  for (const EvaluationRow& run : row.replicas) {
    if (!seen.insert(run.task_case).second) continue;
    links.push_back(fmt::format("[{}]({}/{}/trajectory.png)",
                                spec::CaseName(spec, run.task_case), image_dir,
                                run.content_key));
  }
  return fmt::format("{}", fmt::join(links, ", "));
}

}  // namespace

std::string HeadlineMarkdown(const spec::Spec& spec,
                             const std::vector<EvaluationRow>& rows,
                             const Headline& h, const std::string& image_dir) {
  std::ostringstream md;
  md << "## Answer\n\n";
  if (rows.empty()) return md.str() + "No evaluation has a result yet.\n\n";
  if (h.cheapest < 0) {
    md << fmt::format(
        "**No feasible design** among {}: every one violates a "
        "constraint.\n\n",
        spec::Counted(rows.size(), "evaluation"));
  }
  for (const Line& line : Lines(rows, h)) {
    if (line.row < 0) continue;
    const EvaluationRow& row = rows[line.row];
    std::string what = line.what;
    what[0] = static_cast<char>(std::toupper(what[0]));
    md << fmt::format("- **{}:** `{}` — {}. {}\n", what,
                      spec::FormatPoint(spec.design_space, row.point),
                      Facts(spec, rows, line.row, line.runs),
                      PictureLinks(spec, row, image_dir));
  }
  // The report lists every untried design it holds: the ones to run next.
  if (const std::string cheaper =
          CheaperText(spec, h.cheaper, CheaperDesigns::kMaxListed);
      !cheaper.empty()) {
    md << fmt::format("- **Cheaper designs:** {}.\n", cheaper);
  }
  if (spec.objectives.size() > 2 ||
      (spec.objectives.size() == 2 &&
       !(spec.objectives[0].metric == kCostMetric &&
         spec.objectives[1].metric == kTimeMetric))) {
    md << fmt::format(
        "\nThe picture shows the cost-time view: {} feasible designs "
        "non-dominated in hardware_cost and nav_time_s. The front over all "
        "objectives is listed below.\n",
        h.cost_time_front.size());
  }
  md << "\n![cost and navigation time of every evaluation](pareto.png)\n\n";
  return md.str();
}

namespace {

// The simple bounds the constraints put on `metric`, in file order.
std::vector<double> BoundsOn(const spec::Spec& spec, const char* metric) {
  std::vector<double> bounds;
  for (const std::string& c : spec.constraints) {
    double bound = 0.0;
    if (SimpleBound(c, metric, &bound)) bounds.push_back(bound);
  }
  return bounds;
}

// Every placeable row as a plot point. A censored run's time is unknown
// beyond its stop; it sits at the time bound that stopped it (the largest,
// when there are several), or is left out when no time bound did.
std::vector<analysis::ParetoPlotPoint> PlotPoints(
    const spec::Spec& spec, const std::vector<EvaluationRow>& rows,
    const Headline& h) {
  std::vector<bool> on_front(rows.size(), false);
  for (int i : h.cost_time_front) on_front[i] = true;
  const std::vector<double> time_bounds = BoundsOn(spec, kTimeMetric);
  const double time_bound =
      time_bounds.empty()
          ? std::nan("")
          : *std::max_element(time_bounds.begin(), time_bounds.end());
  std::vector<analysis::ParetoPlotPoint> plot;
  for (size_t i = 0; i < rows.size(); ++i) {
    if (RowMetric(rows[i], analysis::kCensoredMetric) == 1.0 &&
        std::isfinite(RowMetric(rows[i], kCostMetric)) &&
        std::isfinite(time_bound)) {
      analysis::ParetoPlotPoint p;
      p.cost = RowMetric(rows[i], kCostMetric);
      p.nav_time_s = time_bound;
      p.feasible = false;
      p.censored = true;
      plot.push_back(p);
      continue;
    }
    if (!Placed(rows[i])) continue;
    analysis::ParetoPlotPoint p;
    p.cost = RowMetric(rows[i], kCostMetric);
    p.nav_time_s = RowMetric(rows[i], kTimeMetric);
    p.feasible = rows[i].feasible;
    p.unstable = rows[i].unstable;
    p.on_front = on_front[i];
    if (p.on_front) p.label = ShortPoint(spec, rows[i]);
    p.highlight = static_cast<int>(i) == h.cheapest;
    plot.push_back(p);
  }
  return plot;
}

// The cost's axis says what it counts: the scenario's expression.
std::string CostLabel(const spec::Spec& spec) {
  return fmt::format("hardware cost ({})", spec.cost);
}

}  // namespace

Status RenderFrontPicture(const spec::Spec& spec,
                          const std::vector<EvaluationRow>& rows,
                          const Headline& h, const std::string& title,
                          const std::string& png_path, Env* env) {
  const std::vector<analysis::ParetoPlotPoint> plot = PlotPoints(spec, rows, h);
  analysis::ParetoPlotOptions options;
  options.title = title;
  options.x_label = CostLabel(spec);
  if (const std::vector<std::string> undrawn = UndrawnFailures(spec, rows);
      !undrawn.empty()) {
    options.infeasible_name =
        fmt::format(
            "infeasible (inside the lines: {})",
            fmt::join(undrawn.begin(),
                      undrawn.begin() + std::min<size_t>(undrawn.size(), 2),
                      ", ")) +
        (undrawn.size() > 2 ? ", ..." : "");
  }
  options.front_name = fmt::format("cost-time front ({})",
                                   fmt::join(spec.design_space.Names(), "/"));
  options.horizontal_lines = BoundsOn(spec, kTimeMetric);
  options.vertical_lines = BoundsOn(spec, kCostMetric);
  Result<std::string> png = analysis::ParetoPlotPng(plot, options);
  if (!png.ok()) return png.status();
  return WriteFileAtomic(png_path, *png, env);
}

Status RenderStudyPicture(const spec::Spec& spec,
                          const std::vector<EvaluationRow>& rows,
                          const spec::Spec& reference_spec,
                          const std::vector<EvaluationRow>& reference_rows,
                          const std::string& title, const std::string& png_path,
                          Env* env) {
  analysis::StudyPlotOptions options;
  options.title = title;
  options.time_bounds_s = BoundsOn(spec, kTimeMetric);
  options.cost_bounds = BoundsOn(spec, kCostMetric);
  options.points_name = spec.exploration.strategy;
  options.cost_label = CostLabel(spec);
  Result<std::string> png = analysis::StudyPlotPng(
      PlotPoints(spec, rows, ComputeHeadline(spec, rows)),
      PlotPoints(reference_spec, reference_rows,
                 ComputeHeadline(reference_spec, reference_rows)),
      options);
  if (!png.ok()) return png.status();
  return WriteFileAtomic(png_path, *png, env);
}

}  // namespace adse::campaign
