// Shared helpers of the worker pool tests.
#ifndef ADSE_TESTS_HARNESS_POOL_POOL_TEST_UTIL_H_
#define ADSE_TESTS_HARNESS_POOL_POOL_TEST_UTIL_H_

#include <sched.h>
#include <signal.h>
#include <stdlib.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "harness/pool/worker_pool.h"

namespace adse::pool::testing {

// A fresh folder under /tmp, removed with its contents at the end.
class TempDir {
 public:
  TempDir() {
    std::string pattern =
        (std::filesystem::temp_directory_path() / "adse-pool-test-XXXXXX")
            .string();
    path_ = ::mkdtemp(pattern.data());
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

inline std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

inline void WriteText(const std::string& path, const std::string& text) {
  std::filesystem::create_directories(
      std::filesystem::path(path).parent_path());
  std::ofstream(path) << text;
}

inline std::string Trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}

inline Job FakeJob(uint64_t id, const std::string& log_path,
                   std::vector<std::string> ops, double timeout_s = 0.0) {
  Job job;
  job.id = id;
  job.argv.push_back(ADSE_POOL_FAKE_WORKER);
  for (std::string& op : ops) job.argv.push_back(std::move(op));
  job.log_path = log_path;
  job.timeout_s = timeout_s;
  return job;
}

// Waits (up to `max_wait_s`) until all of the pool's jobs have finished.
inline std::vector<JobResult> WaitAll(WorkerPool& pool,
                                      double max_wait_s = 10.0) {
  std::vector<JobResult> all;
  const auto until = std::chrono::steady_clock::now() +
                     std::chrono::duration<double>(max_wait_s);
  while (pool.idle_slots() < pool.slots() &&
         std::chrono::steady_clock::now() < until) {
    for (JobResult& r : pool.Wait(0.5)) all.push_back(std::move(r));
  }
  return all;
}

// The number after "<key> " in a worker's log, once it has printed it.
inline int WaitForNumber(const std::string& log_path, const std::string& key,
                         double max_wait_s = 5.0) {
  const auto until = std::chrono::steady_clock::now() +
                     std::chrono::duration<double>(max_wait_s);
  while (std::chrono::steady_clock::now() < until) {
    std::istringstream lines(ReadText(log_path));
    std::string line;
    while (std::getline(lines, line)) {
      if (line.rfind(key + " ", 0) == 0)
        return std::stoi(line.substr(key.size() + 1));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return -1;
}

// Whether `pid` no longer runs (gone, or a zombie waiting for its parent).
inline bool ProcessGone(int pid, double max_wait_s = 2.0) {
  const auto until = std::chrono::steady_clock::now() +
                     std::chrono::duration<double>(max_wait_s);
  for (;;) {
    const std::string stat = ReadText("/proc/" + std::to_string(pid) + "/stat");
    const size_t paren = stat.rfind(')');
    if (stat.empty() ||
        (paren != std::string::npos && paren + 2 < stat.size() &&
         (stat[paren + 2] == 'Z' || stat[paren + 2] == 'X'))) {
      return true;
    }
    if (std::chrono::steady_clock::now() >= until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

inline int AllowedCores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  ::sched_getaffinity(0, sizeof(set), &set);
  return CPU_COUNT(&set);
}

}  // namespace adse::pool::testing

#endif  // ADSE_TESTS_HARNESS_POOL_POOL_TEST_UTIL_H_
