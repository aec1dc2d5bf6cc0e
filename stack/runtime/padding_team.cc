#include "stack/runtime/internal/padding_team.h"

#include <algorithm>
#include <string>
#include <system_error>
#include <utility>

#include "stack/runtime/internal/executor_parts.h"

namespace adse::stack::internal {

void BusyUntilThreadCpu(double cpu0_s, double target_s) {
  volatile double sink = 1.0;
  while (ThreadCpuSeconds() - cpu0_s < target_s) {
    for (int i = 0; i < 2000; ++i) sink = sink * 1.0000001 + 1e-9;
  }
}

PaddingTeam::PaddingTeam(std::function<Status()> enter)
    : enter_(std::move(enter)) {}

PaddingTeam::~PaddingTeam() { Stop(); }

int PaddingTeam::size() const {
  std::lock_guard<std::mutex> lock(mu_);
  return static_cast<int>(threads_.size());
}

Status PaddingTeam::Run(int helpers, double cpu_s,
                        const std::function<void()>& own_share) {
  Batch batch;
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (stopping_) return Status::Internal("padding team stopped");
    // A parallel region gets its whole team at once, as OpenMP's does:
    // helpers are started for the jobs that idle ones (not yet claimed by
    // queued jobs) cannot take, before any job is queued, so that a thread
    // the system refuses leaves no job waiting for it.
    const int available = std::max(0, idle_ - static_cast<int>(jobs_.size()));
    for (int missing = helpers - available; missing > 0; --missing) {
      try {
        threads_.emplace_back([this] { HelperLoop(); });
      } catch (const std::system_error& e) {
        return Status::Unavailable(
            std::string("cannot start a padding thread: ") + e.what());
      }
    }
    batch.remaining = helpers;
    for (int i = 0; i < helpers; ++i) jobs_.push_back({cpu_s, &batch});
  }
  work_cv_.notify_all();
  if (own_share) own_share();
  std::unique_lock<std::mutex> lock(mu_);
  batch.done.wait(lock, [&batch] { return batch.remaining == 0; });
  return batch.failure;
}

void PaddingTeam::HelperLoop() {
  const Status entered = enter_ ? enter_() : Status::Ok();
  std::unique_lock<std::mutex> lock(mu_);
  while (true) {
    ++idle_;
    work_cv_.wait(lock, [this] { return stopping_ || !jobs_.empty(); });
    --idle_;
    if (jobs_.empty()) return;  // stopping, nothing left to do
    Job job = jobs_.front();
    jobs_.pop_front();
    lock.unlock();
    if (entered.ok()) BusyUntilThreadCpu(ThreadCpuSeconds(), job.cpu_s);
    lock.lock();
    if (!entered.ok() && job.batch->failure.ok()) {
      job.batch->failure = entered;
    }
    if (--job.batch->remaining == 0) job.batch->done.notify_all();
  }
}

void PaddingTeam::Stop() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stopping_ = true;
  }
  work_cv_.notify_all();
  for (std::thread& t : threads_) {
    if (t.joinable()) t.join();
  }
  threads_.clear();
}

}  // namespace adse::stack::internal
