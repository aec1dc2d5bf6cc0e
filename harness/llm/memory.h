// The DSE agent's memory: one append-only record per evaluation in
// <campaign>/llm/memory.jsonl, and the curated, bounded subset of it that
// goes into each dynamic instruction.
#ifndef ADSE_HARNESS_LLM_MEMORY_H_
#define ADSE_HARNESS_LLM_MEMORY_H_

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "harness/spec/spec.h"
#include "stack/base/status.h"

namespace adse::llm {

struct MemoryRecord {
  int64_t index = 0;      // evaluation number
  int64_t iteration = 0;  // -1: told without being proposed (cache)
  spec::DesignPoint point;
  std::map<std::string, double> metrics;  // the scenario's objectives & co.
  bool feasible = false;
  bool failed = false;
  std::string diagnosis;    // one line: the deterministic findings
  std::string rationale;    // why it was proposed
  std::string proposed_by;  // "llm" | "agent" (fallback) | ""
};

struct CurationOptions {
  int cheapest_feasible = 3;
  int front = 3;  // on the Pareto front (as every command computes it)
  int fastest = 2;
  int most_recent = 3;
  int nearest = 3;   // neighbours of the last point, in grid steps
  int failures = 2;  // failed or infeasible, most recent first
  int max_records = 12;
  // The metric that measures speed (smaller is faster).
  std::string time_metric = "nav_time_s";
  std::string cost_metric = "hardware_cost";
};

// Picks the subset, each with the reasons it was picked ("cheapest
// feasible", ...), in evaluation order. Deterministic. When the categories
// pick more than max_records, each category's first pick is kept, then
// each one's second, and so on (categories in the order above). `front`:
// the positions in `records` of the Pareto front (ParetoFrontOfMemory),
// of which the cheapest are picked.
std::vector<std::pair<const MemoryRecord*, std::string>> Curate(
    const std::vector<MemoryRecord>& records, const spec::DesignSpace& space,
    const CurationOptions& options = {}, const std::vector<int>& front = {});

// The Pareto front of the records, by explore::ParetoFrontOf: the same
// front the campaign's headline and every command show.
std::vector<int> ParetoFrontOfMemory(const spec::Spec& spec,
                                     const std::vector<MemoryRecord>& records);

// One line per record: "#7 cores=4 freq_ghz=1.2 | feasible | nav_time_s=48.4
// ... | cpu_bound ndt_scan_matcher | why: ... [cheapest feasible]".
std::string FormatMemory(
    const std::vector<std::pair<const MemoryRecord*, std::string>>& picked);

// Append-only file (a JsonlLog); Load skips a last line cut short by a
// crash.
std::string MemoryPath(const std::string& campaign_folder);
std::string MemoryLine(const MemoryRecord& record);
Result<std::vector<MemoryRecord>> LoadMemory(const std::string& path);

}  // namespace adse::llm

#endif  // ADSE_HARNESS_LLM_MEMORY_H_
