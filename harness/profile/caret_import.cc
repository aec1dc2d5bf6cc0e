// `adse profile import`: a cost profile from a CARET report and a mapping
// file (adse callback -> the CARET callbacks it stands for).
//
// Rules, and why:
// - CARET's callback "latency" is wall time from start to end while the
//   whole stack ran, so it includes preemption by other threads. The
//   profile takes it as the callback's cost: an upper bound.
// - Several sources are summed quantile by quantile (p95 of the sum = sum
//   of the p95s). That is exact when the stages are comonotone, and they
//   nearly are: they process the same scan, so a dense scan is slow in
//   every stage at once. It overstates the tails a little where the stages'
//   slow invocations do not coincide.
// - A source that ran with reference_threads > 1 (NDT with OpenMP) was
//   measured at cost * (1 - p + p / threads); dividing by that Amdahl factor
//   gives the single-thread cost that the executor scales back with the
//   threads a design point grants.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>

#include "harness/profile/internal/yaml_doc.h"
#include "harness/profile/profile.h"

namespace adse::profile {
namespace {

namespace fs = std::filesystem;
using internal::MapReader;
using internal::Range;
using internal::YamlDoc;

// The statistics CARET gives per callback, and the quantile each one is.
struct Statistic {
  const char* key;
  double q;  // < 0: not a quantile
};
constexpr Statistic kLatencyStatistics[] = {{"min", 0.0},  {"p50", 0.5},
                                            {"p95", 0.95}, {"p99", 0.99},
                                            {"max", 1.0},  {"avg", -1.0}};
constexpr char kNeverRan[] = "---";

struct CaretCallback {
  const YamlDoc* doc = nullptr;
  YAML::Node node;   // the callback's map
  std::string path;  // "<node>.callbacks.<id>" in its stats file
  YAML::Mark mark;
};

struct CaretReport {
  std::vector<std::unique_ptr<YamlDoc>> docs;
  std::map<std::string, CaretCallback> callbacks;
  std::vector<std::string> ids;
};

// One source's latency in ms: min, p50, p95, p99, max (quantile order),
// then avg.
struct Latency {
  double quantile_ms[5] = {0, 0, 0, 0, 0};
  double avg_ms = 0.0;
  double rate_hz = 0.0;
};

struct MappingEntry {
  std::string name;
  YAML::Mark mark;
  std::vector<std::string> sources;
  std::vector<YAML::Mark> source_marks;
  double reference_units = 0.0;
  double freq_exponent = 1.0;
  double parallel_fraction = 0.0;
  int max_threads = 1;
  int reference_threads = 1;
};

struct MappingChain {
  std::string name;    // one of ChainNames()
  std::string source;  // CARET's target_path_name
  YAML::Mark mark;
};

struct Mapping {
  std::unique_ptr<YamlDoc> doc;
  std::string name;
  ProfileSource source;
  double reference_ghz = 0.0;
  std::vector<MappingEntry> callbacks;
  std::vector<MappingChain> chains;
};

Status ReadStatsFile(std::unique_ptr<YamlDoc> doc, CaretReport* report) {
  const YamlDoc* d = doc.get();
  report->docs.push_back(std::move(doc));
  const YAML::Node& root = d->root();
  // An area without nodes is written as `{}` (e.g. vehicle/).
  if (!root.IsDefined() || root.IsNull()) return Status::Ok();
  MapReader nodes(d);
  ADSE_RETURN_IF_ERROR(nodes.CheckIsMap());
  std::vector<YAML::Mark> node_marks;
  const auto node_entries = nodes.Entries(&node_marks);
  for (size_t n = 0; n < node_entries.size(); ++n) {
    MapReader node_map(d, node_entries[n].second, node_entries[n].first,
                       node_marks[n]);
    ADSE_RETURN_IF_ERROR(node_map.CheckIsMap());
    Result<MapReader> callbacks = node_map.Map("callbacks");
    if (!callbacks.ok()) return callbacks.status();
    std::vector<YAML::Mark> marks;
    const auto entries = callbacks->Entries(&marks);
    for (size_t i = 0; i < entries.size(); ++i) {
      const std::string& id = entries[i].first;
      CaretCallback cb{d, entries[i].second, callbacks->PathOf(id), marks[i]};
      if (!cb.node.IsMap()) {
        return d->ErrorAt(cb.node, cb.path,
                          "a map of the callback's statistics (callback_type, "
                          "Frequency, Period, Latency)");
      }
      const auto [it, added] = report->callbacks.emplace(id, cb);
      if (!added) {
        return d->Error(
            marks[i], cb.path, "each callback id once in a report",
            fmt::format("'{}' also in {}", id, it->second.doc->path()));
      }
      report->ids.push_back(id);
    }
  }
  return Status::Ok();
}

Result<CaretReport> ReadCaretReport(const std::string& folder) {
  const std::string expected =
      "a CARET report folder holding analyze_node/<area>/stats_node.yaml";
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) {
    return Status::NotFound(
        fmt::format("{}: error: --caret: expected {}, found {}", folder,
                    expected, fs::exists(folder, ec) ? "a file" : "nothing"));
  }
  std::vector<std::string> files;
  const fs::path areas = fs::path(folder) / "analyze_node";
  if (fs::is_directory(areas, ec)) {
    for (const fs::directory_entry& area : fs::directory_iterator(areas, ec)) {
      const fs::path stats = area.path() / "stats_node.yaml";
      if (area.is_directory(ec) && fs::is_regular_file(stats, ec)) {
        files.push_back(stats.string());
      }
    }
  }
  if (files.empty()) {
    return Status::NotFound(
        fmt::format("{}: error: --caret: expected {}, found no stats_node.yaml",
                    folder, expected));
  }
  std::sort(files.begin(), files.end());
  CaretReport report;
  for (const std::string& file : files) {
    Result<YamlDoc> doc = YamlDoc::Load(file, "CARET node statistics");
    if (!doc.ok()) return doc.status();
    ADSE_RETURN_IF_ERROR(ReadStatsFile(
        std::make_unique<YamlDoc>(std::move(doc).value()), &report));
  }
  return report;
}

Result<Mapping> ReadMapping(const std::string& path) {
  Result<YamlDoc> loaded =
      YamlDoc::Load(path, "a profile mapping (adse_profile_mapping: 1)");
  if (!loaded.ok()) return loaded.status();
  Mapping mapping;
  mapping.doc = std::make_unique<YamlDoc>(std::move(loaded).value());
  const YamlDoc& doc = *mapping.doc;
  MapReader root(&doc);
  ADSE_RETURN_IF_ERROR(root.CheckIsMap());
  ADSE_RETURN_IF_ERROR(root.CheckKeys({"adse_profile_mapping", "name", "source",
                                       "reference", "callbacks", "chains"}));
  Result<int> version =
      root.Integer("adse_profile_mapping", Range::IntegerAtLeast(0));
  if (!version.ok()) return version.status();
  if (*version != kMappingFormatVersion) {
    return doc.ErrorAt(root.Get("adse_profile_mapping"), "adse_profile_mapping",
                       fmt::format("{} (the mapping format this adse reads)",
                                   kMappingFormatVersion));
  }
  Result<std::string> name = root.String("name", std::nullopt, true);
  if (!name.ok()) return name.status();
  mapping.name = *name;

  Result<ProfileSource> source = internal::ReadSource(root);
  if (!source.ok()) return source.status();
  mapping.source = *source;
  const std::string note = source->note;

  Result<MapReader> reference = root.Map("reference");
  if (!reference.ok()) return reference.status();
  ADSE_RETURN_IF_ERROR(reference->CheckKeys({"ghz", "assumed", "note"}));
  Result<double> ghz = reference->Number("ghz", Range::Positive());
  if (!ghz.ok()) return ghz.status();
  Result<bool> assumed = reference->Bool("assumed", false);
  if (!assumed.ok()) return assumed.status();
  Result<std::string> reference_note = reference->String("note", "");
  if (!reference_note.ok()) return reference_note.status();
  mapping.reference_ghz = *ghz;
  mapping.source.reference_ghz_assumed = *assumed;
  // One note in the profile: how to read the numbers, then the clock.
  mapping.source.note = note;
  if (!reference_note->empty()) {
    mapping.source.note +=
        (mapping.source.note.empty() ? "" : " ") + *reference_note;
  }

  Result<MapReader> callbacks = root.Map("callbacks");
  if (!callbacks.ok()) return callbacks.status();
  std::vector<YAML::Mark> marks;
  const auto entries = callbacks->Entries(&marks);
  for (size_t i = 0; i < entries.size(); ++i) {
    MappingEntry e;
    e.name = entries[i].first;
    e.mark = marks[i];
    MapReader entry(&doc, entries[i].second, callbacks->PathOf(e.name),
                    marks[i]);
    ADSE_RETURN_IF_ERROR(entry.CheckIsMap());
    ADSE_RETURN_IF_ERROR(entry.CheckKeys(
        {"sources", "reference_units", "freq_exponent", "parallel_fraction",
         "max_threads", "reference_threads", "why"}));
    Result<std::vector<std::string>> sources =
        entry.StringList("sources", &e.source_marks);
    if (!sources.ok()) return sources.status();
    e.sources = *sources;
    Result<double> units =
        entry.Number("reference_units", Range::NonNegative());
    Result<double> alpha =
        entry.Number("freq_exponent", Range::Between(0.0, 4.0), 1.0);
    Result<double> p =
        entry.Number("parallel_fraction", Range::Between(0.0, 1.0), 0.0);
    for (const auto* r : {&units, &alpha, &p}) {
      if (!r->ok()) return r->status();
    }
    Result<int> threads =
        entry.Integer("max_threads", Range::IntegerAtLeast(1), 1);
    if (!threads.ok()) return threads.status();
    Result<int> reference_threads =
        entry.Integer("reference_threads", Range::IntegerAtLeast(1), 1);
    if (!reference_threads.ok()) return reference_threads.status();
    // Why this source stands for this callback: the mapping is the
    // profile's argument, so every entry states it.
    Result<std::string> why = entry.String("why", std::nullopt, true);
    if (!why.ok()) return why.status();
    e.reference_units = *units;
    e.freq_exponent = *alpha;
    e.parallel_fraction = *p;
    e.max_threads = *threads;
    e.reference_threads = *reference_threads;
    mapping.callbacks.push_back(std::move(e));
  }
  if (root.Has("chains")) {
    Result<MapReader> chains = root.Map("chains");
    if (!chains.ok()) return chains.status();
    ADSE_RETURN_IF_ERROR(chains->CheckKeys(ChainNames()));
    for (const std::string& chain : ChainNames()) {
      if (!chains->Has(chain)) continue;
      Result<std::string> source = chains->String(chain, std::nullopt, true);
      if (!source.ok()) return source.status();
      mapping.chains.push_back({chain, *source, chains->KeyMark(chain)});
    }
  }
  return mapping;
}

// Close matches for a CARET id the report lacks: a typo or a wrong index
// by edit distance, else the ids that share the longest prefix when that
// prefix reaches into the node's own name (a shortened or misspelt node,
// e.g. ".../top/velodyne/callback_0").
std::string SuggestIds(const std::string& id,
                       const std::vector<std::string>& ids) {
  std::string close = internal::DidYouMean(id, ids, 3);
  if (!close.empty()) return close;
  const size_t last = id.rfind('/');
  const size_t parent =
      last == std::string::npos || last == 0 ? 0 : id.rfind('/', last - 1);
  size_t best = 0;
  std::vector<std::string> matches;
  for (const std::string& candidate : ids) {
    size_t n = 0;
    while (n < id.size() && n < candidate.size() && id[n] == candidate[n]) ++n;
    if (n > best) {
      best = n;
      matches.clear();
    }
    if (n == best) matches.push_back(candidate);
  }
  if (parent == std::string::npos || best <= parent + 1 || matches.empty()) {
    return "";
  }
  if (matches.size() > 3) matches.resize(3);
  std::string out = " (did you mean ";
  for (size_t i = 0; i < matches.size(); ++i) {
    if (i > 0) out += i + 1 == matches.size() ? " or " : ", ";
    out += "'" + matches[i] + "'";
  }
  return out + "?)";
}

// The mapping must name exactly the stack graph's callbacks: a missing one
// would be charged nothing (the executor refuses it), an unknown one is a
// typo.
Status CheckCoverage(const Mapping& mapping,
                     const std::vector<std::string>& stack_names) {
  const YamlDoc& doc = *mapping.doc;
  MapReader root(&doc);
  for (const MappingEntry& e : mapping.callbacks) {
    if (std::find(stack_names.begin(), stack_names.end(), e.name) ==
        stack_names.end()) {
      return doc.Error(
          e.mark, "callbacks." + e.name, "a callback of adse's stack graph",
          "'" + e.name + "'" + internal::DidYouMean(e.name, stack_names));
    }
  }
  std::vector<std::string> missing;
  for (const std::string& name : stack_names) {
    const bool mapped =
        std::any_of(mapping.callbacks.begin(), mapping.callbacks.end(),
                    [&](const MappingEntry& e) { return e.name == name; });
    if (!mapped) missing.push_back(name);
  }
  if (missing.empty()) return Status::Ok();
  std::string list;
  for (const std::string& m : missing) list += (list.empty() ? "" : ", ") + m;
  return doc.Error(
      root.KeyMark("callbacks"), "callbacks",
      fmt::format("an entry for each of the {} callbacks of "
                  "adse's stack graph",
                  stack_names.size()),
      fmt::format("none for {} callback(s): {}", missing.size(), list));
}

Result<Latency> ReadLatency(const CaretCallback& cb) {
  MapReader callback(cb.doc, cb.node, cb.path, cb.mark);
  Result<MapReader> latency = callback.Map("Latency");
  if (!latency.ok()) return latency.status();
  Latency out;
  int quantile = 0;
  for (const Statistic& s : kLatencyStatistics) {
    const YAML::Node value = latency->Get(s.key);
    if (value.IsDefined() && value.IsScalar() && value.Scalar() == kNeverRan) {
      return cb.doc->Error(
          value.Mark(), latency->PathOf(s.key), "a measured latency in ms",
          "'---': the callback never ran while CARET measured, so it cannot "
          "stand for an adse callback");
    }
    Result<double> ms = latency->Number(s.key, Range::NonNegative());
    if (!ms.ok()) return ms.status();
    if (s.q < 0.0) {
      out.avg_ms = *ms;
      continue;
    }
    if (quantile > 0 && *ms < out.quantile_ms[quantile - 1]) {
      return cb.doc->ErrorAt(
          value, latency->PathOf(s.key),
          fmt::format("a latency >= {} ms ({}): quantiles never fall",
                      internal::FormatNumber(out.quantile_ms[quantile - 1]),
                      kLatencyStatistics[quantile - 1].key));
    }
    out.quantile_ms[quantile++] = *ms;
  }
  // The rate is provenance only: unknown ('---' or absent) reads as 0.
  if (callback.Has("Frequency")) {
    Result<MapReader> frequency = callback.Map("Frequency");
    if (!frequency.ok()) return frequency.status();
    const YAML::Node avg = frequency->Get("avg");
    if (avg.IsDefined() && !(avg.IsScalar() && avg.Scalar() == kNeverRan)) {
      Result<double> hz = frequency->Number("avg", Range::NonNegative());
      if (!hz.ok()) return hz.status();
      out.rate_hz = *hz;
    }
  }
  return out;
}

// The chains the mapping names, from <caret_folder>/analyze_path/
// stats_path.yaml: a list of {target_path_name, best_avg, best_p95,
// worst_max, ...} in ms.
Status ImportChains(const std::string& caret_folder, const Mapping& mapping,
                    Profile* profile) {
  if (mapping.chains.empty()) return Status::Ok();
  const std::string path =
      (fs::path(caret_folder) / "analyze_path" / "stats_path.yaml").string();
  Result<YamlDoc> doc =
      YamlDoc::Load(path, "CARET's path statistics (a list of target paths)");
  if (!doc.ok()) return doc.status();
  if (!doc->root().IsSequence()) {
    return doc->ErrorAt(doc->root(), "(file)",
                        "a list of target paths (target_path_name, best_avg, "
                        "best_p95, worst_max)");
  }
  std::vector<std::string> names;
  for (size_t i = 0; i < doc->root().size(); ++i) {
    const std::string at = fmt::format("[{}]", i);
    MapReader entry(&*doc, doc->root()[i], at, doc->root()[i].Mark());
    ADSE_RETURN_IF_ERROR(entry.CheckIsMap());
    Result<std::string> name = entry.String("target_path_name");
    if (!name.ok()) return name.status();
    names.push_back(*name);
    for (const MappingChain& chain : mapping.chains) {
      if (chain.source != *name) continue;
      Result<double> avg = entry.Number("best_avg", Range::NonNegative());
      Result<double> p95 = entry.Number("best_p95", Range::NonNegative());
      Result<double> worst = entry.Number("worst_max", Range::NonNegative());
      for (const auto* r : {&avg, &p95, &worst}) {
        if (!r->ok()) return r->status();
      }
      profile->chains[chain.name] = {*name, *avg, *p95, *worst};
    }
  }
  for (const MappingChain& chain : mapping.chains) {
    if (profile->chains.count(chain.name) == 0) {
      return mapping.doc->Error(chain.mark, "chains." + chain.name,
                                fmt::format("a target_path_name of {}", path),
                                "'" + chain.source + "', which it lacks" +
                                    SuggestIds(chain.source, names));
    }
  }
  return Status::Ok();
}

}  // namespace

