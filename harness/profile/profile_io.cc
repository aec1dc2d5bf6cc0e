// The profile file: reading (located errors), writing (deterministic,
// atomic) and the table `adse profile show` prints.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "harness/profile/internal/yaml_doc.h"
#include "harness/profile/profile.h"
#include "stack/base/files.h"

namespace adse::profile {
namespace {

using internal::MapReader;
using internal::Range;
using internal::YamlDoc;

// The quantile points a file must give: the executor interpolates between
// them, so the minimum and maximum bound every draw and p50/p95 shape it.
const std::vector<std::string>& RequiredQuantiles() {
  static const std::vector<std::string> kNames = {"min", "p50", "p95", "max"};
  return kNames;
}

// "min" -> 0, "max" -> 1, "p95" -> 0.95, "p99.9" -> 0.999; false otherwise.
bool QuantileOfName(const std::string& name, double* q) {
  if (name == "min") {
    *q = 0.0;
    return true;
  }
  if (name == "max") {
    *q = 1.0;
    return true;
  }
  double percent = 0.0;
  if (name.size() < 2 || name[0] != 'p' ||
      !internal::ParseYamlNumber(name.substr(1), &percent) ||
      !(percent > 0.0 && percent < 100.0)) {
    return false;
  }
  *q = percent / 100.0;
  return true;
}

// The inverse of QuantileOfName; empty when q has no name that reads back
// to exactly q.
std::string NameOfQuantile(double q) {
  if (q == 0.0) return "min";
  if (q == 1.0) return "max";
  const std::string name = "p" + internal::FormatNumber(q * 100.0);
  double back = 0.0;
  return QuantileOfName(name, &back) && back == q ? name : "";
}

// The shortest millisecond value whose value / 1000 is exactly `seconds`,
// so that a profile read back from its file is the same profile and the
// file says 3.981 rather than 3.9810000000000003. Profiles read from files
// or imported (cost = ms / 1000) always have one; for others the nearest
// millisecond value is written.
double ExactMilliseconds(double seconds) {
  const double ms = seconds * 1000.0;
  for (int digits = 1; digits <= 17; ++digits) {
    const double shorter = std::stod(fmt::format("{:.{}g}", ms, digits));
    if (shorter / 1000.0 == seconds) return shorter;
  }
  double up = ms, down = ms;
  for (int i = 0; i < 8; ++i) {
    up = std::nextafter(up, INFINITY);
    down = std::nextafter(down, -INFINITY);
    if (up / 1000.0 == seconds) return up;
    if (down / 1000.0 == seconds) return down;
  }
  return ms;
}

// YAML text for a string: plain when it cannot be mistaken for anything
// else (callback names, CARET ids), otherwise double-quoted.
std::string YamlString(const std::string& s) {
  static const std::vector<std::string> kReserved = {
      "true", "false", "yes", "no", "on", "off", "null", "y", "n", "~"};
  bool plain = !s.empty() && (std::isalpha(static_cast<unsigned char>(s[0])) ||
                              s[0] == '_' || s[0] == '/');
  for (char c : s) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '/' ||
          c == '.' || c == '-')) {
      plain = false;
    }
  }
  std::string lower = s;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  if (std::find(kReserved.begin(), kReserved.end(), lower) != kReserved.end()) {
    plain = false;
  }
  if (plain) return s;
  std::string out = "\"";
  for (unsigned char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (c < 0x20 || c == 0x7f) {
          out += fmt::format("\\x{:02x}", c);
        } else {
          out += static_cast<char>(c);
        }
    }
  }
  return out + "\"";
}

