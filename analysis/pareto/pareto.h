// Constraint-aware Pareto front, non-dominated ranks, hypervolume and the
// "true Pareto points found" comparison against a recorded exhaustive
// campaign. Minimisation throughout: callers negate maximised objectives.
//
// Conventions shared by every function here:
//  - All evaluations should carry the same number of objectives, M >= 1.
//    M is taken as the most common count (ties: the one seen first); an
//    evaluation with another count, or with a NaN objective, is "unusable":
//    never on a front, ranked last, ignored by the hypervolume and the
//    reference point. (±inf objectives are usable and compare as expected.)
//  - `feasible` is authoritative; `violation` only orders infeasible
//    evaluations (NaN or negative counts as +inf / 0).
//  - Objective values equal to 12 significant digits tie, in every
//    dominance test here: float noise (7 x 1.8 against 6 x 2.1) never puts
//    the slower of two equally priced computers on a front.
//  - Index lists are ascending; duplicates are all kept (neither
//    dominates the other).
// Nothing here throws (pagmo's exceptions are caught inside).
#ifndef ADSE_ANALYSIS_PARETO_PARETO_H_
#define ADSE_ANALYSIS_PARETO_PARETO_H_

#include <map>
#include <string>
#include <vector>

namespace adse::analysis {

struct Evaluation {
  std::map<std::string, double> point;  // design point
  std::vector<double> objectives;       // minimisation form
  bool feasible = true;                 // all constraints hold
  double violation = 0.0;  // total constraint violation (>= 0), ranks
                           // infeasible ones
};

// Indices of the constraint-aware non-dominated set: the non-dominated
// feasible evaluations when any is feasible; otherwise, among the usable
// ones, those with the least violation (ties within 1e-12 relative), of
// which the non-dominated ones. Empty when nothing is usable.
std::vector<int> ParetoFront(const std::vector<Evaluation>& evals);

// Non-dominated sorting rank of every evaluation (0 = the front, same set
// as ParetoFront). Feasible evaluations come first (ranks 0..F-1 from
// non-dominated sorting among them); infeasible ones follow, grouped by
// violation level (smallest first) and sorted by dominance within a level;
// unusable ones get the largest rank + 1.
std::vector<int> ParetoRanks(const std::vector<Evaluation>& evals);

// Hypervolume dominated by the feasible front and bounded by `reference`
// (pagmo::hypervolume; exact). Front points that are not strictly better
// than the reference in every objective add nothing and are ignored, as
// are points with an infinite objective. 0 when no feasible point is left;
// NaN when the reference has the wrong size or a non-finite value while
// some feasible evaluation exists (a caller bug made visible).
double Hypervolume(const std::vector<Evaluation>& evals,
                   const std::vector<double>& reference);

// The same volume for bare objective vectors of equal size (minimisation),
// all taken as feasible: the volume they dominate within `reference`.
// Points not strictly better than the reference everywhere, or with a
// non-finite objective, add nothing; 0 when none is left or the reference
// size differs from the points'. Cheap for the small sets a strategy scores
// many times per round (pagmo's exact algorithms, no copies of maps).
double PointsHypervolume(const std::vector<std::vector<double>>& points,
                         const std::vector<double>& reference);

// The value an objective is compared by: rounded to 12 significant
// digits, so that a cost expression's float noise (7 x 1.8 and 6 x 2.1
// GHz-cores a last bit apart) is a tie. Non-finite values and 0 unchanged.
double TieKey(double value);

// Pareto dominance (minimisation) of two objective vectors of equal size:
// `a` is no worse anywhere and better somewhere.
bool Dominates(const std::vector<double>& a, const std::vector<double>& b);
// `a` is no worse anywhere (equal vectors weakly dominate each other).
bool WeaklyDominates(const std::vector<double>& a,
                     const std::vector<double>& b);

// A reference point for Hypervolume: per objective, the worst (largest)
// finite value among feasible usable evaluations, moved outwards by
// margin × |worst| (by `margin` itself when the worst is 0), so the
// extreme front points still add volume. Moving by |worst| rather than
// multiplying keeps negated (maximised) objectives correct. A negative or
// NaN margin counts as 0. Empty when no feasible evaluation is usable or an
// objective has no finite feasible value.
std::vector<double> ReferencePoint(const std::vector<Evaluation>& evals,
                                   double margin = 0.1);

// How well a search (`found`) did against a reference campaign: the true
// front is the feasible front of `reference` (empty if nothing there is
// feasible), counted once per distinct design point. A true-front point is
// found when some evaluation of `found` has an equal design point (same
// names, values within 1e-9 relative to max(1, |value|)); its objectives in
// `found` do not matter for the count. hypervolume_ratio is
// Hypervolume(found, r) / Hypervolume(reference, r) with
// r = ReferencePoint(reference); 0 when the reference volume is 0. It can
// exceed 1 if `found` holds better values than the reference (noise).
struct SearchQuality {
  int true_pareto_points_found = 0;
  int true_front_size = 0;
  double hypervolume_ratio = 0.0;
};
SearchQuality CompareToReference(const std::vector<Evaluation>& found,
                                 const std::vector<Evaluation>& reference);

// Design-point equality as used by CompareToReference.
bool SameDesignPoint(const std::map<std::string, double>& a,
                     const std::map<std::string, double>& b);

}  // namespace adse::analysis

#endif  // ADSE_ANALYSIS_PARETO_PARETO_H_
