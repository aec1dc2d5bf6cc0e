// The words on a trajectory picture, apart from its drawing: the title
// line and the end marker's label. Internal to analysis/pictures.
#ifndef ADSE_ANALYSIS_PICTURES_INTERNAL_TRAJECTORY_TEXT_H_
#define ADSE_ANALYSIS_PICTURES_INTERNAL_TRAJECTORY_TEXT_H_

#include <string>

#include "analysis/runfile/run_data.h"

namespace adse::analysis::internal {

// "scenario (case) | knob=value, ... | outcome": the termination reason
// (FAILED: for a failed run), the nav time as the report prints it (a lower
// bound for a run stopped early), contacts with traffic, re-plans.
std::string TrajectoryTitle(const runfile::RunData& run);

// How a run that did not reach its goal ended, in words, with the time
// `t_s` of its last sample; empty for one that did (its goal marker says
// so).
std::string EndText(const runfile::RunData& run, double t_s);

}  // namespace adse::analysis::internal

#endif  // ADSE_ANALYSIS_PICTURES_INTERNAL_TRAJECTORY_TEXT_H_
