#include "harness/pool/worker_pool.h"

namespace adse::pool {

Result<Isolation> ParseIsolation(const std::string& text) {
  if (text == "auto") return Isolation::kAuto;
  if (text == "cgroup") return Isolation::kCgroup;
  if (text == "affinity") return Isolation::kAffinity;
  return Status::InvalidArgument("isolation '" + text +
                                 "' is not one of: auto, cgroup, affinity");
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
