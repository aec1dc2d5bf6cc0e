// Helper threads for the real-time platform's data-parallel callbacks: the
// parallel part of a callback's profile cost is busy-worked on k threads at
// once, as an OpenMP team would run it, so that it really occupies k host
// CPUs and the OS shares them with everything else. Internal to
// stack/runtime.
#ifndef ADSE_STACK_RUNTIME_INTERNAL_PADDING_TEAM_H_
#define ADSE_STACK_RUNTIME_INTERNAL_PADDING_TEAM_H_

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "stack/base/status.h"

namespace adse::stack::internal {

// Busy-works on the calling thread until its CPU time since `cpu0_s` (a
// ThreadCpuSeconds() reading) reaches `target_s`. Mostly user-mode work
// between clock reads (each read is a system call), as the code it stands
// for would be.
void BusyUntilThreadCpu(double cpu0_s, double target_s);

class PaddingTeam {
 public:
  // `enter` runs first on every helper thread (e.g. to join the stack's
  // cgroup and CPUs); a helper whose enter fails does no work and the
  // failure is returned by Run.
  explicit PaddingTeam(std::function<Status()> enter);
  ~PaddingTeam();
  PaddingTeam(const PaddingTeam&) = delete;
  PaddingTeam& operator=(const PaddingTeam&) = delete;

  // Busy-works `cpu_s` of thread CPU time on each of `helpers` helper
  // threads while the caller runs `own_share` (its own part), and returns
  // when all are done. Helpers are started when none is idle, and kept.
  Status Run(int helpers, double cpu_s, const std::function<void()>& own_share);

  // Ends the helpers; Run may not be called after.
  void Stop();

  // Helper threads started so far.
  int size() const;

 private:
  struct Batch {
    int remaining = 0;
    Status failure;
    std::condition_variable done;
  };
  struct Job {
    double cpu_s;
    Batch* batch;
  };
  void HelperLoop();

  std::function<Status()> enter_;
  mutable std::mutex mu_;
  std::condition_variable work_cv_;
  std::deque<Job> jobs_;
  int idle_ = 0;
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace adse::stack::internal

#endif  // ADSE_STACK_RUNTIME_INTERNAL_PADDING_TEAM_H_
