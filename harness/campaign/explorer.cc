#include "harness/campaign/explorer.h"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <set>
#include <string>

#include "harness/campaign/cheaper.h"
#include "harness/campaign/headline.h"
#include "harness/spec/design_point.h"
#include "harness/spec/text_util.h"

namespace adse::campaign {
namespace {

class Loop {
 public:
  Loop(const spec::Spec& spec, explore::Strategy& strategy,
       Evaluator& evaluator, ExplorerListener* listener)
      : spec_(spec),
        strategy_(strategy),
        evaluator_(evaluator),
        listener_(listener) {}

  ExplorationResult Run() {
    if (strategy_.adaptive()) {
      RunInRounds();
    } else {
      RunAsSlotsFree();
    }
    ExplorationResult result;
    if (spec_.exploration.confirm_runs > 0 && strategy_.failure().ok()) {
      result.confirm_cut = !RunConfirmPhase();
    }
    result.interrupted = evaluator_.interrupted();
    for (auto& [index, row] : done_) result.evaluations.push_back(row);
    for (runfile::IterationRow& it : iterations_) {
      for (int64_t index : proposed_[it.iteration]) {
        auto row = done_.find(index);
        if (row != done_.end())
          it.content_keys.push_back(row->second.content_key);
      }
      result.iterations.push_back(it);
    }
    return result;
  }

 private:
  // Asks for up to k points as one iteration; false when none came.
  bool Propose(int k) {
    const std::vector<spec::DesignPoint> points = strategy_.Ask(k);
    if (points.empty()) return false;
    Issue(points, strategy_.name(), strategy_.rationale(),
          strategy_.fell_back());
    return true;
  }

  // Starts `points` as one iteration.
  void Issue(const std::vector<spec::DesignPoint>& points,
             const std::string& strategy, const std::string& rationale,
             bool fell_back) {
    runfile::IterationRow it;
    it.iteration = static_cast<int64_t>(iterations_.size());
    it.strategy = strategy;
    it.rationale = rationale;
    iterations_.push_back(it);
    if (listener_ != nullptr) listener_->OnProposed(it, points, fell_back);
    for (const spec::DesignPoint& point : points) {
      EvalRequest request{next_index_++, it.iteration, point};
      proposed_[it.iteration].push_back(request.index);
      evaluator_.Start(request);
    }
  }

  // Waits for every outstanding run, recording each; false when an
  // interrupt came before all of them.
  bool Drain() {
    while (evaluator_.outstanding() > 0) {
      const std::vector<EvaluationRow> rows = evaluator_.Wait();
      for (const EvaluationRow& row : rows) Record(row);
      if (rows.empty() && evaluator_.interrupted()) return false;
    }
    return true;
  }

  // The confirm phase; false when an interrupt cut it short.
  bool RunConfirmPhase() {
    const spec::DesignSpace& space = spec_.design_space;
    int left = spec_.exploration.confirm_runs;
    const int round = std::max(1, spec_.exploration.batch);
    int done = 0;
    while (left > 0) {
      if (evaluator_.interrupted()) return false;
      std::vector<EvaluationRow> rows;
      for (const auto& [index, row] : done_) rows.push_back(row);
      const Headline answer = ComputeHeadline(spec_, rows);
      if (answer.cheapest < 0) return true;  // nothing to confirm
      const EvaluationRow& cheapest = rows[answer.cheapest];
      const std::vector<SettlePick> picks = SettlePicks(
          spec_, rows, RowMetric(cheapest, kCostMetric), std::min(round, left));
      if (picks.empty()) return true;
      const int64_t untried = answer.cheaper.untried_count;
      std::vector<spec::DesignPoint> points;
      std::vector<std::string> named;
      for (const SettlePick& pick : picks) {
        points.push_back(pick.point);
        named.push_back(
            fmt::format("{} (cost {:.4g}: if it fails, {} of the {} fail too)",
                        spec::FormatPoint(space, pick.point), pick.cost,
                        pick.settles, untried));
      }
      const std::string which =
          points.size() == 1
              ? fmt::format("run {}", done + 1)
              : fmt::format("runs {}-{}", done + 1, done + points.size());
      Issue(
          points, kConfirmPhase,
          fmt::format("Confirm {} of at most {}: of the {} cheaper than the "
                      "cheapest feasible one, {} (cost {:.4g}), {} {} "
                      "untried; running {}.",
                      which, spec_.exploration.confirm_runs,
                      spec::Counted(static_cast<size_t>(answer.cheaper.cheaper),
                                    "design"),
                      spec::FormatPoint(space, cheapest.point),
                      RowMetric(cheapest, kCostMetric), untried,
                      untried == 1 ? "is" : "are", fmt::join(named, ", ")),
          false);
      left -= static_cast<int>(points.size());
      done += static_cast<int>(points.size());
      if (!Drain()) return false;
    }
    return true;
  }

