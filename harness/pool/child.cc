#include "harness/pool/child.h"

#include <signal.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <initializer_list>

#ifndef CLOSE_RANGE_CLOEXEC
#define CLOSE_RANGE_CLOEXEC (1U << 2)
#endif

namespace adse::pool {

bool PrepareChild(pid_t parent_pid, int death_signal, int stdin_fd,
                  int log_fd) {
  ::setpgid(0, 0);
  ::prctl(PR_SET_PDEATHSIG, death_signal);
  if (::getppid() != parent_pid) return false;  // it died already
  struct sigaction default_action {};
  default_action.sa_handler = SIG_DFL;
  for (int sig :
       {SIGINT, SIGTERM, SIGUSR1, SIGPIPE, SIGCHLD, SIGHUP, SIGQUIT}) {
    ::sigaction(sig, &default_action, nullptr);
  }
  sigset_t none;
  sigemptyset(&none);
  ::sigprocmask(SIG_SETMASK, &none, nullptr);
  ::dup2(stdin_fd, STDIN_FILENO);
  ::dup2(log_fd, STDOUT_FILENO);
  ::dup2(log_fd, STDERR_FILENO);
#ifdef SYS_close_range
  ::syscall(SYS_close_range, 3U, ~0U, CLOSE_RANGE_CLOEXEC);
#endif
  return true;
}

}  // namespace adse::pool
