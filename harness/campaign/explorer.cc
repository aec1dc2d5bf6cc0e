#include "harness/campaign/explorer.h"

#include <algorithm>
#include <map>

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
    runfile::IterationRow it;
    it.iteration = static_cast<int64_t>(iterations_.size());
    it.strategy = strategy_.name();
    it.rationale = strategy_.rationale();
    iterations_.push_back(it);
    if (listener_ != nullptr) listener_->OnProposed(strategy_, it, points);
    for (const spec::DesignPoint& point : points) {
      EvalRequest request{next_index_++, it.iteration, point};
      proposed_[it.iteration].push_back(request.index);
      evaluator_.Start(request);
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
      std::map<int64_t, EvaluationRow> results;
      while (evaluator_.outstanding() > 0) {
        const std::vector<EvaluationRow> rows = evaluator_.Wait();
        for (const EvaluationRow& row : rows) {
          results[row.index] = row;
          Record(row);
        }
        if (rows.empty() && evaluator_.interrupted()) return;
      }
      // An interrupted round is not told: on resume it is asked again.
      if (static_cast<int64_t>(results.size()) != next_index_ - first) return;
      for (const auto& [index, row] : results) {
        strategy_.Tell(ObservationFromRow(row));
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

ExplorationResult Explore(const spec::Spec& spec, explore::Strategy& strategy,
                          Evaluator& evaluator, ExplorerListener* listener) {
  return Loop(spec, strategy, evaluator, listener).Run();
}

}  // namespace adse::campaign