// `text` as comment lines of at most ~78 characters.
std::string CommentBlock(const std::string& text) {
  std::istringstream words(text);
  std::string word, line, out;
  while (words >> word) {
    if (!line.empty() && line.size() + 1 + word.size() > 76) {
      out += "# " + line + "\n";
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
  }
  if (!line.empty()) out += "# " + line + "\n";
  return out;
}

Result<stack::CallbackCost> ReadCostMs(const MapReader& costs) {
  stack::CallbackCost cost;
  std::vector<YAML::Mark> marks;
  const auto entries = costs.Entries(&marks);
  struct Point {
    double q;
    double ms;
    std::string name;
    YAML::Mark mark;
  };
  std::vector<Point> points;
  for (size_t i = 0; i < entries.size(); ++i) {
    const std::string& key = entries[i].first;
    double q = 0.0;
    if (!QuantileOfName(key, &q)) {
      return costs.doc().Error(
          marks[i], costs.PathOf(key),
          "a quantile key: min, max or p<percent> such as p50, p95, p99",
          "'" + key + "'");
    }
    Result<double> ms = costs.Number(key, Range::NonNegative());
    if (!ms.ok()) return ms.status();
    for (const Point& p : points) {
      if (p.q == q) {
        return costs.doc().Error(marks[i], costs.PathOf(key),
                                 "each quantile once",
                                 "'" + key + "' after '" + p.name + "'");
      }
    }
    points.push_back({q, *ms, key, marks[i]});
  }
  for (const std::string& required : RequiredQuantiles()) {
    if (!costs.Has(required)) {
      return costs.doc().Error(costs.node().Mark(), costs.PathOf(required),
                               "a cost in ms (required: min, p50, p95, max)",
                               "nothing");
    }
  }
  std::sort(points.begin(), points.end(),
            [](const Point& a, const Point& b) { return a.q < b.q; });
  for (size_t i = 1; i < points.size(); ++i) {
    if (points[i].ms < points[i - 1].ms) {
      return costs.doc().Error(
          points[i].mark, costs.PathOf(points[i].name),
          fmt::format("a cost >= {} ms ({}): quantiles never fall",
                      internal::FormatNumber(points[i - 1].ms),
                      points[i - 1].name),
          "'" + internal::FormatNumber(points[i].ms) + "'");
    }
  }
  for (const Point& p : points) cost.quantiles.push_back({p.q, p.ms / 1000.0});
  return cost;
}

Result<Profile> ReadProfileDoc(const YamlDoc& doc) {
  MapReader root(&doc);
  ADSE_RETURN_IF_ERROR(root.CheckIsMap());
  ADSE_RETURN_IF_ERROR(root.CheckKeys(
      {"adse_profile", "name", "source", "reference", "callbacks", "chains"}));
  Profile profile;
  Result<int> version = root.Integer("adse_profile", Range::IntegerAtLeast(0));
  if (!version.ok()) return version.status();
  if (*version != kProfileFormatVersion) {
    return doc.ErrorAt(root.Get("adse_profile"), "adse_profile",
                       fmt::format("{} (the profile format this adse reads)",
                                   kProfileFormatVersion));
  }
  Result<std::string> name = root.String("name", std::nullopt, true);
  if (!name.ok()) return name.status();
  profile.name = *name;

  Result<ProfileSource> source = internal::ReadSource(root);
  if (!source.ok()) return source.status();
  profile.source = *source;

  Result<MapReader> reference = root.Map("reference");
  if (!reference.ok()) return reference.status();
  ADSE_RETURN_IF_ERROR(reference->CheckKeys({"ghz", "assumed"}));
  Result<double> ghz = reference->Number("ghz", Range::Positive());
  if (!ghz.ok()) return ghz.status();
  Result<bool> assumed = reference->Bool("assumed", false);
  if (!assumed.ok()) return assumed.status();
  profile.costs.reference_ghz = *ghz;
  profile.source.reference_ghz_assumed = *assumed;

  Result<MapReader> callbacks = root.Map("callbacks");
  if (!callbacks.ok()) return callbacks.status();
  std::vector<YAML::Mark> marks;
  const auto entries = callbacks->Entries(&marks);
  if (entries.empty()) {
    return doc.Error(callbacks->node().Mark(), "callbacks",
                     "at least one callback with its costs", "none");
  }
  for (size_t i = 0; i < entries.size(); ++i) {
    const std::string& key = entries[i].first;
    if (key.empty()) {
      return doc.Error(marks[i], "callbacks", "callback names as keys",
                       "a key that is not text");
    }
    MapReader entry(&doc, entries[i].second, callbacks->PathOf(key), marks[i]);
    ADSE_RETURN_IF_ERROR(entry.CheckIsMap());
    ADSE_RETURN_IF_ERROR(entry.CheckKeys(
        {"cost_ms", "reference_units", "freq_exponent", "parallel_fraction",
         "max_threads", "rate_hz", "avg_ms", "sources"}));
    Result<MapReader> cost_ms = entry.Map("cost_ms");
    if (!cost_ms.ok()) return cost_ms.status();
    Result<stack::CallbackCost> cost = ReadCostMs(*cost_ms);
    if (!cost.ok()) return cost.status();
    // Required, as in the mapping: left out, a work-scaled callback would
    // silently cost the same for every scan.
    Result<double> units =
        entry.Number("reference_units", Range::NonNegative());
    Result<double> alpha =
        entry.Number("freq_exponent", Range::Between(0.0, 4.0), 1.0);
    Result<double> p =
        entry.Number("parallel_fraction", Range::Between(0.0, 1.0), 0.0);
    Result<int> threads =
        entry.Integer("max_threads", Range::IntegerAtLeast(1), 1);
    Result<double> rate = entry.Number("rate_hz", Range::NonNegative(), 0.0);
    Result<double> avg = entry.Number("avg_ms", Range::NonNegative(), 0.0);
    for (const auto* r : {&units, &alpha, &p, &rate, &avg}) {
      if (!r->ok()) return r->status();
    }
    if (!threads.ok()) return threads.status();
    cost->reference_units = *units;
    cost->freq_exponent = *alpha;
    cost->parallel_fraction = *p;
    cost->max_threads = *threads;
    CallbackProvenance provenance;
    provenance.rate_hz = *rate;
    provenance.avg_ms = *avg;
    if (entry.Has("sources")) {
      Result<std::vector<std::string>> sources = entry.StringList("sources");
      if (!sources.ok()) return sources.status();
      provenance.sources = *sources;
    }
    // The executor's own rules, checked on this entry alone so that the
    // error is located at it.
    stack::CostProfile alone;
    alone.reference_ghz = profile.costs.reference_ghz;
    alone.callbacks.emplace(key, *cost);
    if (const Status valid = stack::ValidateCostProfile(alone); !valid.ok()) {
      return Status::InvalidArgument(
          fmt::format("{}:{}:{}: error: {}", doc.path(), marks[i].line + 1,
                      marks[i].column + 1, valid.message()));
    }
    if (!profile.costs.callbacks.emplace(key, std::move(cost).value()).second) {
      return doc.Error(marks[i], callbacks->PathOf(key), "each callback once",
                       "'" + key + "' again");
    }
    profile.provenance[key] = std::move(provenance);
  }

  if (root.Has("chains")) {
    Result<MapReader> chains = root.Map("chains");
    if (!chains.ok()) return chains.status();
    ADSE_RETURN_IF_ERROR(chains->CheckKeys(ChainNames()));
    for (const std::string& name : ChainNames()) {
      if (!chains->Has(name)) continue;
      Result<MapReader> chain = chains->Map(name);
      if (!chain.ok()) return chain.status();
      ADSE_RETURN_IF_ERROR(
          chain->CheckKeys({"source", "avg_ms", "p95_ms", "worst_max_ms"}));
      Result<std::string> source = chain->String("source", std::nullopt, true);
      if (!source.ok()) return source.status();
      Result<double> avg = chain->Number("avg_ms", Range::NonNegative());
      Result<double> p95 = chain->Number("p95_ms", Range::NonNegative());
      Result<double> worst =
          chain->Number("worst_max_ms", Range::NonNegative());
      for (const auto* r : {&avg, &p95, &worst}) {
        if (!r->ok()) return r->status();
      }
      profile.chains[name] = {*source, *avg, *p95, *worst};
    }
  }

  return profile;
}

}  // namespace

