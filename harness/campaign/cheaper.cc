#include "harness/campaign/cheaper.h"

#include <fmt/format.h>

#include <algorithm>
#include <optional>
#include <set>
#include <utility>

#include "analysis/pareto/pareto.h"
#include "harness/explore/capacity.h"
#include "harness/explore/strategy.h"
#include "harness/spec/design_point.h"
#include "harness/spec/text_util.h"

namespace adse::campaign {
namespace {

struct Untried {
  double cost;
  spec::DesignPoint point;
  explore::Genes genes;
};

// The designs cheaper than a cost, as the rows leave them.
struct Search {
  CheaperDesigns counts;         // the counts only, no lists
  std::vector<Untried> untried;  // cheapest first
  // Indices into `untried` of the designs no other untried one exceeds
  // in capacity, ascending (so cheapest first).
  std::vector<size_t> maximal;
  std::vector<spec::KnobRole> roles;
};

// A sum that grows with capacity: a design exceeding another in capacity
// (explore::CompareCapacity == +1) scores strictly more.
int CapacityScore(const std::vector<spec::KnobRole>& roles,
                  const explore::Genes& genes) {
  int score = 0;
  for (size_t d = 0; d < roles.size(); ++d) {
    if (roles[d] == spec::KnobRole::kCores ||
        roles[d] == spec::KnobRole::kFrequency) {
      score += genes[d];
    } else if (roles[d] == spec::KnobRole::kSensorRate) {
      score -= genes[d];
    }
  }
  return score;
}

// The untried designs that no other exceeds, by the skyline method: taken
// in descending score, a design is exceeded by some untried design only
// if it is by one already found maximal (the order is transitive).
std::vector<size_t> Maximal(const std::vector<spec::KnobRole>& roles,
                            const std::vector<Untried>& untried) {
  std::vector<std::pair<int, size_t>> by_score;
  for (size_t i = 0; i < untried.size(); ++i) {
    by_score.emplace_back(-CapacityScore(roles, untried[i].genes), i);
  }
  std::stable_sort(by_score.begin(), by_score.end());
  std::vector<size_t> maximal;
  for (const auto& [negative_score, i] : by_score) {
    const bool exceeded =
        std::any_of(maximal.begin(), maximal.end(), [&](size_t m) {
          return explore::CompareCapacity(roles, {}, untried[m].genes,
                                          untried[i].genes, false) == +1;
        });
    if (!exceeded) maximal.push_back(i);
  }
  std::sort(maximal.begin(), maximal.end());
  return maximal;
}

// With `skip_held`, a design some row holds (a failed run's too) is not
// untried: the confirm phase never proposes a point twice.
Search SearchCheaper(const spec::Spec& spec,
                     const std::vector<EvaluationRow>& rows, double cost,
                     bool skip_held) {
  Search out;
  const uint64_t size = spec.design_space.Size();
  if (size > spec::kMaxCostCheckPoints) {
    out.counts.why_not_counted =
        fmt::format("a space of {} designs, more than the {} adse counts", size,
                    spec::kMaxCostCheckPoints);
    return out;
  }
  const explore::SpaceGrid grid(spec.design_space);
  for (const spec::DesignParameter& p : spec.design_space.parameters) {
    out.roles.push_back(p.role);
  }
  // The designs run, and those whose run failed for lack of capacity
  // (with whether it failed on load alone, so that coarser data counts as
  // more capacity against it, as the agent counts it).
  const std::vector<explore::CapacityConstraint> constraints =
      explore::CapacityConstraintsOf(spec);
  std::set<explore::Genes> run, held;
  std::vector<std::pair<explore::Genes, bool>> failed;
  for (const EvaluationRow& row : rows) {
    std::optional<explore::Genes> genes = grid.FromPoint(row.point);
    if (!genes) continue;
    held.insert(*genes);
    if (!row.complete()) continue;
    run.insert(*genes);
    if (row.feasible) continue;
    const explore::Observation observation = ObservationFromRow(row);
    if (explore::FailsForCapacity(constraints, observation, false)) {
      failed.emplace_back(
          *genes, explore::FailsForCapacity(constraints, observation, true));
    }
  }
  const double limit = analysis::TieKey(cost);
  CheaperDesigns& counts = out.counts;
  const Status status = spec::ForEachPointCost(
      spec, [&](const spec::DesignPoint& point, double design_cost) {
        if (!(analysis::TieKey(design_cost) < limit)) return;
        ++counts.cheaper;
        const std::optional<explore::Genes> genes = grid.FromPoint(point);
        if (!genes) return;
        if (run.count(*genes) > 0) {
          ++counts.run;
          return;
        }
        for (const auto& [failed_genes, load_only] : failed) {
          const int order = explore::CompareCapacity(out.roles, {}, *genes,
                                                     failed_genes, load_only);
          if (order == -1 || order == 0) {
            ++counts.ruled_out;
            return;
          }
        }
        if (skip_held && held.count(*genes) > 0) return;
        ++counts.untried_count;
        out.untried.push_back({design_cost, point, *genes});
      });
  if (!status.ok()) {
    out = Search();
    out.counts.why_not_counted = status.message();
    return out;
  }
  std::stable_sort(out.untried.begin(), out.untried.end(),
                   [](const Untried& a, const Untried& b) {
                     return analysis::TieKey(a.cost) < analysis::TieKey(b.cost);
                   });
  out.maximal = Maximal(out.roles, out.untried);
  counts.to_settle_count = static_cast<int64_t>(out.maximal.size());
  counts.counted = true;
  return out;
}

}  // namespace

CheaperDesigns CountCheaper(const spec::Spec& spec,
                            const std::vector<EvaluationRow>& rows,
                            double cost) {
  Search search = SearchCheaper(spec, rows, cost, false);
  CheaperDesigns out = std::move(search.counts);
  if (!out.counted) return out;
  const size_t listed = static_cast<size_t>(CheaperDesigns::kMaxListed);
  for (size_t k = 0; k < search.maximal.size() && k < listed; ++k) {
    const Untried& u = search.untried[search.maximal[k]];
    out.to_settle.push_back(u.point);
    out.to_settle_cost.push_back(u.cost);
  }
  for (size_t k = 0; k < search.untried.size() && k < listed; ++k) {
    out.untried_cost.push_back(search.untried[k].cost);
    out.untried.push_back(std::move(search.untried[k].point));
  }
  return out;
}

std::vector<SettlePick> SettlePicks(const spec::Spec& spec,
                                    const std::vector<EvaluationRow>& rows,
                                    double cost, int k) {
  const Search search = SearchCheaper(spec, rows, cost, true);
  if (!search.counts.counted || k < 1) return {};
  std::vector<SettlePick> picks;
  for (size_t m : search.maximal) {
    const Untried& top = search.untried[m];
    SettlePick pick{top.point, top.cost, 0};
    for (const Untried& u : search.untried) {
      const int order =
          explore::CompareCapacity(search.roles, {}, top.genes, u.genes, false);
      if (order == +1 || order == 0) ++pick.settles;
    }
    picks.push_back(std::move(pick));
  }
  // Most settled first; stable, so ties stay cheapest first.
  std::stable_sort(picks.begin(), picks.end(),
                   [](const SettlePick& a, const SettlePick& b) {
                     return a.settles > b.settles;
                   });
  if (picks.size() > static_cast<size_t>(k)) picks.resize(k);
  return picks;
}

std::string CheaperText(const spec::Spec& spec, const CheaperDesigns& c,
                        int shown_at_most) {
  if (!c.counted) {
    return c.why_not_counted.empty()
               ? std::string()
               : fmt::format("not counted ({})", c.why_not_counted);
  }
  if (c.cheaper == 0) return "none in the space";
  std::vector<std::string> parts;
  if (c.run > 0) {
    parts.push_back(fmt::format("{} run, none feasible", c.run));
  }
  if (c.ruled_out > 0) {
    parts.push_back(fmt::format(
        "{} with no more capacity than a run that failed", c.ruled_out));
  }
  // "a (cost 6), b (cost 7.2) and 5 more"
  auto list = [&](const std::vector<spec::DesignPoint>& points,
                  const std::vector<double>& costs, int64_t count) {
    std::vector<std::string> listed;
    const size_t shown = std::min<size_t>(
        points.size(), static_cast<size_t>(std::max(shown_at_most, 0)));
    for (size_t k = 0; k < shown; ++k) {
      listed.push_back(fmt::format(
          "{} (cost {:.4g})", spec::FormatPoint(spec.design_space, points[k]),
          costs[k]));
    }
    return fmt::format("{}{}", fmt::join(listed, ", "),
                       count > static_cast<int64_t>(shown)
                           ? fmt::format(" and {} more", count - shown)
                           : std::string());
  };
  if (c.untried_count == 0) {
    // What the user asked: whether this is the cheapest of the space.
    parts.push_back(c.ruled_out > 0
                        ? "none untried: the cheapest feasible design of "
                          "the space, as far as less capacity never helps"
                        : "none untried: the cheapest feasible design of "
                          "the space");
  } else {
    parts.push_back(
        fmt::format("{} untried, cheapest first: {}", c.untried_count,
                    list(c.untried, c.untried_cost, c.untried_count)));
    if (c.to_settle_count > 0 && c.to_settle_count < c.untried_count) {
      parts.push_back(fmt::format(
          "{} settle{} them (if these fail, every other has no more "
          "capacity than one that failed): {}",
          spec::Counted(static_cast<size_t>(c.to_settle_count), "run"),
          c.to_settle_count == 1 ? "s" : "",
          list(c.to_settle, c.to_settle_cost, c.to_settle_count)));
    }
    if (spec.exploration.confirm_runs == 0) {
      parts.push_back(
          "exploration.confirm_runs (--confirm-runs) runs them after the "
          "budget");
    }
  }
  return fmt::format("{} in the space: {}", c.cheaper, fmt::join(parts, "; "));
}

}  // namespace adse::campaign
