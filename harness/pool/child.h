// Setting up a freshly forked worker child before it execs: shared by the
// local pool and the Slurm step pool. Only async-signal-safe calls.
#ifndef ADSE_HARNESS_POOL_CHILD_H_
#define ADSE_HARNESS_POOL_CHILD_H_

#include <sys/types.h>

namespace adse::pool {

// In the child: its own process group (a timeout kills it with killpg, and
// Ctrl-C at a terminal reaches only the coordinator, which cancels jobs
// itself); `death_signal` when the coordinator dies; default dispositions
// and an empty mask for the signals the coordinator handles; stdin, stdout
// and stderr from the given descriptors; every other descriptor
// close-on-exec (other code of the coordinator may have opened some without
// O_CLOEXEC). Returns false when the coordinator `parent_pid` is gone
// already.
bool PrepareChild(pid_t parent_pid, int death_signal, int stdin_fd, int log_fd);

}  // namespace adse::pool

#endif  // ADSE_HARNESS_POOL_CHILD_H_
