#include "analysis/pareto/pareto.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <exception>
#include <limits>
#include <pagmo/types.hpp>
#include <pagmo/utils/hypervolume.hpp>
#include <pagmo/utils/multi_objective.hpp>
#include <utility>

#include "stack/base/decimal.h"

namespace adse::analysis {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Violation sums of the same constraints computed in a different order
// differ in the last bits; they still form one level.
constexpr double kViolationRelTol = 1e-12;
constexpr double kDesignPointTol = 1e-9;

// The most common objective count (first seen wins ties); 0 if none.
size_t ObjectiveCount(const std::vector<Evaluation>& evals) {
  std::vector<std::pair<size_t, int>> counts;  // (size, occurrences)
  for (const Evaluation& e : evals) {
    auto it = std::find_if(counts.begin(), counts.end(), [&](const auto& c) {
      return c.first == e.objectives.size();
    });
    if (it == counts.end()) {
      counts.emplace_back(e.objectives.size(), 1);
    } else {
      ++it->second;
    }
  }
  size_t best = 0;
  int best_count = 0;
  for (const auto& [size, count] : counts) {
    if (size > 0 && count > best_count) {
      best = size;
      best_count = count;
    }
  }
  return best;
}

bool Usable(const Evaluation& e, size_t m) {
  return m > 0 && e.objectives.size() == m &&
         std::none_of(e.objectives.begin(), e.objectives.end(),
                      [](double v) { return std::isnan(v); });
}

double Violation(const Evaluation& e) {
  if (std::isnan(e.violation)) return kInf;
  return std::max(e.violation, 0.0);
}

// The usable evaluations split into feasible and infeasible, ascending.
struct Split {
  size_t m = 0;
  std::vector<int> feasible;
  std::vector<int> infeasible;
  std::vector<int> unusable;
};

Split SplitEvaluations(const std::vector<Evaluation>& evals) {
  Split split;
  split.m = ObjectiveCount(evals);
  for (size_t i = 0; i < evals.size(); ++i) {
    const int index = static_cast<int>(i);
    if (!Usable(evals[i], split.m)) {
      split.unusable.push_back(index);
    } else if (evals[i].feasible) {
      split.feasible.push_back(index);
    } else {
      split.infeasible.push_back(index);
    }
  }
  return split;
}

std::vector<pagmo::vector_double> Objectives(
    const std::vector<Evaluation>& evals, const std::vector<int>& subset) {
  std::vector<pagmo::vector_double> points;
  points.reserve(subset.size());
  for (int i : subset) {
    pagmo::vector_double f = evals[i].objectives;
    for (double& v : f) v = TieKey(v);
    points.push_back(std::move(f));
  }
  return points;
}

// Non-domination rank of each member of `subset` among the subset.
std::vector<int> RanksWithin(const std::vector<Evaluation>& evals,
                             const std::vector<int>& subset) {
  if (subset.size() < 2) return std::vector<int>(subset.size(), 0);
  // pagmo needs two points at least.
  const auto sorted =
      pagmo::fast_non_dominated_sorting(Objectives(evals, subset));
  const auto& ranks = std::get<3>(sorted);
  return std::vector<int>(ranks.begin(), ranks.end());
}

// The non-dominated members of `subset`, ascending.
std::vector<int> NonDominatedWithin(const std::vector<Evaluation>& evals,
                                    const std::vector<int>& subset, size_t m) {
  std::vector<int> front;
  if (subset.size() < 2) return subset;
  if (m == 2) {
    // Kung's algorithm, O(N log N) for the common cost/time case.
    for (auto k : pagmo::non_dominated_front_2d(Objectives(evals, subset))) {
      front.push_back(subset[k]);
    }
  } else {
    const std::vector<int> ranks = RanksWithin(evals, subset);
    for (size_t k = 0; k < subset.size(); ++k) {
      if (ranks[k] == 0) front.push_back(subset[k]);
    }
  }
  std::sort(front.begin(), front.end());
  return front;
}

// Infeasible indices grouped into violation levels, least violating first;
// each level ascending.
std::vector<std::vector<int>> ViolationLevels(
    const std::vector<Evaluation>& evals, std::vector<int> infeasible) {
  std::stable_sort(infeasible.begin(), infeasible.end(), [&](int a, int b) {
    return Violation(evals[a]) < Violation(evals[b]);
  });
  std::vector<std::vector<int>> levels;
  double level_start = 0.0;
  for (int i : infeasible) {
    const double v = Violation(evals[i]);
    const double tol = kViolationRelTol * std::max(1.0, std::abs(level_start));
    if (levels.empty() || !(v <= level_start + tol)) {
      levels.emplace_back();
      level_start = v;
    }
    levels.back().push_back(i);
  }
  for (auto& level : levels) std::sort(level.begin(), level.end());
  return levels;
}

std::vector<int> FrontImpl(const std::vector<Evaluation>& evals) {
  const Split split = SplitEvaluations(evals);
  if (!split.feasible.empty()) {
    return NonDominatedWithin(evals, split.feasible, split.m);
  }
  const auto levels = ViolationLevels(evals, split.infeasible);
  if (levels.empty()) return {};
  return NonDominatedWithin(evals, levels.front(), split.m);
}

std::vector<int> RanksImpl(const std::vector<Evaluation>& evals) {
  const Split split = SplitEvaluations(evals);
  std::vector<int> ranks(evals.size(), 0);
  int next = 0;  // first rank not used yet
  auto assign = [&](const std::vector<int>& subset) {
    const std::vector<int> within = RanksWithin(evals, subset);
    int used = 0;
    for (size_t k = 0; k < subset.size(); ++k) {
      ranks[subset[k]] = next + within[k];
      used = std::max(used, within[k] + 1);
    }
    next += used;
  };
  assign(split.feasible);
  for (const auto& level : ViolationLevels(evals, split.infeasible)) {
    assign(level);
  }
  for (int i : split.unusable) ranks[i] = next;
  return ranks;
}

double PointsHypervolumeImpl(const std::vector<std::vector<double>>& points,
                             const std::vector<double>& reference) {
  if (reference.empty() ||
      std::any_of(reference.begin(), reference.end(),
                  [](double r) { return !std::isfinite(r); })) {
    return 0.0;
  }
  std::vector<pagmo::vector_double> inside;
  for (const std::vector<double>& f : points) {
    bool ok = f.size() == reference.size();
    for (size_t k = 0; ok && k < f.size(); ++k) {
      ok = std::isfinite(f[k]) && f[k] < reference[k];
    }
    if (ok) inside.push_back(f);
  }
  if (inside.empty()) return 0.0;
  // Duplicates add no volume; dropping them keeps pagmo's input minimal.
  std::sort(inside.begin(), inside.end());
  inside.erase(std::unique(inside.begin(), inside.end()), inside.end());
  if (reference.size() == 1) return reference[0] - inside.front()[0];
  pagmo::hypervolume hv(inside, /*verify=*/false);
  return hv.compute(reference);
}

double HypervolumeImpl(const std::vector<Evaluation>& evals,
                       const std::vector<double>& reference) {
  const Split split = SplitEvaluations(evals);
  if (split.feasible.empty()) return 0.0;
  if (reference.size() != split.m ||
      std::any_of(reference.begin(), reference.end(),
                  [](double r) { return !std::isfinite(r); })) {
    return kNaN;
  }
  std::vector<std::vector<double>> points;
  for (int i : NonDominatedWithin(evals, split.feasible, split.m)) {
    points.push_back(evals[i].objectives);
  }
  return PointsHypervolumeImpl(points, reference);
}

std::vector<double> ReferenceImpl(const std::vector<Evaluation>& evals,
                                  double margin) {
  if (!(margin > 0.0)) margin = 0.0;
  const Split split = SplitEvaluations(evals);
  if (split.feasible.empty()) return {};
  std::vector<double> worst(split.m, -kInf);
  for (int i : split.feasible) {
    const auto& f = evals[i].objectives;
    for (size_t k = 0; k < split.m; ++k) {
      if (std::isfinite(f[k])) worst[k] = std::max(worst[k], f[k]);
    }
  }
  std::vector<double> reference(split.m);
  for (size_t k = 0; k < split.m; ++k) {
    if (!std::isfinite(worst[k])) return {};
    reference[k] =
        worst[k] == 0.0 ? margin : worst[k] + margin * std::abs(worst[k]);
  }
  return reference;
}

SearchQuality CompareImpl(const std::vector<Evaluation>& found,
                          const std::vector<Evaluation>& reference) {
  SearchQuality quality;
  std::vector<int> true_front;
  for (int i : FrontImpl(reference)) {
    if (!reference[i].feasible) continue;  // no feasible front at all
    const bool seen =
        std::any_of(true_front.begin(), true_front.end(), [&](int j) {
          return SameDesignPoint(reference[i].point, reference[j].point);
        });
    if (!seen) true_front.push_back(i);
  }
  quality.true_front_size = static_cast<int>(true_front.size());
  for (int i : true_front) {
    const bool hit =
        std::any_of(found.begin(), found.end(), [&](const Evaluation& e) {
          return SameDesignPoint(e.point, reference[i].point);
        });
    if (hit) ++quality.true_pareto_points_found;
  }
  const std::vector<double> r = ReferenceImpl(reference, 0.1);
  if (r.empty()) return quality;
  const double reference_volume = HypervolumeImpl(reference, r);
  if (!(reference_volume > 0.0)) return quality;
  quality.hypervolume_ratio = HypervolumeImpl(found, r) / reference_volume;
  return quality;
}

}  // namespace

