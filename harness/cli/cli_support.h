// Shared pieces of the subcommands: loading a scenario with its errors
// printed, citing a scenario field for a world error, the world setup.
#ifndef ADSE_HARNESS_CLI_CLI_SUPPORT_H_
#define ADSE_HARNESS_CLI_CLI_SUPPORT_H_

#include <optional>
#include <string>
#include <vector>

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

// What a command writes into its output folder, so that an earlier output
// of it can be told from anything else.
struct OutputFolderLayout {
  std::vector<std::string> files;  // "summary.json", ...
  // A subfolder of files with one extension ("scans", ".pcd"), or empty.
  std::string subfolder;
  std::string subfolder_extension;
};

// Ok when `out` may take a new output folder: nothing is there, or an
// earlier output of the same layout is (which PutFolderInPlace replaces).
// Otherwise InvalidArgument saying what is there: a file, the current
// folder or one above it, or an entry no such output holds.
Status CheckOutputFolder(const std::string& out,
                         const OutputFolderLayout& layout);

// Ok unless the nearest existing path at or above `path` ("" the current
// folder) is a file (where a folder must go), "<what>: <it> is a file, not
// a folder", or a folder this process cannot write in, "<what>: cannot
// write in <it> (Permission denied)": InvalidArgument.
Status CheckFolderPath(const std::string& path, const std::string& what);

// Ok when `folder` may hold a campaign (adse run resumes what it holds):
// nothing is there, or a campaign's folder is (its campaign.h5), or any
// other folder holding nothing a campaign writes. Else the current folder
// or one above it, a file, and a folder holding a report.md, summary.json
// or pareto.png that is no campaign's (or a file named runs, images or
// logs) are InvalidArgument naming `what` (the flag or field that gave
// the path).
Status CheckCampaignFolder(const std::string& folder, const std::string& what);

// A campaign's runs/ folder stands for its campaign (for analyze and
// status): the campaign's folder when `target` is <campaign>/runs, else
// `target` itself.
std::string CampaignOfRunsFolder(const std::string& target);
// The same for the folder a campaign of `spec` goes to: `-o out`, or the
// scenario's output when `out` is empty (named by its line).
Status CheckCampaignFolderOf(const spec::Spec& spec, const std::string& out);
// CheckCampaignFolderOf, then (with `use_cache`) CheckFolderPath of the
// shared run cache the campaign uses: `--cache-dir cache_dir`, or the
// scenario's harness.cache_dir when `cache_dir` is empty (named by its
// line); the default cache is not checked.
Status CheckCampaignFolders(const spec::Spec& spec, const std::string& out,
                            bool use_cache, const std::string& cache_dir);

// What a command's output file is, so that an earlier one can be told
// from anything else.
enum class OutputFileKind {
  kRunFile,              // a readable run file (adse simulate)
  kCalibrationFile,      // JSON with "adse_calibration" (adse calibrate)
  kProfileFile,          // YAML with "adse_profile" (adse profile import)
  kInterpretedScenario,  // a scenario adse interpret wrote (its header)
};
inline constexpr OutputFileKind kRunFile = OutputFileKind::kRunFile;
inline constexpr OutputFileKind kCalibrationFile =
    OutputFileKind::kCalibrationFile;
inline constexpr OutputFileKind kProfileFile = OutputFileKind::kProfileFile;
inline constexpr OutputFileKind kInterpretedScenario =
    OutputFileKind::kInterpretedScenario;

// The first line of every scenario adse interpret writes.
inline constexpr char kInterpretHeader[] = "# Written by `adse interpret`";

// Ok when the command may write `out`: nothing is there, or an earlier
// output of its kind is (which the new one replaces). A scenario, a
// folder, any other file, a parent that is a file, or (for a run file) a
// place in a campaign's runs/ folder is InvalidArgument, so that it is
// said before anything runs.
Status CheckOutputFile(const std::string& out, OutputFileKind kind);

// The private folder an output is written into before PutFolderInPlace
// (TemporaryPathFor(out), emptied). What commands killed before their end
// left beside `out` goes first (RemoveAbandonedTemporaries).
std::string StartOutputFolder(const std::string& out);

// Renames the finished folder `tmp` to `out`, an earlier output there
// stepping aside first and going only once the new one is in place.
Status PutFolderInPlace(const std::string& tmp, const std::string& out);

}  // namespace adse::cli

#endif  // ADSE_HARNESS_CLI_CLI_SUPPORT_H_
