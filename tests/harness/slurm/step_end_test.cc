// How the end of an srun is classified: srun says out of memory and time
// limits only in words, and exits 128 + N for a task killed by signal N.
// The texts below are srun 22.05's, copied from real runs.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include "harness/slurm/step_pool.h"

namespace adse::slurm {
namespace {

int Exited(int code) { return (code & 0xff) << 8; }  // a wait status
int Signalled(int sig) { return sig & 0x7f; }

pool::JobResult Classify(int status, const std::string& output) {
  pool::JobResult r;
  ClassifyStepEnd(status, output, &r);
  return r;
}

TEST(StepEndTest, AnOutOfMemoryKillIsOutOfMemoryThoughSrunExits1) {
  const pool::JobResult r = Classify(
      Exited(1),
      "loading map\nsrun: error: vm: task 0: Out Of Memory\n"
      "slurmstepd-vm: error: Detected 1 oom-kill event(s) in StepId=1009.0. "
      "Some of your processes may have been killed by the cgroup "
      "out-of-memory handler.\n");
  EXPECT_EQ(r.outcome, pool::Outcome::kOutOfMemory);
  EXPECT_EQ(r.exit_code, 1);
}

TEST(StepEndTest, TheWorkersOwnWordsAreNotTakenForSlurms) {
  EXPECT_EQ(Classify(Exited(1), "error: Out Of Memory in my plan\n").outcome,
            pool::Outcome::kExitError);
  EXPECT_EQ(Classify(Exited(0), "I print oom-kill for fun\n").outcome,
            pool::Outcome::kOk);
}

TEST(StepEndTest, ExitStatusesSignalsAndTimeLimits) {
  EXPECT_EQ(Classify(Exited(0), "").outcome, pool::Outcome::kOk);
  pool::JobResult r =
      Classify(Exited(3), "srun: error: vm: task 0: Exited with exit code 3\n");
  EXPECT_EQ(r.outcome, pool::Outcome::kOutOfMemory);  // adse worker's bad_alloc
  r = Classify(Exited(2), "error: --point: no such parameter\n");
  EXPECT_EQ(r.outcome, pool::Outcome::kExitError);
  EXPECT_EQ(r.exit_code, 2);
  r = Classify(Exited(137), "srun: error: vm: task 0: Killed\n");
  EXPECT_EQ(r.outcome, pool::Outcome::kCrashed);
  EXPECT_EQ(r.signal, 9);
  EXPECT_EQ(r.exit_code, -1);
  r = Classify(Signalled(9), "");
  EXPECT_EQ(r.outcome, pool::Outcome::kCrashed);
  EXPECT_EQ(r.signal, 9);
  r = Classify(Exited(143),
               "slurmstepd-vm: error: *** STEP 12.3 ON vm CANCELLED AT "
               "2026-11-21T06:03:17 DUE TO TIME LIMIT ***\n");
  EXPECT_EQ(r.outcome, pool::Outcome::kTimeout);
}

TEST(StepEndTest, SrunsCommandLineAsksForExactlyTheStepsShare) {
  StepPoolOptions o;
  o.job_id = "42";
  o.cores_per_step = 2;
  o.memory_mb = 1500;
  pool::Job job;
  job.name = "adse-0123456789abcdef";
  job.timeout_s = 61;
  EXPECT_EQ(SrunCommand(o, "/usr/bin/srun", job),
            (std::vector<std::string>{
                "/usr/bin/srun", "--jobid=42", "--exact", "--ntasks=1",
                "--nodes=1", "--cpus-per-task=2", "--mem=1500M",
                "--job-name=adse-0123456789abcdef", "--quit-on-interrupt",
                "--time=3", "--"}));
}

}  // namespace
}  // namespace adse::slurm