Result<Profile> ReadProfile(const std::string& path) {
  Result<YamlDoc> doc = YamlDoc::Load(path, "a cost profile (adse_profile: 1)");
  if (!doc.ok()) return doc.status();
  try {
    return ReadProfileDoc(*doc);
  } catch (const YAML::Exception& e) {
    return doc->Error(e.mark, "(file)", "a readable cost profile", e.msg);
  }
}

Status WriteProfile(const std::string& path, const Profile& profile, Env* env) {
  ADSE_RETURN_IF_ERROR(stack::ValidateCostProfile(profile.costs));
  if (profile.name.empty()) {
    return Status::InvalidArgument("cost profile: name must not be empty");
  }
  std::string out;
  out += CommentBlock(
      "Generated by `adse profile import` from: " + profile.source.description +
      ". Costs are per invocation in ms at reference.ghz, single-thread "
      "equivalent (the executor scales them by work units, clock and "
      "threads). Edit the mapping and import again rather than this file.");
  out += fmt::format("adse_profile: {}\n", kProfileFormatVersion);
  out += "name: " + YamlString(profile.name) + "\n";
  out += "source:\n";
  out += "  description: " + YamlString(profile.source.description) + "\n";
  out += "  license: " + YamlString(profile.source.license) + "\n";
  out += "  cpu: " + YamlString(profile.source.cpu) + "\n";
  out += "  note: " + YamlString(profile.source.note) + "\n";
  out += fmt::format("reference: {{ghz: {}, assumed: {}}}\n",
                     internal::FormatNumber(profile.costs.reference_ghz),
                     profile.source.reference_ghz_assumed ? "true" : "false");
  out += "callbacks:\n";
  for (const auto& [name, cost] : profile.costs.callbacks) {
    out += "  " + YamlString(name) + ":\n";
    std::string quantiles;
    for (const stack::CostQuantile& point : cost.quantiles) {
      const std::string key = NameOfQuantile(point.q);
      if (key.empty()) {
        return Status::InvalidArgument(fmt::format(
            "cost profile: callbacks.{}: quantile {} has no name in the file "
            "format (min, max or p<percent>)",
            name, point.q));
      }
      quantiles +=
          fmt::format("{}{}: {}", quantiles.empty() ? "" : ", ", key,
                      internal::FormatNumber(ExactMilliseconds(point.cost_s)));
    }
    out += "    cost_ms: {" + quantiles + "}\n";
    out += fmt::format("    reference_units: {}\n",
                       internal::FormatNumber(cost.reference_units));
    out += fmt::format("    freq_exponent: {}\n",
                       internal::FormatNumber(cost.freq_exponent));
    out += fmt::format("    parallel_fraction: {}\n",
                       internal::FormatNumber(cost.parallel_fraction));
    out += fmt::format("    max_threads: {}\n", cost.max_threads);
    const auto it = profile.provenance.find(name);
    if (it != profile.provenance.end()) {
      const CallbackProvenance& p = it->second;
      out +=
          fmt::format("    rate_hz: {}\n", internal::FormatNumber(p.rate_hz));
      out += fmt::format("    avg_ms: {}\n", internal::FormatNumber(p.avg_ms));
      if (!p.sources.empty()) {
        std::string list;
        for (const std::string& s : p.sources) {
          list += (list.empty() ? "" : ", ") + YamlString(s);
        }
        out += "    sources: [" + list + "]\n";
      }
    }
  }
  if (!profile.chains.empty()) out += "chains:\n";
  for (const auto& [name, chain] : profile.chains) {
    out += fmt::format(
        "  {}: {{source: {}, avg_ms: {}, p95_ms: {}, worst_max_ms: {}}}\n",
        YamlString(name), YamlString(chain.source),
        internal::FormatNumber(chain.avg_ms),
        internal::FormatNumber(chain.p95_ms),
        internal::FormatNumber(chain.worst_max_ms));
  }
  return WriteFileAtomic(path, out, env);
}

