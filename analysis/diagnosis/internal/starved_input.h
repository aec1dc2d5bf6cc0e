// The starved_input rule of the diagnosis: a subscription its own node
// starves. Callbacks of one node exclude each other, so callbacks ahead of
// a subscription in its node's line that run for seconds keep it from its
// messages however many cores are free. Runs of run key v23 and before
// show it most: their executor counted a keep-last subscription's wait
// from its newest message, so a timer that outlasted its period ran back
// to back and the subscription never took a message again.
#ifndef ADSE_ANALYSIS_DIAGNOSIS_INTERNAL_STARVED_INPUT_H_
#define ADSE_ANALYSIS_DIAGNOSIS_INTERNAL_STARVED_INPUT_H_

#include <string>
#include <vector>

#include "analysis/diagnosis/diagnosis.h"
#include "analysis/runfile/run_data.h"

namespace adse::analysis::internal {

// Per subscription, the longest stretch of [start_s, end_s) without a take
// that is at least options.starved_input_min_s long, during which at least
// options.min_messages of its messages were dropped unread and its node ran
// its other callbacks at least options.starved_input_busy_share of the
// time. One finding per such subscription (severity: the stretch's share
// of the window). `node_of` names each callback's node; `topics` are the
// diagnosis' topic statistics (for the publisher).
std::vector<Finding> FindStarvedInputs(const runfile::RunData& run,
                                       double start_s, double end_s,
                                       const DiagnosisOptions& options,
                                       const std::vector<std::string>& node_of,
                                       const std::vector<TopicStats>& topics);

}  // namespace adse::analysis::internal

#endif  // ADSE_ANALYSIS_DIAGNOSIS_INTERNAL_STARVED_INPUT_H_
