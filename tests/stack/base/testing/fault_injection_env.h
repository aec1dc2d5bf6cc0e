// An Env that fails on purpose (after LevelDB's fault_injection_test): a
// full disk, EIO, a failed rename, or a process that dies at a chosen call.
// Faults match an operation and a substring of its path (for a rename or a
// copy, the destination), let `after` matching calls through, then fail
// `times` of them.
#ifndef ADSE_TESTS_STACK_BASE_TESTING_FAULT_INJECTION_ENV_H_
#define ADSE_TESTS_STACK_BASE_TESTING_FAULT_INJECTION_ENV_H_

#include <cerrno>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "stack/base/env.h"

namespace adse::testing {

enum class FaultOp {
  kCreateDir,
  kWriteFile,
  kAppendFile,
  kSyncFile,
  kSyncDir,
  kRenameFile,
  kCopyFile,
};

struct Fault {
  FaultOp op = FaultOp::kWriteFile;
  // The call's path must contain this ("" matches every path).
  std::string path_contains;
  // errno of the failure. A failed write first writes half of its data, as
  // a disk that fills up part-way does.
  int error = ENOSPC;
  // Matching calls that succeed before the first failure.
  int after = 0;
  // Failures, then calls succeed again; < 0: every later matching call.
  int times = -1;
  // Instead of failing, the process ends at once with kCrashExitCode, as if
  // killed at this point (run it in a forked child).
  bool crash = false;
};

// Exit status of a process that a crash fault ended.
inline constexpr int kCrashExitCode = 86;

class FaultInjectionEnv;

// Runs `body` in a forked child process, with an Env that ends the child
// at the first `op` on a path containing `path_contains` after `after`
// such calls went through (e.g. a rename after the write: a crash between
// the two). Returns the child's exit status: kCrashExitCode when it died
// there, 0 when it got through, -1 when it could not be started or was
// killed by a signal.
int RunUntilCrash(FaultOp op, const std::string& path_contains,
                  const std::function<void(Env* env)>& body, int after = 0);

class FaultInjectionEnv : public EnvWrapper {
 public:
  explicit FaultInjectionEnv(Env* target = Env::Default())
      : EnvWrapper(target), target_(target) {}

  void Inject(const Fault& fault);
  // Failures returned so far.
  int failures() const;

  Status CreateDir(const std::string& path) override;
  Status WriteFile(const std::string& path, std::string_view data) override;
  Status AppendFile(const std::string& path, std::string_view data) override;
  Status SyncFile(const std::string& path) override;
  Status SyncDir(const std::string& path) override;
  Status RenameFile(const std::string& from, const std::string& to) override;
  Status CopyFile(const std::string& from, const std::string& to) override;

 private:
  struct Armed {
    Fault fault;
    int seen = 0;
    int failed = 0;
  };
  // The error to return for this call, Ok to let it through. Ends the
  // process for a crash fault.
  Status Check(FaultOp op, const std::string& path, const char* what);

  Env* target_;
  mutable std::mutex mu_;
  std::vector<Armed> faults_;
  int failures_ = 0;
};

}  // namespace adse::testing

#endif  // ADSE_TESTS_STACK_BASE_TESTING_FAULT_INJECTION_ENV_H_
