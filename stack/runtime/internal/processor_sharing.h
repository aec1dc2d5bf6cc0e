// Ideal processor sharing of a platform's cores among the threads of the
// callbacks in progress, for the virtual platform's `processor_sharing`
// dispatch. Every runnable thread runs at min(1, cores / threads) of a core,
// as a fair preemptive scheduler (Linux's CFS) shares CPUs over times long
// against its slice. Internal to stack/runtime.
#ifndef ADSE_STACK_RUNTIME_INTERNAL_PROCESSOR_SHARING_H_
#define ADSE_STACK_RUNTIME_INTERNAL_PROCESSOR_SHARING_H_

#include <vector>

namespace adse::stack::internal {

class ProcessorSharing {
 public:
  explicit ProcessorSharing(int cores) : cores_(cores) {}

  // Advances every job to `now_s` (>= the last time given), then adds job
  // `id` (>= 0): `serial_s` of CPU time on one thread, then `share_s` on each
  // of `team` threads at once (a data-parallel part; share_s 0 or team 1:
  // none).
  void Add(int id, double now_s, double serial_s, double share_s, int team);

  // Advances every job to `now_s` and moves each whose serial part has
  // ended to its parallel part. Appends the ids of the jobs that have ended
  // to `ended` (in the order they were added) and forgets them.
  void AdvanceTo(double now_s, std::vector<int>* ended);

  // When the next part ends at the current rates; +inf with no job.
  double NextEndS() const;

  bool empty() const { return jobs_.empty(); }

 private:
  struct Job {
    int id = 0;
    double left_s = 0.0;   // CPU time left of the current part, per thread
    double share_s = 0.0;  // the parallel part's per-thread CPU time, to come
    int team = 1;          // threads of the parallel part
    bool parallel = false;
  };

  // Each runnable thread's speed, in cores.
  double Rate() const;
  // Moves the jobs' work on to `now_s` at the current rate.
  void Progress(double now_s);
  // True when `job`'s current part has no representable time left.
  bool PartEnded(const Job& job, double rate) const;

  int cores_;
  double last_s_ = 0.0;
  std::vector<Job> jobs_;
};

}  // namespace adse::stack::internal

#endif  // ADSE_STACK_RUNTIME_INTERNAL_PROCESSOR_SHARING_H_
