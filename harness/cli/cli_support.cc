#include "harness/cli/cli_support.h"

#include <fmt/core.h>

#include <cctype>
#include <cstdio>

#include "harness/spec/spec_parser.h"

namespace adse::cli {

std::optional<spec::Spec> LoadScenarioOrReport(const std::string& path) {
  Result<spec::Spec> loaded = spec::LoadSpec(path);
  if (!loaded.ok()) {
    // Parser messages carry their own locations, one error per line.
    std::fprintf(stderr, "%s\n", loaded.status().message().c_str());
    return std::nullopt;
  }
  return std::move(loaded).value();
}

void ReportError(const spec::Spec& spec, const Status& status) {
  const std::string& message = status.message();
  const size_t colon = message.find(": ");
  std::string field;
  if (colon != std::string::npos) {
    field = message.substr(0, colon);
    for (char c : field) {
      if (!(std::islower(static_cast<unsigned char>(c)) ||
            std::isdigit(static_cast<unsigned char>(c)) || c == '_' ||
            c == '.' || c == '[' || c == ']')) {
        field.clear();
        break;
      }
    }
  }
  const std::string where =
      field.empty() ? spec.source_path + ": " : spec.Where(field);
  std::fprintf(stderr, "%serror: %s\n", where.c_str(), message.c_str());
}

}  // namespace adse::cli
