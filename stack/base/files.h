// Filesystem helpers: atomic writes, cache folders, bounded reads.
#ifndef ADSE_STACK_BASE_FILES_H_
#define ADSE_STACK_BASE_FILES_H_

#include <cstddef>
#include <string>

#include "stack/base/env.h"
#include "stack/base/status.h"

namespace adse {

// Reads a whole file; refuses files larger than `max_bytes`.
Result<std::string> ReadFile(const std::string& path,
                             size_t max_bytes = 64u << 20);

// Writes `data` to a temporary name in the target's folder
// (TemporaryPathFor), flushes it and renames it over `path`, so readers see
// the old file or the whole new one, never a part. No temporary is left on
// failure, except after a crash between write and rename, and a temporary's
// name never looks like the file's.
Status WriteFileAtomic(const std::string& path, const std::string& data,
                       Env* env = Env::Default());

// The second half of an atomic write: `temporary`, fully written by its
// writer, is flushed, renamed over `path` and the folder flushed. On failure
// the temporary is removed.
Status CommitTemporary(const std::string& temporary, const std::string& path,
                       Env* env = Env::Default());

// Appends `line` and a newline to `path` (created if missing) in one
// write and flushes it to disk, so an append-only record survives a crash
// with at most its last line cut short.
Status AppendLineDurable(const std::string& path, const std::string& line,
                         Env* env = Env::Default());

// adse's cache root: $ADSE_CACHE_DIR, else $XDG_CACHE_HOME/adse, else
// ~/.cache/adse, else <tmp>/adse-cache.
std::string DefaultCacheDir();

// Creates `path` and its parents. Ok when it exists already.
Status MakeDirs(const std::string& path, Env* env = Env::Default());

// The temporary name a file is written under before it is renamed to
// `path`: "<path>.tmp.<host>.<pid>", unique among the writers that share a
// folder on a network filesystem (pids repeat across hosts).
std::string TemporaryPathFor(const std::string& path);

// Removes what writers on this host that are gone left in `folder`: every
// "<name>.tmp.<this host>.<pid>" whose process no longer exists (killed
// before it could rename or remove it). Others' and live writers' are
// kept. Returns how many were removed; a folder that cannot be read
// removes none.
int RemoveAbandonedTemporaries(const std::string& folder);

}  // namespace adse

#endif  // ADSE_STACK_BASE_FILES_H_
