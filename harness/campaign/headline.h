// The answer a campaign leads with. The user asked for the cheapest
// computer that still drives well, so every view (terminal, report.md,
// summary.json, pareto.png, adse analyze) starts with the same three
// designs, taken from the same front function, before the front itself.
#ifndef ADSE_HARNESS_CAMPAIGN_HEADLINE_H_
#define ADSE_HARNESS_CAMPAIGN_HEADLINE_H_

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "harness/campaign/cheaper.h"
#include "harness/campaign/evaluation.h"
#include "harness/spec/spec.h"
#include "stack/base/env.h"
#include "stack/base/status.h"

namespace adse::campaign {

// The two metrics of the cost-time view; every scenario reports both.
inline constexpr char kCostMetric[] = "hardware_cost";
inline constexpr char kTimeMetric[] = "nav_time_s";

struct Headline {
  // Row indices; -1 when no row qualifies.
  int cheapest = -1;  // feasible, least hardware_cost (ties: less nav time)
  int fastest = -1;   // feasible, least nav_time_s (ties: less cost)
  // The knee of cost_time_front: the point farthest from the chord between
  // its two ends, both axes scaled to the front's range; -1 with fewer than
  // three points on that front.
  int knee = -1;
  // The scenario's front (ParetoFrontOf: every objective, constraint-aware).
  std::vector<int> front;
  // Feasible rows non-dominated in (hardware_cost, nav_time_s), by cost.
  // Equal to `front` for the usual two objectives; with more objectives it
  // is the 2-D view, and the n-D front is listed separately.
  std::vector<int> cost_time_front;
  // Other feasible rows of the cheapest's cost and nav time (TieKey): other
  // computers that answer the question as well, e.g. 6 cores at 2 GHz
  // beside 4 at 3 GHz.
  std::vector<int> cheapest_ties;
  // The designs cheaper than `cheapest` (counted only when it exists).
  CheaperDesigns cheaper;
  // Rows at the same design point as each of cheapest/fastest/knee
  // (replicas); 1 when the point ran once.
  int cheapest_runs = 0, fastest_runs = 0, knee_runs = 0;
};

Headline ComputeHeadline(const spec::Spec& spec,
                         const std::vector<EvaluationRow>& rows);

// "cheapest feasible: cores=2,freq_ghz=1.2 cost 2.4, nav 150.2 s,
// ctrl 9.8 Hz (1 run)" and the like, one line per design, what the
// campaign knows of cheaper designs, then the front; for the terminal.
std::string HeadlineText(const spec::Spec& spec,
                         const std::vector<EvaluationRow>& rows,
                         const Headline& headline);
// The same as the top section of report.md; `image_dir` is where the rows'
// trajectory pictures are, relative to the report ("images").
std::string HeadlineMarkdown(const spec::Spec& spec,
                             const std::vector<EvaluationRow>& rows,
                             const Headline& headline,
                             const std::string& image_dir);

// The headline as summary.json's "answer" (also in `adse status --json`
// and `adse explore --json`): cheapest, fastest and knee rows, null when
// none, and the cost-time front's row indices.
nlohmann::json AnswerJson(const spec::Spec& spec,
                          const std::vector<EvaluationRow>& rows,
                          const Headline& headline);

// pareto.png: every row by cost and nav time, the cost-time front as a
// staircase with its points labelled, the cheapest feasible design ringed,
// and each simple bound of the constraints on either axis (e.g.
// `nav_time_s <= 400`) dashed.
Status RenderFrontPicture(const spec::Spec& spec,
                          const std::vector<EvaluationRow>& rows,
                          const Headline& headline, const std::string& title,
                          const std::string& png_path,
                          Env* env = Env::Default());

// The same in the reference study's form (navigation time across, cost
// up): this campaign's rows as red triangles over a reference campaign's
// (an exhaustive recording's) points in grey and its cost-time front as a
// grey line, each simple bound dashed. `points_name` in the legend is the
// campaign's strategy.
Status RenderStudyPicture(const spec::Spec& spec,
                          const std::vector<EvaluationRow>& rows,
                          const spec::Spec& reference_spec,
                          const std::vector<EvaluationRow>& reference_rows,
                          const std::string& title, const std::string& png_path,
                          Env* env = Env::Default());

// `indices` (rows) cheapest first, then fastest, as every front is
// listed for the user.
std::vector<int> CheapestFirst(const std::vector<EvaluationRow>& rows,
                               std::vector<int> indices);

// A constraint of the form `metric OP number` or `number OP metric`
// (OP one of < <= > >=) on `metric`: its bound. False for anything else.
bool SimpleBound(const std::string& constraint, const std::string& metric,
                 double* bound);

// The constraints that infeasible designs drawn inside the picture's lines
// fail: of the completed runs that violate no simple bound on cost or
// nav time (a deviation bound, say), what they do violate, in the spec's
// order. The picture's legend names them, or such a cross would look
// feasible.
std::vector<std::string> UndrawnFailures(
    const spec::Spec& spec, const std::vector<EvaluationRow>& rows);

}  // namespace adse::campaign

#endif  // ADSE_HARNESS_CAMPAIGN_HEADLINE_H_
