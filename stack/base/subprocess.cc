#include "stack/base/subprocess.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

extern char** environ;

namespace adse {

Result<ProcessResult> RunProcess(const std::vector<std::string>& argv,
                                 size_t max_output_bytes) {
  if (argv.empty()) return Status::Internal("RunProcess: empty argv");
  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0) {
    return Status::IoError(std::string("pipe: ") + std::strerror(errno));
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDERR_FILENO);
  std::vector<char*> args;
  for (const std::string& a : argv)
    args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc =
      ::posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(pipe_fds[1]);
  if (rc != 0) {
    ::close(pipe_fds[0]);
    return Status::IoError("cannot start " + argv[0] + ": " +
                           std::strerror(rc));
  }
  ProcessResult result;
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::read(pipe_fds[0], buffer, sizeof(buffer));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    result.output.append(buffer, static_cast<size_t>(n));
    // Keep the tail: the end of a tool's output says why it failed.
    if (result.output.size() > 2 * max_output_bytes) {
      result.output.erase(0, result.output.size() - max_output_bytes);
    }
  }
  ::close(pipe_fds[0]);
  int wstatus = 0;
  while (::waitpid(pid, &wstatus, 0) < 0) {
    if (errno != EINTR) {
      return Status::IoError("waitpid " + argv[0] + ": " +
                             std::strerror(errno));
    }
  }
  if (result.output.size() > max_output_bytes) {
    result.output.erase(0, result.output.size() - max_output_bytes);
  }
  if (WIFEXITED(wstatus)) result.exit_code = WEXITSTATUS(wstatus);
  if (WIFSIGNALED(wstatus)) result.signal = WTERMSIG(wstatus);
  return result;
}

Status RunChecked(const std::vector<std::string>& argv) {
  Result<ProcessResult> r = RunProcess(argv);
  if (!r.ok()) return r.status();
  if (r->exit_code == 0) return Status::Ok();
  std::string tail = r->output;
  if (tail.size() > 2000) tail = "..." + tail.substr(tail.size() - 2000);
  const std::string how =
      r->signal ? "was killed by signal " + std::to_string(r->signal)
                : "exited with status " + std::to_string(r->exit_code);
  return Status::IoError(argv[0] + " " + how + ":\n" + tail);
}

std::string SelfExecutable() {
  std::error_code ec;
  const std::filesystem::path self =
      std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("adse") : self.string();
}

}  // namespace adse
