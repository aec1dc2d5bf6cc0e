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

#include "harness/spec/design_point.h"
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

}  // namespace adse::spec

#endif  // ADSE_HARNESS_SPEC_SPEC_PARSER_H_