Result<Profile> ImportCaret(const std::string& caret_folder,
                            const std::string& mapping_path) {
  try {
    Result<CaretReport> report = ReadCaretReport(caret_folder);
    if (!report.ok()) return report.status();
    Result<Mapping> mapping = ReadMapping(mapping_path);
    if (!mapping.ok()) return mapping.status();
    Result<std::vector<std::string>> stack_names = StackCallbackNames();
    if (!stack_names.ok()) return stack_names.status();
    ADSE_RETURN_IF_ERROR(CheckCoverage(*mapping, *stack_names));

    Profile profile;
    profile.name = mapping->name;
    profile.source = mapping->source;
    profile.costs.reference_ghz = mapping->reference_ghz;
    for (const MappingEntry& e : mapping->callbacks) {
      double sum_ms[5] = {0, 0, 0, 0, 0};
      CallbackProvenance provenance;
      for (size_t i = 0; i < e.sources.size(); ++i) {
        const std::string& id = e.sources[i];
        const auto it = report->callbacks.find(id);
        if (it == report->callbacks.end()) {
          return mapping->doc->Error(
              e.source_marks[i],
              fmt::format("callbacks.{}.sources[{}]", e.name, i),
              fmt::format("a callback id of the CARET report in {} (a key "
                          "under 'callbacks:' in a stats_node.yaml)",
                          caret_folder),
              "'" + id + "', which the report lacks" +
                  SuggestIds(id, report->ids));
        }
        Result<Latency> latency = ReadLatency(it->second);
        if (!latency.ok()) return latency.status();
        for (int q = 0; q < 5; ++q) sum_ms[q] += latency->quantile_ms[q];
        provenance.avg_ms += latency->avg_ms;
        if (i == 0) provenance.rate_hz = latency->rate_hz;
        provenance.sources.push_back(id);
      }
      provenance.avg_ms = std::round(provenance.avg_ms * 1e6) / 1e6;
      const double p = e.parallel_fraction;
      const double amdahl = 1.0 - p + p / e.reference_threads;
      stack::CallbackCost cost;
      for (int q = 0; q < 5; ++q) {
        // To the nanosecond: sums of the report's microsecond values would
        // otherwise carry binary noise (20.458000000000002) into the file.
        const double ms = std::round(sum_ms[q] / amdahl * 1e6) / 1e6;
        cost.quantiles.push_back({kLatencyStatistics[q].q, ms / 1000.0});
      }
      cost.reference_units = e.reference_units;
      cost.freq_exponent = e.freq_exponent;
      cost.parallel_fraction = p;
      cost.max_threads = e.max_threads;
      profile.costs.callbacks[e.name] = std::move(cost);
      profile.provenance[e.name] = std::move(provenance);
    }
    ADSE_RETURN_IF_ERROR(ImportChains(caret_folder, *mapping, &profile));
    const Status valid = stack::ValidateCostProfile(profile.costs);
    if (!valid.ok()) return valid.WithContext(mapping_path);
    return profile;
  } catch (const YAML::Exception& e) {
    // Reading nodes is checked before use; this is a last net.
    return Status::InvalidArgument(fmt::format(
        "importing {} with {}: unexpected YAML content at line {}: {}",
        caret_folder, mapping_path, e.mark.is_null() ? 1 : e.mark.line + 1,
        e.msg));
  }
}

}  // namespace adse::profile
