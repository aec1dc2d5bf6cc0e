// What the diagnosis proposes against a bottleneck, as data: a kind from one
// fixed vocabulary and the thing it is about. Strategies act on the kind and
// the target; the readable text (Finding::remedy, reports, LLM prompts) is
// derived from them by RemediesText, so text and data never disagree.
//
// Deliberately light (the standard library and Status only): the explore
// module's BottleneckHint carries these without depending on the diagnosis.
#ifndef ADSE_ANALYSIS_DIAGNOSIS_REMEDY_H_
#define ADSE_ANALYSIS_DIAGNOSIS_REMEDY_H_

#include <iosfwd>
#include <string>
#include <vector>

#include "stack/base/status.h"

namespace adse::analysis {

// What a finding of the diagnosis says is wrong (Finding::kind, the
// explore module's BottleneckHint::kind, the LLM text agent's answers
// carry its token). A new kind needs its token in remedy.cc's
// FindingKindTerms.
enum class FindingKind {
  // A node cannot keep up with its input.
  kCpuBound,
  // A node's input arrives too slowly although the node keeps up.
  kFrequencyBound,
  // A subscription goes untaken for seconds while its own node's other
  // callbacks keep the node busy.
  kStarvedInput,
};

// The snake_case token of a kind ("cpu_bound"), as stored in JSON.
const char* FindingKindToString(FindingKind kind);
// The kind of a token; InvalidArgument naming the token and the valid ones.
Result<FindingKind> StringToFindingKind(const std::string& token);
// Every token, in enum order.
std::vector<std::string> FindingKindTokens();

// One per thing the diagnosis proposes. A new kind needs its token in
// remedy.cc's RemedyKindTerms (the single list of the vocabulary) and its
// text in RemedyText.
enum class RemedyKind {
  // cpu_bound: the node's callbacks wait for a core longer than they run.
  kMoreCores,
  // cpu_bound: the node's own execution load reaches 1, so only faster
  // cores help (its callbacks exclude each other).
  kHigherFrequency,
  // cpu_bound: the node falls behind a topic published from outside the
  // graph (a sensor), whose rate can be lowered.
  kLowerSensorRate,
  // frequency_bound: the slow input's publisher should publish faster.
  kRaisePublisherRate,
  // frequency_bound: the slow input's rate is set by a sensor.
  kRaiseSensorRate,
  // frequency_bound: the slow input's rate is set by a timer.
  kShortenTimerPeriod,
  // frequency_bound: the slow input's rate is set by a cpu_bound node.
  kRelieveNode,
  // starved_input: the subscription's own node starves it; a callback
  // group of its own lets it run beside the node's other callbacks.
  kOwnCallbackGroup,
};

struct Remedy {
  RemedyKind kind = RemedyKind::kMoreCores;
  // What the remedy is about, by kind (names as in the run's graph):
  //   more_cores, higher_frequency, relieve_node: a node;
  //   lower_sensor_rate, raise_sensor_rate: a sensor topic (published from
  //     outside the graph), e.g. "/sensing/lidar/points_raw";
  //   raise_publisher_rate: the slow topic;
  //   shorten_timer_period: the timer callback, "<node>/<callback>";
  //   own_callback_group: the subscription, "<node>/<callback>".
  std::string target;
  // raise_publisher_rate only: the node(s) publishing `target`, sorted and
  // ", "-joined ("external" for a sensor, "unknown" when none was seen), as
  // its text names them. Empty for every other kind. (The initialiser lets
  // {kind, target} leave it out without a -Wextra warning.)
  std::string publisher = {};
};

bool operator==(const Remedy& a, const Remedy& b);
bool operator!=(const Remedy& a, const Remedy& b);
// "<token> <target>" (and " via <publisher>"), for test failure messages.
std::ostream& operator<<(std::ostream& os, const Remedy& remedy);

// The snake_case token of a kind ("more_cores"), as stored in JSON.
const char* RemedyKindToString(RemedyKind kind);
// The kind of a token; InvalidArgument naming the token and the valid ones.
Result<RemedyKind> StringToRemedyKind(const std::string& token);
// Every token, in enum order.
std::vector<std::string> RemedyKindTokens();

// The readable text of one remedy: "more cores", "higher frequency", "lower
// sensor rate", "raise the rate of <topic>'s publisher (<publisher>)",
// "raise the rate of sensor <topic>", "shorten the period of <timer>",
// "relieve <node> (cpu_bound)", "give <subscription> a callback group of
// its own".
std::string RemedyText(const Remedy& remedy);
// The texts "; "-joined in order (most important first): Finding::remedy.
std::string RemediesText(const std::vector<Remedy>& remedies);

}  // namespace adse::analysis

#endif  // ADSE_ANALYSIS_DIAGNOSIS_REMEDY_H_
