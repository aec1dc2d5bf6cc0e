#include "harness/pool/worker_pool.h"

#include <fmt/format.h>

#include "stack/base/vocabulary.h"

namespace adse::pool {

namespace {

const std::vector<Term<Isolation>>& IsolationTerms() {
  static const std::vector<Term<Isolation>> kTerms = {
      {Isolation::kAuto, "auto"},
      {Isolation::kCgroup, "cgroup"},
      {Isolation::kAffinity, "affinity"}};
  return kTerms;
}

}  // namespace

const char* IsolationToString(Isolation isolation) {
  return NameOf(IsolationTerms(), isolation);
}
bool StringToIsolation(std::string_view name, Isolation* isolation) {
  return ValueOf(IsolationTerms(), name, isolation);
}
std::vector<std::string> IsolationNames() { return NamesOf(IsolationTerms()); }

Result<Isolation> ParseIsolation(const std::string& text) {
  Isolation isolation = Isolation::kAuto;
  if (StringToIsolation(text, &isolation)) return isolation;
  return Status::InvalidArgument(
      fmt::format("isolation '{}' is not one of: {}", text,
                  fmt::join(IsolationNames(), ", ")));
}

const char* OutcomeName(Outcome outcome) {
  switch (outcome) {
    case Outcome::kOk:
      return "ok";
    case Outcome::kExitError:
      return "exit_error";
    case Outcome::kCrashed:
      return "crashed";
    case Outcome::kTimeout:
      return "timeout";
    case Outcome::kOutOfMemory:
      return "out_of_memory";
    case Outcome::kCancelled:
      return "cancelled";
  }
  return "unknown";
}

}  // namespace adse::pool
