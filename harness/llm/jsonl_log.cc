#include "harness/llm/jsonl_log.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "stack/base/files.h"

namespace adse::llm {

Result<JsonlLog> JsonlLog::Open(const std::string& path, Env* env) {
  JsonlLog log;
  log.path_ = path;
  log.env_ = env;
  if (path.empty()) return log;
  const std::filesystem::path p(path);
  if (p.has_parent_path())
    ADSE_RETURN_IF_ERROR(MakeDirs(p.parent_path().string(), env));
  std::error_code ec;
  if (!std::filesystem::exists(p, ec)) return log;
  Result<std::string> text = ReadFile(path, size_t{1} << 30);
  if (!text.ok()) return text.status();
  const size_t last_newline = text->rfind('\n');
  const size_t complete =
      last_newline == std::string::npos ? 0 : last_newline + 1;
  if (complete < text->size()) {
    // A crash cut the last append short: that line was never complete.
    if (::truncate(path.c_str(), static_cast<off_t>(complete)) != 0) {
      return Status::IoError(path + ": cannot drop its incomplete last line");
    }
  }
  for (size_t i = 0; i < complete; ++i) {
    if ((*text)[i] == '\n') ++log.existing_;
  }
  return log;
}

Status JsonlLog::Append(const std::string& line) {
  if (path_.empty()) return Status::Ok();
  if (written_++ < existing_) return Status::Ok();
  return AppendLineDurable(path_, line, env_);
}

Status JsonlLog::AppendNew(const std::string& line) {
  if (path_.empty()) return Status::Ok();
  ++written_;
  return AppendLineDurable(path_, line, env_);
}

Status ReadJsonLines(
    const std::string& path, const std::string& what,
    const std::function<void(const std::string& line)>& parse) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Ok();
  const std::string text((std::istreambuf_iterator<char>(in)),
                         std::istreambuf_iterator<char>());
  std::vector<std::string> lines;
  for (size_t start = 0; start < text.size();) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    lines.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  // Only a last line without its newline was cut short by a crash (the
  // same rule as JsonlLog::Open): a complete bad line is corruption, and
  // JsonlLog would count it as a line the file holds.
  const bool cut_short = !text.empty() && text.back() != '\n';
  for (size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].empty()) continue;
    try {
      parse(lines[i]);
    } catch (const std::exception& e) {
      if (i + 1 == lines.size() && cut_short) break;
      return Status::Corruption(path + ":" + std::to_string(i + 1) + ": not " +
                                what + " (" + e.what() + ")");
    }
  }
  return Status::Ok();
}

}  // namespace adse::llm
