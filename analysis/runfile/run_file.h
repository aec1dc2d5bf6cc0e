// Run files: one HDF5 file per simulated run, laid out as described in
// results-schema/run.schema.json (human guide: results-schema/README.md).
// No HDF5 types leak from here; all functions are thread-safe (HDF5 use is
// serialized inside) and never throw.
#ifndef ADSE_ANALYSIS_RUNFILE_RUN_FILE_H_
#define ADSE_ANALYSIS_RUNFILE_RUN_FILE_H_

#include <cstddef>
#include <string>
#include <vector>

#include "analysis/runfile/run_data.h"
#include "stack/base/env.h"
#include "stack/base/status.h"

namespace adse::runfile {

// Version of the layout this code writes and reads; the file's root
// attribute `schema_version` and the schema JSON carry the same number.
inline constexpr int kSchemaVersion = 1;

// Widths of fixed-length strings inside compound datasets (bytes, UTF-8,
// NUL-padded). Longer values are cut at a character boundary on write.
inline constexpr size_t kIdBytes = 64;  // vehicle ids, collision other_id
inline constexpr size_t kNameBytes =
    128;  // node, callback, topic and signal names
inline constexpr size_t kKindBytes = 32;  // callback kind

// Writes `run` to `<path>.tmp.<host>.<pid>`, flushes it to disk and
// renames it over `path` (creating parent folders), so readers see either
// the old file or the whole new one and a crash never leaves a file that
// looks complete.
// The root attribute `status` is written last. InvalidArgument if
// run.status is no run status (run_data.h), a topic event or callback has
// an unknown kind or a non-empty scenario_hash is not the sha256 of
// scenario_text; IoError if the file cannot be written (no temporary is left).
Status WriteRunFile(const std::string& path, const RunData& run,
                    Env* env = Env::Default());

// Reads a whole run file back; WriteRunFile then ReadRunFile is exact except
// for compound strings longer than their width. NotFound if `path` does not
// exist; Corruption (naming the file and the HDF5 object) if it is not HDF5,
// truncated, damaged (HDF5 checksums on metadata and table chunks; the
// scenario text against scenario_hash), has a different schema_version or
// lacks a required part.
Result<RunData> ReadRunFile(const std::string& path);

// Path of results-schema/run.schema.json as built into this binary.
std::string SchemaPath();

// Validates a file's structure against the schema JSON: every required root
// attribute, group, dataset and compound field is present with the right
// type class (float/int/string/enum), enum codes and status values match,
// schema_version equals the schema's, and the scenario text matches its
// hash. Table contents are not read (ReadRunFile does, with checksums).
// Appends one line per problem to `problems` (may be null), each starting
// with the HDF5 path. Returns NotFound if the file is missing, Corruption if
// there is any problem, and the schema's own error if it cannot be loaded.
Status CheckRunFile(const std::string& path,
                    std::vector<std::string>* problems);
Status CheckRunFile(const std::string& path, const std::string& schema_path,
                    std::vector<std::string>* problems);

}  // namespace adse::runfile

#endif  // ADSE_ANALYSIS_RUNFILE_RUN_FILE_H_
