// An append-only JSON-lines record that a resumed session continues
// without duplicating: the session's n-th line is written only when the
// file does not hold n lines already. Sessions that replay the same
// history produce the same lines, so the file ends up as one session's.
#ifndef ADSE_HARNESS_LLM_JSONL_LOG_H_
#define ADSE_HARNESS_LLM_JSONL_LOG_H_

#include <cstdint>
#include <functional>
#include <string>

#include "stack/base/env.h"
#include "stack/base/status.h"

namespace adse::llm {

class JsonlLog {
 public:
  // An empty path records nothing. Creates the folder; drops a last line
  // cut short by a crash (so the next append starts on a fresh line).
  // Appends go through `env`.
  static Result<JsonlLog> Open(const std::string& path,
                               Env* env = Env::Default());
  JsonlLog() = default;

  // Appends `line` unless the file already holds this session's line.
  Status Append(const std::string& line);
  // Appends `line` whatever the file holds: for what is new by nature
  // (an answer a model just gave), which must never be lost.
  Status AppendNew(const std::string& line);
  int64_t existing() const { return existing_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  int64_t existing_ = 0;  // complete lines found at Open
  int64_t written_ = 0;   // lines this session has produced
  Env* env_ = Env::Default();
};

// Calls `parse` on each non-empty line of `path` (a missing file has
// none). `parse` throws (e.g. nlohmann::json's exceptions) on a bad line: a
// last line cut short by a crash (no newline after it) is skipped, any
// other is Corruption naming the file, the line and `what` it should be.
Status ReadJsonLines(const std::string& path, const std::string& what,
                     const std::function<void(const std::string& line)>& parse);

}  // namespace adse::llm

#endif  // ADSE_HARNESS_LLM_JSONL_LOG_H_
