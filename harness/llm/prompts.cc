#include "harness/llm/prompts.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "stack/base/files.h"
#include "stack/base/subprocess.h"

namespace adse::llm {
namespace fs = std::filesystem;

const std::vector<TemplateInfo>& TemplateCatalog() {
  static const std::vector<TemplateInfo> kCatalog = {
      {"dse_system",
       {"scenario_name", "task", "objectives", "constraints", "cost",
        "design_space", "budget"}},
      {"dse_step",
       {"iteration", "remaining", "last_point", "last_result", "last_report",
        "memory", "evaluated"}},
      {"command", {"point", "bindings", "world", "tracing_options"}},
      {"decipher_text", {"point", "trace_summary"}},
      {"decipher_vision", {"point", "legend"}},
      {"interpret", {"request", "maps", "metrics", "defaults", "example"}},
      {"correction", {"problem", "expected"}},
  };
  return kCatalog;
}

std::string DefaultPromptsDir() {
  // An installed binary looks beside itself first: <prefix>/bin/adse ->
  // <prefix>/share/adse/prompts.
  const fs::path installed =
      fs::path(SelfExecutable()).parent_path().parent_path() / "share" /
      "adse" / "prompts";
  std::error_code ec;
  if (fs::is_directory(installed, ec)) return installed.string();
  return ADSE_PROMPTS_DIR;
}

namespace {

// Placeholder names in `text` with the 1-based line of each, or the line
// of an unclosed "{{" (name empty).
std::vector<std::pair<std::string, int>> Placeholders(const std::string& text) {
  std::vector<std::pair<std::string, int>> out;
  size_t pos = 0;
  while ((pos = text.find("{{", pos)) != std::string::npos) {
    const int line = 1 + static_cast<int>(std::count(text.begin(),
                                                     text.begin() + pos, '\n'));
    const size_t end = text.find("}}", pos + 2);
    const size_t newline = text.find('\n', pos);
    if (end == std::string::npos || end > newline) {
      out.push_back({"", line});
      return out;
    }
    out.push_back({text.substr(pos + 2, end - pos - 2), line});
    pos = end + 2;
  }
  return out;
}

}  // namespace

Result<PromptSet> PromptSet::Load(const std::string& folder) {
  PromptSet set;
  set.folder_ = folder.empty() ? DefaultPromptsDir() : folder;
  for (const TemplateInfo& info : TemplateCatalog()) {
    const std::string path = set.folder_ + "/" + info.name + ".txt";
    std::error_code ec;
    if (!fs::exists(path, ec)) {
      return Status::NotFound(path +
                              ": prompt template missing (a prompts "
                              "folder needs one file per role; see "
                              "prompts/README.md)");
    }
    Result<std::string> text = ReadFile(path, 1u << 20);
    if (!text.ok()) return text.status();
    Template t;
    t.path = path;
    // Leading '#' lines are the file's header comments.
    std::istringstream in(*text);
    std::string line, body;
    int header_lines = 0;
    bool in_header = true;
    while (std::getline(in, line)) {
      if (in_header && !line.empty() && line[0] == '#') {
        ++header_lines;
        const std::string key = "# version:";
        if (line.compare(0, key.size(), key) == 0) {
          t.version = line.substr(key.size());
          const size_t first = t.version.find_first_not_of(" \t\r");
          const size_t last = t.version.find_last_not_of(" \t\r");
          t.version = first == std::string::npos
                          ? ""
                          : t.version.substr(first, last - first + 1);
        }
        continue;
      }
      in_header = false;
      body += line + "\n";
    }
    while (!body.empty() && body.back() == '\n') body.pop_back();
    for (const auto& [name, line_no] : Placeholders(body)) {
      const std::string where =
          path + ":" + std::to_string(line_no + header_lines);
      if (name.empty()) {
        return Status::InvalidArgument(where +
                                       ": '{{' without a closing '}}' "
                                       "on the same line");
      }
      if (std::find(info.placeholders.begin(), info.placeholders.end(), name) ==
          info.placeholders.end()) {
        std::string known;
        for (const std::string& p : info.placeholders) {
          known += (known.empty() ? "" : ", ") + ("{{" + p + "}}");
        }
        return Status::InvalidArgument(where + ": unknown placeholder {{" +
                                       name + "}}; " + info.name + " may use " +
                                       known);
      }
    }
    t.text = std::move(body);
    set.templates_[info.name] = std::move(t);
  }
  return set;
}

Result<std::string> PromptSet::Render(
    const std::string& name,
    const std::map<std::string, std::string>& values) const {
  auto it = templates_.find(name);
  if (it == templates_.end()) {
    return Status::Internal("no prompt template named " + name);
  }
  const std::string& text = it->second.text;
  std::string out;
  size_t pos = 0;
  while (true) {
    const size_t open = text.find("{{", pos);
    if (open == std::string::npos) break;
    const size_t close = text.find("}}", open + 2);
    const std::string key = text.substr(open + 2, close - open - 2);
    auto value = values.find(key);
    if (value == values.end()) {
      return Status::Internal(it->second.path + ": no value for {{" + key +
                              "}}");
    }
    out.append(text, pos, open - pos);
    out += value->second;
    pos = close + 2;
  }
  out.append(text, pos, std::string::npos);
  return out;
}

std::string PromptSet::Versions() const {
  std::string out;
  for (const TemplateInfo& info : TemplateCatalog()) {
    auto it = templates_.find(info.name);
    if (it == templates_.end()) continue;
    const std::string& version = it->second.version;
    out += (out.empty() ? "" : ", ") + info.name +
           (version.empty() ? " unversioned" : " v" + version);
  }
  return out;
}

}  // namespace adse::llm
