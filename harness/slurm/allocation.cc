#include "harness/slurm/allocation.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>

#include <fmt/format.h>

namespace adse::slurm {
namespace {

// A whole non-negative number, or nullopt.
std::optional<int64_t> ParseCount(const std::string& text) {
  if (text.empty() || text.size() > 15 ||
      text.find_first_not_of("0123456789") != std::string::npos) {
    return std::nullopt;
  }
  return std::stoll(text);
}

// Memory as Slurm exports it: megabytes, possibly with a unit suffix.
std::optional<int64_t> ParseMegabytes(std::string text) {
  int64_t multiply = 1, divide = 1;
  if (!text.empty() && std::isalpha(static_cast<unsigned char>(text.back()))) {
    switch (std::toupper(static_cast<unsigned char>(text.back()))) {
      case 'K':
        divide = 1024;
        break;
      case 'M':
        break;
      case 'G':
        multiply = 1024;
        break;
      case 'T':
        multiply = 1024 * 1024;
        break;
      default:
        return std::nullopt;
    }
    text.pop_back();
  }
  std::optional<int64_t> value = ParseCount(text);
  if (!value) return std::nullopt;
  return *value * multiply / divide;
}

}  // namespace

int Allocation::TotalCpus() const {
  int total = 0;
  for (int cpus : cpus_per_node) total += cpus;
  return total;
}

std::string Allocation::Describe() const {
  std::string memory = "no memory limit";
  if (memory_per_node_mb > 0) {
    memory = fmt::format("{} MB per node", memory_per_node_mb);
  } else if (memory_per_cpu_mb > 0) {
    memory = fmt::format("{} MB per CPU", memory_per_cpu_mb);
  }
  return fmt::format("job {}{}: {} CPUs on {} node{}, {}", job_id,
                     node_list.empty() ? "" : " on " + node_list, TotalCpus(),
                     cpus_per_node.size(), cpus_per_node.size() == 1 ? "" : "s",
                     memory);
}

Result<std::vector<int>> ParseCpusPerNode(const std::string& text) {
  std::vector<int> cpus;
  size_t at = 0;
  const auto bad = [&text]() {
    return Status::InvalidArgument(fmt::format(
        "SLURM_JOB_CPUS_PER_NODE: expected a list like '4(x2),2', found '{}'",
        text));
  };
  while (at <= text.size()) {
    const size_t comma = std::min(text.find(',', at), text.size());
    const std::string item = text.substr(at, comma - at);
    std::string count_text = item;
    int64_t repeat = 1;
    if (const size_t paren = item.find("(x"); paren != std::string::npos) {
      if (item.back() != ')') return bad();
      std::optional<int64_t> r =
          ParseCount(item.substr(paren + 2, item.size() - paren - 3));
      if (!r || *r < 1 || *r > 1000000) return bad();
      repeat = *r;
      count_text = item.substr(0, paren);
    }
    std::optional<int64_t> count = ParseCount(count_text);
    if (!count || *count < 1 || *count > 1000000) return bad();
    cpus.insert(cpus.end(), static_cast<size_t>(repeat),
                static_cast<int>(*count));
    at = comma + 1;
  }
  if (cpus.empty()) return bad();
  return cpus;
}

Result<std::optional<Allocation>> CurrentAllocation(const Environment& env) {
  const Environment get =
      env ? env : [](const char* name) { return std::getenv(name); };
  const auto value = [&get](const char* name) {
    const char* v = get(name);
    return std::string(v == nullptr ? "" : v);
  };
  Allocation a;
  a.job_id = value("SLURM_JOB_ID");
  if (a.job_id.empty()) return std::optional<Allocation>();
  a.array_job_id = value("SLURM_ARRAY_JOB_ID");
  a.array_task_id = value("SLURM_ARRAY_TASK_ID");
  a.node_list = value("SLURM_JOB_NODELIST");
  std::string cpus = value("SLURM_JOB_CPUS_PER_NODE");
  // salloc/sbatch always set it; a bare srun step may only have this one.
  if (cpus.empty()) cpus = value("SLURM_CPUS_ON_NODE");
  if (cpus.empty()) {
    return Status::InvalidArgument(
        "SLURM_JOB_ID is set but SLURM_JOB_CPUS_PER_NODE is not: cannot tell "
        "how many CPUs the allocation holds");
  }
  Result<std::vector<int>> per_node = ParseCpusPerNode(cpus);
  if (!per_node.ok()) return per_node.status();
  a.cpus_per_node = *per_node;
  for (const auto& [name, field] :
       {std::pair{"SLURM_MEM_PER_NODE", &a.memory_per_node_mb},
        std::pair{"SLURM_MEM_PER_CPU", &a.memory_per_cpu_mb}}) {
    const std::string text = value(name);
    if (text.empty()) continue;
    std::optional<int64_t> mb = ParseMegabytes(text);
    if (!mb) {
      return Status::InvalidArgument(
          fmt::format("{}: expected megabytes, found '{}'", name, text));
    }
    *field = *mb;
  }
  if (std::optional<int64_t> restarts =
          ParseCount(value("SLURM_RESTART_COUNT"))) {
    a.restart_count = static_cast<int>(std::min<int64_t>(*restarts, 1 << 30));
  }
  return std::optional<Allocation>(a);
}

int StepsThatFit(const Allocation& allocation, int cores_per_step,
                 int memory_mb) {
  if (cores_per_step < 1 || memory_mb < 1) return 0;
  int64_t steps = 0;
  for (int cpus : allocation.cpus_per_node) {
    int64_t fit = cpus / cores_per_step;
    int64_t memory = allocation.memory_per_node_mb;
    if (memory == 0 && allocation.memory_per_cpu_mb > 0) {
      memory = allocation.memory_per_cpu_mb * cpus;
    }
    if (memory > 0) fit = std::min<int64_t>(fit, memory / memory_mb);
    steps += fit;
  }
  return static_cast<int>(std::min<int64_t>(steps, 1 << 20));
}

}  // namespace adse::slurm
