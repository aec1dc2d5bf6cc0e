// A stand-in for `adse worker` whose behaviour the pool tests choose. It
// runs its arguments as a list of operations, in order:
//   pid                 print "pid <pid>"
//   cgroup              print /proc/self/cgroup
//   affinity            print "cpus <list>" (sched_getaffinity)
//   stderr TEXT         print TEXT to stderr
//   stderr-bytes N      print N bytes of numbered lines to stderr
//   sleep S             sleep S seconds
//   grandchild S        fork a child that sleeps S s; print "grandchild <pid>"
//   escapee S           the same, but the child leaves the process group
//                       (setsid), so only a cgroup kill reaches it
//   alloc MB            allocate and touch MB MiB; std::bad_alloc => exit 3
//   crash segv|abort    die by SIGSEGV or abort()
//   exit N              exit with status N
// Output is flushed after every operation: the tests read the log while
// the worker still runs.
#include <sched.h>
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>
#include <new>
#include <string>
#include <vector>

namespace {

constexpr int kExitOutOfMemory = 3;  // as adse::pool::kExitOutOfMemory

void SleepSeconds(double s) {
  if (s > 0) ::usleep(static_cast<useconds_t>(s * 1e6));
}

void SpawnSleeper(double s, bool escape, const char* label) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (escape) ::setsid();
    SleepSeconds(s);
    ::_exit(0);
  }
  std::printf("%s %d\n", label, static_cast<int>(pid));
}

int Allocate(long megabytes) {
  std::vector<std::unique_ptr<char[]>> blocks;
  blocks.reserve(static_cast<size_t>(megabytes));
  try {
    for (long i = 0; i < megabytes; ++i) {
      blocks.emplace_back(new char[1 << 20]);
      std::memset(blocks.back().get(), 1, 1 << 20);  // make it resident
    }
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "allocation failed after %zu MiB\n", blocks.size());
    return kExitOutOfMemory;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string op = argv[i];
    const char* arg = i + 1 < argc ? argv[i + 1] : "";
    if (op == "pid") {
      std::printf("pid %d\n", static_cast<int>(::getpid()));
    } else if (op == "cgroup") {
      std::ifstream in("/proc/self/cgroup");
      std::cout << in.rdbuf() << std::flush;
    } else if (op == "affinity") {
      cpu_set_t set;
      CPU_ZERO(&set);
      ::sched_getaffinity(0, sizeof(set), &set);
      std::string list;
      for (int c = 0; c < CPU_SETSIZE; ++c) {
        if (CPU_ISSET(c, &set))
          list += (list.empty() ? "" : ",") + std::to_string(c);
      }
      std::printf("cpus %s\n", list.c_str());
    } else if (op == "stderr") {
      std::fprintf(stderr, "%s\n", arg);
      ++i;
    } else if (op == "stderr-bytes") {
      const long n = std::atol(arg);
      for (long written = 0, line = 0; written < n; ++line) {
        written += std::fprintf(stderr, "line %08ld of filler text\n", line);
      }
      ++i;
    } else if (op == "sleep") {
      std::fflush(nullptr);
      SleepSeconds(std::atof(arg));
      ++i;
    } else if (op == "grandchild" || op == "escapee") {
      std::fflush(nullptr);
      SpawnSleeper(std::atof(arg), op == "escapee", op.c_str());
      ++i;
    } else if (op == "alloc") {
      std::fflush(nullptr);
      const int rc = Allocate(std::atol(arg));
      if (rc != 0) return rc;
      ++i;
    } else if (op == "crash") {
      std::fflush(nullptr);
      if (std::string(arg) == "abort") std::abort();
      ::raise(SIGSEGV);
    } else if (op == "exit") {
      std::fflush(nullptr);
      return std::atoi(arg);
    } else {
      std::fprintf(stderr, "fake_worker: unknown operation '%s'\n", op.c_str());
      return 64;
    }
    std::fflush(nullptr);
  }
  return 0;
}
