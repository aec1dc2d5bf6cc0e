// Callback cost profiles as files: the `adse_profile: 1` YAML format that
// `platform.profile` names, its reader and writer, and the importer that
// builds one from a CARET report of a production stack (`adse profile
// import`). The executor's side of a profile is stack::CostProfile; this
// module adds where the numbers came from. yaml-cpp stays in the .cc files.
#ifndef ADSE_HARNESS_PROFILE_PROFILE_H_
#define ADSE_HARNESS_PROFILE_PROFILE_H_

#include <map>
#include <string>
#include <vector>

#include "stack/base/env.h"
#include "stack/base/status.h"
#include "stack/runtime/cost_profile.h"

namespace adse::profile {

// The version this code reads and writes (`adse_profile: 1`).
inline constexpr int kProfileFormatVersion = 1;
// The version of the importer's mapping files (`adse_profile_mapping: 1`).
inline constexpr int kMappingFormatVersion = 1;

// Where a profile's numbers were measured.
struct ProfileSource {
  std::string description;  // what ran, on what
  std::string license;      // of the measurements
  std::string cpu;
  // The source states no clock, so CostProfile::reference_ghz is a guess.
  bool reference_ghz_assumed = false;
  std::string note;  // how to read the numbers (e.g. latency is wall time)
};

// Which measured callbacks one adse callback stands for.
struct CallbackProvenance {
  std::vector<std::string> sources;  // source callback ids, e.g. CARET's
  double rate_hz = 0.0;  // observed rate of the first source; 0: unknown
  double avg_ms = 0.0;   // sum of the sources' mean latency, as measured
};

// The chains whose latency `adse profile check` compares: sensing (a raw
// scan to the preprocessed cloud), localization (the preprocessed cloud to
// the fused pose) and sensing_to_control (a scan to the command whose
// trajectory was checked against that scan's tracked objects: through
// perception, planning and control, the path of CARET's e2e chain). The
// one list of their names.
const std::vector<std::string>& ChainNames();

// A chain's response time as the source measured it (CARET's path
// analysis: the "best" case follows the newest input, ms).
struct ChainReference {
  std::string source;   // the source's path name, e.g. component_sensing_0
  double avg_ms = 0.0;  // mean
  double p95_ms = 0.0;  // 95th percentile
  double worst_max_ms = 0.0;  // CARET's "worst" case (oldest input), max
};

struct Profile {
  int format_version = kProfileFormatVersion;
  std::string name;
  ProfileSource source;
  stack::CostProfile costs;
  // Keyed like costs.callbacks ("<node>/<callback>").
  std::map<std::string, CallbackProvenance> provenance;
  // Keyed by ChainNames(); may be empty (the source measured no chains).
  std::map<std::string, ChainReference> chains;
};

// Reads a profile file. Bad input is InvalidArgument naming the file, the
// line, the field path (e.g. `callbacks.ndt_scan_matcher/points.cost_ms.p95`)
// and what was expected; a missing file is NotFound. The costs then pass
// stack::ValidateCostProfile.
Result<Profile> ReadProfile(const std::string& path);

// Writes `profile` atomically (the old file or the whole new one, never a
// part): keys sorted, numbers that read back to the same double, and a
// header comment saying where it came from. Refuses a profile that fails
// stack::ValidateCostProfile.
Status WriteProfile(const std::string& path, const Profile& profile,
                    Env* env = Env::Default());

// Builds a profile from a CARET report (`<caret_folder>/analyze_node/*/
// stats_node.yaml`) and a mapping file that says which CARET callbacks each
// adse callback stands for. The mapping must cover every callback of adse's
// stack graph (StackCallbackNames). Errors name the file, the field path
// and what was expected.
Result<Profile> ImportCaret(const std::string& caret_folder,
                            const std::string& mapping_path);

// Every callback name ("<node>/<callback>") of adse's stack graph, read from
// a graph built over placeholder inputs: the one list a profile must cover.
Result<std::vector<std::string>> StackCallbackNames();

// Mean cost of an invocation (ms at the reference clock), from the
// quantiles' piecewise-linear inverse CDF, as SampleCost draws it.
double MeanCostMs(const stack::CallbackCost& cost);

// Per callback p50 and p95 (ms at the reference clock), the observed rate,
// and the load it puts on the reference machine (mean cost x rate, cores
// busy), then the total load: what `adse profile show` prints.
std::string FormatProfileTable(const Profile& profile);

// Cores busy at the reference clock: sum over callbacks of mean cost x rate.
double TotalLoadCores(const Profile& profile);

}  // namespace adse::profile

#endif  // ADSE_HARNESS_PROFILE_PROFILE_H_
