// Reading and validating scenario files (format v1, see scenarios/README.md).
//
// Every error is one line
//   <file>:<line>:<col>: error: <field.path>: expected <what>, found <what>
// optionally followed by " (did you mean 'x'?)". All errors of a file (up to
// a cap) come back at once, sorted by position, in one InvalidArgument
// status whose message is the lines joined by '\n'. Parsing never writes
// anything and never throws.
#ifndef ADSE_HARNESS_SPEC_SPEC_PARSER_H_
#define ADSE_HARNESS_SPEC_SPEC_PARSER_H_

#include <cstddef>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "harness/spec/spec.h"
#include "stack/base/status.h"
#include "stack/config/stack_config.h"

namespace adse::spec {

// Limits that keep hostile files cheap; checked before any node is built.
inline constexpr size_t kMaxSpecBytes = 1u << 20;
inline constexpr int kMaxYamlDepth = 64;
inline constexpr int kMaxYamlAliases = 100;
inline constexpr int kMaxYamlNodes = 100000;
inline constexpr int kMaxSpecErrors = 20;
// A `range:` may not expand to more values than this.
inline constexpr size_t kMaxParameterValues = 100000;

// Reads `path` (at most kMaxSpecBytes) and parses it; relative paths in the
// file resolve from the file's folder.
Result<Spec> LoadSpec(const std::string& path);

struct ParseOptions {
  // Require the files the scenario names (net, polygons, calibration,
  // prompts, replay_from) to exist. Off when re-reading the scenario
  // stored in a run file, which is only read for its expressions.
  bool check_files = true;
};

// Parses spec text. `file_name` is used in messages and for the default
// name (its stem); `base_dir` is where relative paths resolve from (empty:
// the current directory).
Result<Spec> ParseSpec(std::string_view text, const std::string& file_name,
                       const std::string& base_dir,
                       const ParseOptions& options = {});

// The whole spec, defaults filled in and paths absolute, in the v1 format.
// ParseSpec reads it back to an equal spec.
std::string NormalizedYaml(const Spec& spec);

// Parses a command-line point "cores=4,freq_ghz=1.2,lidar_hz=14" against
// the space. Values are snapped to the exact allowed values. Errors name
// unknown parameters (with a suggestion), values not allowed (with the
// allowed ones) and missing parameters.
Result<DesignPoint> ParsePoint(const DesignSpace& space, std::string_view text);

// The inverse of ParsePoint: "cores=4,freq_ghz=1.2,lidar_hz=14", parameters
// in space order (names the space lacks follow in name order), values in
// their shortest exact form.
std::string FormatPoint(const DesignSpace& space, const DesignPoint& point);

// Names the `cost` expression may use: design parameters, `cores`,
// `freq_ghz`.
std::vector<std::string> CostVariableNames(const DesignSpace& space);
// Names constraints may use: known metrics and design parameters.
std::vector<std::string> ConstraintVariableNames(const DesignSpace& space);

// The hardware cost of a point: the spec's cost expression with the point's
// values, and `cores`/`freq_ghz` from the point when bound, else from the
// platform defaults.
Result<double> EvaluateCost(const Spec& spec, const DesignPoint& point);

// Whether `metrics` (name -> value; booleans as 0/1) and the point satisfy
// one constraint expression of the spec (true when non-zero).
Result<bool> EvaluateConstraint(const Spec& spec, const std::string& constraint,
                                const std::map<std::string, double>& metrics,
                                const DesignPoint& point);

// A design point applied to the spec: the platform and stack one run uses.
struct PointConfig {
  PlatformOptions platform;
  StackConfig stack;
};
Result<PointConfig> ApplyPoint(const Spec& spec, const DesignPoint& point);

}  // namespace adse::spec

#endif  // ADSE_HARNESS_SPEC_SPEC_PARSER_H_