double TieKey(double value) {
  return RoundToSignificantDigits(value, kDecimalDigits);
}

bool SameDesignPoint(const std::map<std::string, double>& a,
                     const std::map<std::string, double>& b) {
  if (a.size() != b.size()) return false;
  for (auto i = a.begin(), j = b.begin(); i != a.end(); ++i, ++j) {
    if (i->first != j->first) return false;
    const double scale =
        std::max({1.0, std::abs(i->second), std::abs(j->second)});
    if (!(std::abs(i->second - j->second) <= kDesignPointTol * scale)) {
      return false;
    }
  }
  return true;
}

// pagmo reports bad input by throwing; the checks above make that a bug,
// so these edges only keep exceptions from escaping.
double PointsHypervolume(const std::vector<std::vector<double>>& points,
                         const std::vector<double>& reference) {
  try {
    return PointsHypervolumeImpl(points, reference);
  } catch (const std::exception&) {
    return 0.0;
  }
}

namespace {
// Compares a and b as their TieKeys compare (-1, 0, 1; 0 also for NaN),
// rounding only values close enough to tie: values that round to one key
// lie within one unit of the 12th digit (under 1e-11 of either), and
// TieKey keeps the order of any others. The agent compares in a hot loop.
int CompareTied(double a, double b) {
  if (!(std::abs(a - b) <= 1e-10 * std::max(std::abs(a), std::abs(b)))) {
    return a < b ? -1 : a > b ? 1 : 0;  // far apart, infinite or NaN
  }
  const double x = TieKey(a), y = TieKey(b);
  return x < y ? -1 : x > y ? 1 : 0;
}
}  // namespace

