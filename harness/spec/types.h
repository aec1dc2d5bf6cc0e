// The vocabulary of the scenario format: one list per enum or enumerated
// field. The parser, the factories, --help and the docs (checked by
// tests/harness/spec/vocabulary_docs_test.cc) all read these lists. Enums
// owned by other modules keep their lists there: world::WeatherNames,
// world::TaskKindNames, world::MapGeneratorNames, pool::IsolationNames.
#ifndef ADSE_HARNESS_SPEC_TYPES_H_
#define ADSE_HARNESS_SPEC_TYPES_H_

#include <string>
#include <string_view>
#include <vector>

#include "harness/spec/spec.h"

namespace adse::spec {

const char* PlatformKindToString(PlatformKind kind);
bool StringToPlatformKind(std::string_view name, PlatformKind* kind);
std::vector<std::string> PlatformKindNames();

// design_space.<name>.role: none, cores, frequency, sensor_rate,
// downsample.
const char* KnobRoleToString(KnobRole role);
bool StringToKnobRole(std::string_view name, KnobRole* role);
std::vector<std::string> KnobRoleNames();
// The role a parameter bound to `bind` has unless it says otherwise.
KnobRole DefaultKnobRole(const std::string& bind);

// platform.clock_by: padding, quota, cpufreq.
const char* ClockByToString(ClockBy clock_by);
bool StringToClockBy(std::string_view name, ClockBy* clock_by);
std::vector<std::string> ClockByNames();

// platform.dispatch: run_to_completion, processor_sharing.
const char* DispatchToString(Dispatch dispatch);
bool StringToDispatch(std::string_view name, Dispatch* dispatch);
std::vector<std::string> DispatchNames();

const char* CostModelToString(CostModel model);
bool StringToCostModel(std::string_view name, CostModel* model);
std::vector<std::string> CostModelNames();

// exploration.strategy: exhaustive, random, ga, nsga2, agent, llm. The
// last is built by harness/llm, the others by explore::CreateStrategy.
inline constexpr char kLlmStrategy[] = "llm";
const std::vector<std::string>& StrategyNames();
bool IsStrategyName(std::string_view name);

// llm.backend: ollama, openai, replay.
const std::vector<std::string>& LlmBackendNames();
// Keys of llm.models: dse, vision, text, command, interpretation.
const std::vector<std::string>& LlmRoleNames();
// harness.executor: local, slurm.
const std::vector<std::string>& ExecutorNames();

}  // namespace adse::spec

#endif  // ADSE_HARNESS_SPEC_TYPES_H_
