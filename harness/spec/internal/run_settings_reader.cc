// How the study runs: exploration, the language models, the harness
// (workers, isolation, Slurm) and the output folder.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>

#include "harness/pool/worker_pool.h"
#include "harness/spec/internal/spec_reader.h"
#include "harness/spec/text_util.h"
#include "harness/spec/types.h"
#include "stack/base/platform_limits.h"

namespace adse::spec::internal {

namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kExplorationKeys = {
    "strategy",       "budget",       "confirm_runs",   "batch",
    "seed",           "start_from",   "initial_points", "population",
    "crossover_rate", "mutation_rate"};
const std::vector<std::string> kLlmKeys = {
    "backend",     "endpoint",  "models",  "prompts",
    "replay_from", "timeout_s", "retries", "api_key_env"};
const std::vector<std::string> kHarnessKeys = {
    "workers",  "cores_per_worker", "memory_mb",  "run_timeout_s",
    "retries",  "replicas",         "early_stop", "isolation",
    "executor", "cache_dir",        "slurm"};
const std::vector<std::string> kSlurmKeys = {
    "partition",     "account",       "nodes",      "cpus",
    "time_limit",    "max_parallel",  "shard_size", "extra_args",
    "signal_lead_s", "run_estimate_s"};

}  // namespace

void SpecReader::ReadExploration(const Val& v) {
  Fields f;
  if (!ReadFields(v, &kExplorationKeys, &f)) return;
  ExplorationOptions& x = spec_.exploration;
  if (const Val* e = f.Get("strategy"))
    ReadEnum(*e, &x.strategy, StrategyNames());
  if (const Val* e = f.Get("budget")) {
    ReadInt(*e, &x.budget, Bounds::Closed(kMinBudget, kMaxBudget));
  }
  if (const Val* e = f.Get("confirm_runs")) {
    ReadInt(*e, &x.confirm_runs, Bounds::Closed(0, kMaxBudget));
  }
  if (const Val* e = f.Get("initial_points")) {
    ReadInt(*e, &x.initial_points, Bounds::Closed(0, kMaxBudget));
  }
  if (const Val* e = f.Get("batch")) {
    ReadInt(*e, &x.batch, Bounds::Closed(1, 1e6));
  }
  if (const Val* e = f.Get("seed")) ReadSeed(*e, &x.seed);
  if (const Val* e = f.Get("population")) {
    ReadInt(*e, &x.population, Bounds::Closed(2, 1e6));
  }
  if (const Val* e = f.Get("crossover_rate")) {
    ReadNumber(*e, &x.crossover_rate, Bounds::Closed(0, 1));
  }
  if (const Val* e = f.Get("mutation_rate")) {
    ReadNumber(*e, &x.mutation_rate, Bounds::Closed(0, 1));
  }
  if (const Val* e = f.Get("start_from")) ReadStartFrom(*e);
}

void SpecReader::ReadStartFrom(const Val& v) {
  Fields f;
  if (!ReadFields(v, nullptr, &f,
                  "a design point {<parameter>: <value>, ...}")) {
    return;
  }
  if (!space_ok_) return;  // already reported; nothing to check against
  const DesignSpace& space = spec_.design_space;
  const std::vector<std::string> names = space.Names();
  DesignPoint point;
  for (const std::string& name : f.order) {
    const Val& e = *f.Get(name);
    const DesignParameter* p = space.Find(name);
    if (p == nullptr) {
      Error(e.key_mark, e.path, "a design parameter (" + JoinList(names) + ")",
            Quote(name), DidYouMean(name, names));
      continue;
    }
    double value = 0;
    if (!ReadNumber(e, &value, {})) continue;
    const int index = p->IndexOf(value);
    if (index < 0) {
      Error(e, "one of the values of design_space." + name + ": " +
                   p->DescribeValues() + " (the point must be in the space)");
      continue;
    }
    point[name] = p->values[index];
  }
  std::vector<std::string> missing;
  for (const DesignParameter& p : space.parameters) {
    if (f.Get(p.name) == nullptr) missing.push_back(p.name);
  }
  if (!missing.empty()) {
    Error(v.key_mark, v.path, "a value for every design parameter",
          "no value for " + JoinList(missing));
    return;
  }
  if (point.size() == space.parameters.size()) {
    spec_.exploration.start_from = std::move(point);
  }
}