bool Dominates(const std::vector<double>& a, const std::vector<double>& b) {
  bool better = false;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) {
    const int c = CompareTied(a[i], b[i]);
    if (c > 0) return false;
    if (c < 0) better = true;
  }
  return better;
}

bool WeaklyDominates(const std::vector<double>& a,
                     const std::vector<double>& b) {
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) {
    if (CompareTied(a[i], b[i]) > 0) return false;
  }
  return true;
}

std::vector<int> ParetoFront(const std::vector<Evaluation>& evals) {
  try {
    return FrontImpl(evals);
  } catch (const std::exception&) {
    return {};
  }
}

std::vector<int> ParetoRanks(const std::vector<Evaluation>& evals) {
  try {
    return RanksImpl(evals);
  } catch (const std::exception&) {
    return std::vector<int>(evals.size(), 0);
  }
}

double Hypervolume(const std::vector<Evaluation>& evals,
                   const std::vector<double>& reference) {
  try {
    return HypervolumeImpl(evals, reference);
  } catch (const std::exception&) {
    return kNaN;
  }
}

std::vector<double> ReferencePoint(const std::vector<Evaluation>& evals,
                                   double margin) {
  try {
    return ReferenceImpl(evals, margin);
  } catch (const std::exception&) {
    return {};
  }
}

SearchQuality CompareToReference(const std::vector<Evaluation>& found,
                                 const std::vector<Evaluation>& reference) {
  try {
    return CompareImpl(found, reference);
  } catch (const std::exception&) {
    return SearchQuality{0, 0, kNaN};
  }
}

}  // namespace adse::analysis
