#include "analysis/diagnosis/remedy.h"

#include <cstddef>
#include <ostream>

namespace adse::analysis {
namespace {

struct KindToken {
  RemedyKind kind;
  const char* token;
};

// The single list of the vocabulary, in enum order (checked below), so a
// kind's token is one array lookup and a token's kind one scan.
constexpr KindToken kRemedyKindTokens[] = {
    {RemedyKind::kMoreCores, "more_cores"},
    {RemedyKind::kHigherFrequency, "higher_frequency"},
    {RemedyKind::kLowerSensorRate, "lower_sensor_rate"},
    {RemedyKind::kRaisePublisherRate, "raise_publisher_rate"},
    {RemedyKind::kRaiseSensorRate, "raise_sensor_rate"},
    {RemedyKind::kShortenTimerPeriod, "shorten_timer_period"},
    {RemedyKind::kRelieveNode, "relieve_node"},
};
constexpr size_t kNumRemedyKinds =
    sizeof(kRemedyKindTokens) / sizeof(kRemedyKindTokens[0]);

constexpr bool TokensInEnumOrder() {
  for (size_t i = 0; i < kNumRemedyKinds; ++i) {
    if (static_cast<size_t>(kRemedyKindTokens[i].kind) != i) return false;
  }
  return true;
}
static_assert(TokensInEnumOrder(),
              "kRemedyKindTokens must list the kinds in enum order");
static_assert(static_cast<size_t>(RemedyKind::kRelieveNode) + 1 ==
                  kNumRemedyKinds,
              "every RemedyKind needs a token in kRemedyKindTokens");

}  // namespace

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
  const size_t i = static_cast<size_t>(kind);
  return i < kNumRemedyKinds ? kRemedyKindTokens[i].token : "unknown";
}

Result<RemedyKind> StringToRemedyKind(const std::string& token) {
  for (const KindToken& entry : kRemedyKindTokens) {
    if (token == entry.token) return entry.kind;
  }
  std::string valid;
  for (const KindToken& entry : kRemedyKindTokens) {
    if (!valid.empty()) valid += ", ";
    valid += entry.token;
  }
  return Status::InvalidArgument("unknown remedy kind '" + token +
                                 "'; valid kinds: " + valid);
}

std::vector<std::string> RemedyKindTokens() {
  std::vector<std::string> tokens;
  for (const KindToken& entry : kRemedyKindTokens) {
    tokens.emplace_back(entry.token);
  }
  return tokens;
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
