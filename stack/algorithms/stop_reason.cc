#include "stack/algorithms/stop_reason.h"

#include "stack/base/vocabulary.h"

namespace adse {
namespace {

// The single list of the vocabulary.
const std::vector<Term<StopReason>>& StopReasonTerms() {
  static const std::vector<Term<StopReason>> kTerms = {
      {StopReason::kNone, "none"},
      {StopReason::kGoal, "goal"},
      {StopReason::kObstacle, "obstacle"},
      {StopReason::kLocalizationLost, "localization_lost"},
      {StopReason::kNoTrajectory, "no_trajectory"},
      {StopReason::kRedLight, "red_light"},
      {StopReason::kLaneChange, "lane_change"},
      {StopReason::kTurnaround, "turnaround"},
  };
  return kTerms;
}

}  // namespace

const char* StopReasonToString(StopReason reason) {
  return NameOf(StopReasonTerms(), reason);
}

bool StringToStopReason(std::string_view name, StopReason* reason) {
  return ValueOf(StopReasonTerms(), name, reason);
}

std::vector<std::string> StopReasonNames() {
  return NamesOf(StopReasonTerms());
}

bool StopReasonNamesTrack(StopReason reason) {
  return reason == StopReason::kObstacle || reason == StopReason::kLaneChange;
}

}  // namespace adse
