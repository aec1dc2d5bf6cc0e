#include "analysis/diagnosis/remedy.h"

#include <ostream>

#include "stack/base/vocabulary.h"

namespace adse::analysis {
namespace {

// The single list of the vocabulary.
const std::vector<Term<RemedyKind>>& RemedyKindTerms() {
  static const std::vector<Term<RemedyKind>> kTerms = {
      {RemedyKind::kMoreCores, "more_cores"},
      {RemedyKind::kHigherFrequency, "higher_frequency"},
      {RemedyKind::kLowerSensorRate, "lower_sensor_rate"},
      {RemedyKind::kRaisePublisherRate, "raise_publisher_rate"},
      {RemedyKind::kRaiseSensorRate, "raise_sensor_rate"},
      {RemedyKind::kShortenTimerPeriod, "shorten_timer_period"},
      {RemedyKind::kRelieveNode, "relieve_node"},
      {RemedyKind::kOwnCallbackGroup, "own_callback_group"},
  };
  return kTerms;
}

const std::vector<Term<FindingKind>>& FindingKindTerms() {
  static const std::vector<Term<FindingKind>> kTerms = {
      {FindingKind::kCpuBound, "cpu_bound"},
      {FindingKind::kFrequencyBound, "frequency_bound"},
      {FindingKind::kStarvedInput, "starved_input"},
  };
  return kTerms;
}

// The value of `token` in a vocabulary; InvalidArgument naming the token,
// what it should be (`what`) and every valid token.
template <typename E>
Result<E> Parsed(const std::vector<Term<E>>& terms, const std::string& token,
                 const char* what) {
  E value = terms.front().value;
  if (ValueOf(terms, token, &value)) return value;
  return Status::InvalidArgument(
      UnknownTermMessage(what, token, NamesOf(terms)));
}

}  // namespace

const char* FindingKindToString(FindingKind kind) {
  return NameOf(FindingKindTerms(), kind);
}

Result<FindingKind> StringToFindingKind(const std::string& token) {
  return Parsed(FindingKindTerms(), token, "bottleneck kind");
}

std::vector<std::string> FindingKindTokens() {
  return NamesOf(FindingKindTerms());
}

bool operator==(const Remedy& a, const Remedy& b) {
  return a.kind == b.kind && a.target == b.target && a.publisher == b.publisher;
}

bool operator!=(const Remedy& a, const Remedy& b) { return !(a == b); }

std::ostream& operator<<(std::ostream& os, const Remedy& remedy) {
  os << RemedyKindToString(remedy.kind) << " " << remedy.target;
  if (!remedy.publisher.empty()) os << " via " << remedy.publisher;
  return os;
}

const char* RemedyKindToString(RemedyKind kind) {
  return NameOf(RemedyKindTerms(), kind);
}

Result<RemedyKind> StringToRemedyKind(const std::string& token) {
  return Parsed(RemedyKindTerms(), token, "remedy kind");
}

std::vector<std::string> RemedyKindTokens() {
  return NamesOf(RemedyKindTerms());
}

std::string RemedyText(const Remedy& remedy) {
  // These phrases are what the diagnosis has always written (recorded
  // campaigns, LLM prompts): changing one changes what readers see.
  switch (remedy.kind) {
    case RemedyKind::kMoreCores:
      return "more cores";
    case RemedyKind::kHigherFrequency:
      return "higher frequency";
    case RemedyKind::kLowerSensorRate:
      return "lower sensor rate";
    case RemedyKind::kRaisePublisherRate:
      return "raise the rate of " + remedy.target + "'s publisher (" +
             remedy.publisher + ")";
    case RemedyKind::kRaiseSensorRate:
      return "raise the rate of sensor " + remedy.target;
    case RemedyKind::kShortenTimerPeriod:
      return "shorten the period of " + remedy.target;
    case RemedyKind::kRelieveNode:
      return "relieve " + remedy.target + " (cpu_bound)";
    case RemedyKind::kOwnCallbackGroup:
      return "give " + remedy.target + " a callback group of its own";
  }
  return RemedyKindToString(remedy.kind);  // a value outside the enum
}

std::string RemediesText(const std::vector<Remedy>& remedies) {
  std::string out;
  for (size_t i = 0; i < remedies.size(); ++i) {
    if (i > 0) out += "; ";
    out += RemedyText(remedies[i]);
  }
  return out;
}

}  // namespace adse::analysis
