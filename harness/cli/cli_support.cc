#include "harness/cli/cli_support.h"

#include <fmt/core.h>

#include <cctype>
#include <cstdio>

#include "harness/sim/run_key.h"
#include "harness/spec/spec_parser.h"

namespace adse::cli {

namespace {

std::optional<spec::Spec> ParseScenarioOrReport(const std::string& path) {
  Result<spec::Spec> loaded = spec::LoadSpec(path);
  if (!loaded.ok()) {
    // Parser messages carry their own locations, one error per line.
    std::fprintf(stderr, "%s\n", loaded.status().message().c_str());
    return std::nullopt;
  }
  return std::move(loaded).value();
}

std::optional<spec::Spec> CaseOrReport(std::optional<spec::Spec> loaded,
                                       const std::string& name) {
  if (!loaded) return std::nullopt;
  const spec::Spec& spec = *loaded;
  if (spec.cases.empty()) {
    if (name.empty()) return loaded;
    std::fprintf(stderr, "error: --case: %s has no task.cases\n",
                 spec.source_path.c_str());
    return std::nullopt;
  }
  if (name.empty()) {
    std::fprintf(stderr,
                 "error: --case: %s has %zu task.cases (%s); name the one "
                 "to run\n",
                 spec.source_path.c_str(), spec.cases.size(),
                 spec::CaseNames(spec).c_str());
    return std::nullopt;
  }
  const int index = spec::FindCase(spec, name);
  if (index < 0) {
    std::fprintf(stderr, "error: --case: %s has no case '%s' (its cases: %s)\n",
                 spec.source_path.c_str(), name.c_str(),
                 spec::CaseNames(spec).c_str());
    return std::nullopt;
  }
  return spec::ForCase(spec, index);
}

}  // namespace

std::optional<spec::Spec> LoadScenarioOrReport(const std::string& path) {
  std::optional<spec::Spec> loaded = ParseScenarioOrReport(path);
  if (!loaded) return std::nullopt;
  for (const Status& checked :
       {spec::CheckCostOverSpace(*loaded), sim::CheckKnobsAct(*loaded)}) {
    if (!checked.ok()) {
      ReportError(*loaded, checked);
      return std::nullopt;
    }
  }
  return loaded;
}

std::optional<spec::Spec> LoadCaseOrReport(const std::string& path,
                                           const std::string& name) {
  return CaseOrReport(LoadScenarioOrReport(path), name);
}

std::optional<spec::Spec> LoadWorkerCaseOrReport(const std::string& path,
                                                 const std::string& name) {
  return CaseOrReport(ParseScenarioOrReport(path), name);
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