void SpecReader::ReadLlm(const Val& v) {
  Fields f;
  if (!ReadFields(v, &kLlmKeys, &f)) return;
  LlmOptions& llm = spec_.llm;
  if (const Val* e = f.Get("backend"))
    ReadEnum(*e, &llm.backend, LlmBackendNames());
  if (const Val* e = f.Get("endpoint")) {
    std::string url;
    if (ReadString(*e, &url, "an http:// or https:// URL")) {
      if (url.rfind("http://", 0) == 0 || url.rfind("https://", 0) == 0) {
        llm.endpoint = url;
      } else {
        Error(*e, "an http:// or https:// URL");
      }
    }
  }
  if (const Val* e = f.Get("models")) {
    Fields mf;
    if (ReadFields(*e, &LlmRoleNames(), &mf, "a map of role -> model name")) {
      for (const std::string& role : mf.order) {
        ReadString(*mf.Get(role), &llm.models[role], "a model name");
      }
    }
  }
  if (const Val* e = f.Get("prompts")) {
    if (ReadPath(*e, &llm.prompts, "a folder of prompt templates")) {
      std::error_code ec;
      if (check_files_ && !fs::is_directory(llm.prompts, ec)) {
        Error(
            e->mark, e->path, "an existing folder of prompt templates",
            Quote(e->node.Scalar()) + " (no such folder: " + llm.prompts + ")");
      }
    }
  }
  if (const Val* e = f.Get("replay_from")) {
    if (ReadPath(*e, &llm.replay_from, "a recorded campaign folder")) {
      std::error_code ec;
      if (check_files_ && !fs::exists(llm.replay_from, ec)) {
        Error(e->mark, e->path, "an existing recorded campaign folder",
              Quote(e->node.Scalar()) + " (no such folder: " + llm.replay_from +
                  ")");
      }
    }
  }
  if (const Val* e = f.Get("timeout_s")) {
    ReadNumber(*e, &llm.timeout_s, Bounds::Positive());
  }
  if (const Val* e = f.Get("retries")) {
    ReadInt(*e, &llm.retries, Bounds::Closed(0, 100));
  }
  if (const Val* e = f.Get("api_key_env")) {
    if (ReadString(*e, &llm.api_key_env, "an environment variable name") &&
        !IsIdentifier(llm.api_key_env)) {
      Error(*e, "an environment variable name (letters, digits, '_')");
    }
  }
  if (llm.backend == "replay" && llm.replay_from.empty() &&
      f.Get("replay_from") == nullptr) {
    const Val* backend = f.Get("backend");
    Error(backend->mark, Join(v.path, "replay_from"),
          "a recorded campaign folder (required by backend: replay)",
          "nothing");
  }
}

void SpecReader::ReadHarness(const Val& v) {
  Fields f;
  if (!ReadFields(v, &kHarnessKeys, &f)) return;
  HarnessOptions& h = spec_.harness;
  if (const Val* e = f.Get("workers")) {
    if (e->node.IsScalar() && e->node.Scalar() == "auto") {
      h.workers = 0;
    } else {
      double value = 0;
      if (!e->node.IsScalar() || !ParseNumber(e->node.Scalar(), &value) ||
          value != std::floor(value) || value < 1 || value > kMaxWorkers) {
        Error(*e, "'auto' or an integer >= 1");
      } else {
        h.workers = static_cast<int>(value);
      }
    }
  }
  if (const Val* e = f.Get("cores_per_worker")) {
    ReadInt(*e, &h.cores_per_worker, Bounds::Closed(1, kMaxPlatformCores));
  }
  if (const Val* e = f.Get("memory_mb")) {
    ReadInt(*e, &h.memory_mb, Bounds::Closed(1, 1e9));
  }
  if (const Val* e = f.Get("run_timeout_s")) {
    ReadNumber(*e, &h.run_timeout_s, Bounds::Positive());
  }
  if (const Val* e = f.Get("retries")) {
    ReadInt(*e, &h.retries, Bounds::Closed(0, 100));
  }
  if (const Val* e = f.Get("replicas")) {
    ReadInt(*e, &h.replicas, Bounds::Closed(1, 1000));
  }
  if (const Val* e = f.Get("early_stop")) ReadBool(*e, &h.early_stop);
  if (const Val* e = f.Get("isolation")) {
    ReadEnum(*e, &h.isolation, pool::IsolationNames());
  }
  if (const Val* e = f.Get("executor"))
    ReadEnum(*e, &h.executor, ExecutorNames());
  if (const Val* e = f.Get("cache_dir")) {
    ReadPath(*e, &h.cache_dir, "a folder for the result cache");
  }
  if (const Val* e = f.Get("slurm")) ReadSlurm(*e);
}

