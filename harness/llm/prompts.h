// Prompt templates: one plain-text file per agent role, with named
// placeholders ({{name}}) filled from the scenario and the run reports.
// Loaded at run time from prompts/ (or the folder `llm.prompts` names), so
// the wording can change without rebuilding adse.
#ifndef ADSE_HARNESS_LLM_PROMPTS_H_
#define ADSE_HARNESS_LLM_PROMPTS_H_

#include <map>
#include <string>
#include <vector>

#include "stack/base/status.h"

namespace adse::llm {

// The templates adse uses and the placeholders each may contain.
struct TemplateInfo {
  std::string name;  // file name without ".txt"
  std::vector<std::string> placeholders;
};
const std::vector<TemplateInfo>& TemplateCatalog();

// The bundled prompts folder (the source tree's prompts/, or
// <prefix>/share/adse/prompts next to an installed binary).
std::string DefaultPromptsDir();

class PromptSet {
 public:
  // Loads every template of the catalogue from `folder` (empty: the
  // default). NotFound naming the file when one is missing;
  // InvalidArgument naming file and line for an unknown placeholder or an
  // unclosed "{{". A file's leading lines starting with '#' are comments;
  // "# version: N" among them is the template's version.
  static Result<PromptSet> Load(const std::string& folder);

  // The template filled with `values` (each placeholder once; values are
  // not expanded again). Internal when a placeholder it uses has no value
  // or no template has that name (a bug: callers pass them all).
  Result<std::string> Render(
      const std::string& name,
      const std::map<std::string, std::string>& values) const;

  // "dse_system v1, dse_step v1, ..." for records and reports, in catalogue
  // order ("command unversioned" for a file without "# version:").
  std::string Versions() const;
  const std::string& folder() const { return folder_; }

 private:
  struct Template {
    std::string path;
    std::string text;
    std::string version;  // empty: the file has no "# version:"
  };
  std::string folder_;
  std::map<std::string, Template> templates_;
};

}  // namespace adse::llm

#endif  // ADSE_HARNESS_LLM_PROMPTS_H_
