#include "tests/stack/base/testing/fault_injection_env.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>

namespace adse::testing {

void FaultInjectionEnv::Inject(const Fault& fault) {
  std::lock_guard<std::mutex> lock(mu_);
  faults_.push_back({fault});
}

int FaultInjectionEnv::failures() const {
  std::lock_guard<std::mutex> lock(mu_);
  return failures_;
}

Status FaultInjectionEnv::Check(FaultOp op, const std::string& path,
                                const char* what) {
  std::lock_guard<std::mutex> lock(mu_);
  for (Armed& armed : faults_) {
    const Fault& f = armed.fault;
    if (f.op != op || path.find(f.path_contains) == std::string::npos) {
      continue;
    }
    if (armed.seen++ < f.after) continue;
    if (f.times >= 0 && armed.failed >= f.times) continue;
    if (f.crash) std::_Exit(kCrashExitCode);
    ++armed.failed;
    ++failures_;
    return Status::IoError(path + ": " + what + ": " + std::strerror(f.error));
  }
  return Status::Ok();
}

Status FaultInjectionEnv::CreateDir(const std::string& path) {
  ADSE_RETURN_IF_ERROR(
      Check(FaultOp::kCreateDir, path, "cannot create folder"));
  return target_->CreateDir(path);
}

Status FaultInjectionEnv::WriteFile(const std::string& path,
                                    std::string_view data) {
  if (Status s = Check(FaultOp::kWriteFile, path, "write"); !s.ok()) {
    (void)target_->WriteFile(path, data.substr(0, data.size() / 2));
    return s;
  }
  return target_->WriteFile(path, data);
}

Status FaultInjectionEnv::AppendFile(const std::string& path,
                                     std::string_view data) {
  if (Status s = Check(FaultOp::kAppendFile, path, "write"); !s.ok()) {
    (void)target_->AppendFile(path, data.substr(0, data.size() / 2));
    return s;
  }
  return target_->AppendFile(path, data);
}

Status FaultInjectionEnv::SyncFile(const std::string& path) {
  ADSE_RETURN_IF_ERROR(Check(FaultOp::kSyncFile, path, "fsync"));
  return target_->SyncFile(path);
}

Status FaultInjectionEnv::SyncDir(const std::string& path) {
  ADSE_RETURN_IF_ERROR(Check(FaultOp::kSyncDir, path, "fsync"));
  return target_->SyncDir(path);
}

Status FaultInjectionEnv::RenameFile(const std::string& from,
                                     const std::string& to) {
  ADSE_RETURN_IF_ERROR(
      Check(FaultOp::kRenameFile, to, ("rename from " + from).c_str()));
  return target_->RenameFile(from, to);
}

Status FaultInjectionEnv::CopyFile(const std::string& from,
                                   const std::string& to) {
  ADSE_RETURN_IF_ERROR(
      Check(FaultOp::kCopyFile, to, ("copy from " + from).c_str()));
  return target_->CopyFile(from, to);
}

int RunUntilCrash(FaultOp op, const std::string& path_contains,
                  const std::function<void(Env* env)>& body, int after) {
  const pid_t child = ::fork();
  if (child < 0) return -1;
  if (child == 0) {
    FaultInjectionEnv env;
    Fault crash;
    crash.op = op;
    crash.path_contains = path_contains;
    crash.after = after;
    crash.crash = true;
    env.Inject(crash);
    body(&env);
    std::_Exit(0);
  }
  int status = 0;
  if (::waitpid(child, &status, 0) != child || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

}  // namespace adse::testing
