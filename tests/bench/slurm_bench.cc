// What Slurm adds to a campaign, on a one-node Slurm started for the
// purpose (tests/harness/slurm/testing): the round trip of one job step
// (srun --exact of /bin/true inside an allocation) against a local worker
// process, and the time from `adse submit` to the first run started (its
// log file created) for a job array and for a coordinator. On a real
// cluster add the queue wait; here the node is idle and the scheduler runs
// with batch_sched_delay=0. Needs root (it starts munged, slurmctld and
// slurmd); prints why and does nothing otherwise.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <thread>

#include "harness/pool/worker_pool.h"
#include "harness/slurm/client.h"
#include "harness/slurm/step_pool.h"
#include "tests/harness/slurm/testing/adse_commands.h"
#include "tests/harness/slurm/testing/slurm_cluster.h"

namespace adse::slurm::testing {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

SlurmCluster* g_cluster = nullptr;
std::string g_allocation;  // a job made with salloc --no-shell
std::string g_dir;

pool::Job TrueJob(uint64_t id) {
  pool::Job job;
  job.id = id;
  job.argv = {"/bin/true"};
  job.log_path = g_dir + "/true.log";
  return job;
}

void RoundTrips(benchmark::State& state, pool::WorkerPool& pool) {
  uint64_t id = 0;
  for (auto _ : state) {
    if (!pool.Submit(TrueJob(++id)).ok()) {
      state.SkipWithError("submit failed");
      return;
    }
    std::vector<pool::JobResult> done;
    while (done.empty()) done = pool.Wait(10);
    if (done[0].outcome != pool::Outcome::kOk) {
      state.SkipWithError(("/bin/true: " + done[0].stderr_tail).c_str());
      return;
    }
  }
}

void BM_SrunStepRoundTrip(benchmark::State& state) {
  StepPoolOptions options;
  options.job_id = g_allocation;
  options.memory_mb = 100;
  Result<std::unique_ptr<pool::WorkerPool>> pool = CreateStepPool(options);
  if (!pool.ok()) {
    state.SkipWithError(pool.status().message().c_str());
    return;
  }
  RoundTrips(state, **pool);
}
BENCHMARK(BM_SrunStepRoundTrip)->Unit(benchmark::kMillisecond)->Iterations(30);

void BM_LocalWorkerRoundTrip(benchmark::State& state) {
  pool::PoolOptions options;
  options.workers = 1;
  options.isolation = state.range(0) == 0 ? pool::Isolation::kAffinity
                                          : pool::Isolation::kCgroup;
  Result<std::unique_ptr<pool::WorkerPool>> pool =
      pool::WorkerPool::Create(options);
  if (!pool.ok()) {
    state.SkipWithError(pool.status().message().c_str());
    return;
  }
  state.SetLabel(state.range(0) == 0 ? "affinity" : "cgroup");
  RoundTrips(state, **pool);
}
BENCHMARK(BM_LocalWorkerRoundTrip)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(30);

// adse submit -> the first runs/..log of the campaign exists (the pool has
// started srun for the first run); the job is cancelled right after.
void BM_SubmitToFirstRunStarted(benchmark::State& state) {
  const bool sweep = state.range(0) == 0;
  state.SetLabel(sweep ? "job array (exhaustive)" : "coordinator (agent)");
  const std::string scenario =
      SmallScenarioIn(g_dir,
                      sweep ? "{strategy: exhaustive, budget: 1}"
                            : "{strategy: agent, budget: 1}",
                      "{memory_mb: 1024, slurm: {signal_lead_s: 60}}");
  int n = 0;
  double submit_s = 0;  // adse submit alone, summed
  for (auto _ : state) {
    const std::string out =
        g_dir + (sweep ? "/array-" : "/coordinator-") + std::to_string(++n);
    const auto start = Clock::now();
    const AdseRun run = Adse({"submit", scenario, "-o", out, "--no-cache"});
    submit_s += std::chrono::duration<double>(Clock::now() - start).count();
    if (run.exit_code != 0) {
      state.SkipWithError(run.output.c_str());
      return;
    }
    bool started = false;
    const auto until = start + std::chrono::seconds(60);
    while (!started && Clock::now() < until) {
      std::error_code ec;
      for (const auto& e : fs::directory_iterator(out + "/logs", ec)) {
        started = started || e.path().extension() == ".log";
      }
      if (!started) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    state.SetIterationTime(
        std::chrono::duration<double>(Clock::now() - start).count());
    if (!started) {
      state.SkipWithError("no run started within 60 s");
      return;
    }
    // Cancel this campaign's jobs and wait for the node to be free.
    (void)g_cluster->Run({"scancel", "--name=adse-robotaxi-small"});
    (void)g_cluster->Run({"scancel", "--name=adse-robotaxi-small-index"});
    for (int i = 0; i < 200; ++i) {
      Result<ProcessResult> left =
          g_cluster->Run({"squeue", "--noheader",
                          "--name=adse-robotaxi-small,"
                          "adse-robotaxi-small-index"});
      if (left.ok() &&
          left->output.find_first_not_of(" \n") == std::string::npos) {
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  state.counters["submit_ms"] =
      benchmark::Counter(1000 * submit_s / std::max(1, n));
}
BENCHMARK(BM_SubmitToFirstRunStarted)
    ->Arg(0)
    ->Arg(1)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);

}  // namespace
}  // namespace adse::slurm::testing

int main(int argc, char** argv) {
  using namespace adse::slurm::testing;
  if (const std::string why = SlurmSkipReason(); !why.empty()) {
    std::printf("slurm_bench: skipped: %s\n", why.c_str());
    return 0;
  }
  adse::Result<std::unique_ptr<SlurmCluster>> cluster = SlurmCluster::Start();
  if (!cluster.ok()) {
    std::fprintf(stderr, "slurm_bench: %s\n",
                 cluster.status().message().c_str());
    return 1;
  }
  g_cluster = cluster->get();
  TestFolder folder("bench");
  g_dir = folder.path();
  adse::Result<adse::ProcessResult> r =
      g_cluster->Run({"salloc", "--no-shell", "--ntasks=1", "--cpus-per-task=1",
                      "--mem=500M", "--time=30"});
  std::smatch m;
  if (!r.ok() ||
      !std::regex_search(r->output, m, std::regex("allocation (\\d+)"))) {
    std::fprintf(stderr, "slurm_bench: salloc failed: %s\n",
                 r.ok() ? r->output.c_str() : r.status().message().c_str());
    return 1;
  }
  g_allocation = m[1];
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  (void)g_cluster->Run({"scancel", g_allocation});
  benchmark::Shutdown();
  return 0;
}
