// Shared pieces of the subcommands: loading a scenario with its errors
// printed, citing a scenario field for a world error, the world setup.
#ifndef ADSE_HARNESS_CLI_CLI_SUPPORT_H_
#define ADSE_HARNESS_CLI_CLI_SUPPORT_H_

#include <optional>
#include <string>

#include "harness/spec/spec.h"
#include "stack/base/status.h"

namespace adse::cli {

// Loads and validates `path`, its cost at every design point of a space
// of up to spec::kMaxCostCheckPoints included; on failure prints the
// errors to stderr.
std::optional<spec::Spec> LoadScenarioOrReport(const std::string& path);

// LoadScenarioOrReport, then the spec of the case `--case` names
// (spec::ForCase): the scenario itself when it has no task.cases and
// `task_case` is empty. Otherwise prints what is wrong (a case missing,
// unknown, or named for a scenario without cases) and returns nullopt.
std::optional<spec::Spec> LoadCaseOrReport(const std::string& path,
                                           const std::string& task_case);

// The same for a campaign's worker, without the cost's check over the
// space: its coordinator made it, and the run checks its own point
// (sim::SimulatePoint), so each run does not price the whole space again.
std::optional<spec::Spec> LoadWorkerCaseOrReport(const std::string& path,
                                                 const std::string& task_case);

// Prints `status` as "file:line:col: error: message", locating the field
// path that starts the message ("task.goal: ...") in the scenario.
void ReportError(const spec::Spec& spec, const Status& status);

}  // namespace adse::cli

#endif  // ADSE_HARNESS_CLI_CLI_SUPPORT_H_
