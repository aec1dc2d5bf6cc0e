#include "harness/llm/memory.h"

#include <algorithm>
#include <cmath>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "harness/explore/strategy.h"
#include "harness/llm/jsonl_log.h"
#include "harness/spec/spec_parser.h"

namespace adse::llm {
namespace {

using nlohmann::json;

double MetricOr(const MemoryRecord& r, const std::string& name,
                double fallback) {
  auto it = r.metrics.find(name);
  return it == r.metrics.end() || !std::isfinite(it->second) ? fallback
                                                             : it->second;
}

// Distance in grid steps (sum over parameters of |index difference|).
double GridDistance(const spec::DesignSpace& space, const spec::DesignPoint& a,
                    const spec::DesignPoint& b) {
  double d = 0.0;
  for (const spec::DesignParameter& p : space.parameters) {
    auto ia = a.find(p.name), ib = b.find(p.name);
    if (ia == a.end() || ib == b.end()) return 1e9;
    d += std::abs(p.IndexOf(ia->second) - p.IndexOf(ib->second));
  }
  return d;
}

}  // namespace

std::vector<std::pair<const MemoryRecord*, std::string>> Curate(
    const std::vector<MemoryRecord>& records, const spec::DesignSpace& space,
    const CurationOptions& o, const std::vector<int>& front) {
  std::map<size_t, std::string> reasons;  // record position -> reasons
  auto add = [&](size_t i, const std::string& why) {
    std::string& r = reasons[i];
    r += (r.empty() ? "" : ", ") + why;
  };
  // Each category's picks, best first.
  std::vector<std::vector<size_t>> ranked;
  // Orders positions by a key (ties by evaluation order) and takes n.
  auto take = [&](std::vector<size_t> pos, auto key, int n, const char* why) {
    std::stable_sort(pos.begin(), pos.end(),
                     [&](size_t a, size_t b) { return key(a) < key(b); });
    std::vector<size_t>& picks = ranked.emplace_back();
    for (int k = 0; k < n && k < static_cast<int>(pos.size()); ++k) {
      add(pos[k], why);
      picks.push_back(pos[k]);
    }
  };
  std::vector<size_t> feasible, completed, all, bad;
  for (size_t i = 0; i < records.size(); ++i) {
    const MemoryRecord& r = records[i];
    all.push_back(i);
    if (r.feasible && !r.failed) feasible.push_back(i);
    if (!r.failed && MetricOr(r, "completed", 0.0) > 0.5)
      completed.push_back(i);
    if (r.failed || !r.feasible) bad.push_back(i);
  }
  take(
      feasible,
      [&](size_t i) { return MetricOr(records[i], o.cost_metric, 1e300); },
      o.cheapest_feasible, "cheapest feasible");
  std::vector<size_t> on_front;
  for (int i : front) {
    if (i >= 0 && static_cast<size_t>(i) < records.size())
      on_front.push_back(i);
  }
  take(
      on_front,
      [&](size_t i) { return MetricOr(records[i], o.cost_metric, 1e300); },
      o.front, "on the Pareto front");
  take(
      completed,
      [&](size_t i) { return MetricOr(records[i], o.time_metric, 1e300); },
      o.fastest, "fastest");
  take(
      all, [&](size_t i) { return -static_cast<double>(i); }, o.most_recent,
      "most recent");
  if (!records.empty()) {
    const spec::DesignPoint& last = records.back().point;
    std::vector<size_t> others(all.begin(), all.end() - 1);
    take(
        others,
        [&](size_t i) { return GridDistance(space, records[i].point, last); },
        o.nearest, "near the last point");
  }
  take(
      bad, [&](size_t i) { return -static_cast<double>(i); }, o.failures,
      "failed or infeasible");

  // Over the bound, keep the best picks of every category: each one's
  // first, then each one's second, ... (in category order). Cutting by
  // evaluation order instead would drop the most recent records first.
  std::set<size_t> kept;
  const size_t bound = static_cast<size_t>(std::max(o.max_records, 0));
  for (size_t rank = 0; kept.size() < std::min(bound, reasons.size()); ++rank) {
    for (const std::vector<size_t>& picks : ranked) {
      if (rank < picks.size() && kept.size() < bound) kept.insert(picks[rank]);
    }
  }
  std::vector<std::pair<const MemoryRecord*, std::string>> out;
  for (size_t i : kept) out.push_back({&records[i], reasons[i]});
  return out;
}

std::vector<int> ParetoFrontOfMemory(const spec::Spec& spec,
                                     const std::vector<MemoryRecord>& records) {
  std::vector<explore::Observation> observations;
  observations.reserve(records.size());
  for (const MemoryRecord& r : records) {
    explore::Observation o;
    o.point = r.point;
    o.metrics = r.metrics;
    o.feasible = r.feasible;
    o.failed = r.failed;
    observations.push_back(std::move(o));
  }
  return explore::ParetoFrontOf(spec, observations);
}

std::string FormatMemory(
    const std::vector<std::pair<const MemoryRecord*, std::string>>& picked) {
  if (picked.empty()) return "(none yet)";
  std::string out;
  for (const auto& [r, why] : picked) {
    std::string point;
    for (const auto& [name, value] : r->point) {
      point += fmt::format("{}{}={:g}", point.empty() ? "" : " ", name, value);
    }
    std::string line = fmt::format("#{} {} | ", r->index, point);
    if (r->failed) {
      line += "run failed";
    } else {
      line += r->feasible ? "feasible" : "infeasible";
      std::string metrics;
      for (const auto& [name, value] : r->metrics) {
        metrics +=
            fmt::format("{}{}={:.4g}", metrics.empty() ? "" : " ", name, value);
      }
      if (!metrics.empty()) line += " | " + metrics;
    }
    if (!r->diagnosis.empty()) line += " | " + r->diagnosis;
    if (!r->rationale.empty()) line += " | why: " + r->rationale;
    line += " [" + why + "]";
    out += (out.empty() ? "" : "\n") + line;
  }
  return out;
}

std::string MemoryPath(const std::string& campaign_folder) {
  return campaign_folder + "/llm/memory.jsonl";
}

std::string MemoryLine(const MemoryRecord& r) {
  json metrics = json::object();
  for (const auto& [name, value] : r.metrics) {
    if (std::isfinite(value)) metrics[name] = value;
  }
  const json j = {{"index", r.index},
                  {"iteration", r.iteration},
                  {"point", r.point},
                  {"metrics", metrics},
                  {"feasible", r.feasible},
                  {"failed", r.failed},
                  {"diagnosis", r.diagnosis},
                  {"rationale", r.rationale},
                  {"proposed_by", r.proposed_by}};
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

Result<std::vector<MemoryRecord>> LoadMemory(const std::string& path) {
  std::vector<MemoryRecord> records;
  ADSE_RETURN_IF_ERROR(
      ReadJsonLines(path, "a memory record", [&](const std::string& line) {
        const json j = json::parse(line);
        MemoryRecord r;
        r.index = j.at("index").get<int64_t>();
        r.iteration = j.at("iteration").get<int64_t>();
        r.point = j.at("point").get<spec::DesignPoint>();
        r.metrics = j.at("metrics").get<std::map<std::string, double>>();
        r.feasible = j.at("feasible").get<bool>();
        r.failed = j.at("failed").get<bool>();
        r.diagnosis = j.value("diagnosis", "");
        r.rationale = j.value("rationale", "");
        r.proposed_by = j.value("proposed_by", "");
        records.push_back(std::move(r));
      }));
  return records;
}

}  // namespace adse::llm
