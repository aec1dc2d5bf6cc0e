#include "stack/runtime/internal/processor_sharing.h"

#include <algorithm>
#include <limits>

namespace adse::stack::internal {
namespace {

// Work left below this (a picosecond) is rounding, not work.
constexpr double kNoWorkS = 1e-12;

}  // namespace

void ProcessorSharing::Add(int id, double now_s, double serial_s,
                           double share_s, int team) {
  Progress(now_s);
  Job job;
  job.id = id;
  job.team = std::max(1, team);
  job.share_s = job.team > 1 ? std::max(0.0, share_s) : 0.0;
  job.left_s = std::max(0.0, serial_s);
  if (job.team == 1) job.left_s += std::max(0.0, share_s);
  if (job.left_s <= kNoWorkS && job.share_s > 0.0) {
    job.parallel = true;  // all of it parallel: the team starts at once
    job.left_s = job.share_s;
    job.share_s = 0.0;
  }
  jobs_.push_back(job);
}

void ProcessorSharing::AdvanceTo(double now_s, std::vector<int>* ended) {
  Progress(now_s);
  const double rate = Rate();
  for (Job& job : jobs_) {
    if (!PartEnded(job, rate)) continue;
    if (!job.parallel && job.share_s > 0.0) {
      // On to the parallel part, whose threads join from now.
      job.parallel = true;
      job.left_s = job.share_s;
      job.share_s = 0.0;
    } else {
      ended->push_back(job.id);
      job.id = -1;  // taken out below
    }
  }
  std::erase_if(jobs_, [](const Job& job) { return job.id < 0; });
}

double ProcessorSharing::NextEndS() const {
  if (jobs_.empty()) return std::numeric_limits<double>::infinity();
  double left_s = jobs_.front().left_s;
  for (const Job& job : jobs_) left_s = std::min(left_s, job.left_s);
  return last_s_ + left_s / Rate();
}

double ProcessorSharing::Rate() const {
  int threads = 0;
  for (const Job& job : jobs_) threads += job.parallel ? job.team : 1;
  return threads <= cores_
             ? 1.0
             : static_cast<double>(cores_) / static_cast<double>(threads);
}

void ProcessorSharing::Progress(double now_s) {
  if (now_s <= last_s_) return;
  const double done_s = (now_s - last_s_) * Rate();
  for (Job& job : jobs_) job.left_s = std::max(0.0, job.left_s - done_s);
  last_s_ = now_s;
}

bool ProcessorSharing::PartEnded(const Job& job, double rate) const {
  // The second test: so little is left that its end is not a later
  // double than now, which would stop the clock.
  return job.left_s <= kNoWorkS || last_s_ + job.left_s / rate <= last_s_;
}

}  // namespace adse::stack::internal