void SpecReader::ReadSlurm(const Val& v) {
  Fields f;
  if (!ReadFields(v, &kSlurmKeys, &f)) return;
  SlurmOptions& s = spec_.harness.slurm;
  if (const Val* e = f.Get("partition")) {
    ReadString(*e, &s.partition, "a Slurm partition name");
  }
  if (const Val* e = f.Get("account")) {
    ReadString(*e, &s.account, "a Slurm account name");
  }
  if (const Val* e = f.Get("nodes")) {
    ReadInt(*e, &s.nodes, Bounds::Closed(1, 1e6));
  }
  if (const Val* e = f.Get("cpus"))
    ReadInt(*e, &s.cpus, Bounds::Closed(0, 1e7));
  if (const Val* e = f.Get("time_limit")) {
    const std::string expected =
        "a Slurm time limit (M, M:S, H:M:S, D-H, D-H:M or D-H:M:S)";
    std::string limit;
    if (ReadString(*e, &limit, expected)) {
      if (IsSlurmTime(limit)) {
        s.time_limit = limit;
      } else {
        Error(*e, expected);
      }
    }
  }
  if (const Val* e = f.Get("max_parallel")) {
    ReadInt(*e, &s.max_parallel, Bounds::Closed(0, 1e7));
  }
  if (const Val* e = f.Get("shard_size")) {
    ReadInt(*e, &s.shard_size, Bounds::Closed(0, 1e9));
  }
  if (const Val* e = f.Get("signal_lead_s")) {
    ReadInt(*e, &s.signal_lead_s, Bounds::Closed(0, 65535));
  }
  if (const Val* e = f.Get("run_estimate_s")) {
    ReadNumber(*e, &s.run_estimate_s, Bounds::Positive());
  }
  if (const Val* e = f.Get("extra_args")) {
    std::vector<Val> items;
    if (ReadList(*e, &items, "a list of sbatch arguments")) {
      for (const Val& item : items) {
        std::string arg;
        const std::string expected = "an sbatch option, e.g. --qos=long";
        if (!ReadString(item, &arg, expected)) continue;
        // adse sets these itself; one given here would fight it.
        const std::string name = arg.substr(0, arg.find('='));
        if (arg.size() < 2 || arg[0] != '-' ||
            arg.find_first_of("\n\r") != std::string::npos) {
          Error(item, expected + " (one line, starting with '-')");
        } else if (name == "--array" || name == "-a" ||
                   name == "--dependency" || name == "-d" || name == "--wrap" ||
                   name == "--parsable") {
          Error(item, expected + "; " + name + " is set by adse submit itself");
        } else {
          s.extra_args.push_back(arg);
        }
      }
    }
  }
}

void SpecReader::ReadOutput(const Val* v) {
  if (v == nullptr) {
    spec_.output = "results/" + spec_.name;
    return;
  }
  const std::string expected =
      "a folder path, absolute or below the working directory";
  std::string written;
  if (!ReadString(*v, &written, expected)) return;
  const fs::path path(written);
  if (path.is_relative()) {
    const fs::path normal = path.lexically_normal();
    const std::string first =
        normal.empty() ? std::string() : normal.begin()->string();
    if (first == "..") {
      Error(*v, expected, " (the path escapes the working directory)");
      return;
    }
    if (normal.empty() || normal == ".") {
      Error(*v, expected + ", not the working directory itself");
      return;
    }
  }
  spec_.output = written;
}

}  // namespace adse::spec::internal
