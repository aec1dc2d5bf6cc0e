// The designs cheaper than a campaign's cheapest feasible one: what its
// runs say of them (run, ruled out by the capacity order, untried) and the
// runs that would settle the untried ones. The headline reports them; the
// confirm phase (exploration.confirm_runs) runs the settling designs.
#ifndef ADSE_HARNESS_CAMPAIGN_CHEAPER_H_
#define ADSE_HARNESS_CAMPAIGN_CHEAPER_H_

#include <cstdint>
#include <string>
#include <vector>

#include "harness/campaign/evaluation.h"
#include "harness/spec/spec.h"

namespace adse::campaign {

// How sure the cheapest feasible design is of being the cheapest: what the
// campaign knows of the designs of the space that cost less.
struct CheaperDesigns {
  // The space was enumerated: a design is feasible and the space holds at
  // most spec::kMaxCostCheckPoints designs.
  bool counted = false;
  std::string why_not_counted;  // when a design is feasible but not counted
  int64_t cheaper = 0;  // designs that cost less (costs equal to 12 digits tie)
  int64_t run = 0;  // of them, run to the end or stopped early (none feasible)
  // Not run, with no more capacity than a run that failed a constraint on
  // measured metrics (explore::CompareCapacity, a faster sensor counted as
  // more load): by the knobs' roles they fail too.
  int64_t ruled_out = 0;
  // The rest: neither run nor ruled out, the designs a longer search
  // would try. `untried` holds the first kMaxListed of them, cheapest first.
  int64_t untried_count = 0;
  std::vector<spec::DesignPoint> untried;
  std::vector<double> untried_cost;  // per entry of `untried`
  // The untried designs no other untried one exceeds in capacity: run
  // these, and if each fails, every untried design is ruled out.
  // `to_settle` holds the first kMaxListed, cheapest first.
  int64_t to_settle_count = 0;
  std::vector<spec::DesignPoint> to_settle;
  std::vector<double> to_settle_cost;  // per entry of `to_settle`
  static constexpr int kMaxListed = 20;
};

// What `rows` say of the designs of the space that cost less than `cost`.
CheaperDesigns CountCheaper(const spec::Spec& spec,
                            const std::vector<EvaluationRow>& rows,
                            double cost);

// "12 in the space: 3 run, none feasible; 8 with no more capacity than
// a run that failed; 1 untried, cheapest first: cores=5,freq_ghz=1.5
// (cost 7.5)"; with more untried than settle them, "...; 2 runs settle
// them (if these fail, ...): cores=5,freq_ghz=1.5 (cost 7.5), ...", naming at
// most `shown_at_most` designs per list ("and 4 more"), or "not counted
// (...)"; empty without a cheapest design.
std::string CheaperText(const spec::Spec& spec, const CheaperDesigns& cheaper,
                        int shown_at_most = 3);

// A run of the confirm phase.
struct SettlePick {
  spec::DesignPoint point;
  double cost = 0.0;
  // Untried cheaper designs (itself included) with no more capacity than
  // it: its failure would rule them all out.
  int64_t settles = 0;
};

// The confirm phase's next runs: up to `k` of the untried designs cheaper
// than `cost` that no other untried one exceeds in capacity, those that
// would settle the most first (ties: cheapest first). A design some row
// already holds is never picked, even when its run failed. Empty when
// nothing cheaper is untried, or the space is too large to count.
std::vector<SettlePick> SettlePicks(const spec::Spec& spec,
                                    const std::vector<EvaluationRow>& rows,
                                    double cost, int k);

}  // namespace adse::campaign

#endif  // ADSE_HARNESS_CAMPAIGN_CHEAPER_H_
