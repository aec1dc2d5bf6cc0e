// Replay: runs strategies against a recorded campaign's results instead of
// simulating, to compare strategies over many seeds in seconds. A point
// the recording lacks is told as failed ("not recorded") and counted.
#ifndef ADSE_HARNESS_CAMPAIGN_REPLAY_H_
#define ADSE_HARNESS_CAMPAIGN_REPLAY_H_

#include <cstdint>
#include <string>
#include <vector>

#include "analysis/runfile/campaign_file.h"
#include "harness/campaign/explorer.h"
#include "harness/spec/spec.h"
#include "stack/base/status.h"

namespace adse::campaign {

// A recorded campaign: its scenario and every evaluated row.
struct Recording {
  spec::Spec spec;  // parsed from the scenario text stored in campaign.h5
  std::vector<EvaluationRow> rows;
  std::string folder;  // the campaign folder (llm replays read llm/ there)
};

// Reads <folder>/campaign.h5 (or a campaign.h5 path). Errors name the file.
Result<Recording> LoadRecording(const std::string& folder_or_file);

// Keeps only the scenario's objectives on these metrics, in its order, so
// that strategies and the true front see those alone (`adse explore
// --objectives`). Each must be one of its objectives, and two at least
// must stay: a front of one objective is a single point.
Status KeepObjectives(const std::vector<std::string>& metrics,
                      Recording* recording);

// Answers evaluations from a recording, one at a time.
class RecordingEvaluator : public Evaluator {
 public:
  explicit RecordingEvaluator(const Recording* recording);
  int capacity() const override { return 1; }
  void Start(const EvalRequest& request) override;
  int outstanding() const override { return static_cast<int>(ready_.size()); }
  std::vector<EvaluationRow> Wait() override;
  bool interrupted() const override { return false; }
  int missing() const { return missing_; }

 private:
  const Recording* recording_;
  std::vector<EvaluationRow> ready_;
  int missing_ = 0;
};

// One round of a replay: what the strategy proposed and why.
struct ReplayIteration {
  int64_t iteration = 0;
  std::string rationale;  // empty for strategies that give none
  std::vector<spec::DesignPoint> points;
};

struct ReplayRun {
  std::string strategy;
  uint64_t seed = 0;
  int evaluations = 0;          // the confirm phase's included
  int confirm_evaluations = 0;  // of them, the confirm phase's
  int missing = 0;              // proposed points the recording lacks
  int true_pareto_found = 0;    // of the recording's front
  int front_size = 0;           // the recording's front
  double hypervolume_ratio = 0.0;
  // Evaluation index (1-based) of the first true Pareto point, 0 if none.
  int first_true_pareto_at = 0;
  // Whether it evaluated a feasible design at the recording's cheapest
  // feasible cost (what the user asked for; designs tying in cost are
  // equally cheap); false when the recording has none.
  bool found_cheapest_feasible = false;
  // It found it, and its own runs leave no cheaper design untried: each was
  // run or has no more capacity than one of its runs that failed
  // (Headline::cheaper over its evaluations), so the seed's campaign could
  // tell its user the answer is the cheapest, not only the cheapest found.
  bool cheapest_confirmed = false;
  // When it found it: how many cheaper designs its runs leave untried
  // (CheaperDesigns::untried_count; 0 when confirmed); -1 otherwise, or
  // when the space is too large to count.
  int64_t cheaper_left_untried = -1;
  // ... and how many more runs would settle them if they fail
  // (CheaperDesigns::to_settle_count; -1 likewise).
  int64_t runs_to_settle = -1;
  std::vector<spec::DesignPoint> proposals;  // in order
  std::vector<ReplayIteration> iterations;   // in order
};

// Replays `strategy` with exploration.seed = seed, the given budget (<= 0:
// the recording's scenario budget), confirm runs and initial points (< 0:
// the recording's exploration.confirm_runs, exploration.initial_points)
// over the recording.
Result<ReplayRun> Replay(const Recording& recording,
                         const std::string& strategy, uint64_t seed, int budget,
                         int confirm_runs = -1, int initial_points = -1);

}  // namespace adse::campaign

#endif  // ADSE_HARNESS_CAMPAIGN_REPLAY_H_
