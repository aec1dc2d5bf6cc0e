// A one-node Slurm on localhost for tests: munged, slurmctld and slurmd
// from Debian's slurm-wlm and munge packages, everything (configuration,
// munge key and socket, state, spool, logs) under a fresh temporary folder,
// ports chosen free, torn down — jobs cancelled, daemons stopped — when the
// object goes, also after a failed assertion. Nothing global is touched:
// munged gets its own key, socket, pid and seed files, and slurm.conf
// points Slurm's munge plugin at that socket (AuthInfo=socket=...).
//
// Facts it relies on (Slurm 22.05, munge 0.5.15, root, no systemd):
// munged refuses to run as root, so it runs as the `munge` user
// (setpriv); the socket's folder must be searchable by all; a node whose
// RealMemory exceeds the machine's stays invalid, so CPUs and memory come
// from `slurmd -C`; task/cgroup and proctrack/cgroup work on the cgroup v1
// hierarchy (used when its memory controller is mounted, which makes
// steps' --mem a real limit); the node is idle about 1 s after start.
#ifndef ADSE_TESTS_HARNESS_SLURM_TESTING_SLURM_CLUSTER_H_
#define ADSE_TESTS_HARNESS_SLURM_TESTING_SLURM_CLUSTER_H_

#include <sys/types.h>

#include <memory>
#include <string>
#include <vector>

#include "stack/base/status.h"
#include "stack/base/subprocess.h"

namespace adse::slurm::testing {

// Why a real Slurm cannot be started here (not root, a program or the
// munge user missing), or "" when it can.
std::string SlurmSkipReason();

class SlurmCluster {
 public:
  // Starts the daemons, exports SLURM_CONF for this process and its
  // children, and waits until the node is idle. Unavailable with what
  // failed and the daemons' log tails.
  static Result<std::unique_ptr<SlurmCluster>> Start();
  ~SlurmCluster();
  SlurmCluster(const SlurmCluster&) = delete;
  SlurmCluster& operator=(const SlurmCluster&) = delete;

  const std::string& dir() const { return dir_; }
  const std::string& conf() const { return conf_; }
  const std::string& node() const { return node_; }
  int cpus() const { return cpus_; }
  // Whether a step's --mem is enforced (task/cgroup, ConstrainRAMSpace).
  bool memory_enforced() const { return memory_enforced_; }

  // Runs a Slurm client command (SLURM_CONF is exported).
  Result<ProcessResult> Run(const std::vector<std::string>& argv) const;
  // The job's state as squeue has it ("" once squeue has forgotten it);
  // for an array job, the states of its tasks joined by ','.
  std::string JobState(const std::string& job_id) const;
  // Polls squeue until no task of the job is pending, running or
  // completing. DeadlineExceeded-like Unavailable with the logs otherwise.
  Status WaitForJobEnd(const std::string& job_id, double timeout_s) const;
  // The last lines of slurmctld's and slurmd's logs, for failure messages.
  std::string LogTail() const;

 private:
  SlurmCluster() = default;
  Status Launch();
  void Stop();

  std::string dir_, conf_, node_;
  int cpus_ = 0;
  bool memory_enforced_ = false;
  pid_t munged_ = -1, slurmctld_ = -1, slurmd_ = -1;
};

}  // namespace adse::slurm::testing

#endif  // ADSE_TESTS_HARNESS_SLURM_TESTING_SLURM_CLUSTER_H_