const std::vector<std::string>& ChainNames() {
  static const std::vector<std::string> kNames = {"sensing", "localization",
                                                  "sensing_to_control"};
  return kNames;
}

double MeanCostMs(const stack::CallbackCost& cost) {
  // The integral of the piecewise-linear inverse CDF SampleCost draws from.
  double mean_s = 0.0;
  const auto& qs = cost.quantiles;
  for (size_t i = 1; i < qs.size(); ++i) {
    mean_s += (qs[i].q - qs[i - 1].q) * (qs[i].cost_s + qs[i - 1].cost_s) / 2;
  }
  return mean_s * 1000.0;
}

namespace {

double RateOf(const Profile& profile, const std::string& name) {
  const auto it = profile.provenance.find(name);
  return it == profile.provenance.end() ? 0.0 : it->second.rate_hz;
}

}  // namespace

double TotalLoadCores(const Profile& profile) {
  double load = 0.0;
  for (const auto& [name, cost] : profile.costs.callbacks) {
    load += MeanCostMs(cost) / 1000.0 * RateOf(profile, name);
  }
  return load;
}

std::string FormatProfileTable(const Profile& profile) {
  std::string out =
      fmt::format("profile {}: {}\n", profile.name, profile.source.description);
  out += fmt::format(
      "reference clock {} GHz{}; costs per invocation at the reference "
      "(single-thread equivalent)\n",
      internal::FormatNumber(profile.costs.reference_ghz),
      profile.source.reference_ghz_assumed ? " (assumed)" : "");
  size_t width = std::string("callback").size();
  for (const auto& entry : profile.costs.callbacks) {
    width = std::max(width, entry.first.size());
  }
  out += fmt::format("{:<{}}  {:>9}  {:>9}  {:>9}  {:>8}  {:>10}  {}\n",
                     "callback", width, "p50 ms", "p95 ms", "mean ms",
                     "rate Hz", "load cores", "sources");
  for (const auto& [name, cost] : profile.costs.callbacks) {
    const double rate = RateOf(profile, name);
    const double mean_ms = MeanCostMs(cost);
    const auto it = profile.provenance.find(name);
    const size_t sources =
        it == profile.provenance.end() ? 0 : it->second.sources.size();
    out +=
        fmt::format("{:<{}}  {:>9.3f}  {:>9.3f}  {:>9.3f}  {:>8}  {:>10}  {}\n",
                    name, width, stack::SampleCost(cost, 0.5) * 1000.0,
                    stack::SampleCost(cost, 0.95) * 1000.0, mean_ms,
                    rate > 0.0 ? fmt::format("{:.1f}", rate) : std::string("-"),
                    rate > 0.0 ? fmt::format("{:.4f}", mean_ms / 1000.0 * rate)
                               : std::string("-"),
                    sources);
  }
  out += fmt::format(
      "total load at {} GHz: {:.2f} cores busy (sum of mean cost x observed "
      "rate over {} callbacks)\n",
      internal::FormatNumber(profile.costs.reference_ghz),
      TotalLoadCores(profile), profile.costs.callbacks.size());
  return out;
}

}  // namespace adse::profile