  void Record(const EvaluationRow& row) {
    done_[row.index] = row;
    if (listener_ != nullptr) listener_->OnEvaluated(row);
  }

  // Exhaustive and random: proposals do not depend on Tells, so keep every
  // slot busy and tell results as they come.
  void RunAsSlotsFree() {
    bool exhausted = false;
    while (true) {
      while (!exhausted && !evaluator_.interrupted() &&
             evaluator_.outstanding() < evaluator_.capacity()) {
        exhausted = !Propose(evaluator_.capacity() - evaluator_.outstanding());
      }
      if (evaluator_.outstanding() == 0) return;
      const std::vector<EvaluationRow> rows = evaluator_.Wait();
      // Tell in index order within a batch for tidiness; order does not
      // change what a non-adaptive strategy proposes.
      std::vector<EvaluationRow> sorted = rows;
      std::sort(sorted.begin(), sorted.end(),
                [](const EvaluationRow& a, const EvaluationRow& b) {
                  return a.index < b.index;
                });
      for (const EvaluationRow& row : sorted) {
        Record(row);
        strategy_.Tell(ObservationFromRow(row));
      }
      if (rows.empty() && evaluator_.interrupted()) return;
    }
  }

  // Adaptive strategies: a round's Tells all arrive, in proposal order,
  // before the next Ask.
  void RunInRounds() {
    const int round = strategy_.RoundSize(spec_.exploration.batch);
    while (!evaluator_.interrupted()) {
      const int64_t first = next_index_;
      if (!Propose(round)) return;
      // An interrupted round is not told: on resume it is asked again.
      if (!Drain()) return;
      for (auto it = done_.lower_bound(first); it != done_.end(); ++it) {
        strategy_.Tell(ObservationFromRow(it->second));
      }
    }
  }

  const spec::Spec& spec_;
  explore::Strategy& strategy_;
  Evaluator& evaluator_;
  ExplorerListener* listener_;
  int64_t next_index_ = 0;
  std::vector<runfile::IterationRow> iterations_;
  std::map<int64_t, std::vector<int64_t>> proposed_;  // iteration -> indices
  std::map<int64_t, EvaluationRow> done_;
};

}  // namespace

int ConfirmEvaluations(const ExplorationResult& result) {
  std::set<int64_t> confirming;
  for (const runfile::IterationRow& it : result.iterations) {
    if (it.strategy == kConfirmPhase) confirming.insert(it.iteration);
  }
  return static_cast<int>(
      std::count_if(result.evaluations.begin(), result.evaluations.end(),
                    [&](const EvaluationRow& row) {
                      return confirming.count(row.iteration) > 0;
                    }));
}

ExplorationResult Explore(const spec::Spec& spec, explore::Strategy& strategy,
                          Evaluator& evaluator, ExplorerListener* listener) {
  return Loop(spec, strategy, evaluator, listener).Run();
}

}  // namespace adse::campaign
