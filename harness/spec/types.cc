#include "harness/spec/types.h"

#include <algorithm>

#include "harness/spec/internal/spec_reader.h"
#include "stack/base/vocabulary.h"
#include "stack/config/stack_config.h"

namespace adse::spec {
namespace {

const std::vector<Term<PlatformKind>>& PlatformKindTerms() {
  static const std::vector<Term<PlatformKind>> kTerms = {
      {PlatformKind::kVirtual, "virtual"}, {PlatformKind::kCgroup, "cgroup"}};
  return kTerms;
}

const std::vector<Term<ClockBy>>& ClockByTerms() {
  static const std::vector<Term<ClockBy>> kTerms = {
      {ClockBy::kPadding, "padding"},
      {ClockBy::kQuota, "quota"},
      {ClockBy::kCpufreq, "cpufreq"}};
  return kTerms;
}

const std::vector<Term<Dispatch>>& DispatchTerms() {
  static const std::vector<Term<Dispatch>> kTerms = {
      {Dispatch::kRunToCompletion, "run_to_completion"},
      {Dispatch::kProcessorSharing, "processor_sharing"}};
  return kTerms;
}

const std::vector<Term<CostModel>>& CostModelTerms() {
  static const std::vector<Term<CostModel>> kTerms = {
      {CostModel::kMeasured, "measured"}, {CostModel::kCounted, "counted"}};
  return kTerms;
}

const std::vector<Term<KnobRole>>& KnobRoleTerms() {
  static const std::vector<Term<KnobRole>> kTerms = {
      {KnobRole::kNone, "none"},
      {KnobRole::kCores, "cores"},
      {KnobRole::kFrequency, "frequency"},
      {KnobRole::kSensorRate, "sensor_rate"},
      {KnobRole::kDownsample, "downsample"}};
  return kTerms;
}

}  // namespace

const char* KnobRoleToString(KnobRole role) {
  return NameOf(KnobRoleTerms(), role);
}
bool StringToKnobRole(std::string_view name, KnobRole* role) {
  return ValueOf(KnobRoleTerms(), name, role);
}
std::vector<std::string> KnobRoleNames() { return NamesOf(KnobRoleTerms()); }

KnobRole DefaultKnobRole(const std::string& bind) {
  if (bind == internal::kPlatformCores) return KnobRole::kCores;
  if (bind == internal::kPlatformFreq) return KnobRole::kFrequency;
  const std::string prefix = "stack.";
  if (bind.compare(0, prefix.size(), prefix) == 0) {
    const KnobInfo* knob = FindStackKnob(bind.substr(prefix.size()));
    switch (knob != nullptr ? knob->load : KnobInfo::Load::kOther) {
      case KnobInfo::Load::kSensorRate:
        return KnobRole::kSensorRate;
      case KnobInfo::Load::kDownsample:
        return KnobRole::kDownsample;
      case KnobInfo::Load::kOther:
        break;
    }
  }
  return KnobRole::kNone;
}

const char* PlatformKindToString(PlatformKind kind) {
  return NameOf(PlatformKindTerms(), kind);
}
bool StringToPlatformKind(std::string_view name, PlatformKind* kind) {
  return ValueOf(PlatformKindTerms(), name, kind);
}
std::vector<std::string> PlatformKindNames() {
  return NamesOf(PlatformKindTerms());
}

const char* ClockByToString(ClockBy clock_by) {
  return NameOf(ClockByTerms(), clock_by);
}
bool StringToClockBy(std::string_view name, ClockBy* clock_by) {
  return ValueOf(ClockByTerms(), name, clock_by);
}
std::vector<std::string> ClockByNames() { return NamesOf(ClockByTerms()); }

const char* DispatchToString(Dispatch dispatch) {
  return NameOf(DispatchTerms(), dispatch);
}
bool StringToDispatch(std::string_view name, Dispatch* dispatch) {
  return ValueOf(DispatchTerms(), name, dispatch);
}
std::vector<std::string> DispatchNames() { return NamesOf(DispatchTerms()); }

const char* CostModelToString(CostModel model) {
  return NameOf(CostModelTerms(), model);
}
bool StringToCostModel(std::string_view name, CostModel* model) {
  return ValueOf(CostModelTerms(), name, model);
}
std::vector<std::string> CostModelNames() { return NamesOf(CostModelTerms()); }

const std::vector<std::string>& StrategyNames() {
  static const std::vector<std::string> kNames = {
      "exhaustive", "random", "ga", "nsga2", "agent", kLlmStrategy};
  return kNames;
}

bool IsStrategyName(std::string_view name) {
  const std::vector<std::string>& names = StrategyNames();
  return std::find(names.begin(), names.end(), name) != names.end();
}

const std::vector<std::string>& LlmBackendNames() {
  static const std::vector<std::string> kNames = {"ollama", "openai", "replay"};
  return kNames;
}

const std::vector<std::string>& LlmRoleNames() {
  static const std::vector<std::string> kNames = {"dse", "vision", "text",
                                                  "command", "interpretation"};
  return kNames;
}

const std::vector<std::string>& ExecutorNames() {
  static const std::vector<std::string> kNames = {"local", "slurm"};
  return kNames;
}

}  // namespace adse::spec
