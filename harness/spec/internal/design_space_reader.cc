// The design space, the cost expression, objectives and constraints.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "harness/spec/expression.h"
#include "harness/spec/internal/spec_reader.h"
#include "harness/spec/text_util.h"
#include "harness/spec/types.h"
#include "stack/base/platform_limits.h"
#include "stack/config/stack_config.h"

namespace adse::spec::internal {
namespace {

const std::vector<std::string> kParameterKeys = {"bind", "range", "values",
                                                 "step", "role"};
const std::vector<std::string> kObjectiveKeys = {"minimize", "maximize"};

}  // namespace

void SpecReader::ReadDesignSpace(const Val& v) {
  Fields f;
  if (!ReadFields(v, nullptr, &f,
                  "a map of parameters, e.g. {cores: {bind: platform.cores, "
                  "range: [1, 8]}}")) {
    return;
  }
  if (f.order.empty()) {
    Error(v, "at least one parameter");
    return;
  }
  std::map<std::string, std::string> bound;  // target -> parameter
  for (const std::string& name : f.order) {
    if (full()) return;
    ReadParameter(name, *f.Get(name), &bound);
  }
}

void SpecReader::ReadParameter(const std::string& name, const Val& v,
                               std::map<std::string, std::string>* bound) {
  bool ok = true;
  if (!IsIdentifier(name)) {
    Error(v.key_mark, v.path,
          "a parameter name usable in expressions (letters, digits and '_', "
          "not starting with a digit)",
          Quote(name));
    ok = false;
  } else if (const std::vector<std::string> metrics = MetricNames();
             std::find(metrics.begin(), metrics.end(), name) != metrics.end()) {
    Error(v.key_mark, v.path, "a parameter name that is not a metric name",
          Quote(name));
    ok = false;
  } else if (const auto& reserved = Expression::ReservedNames();
             std::find(reserved.begin(), reserved.end(), name) !=
             reserved.end()) {
    Error(v.key_mark, v.path,
          "a parameter name that is not a built-in function or constant",
          Quote(name));
    ok = false;
  }
  Fields f;
  if (!ReadFields(v, &kParameterKeys, &f,
                  "a map {bind: <target>, range: [lo, hi]} or "
                  "{bind: <target>, values: [...]}")) {
    return;
  }
  DesignParameter p;
  p.name = name;
  const std::vector<std::string> targets = BindTargets();
  if (const Val* e = f.Get("bind")) {
    if (ReadString(*e, &p.bind,
                   "a target: platform.cores, platform.freq_ghz "
                   "or stack.<knob>")) {
      if (std::find(targets.begin(), targets.end(), p.bind) == targets.end()) {
        Error(*e,
              "a target: platform.cores, platform.freq_ghz or stack.<knob> "
              "(knobs are listed in scenarios/README.md)",
              DidYouMean(p.bind, targets));
        ok = false;
      } else if (auto it = bound->find(p.bind); it != bound->end()) {
        Error(*e, "a target no other parameter binds",
              " (already bound by '" + it->second + "')");
        ok = false;
      } else {
        (*bound)[p.bind] = name;
      }
      // `cores` and `freq_ghz` always mean the platform's in expressions.
      if (ok && ((name == "cores" && p.bind != kPlatformCores) ||
                 (name == "freq_ghz" && p.bind != kPlatformFreq))) {
        Error(v.key_mark, v.path,
              std::string("the name '") + name + "' to bind platform." + name +
                  " (it means the platform's value in expressions)",
              Quote(p.bind) + " as its target");
        ok = false;
      }
    } else {
      ok = false;
    }
  } else {
    Missing(v, "bind",
            "a target: platform.cores, platform.freq_ghz or "
            "stack.<knob>");
    ok = false;
  }

  p.role = DefaultKnobRole(p.bind);
  if (const Val* e = f.Get("role")) {
    std::string role;
    const std::string expected =
        "a role: " + JoinList(KnobRoleNames()) + " (what the knob stands for)";
    if (ReadString(*e, &role, expected) && !StringToKnobRole(role, &p.role)) {
      Error(*e, expected, DidYouMean(role, KnobRoleNames()));
      ok = false;
    }
  }

  const Val* range = f.Get("range");
  const Val* values = f.Get("values");
  const Val* step = f.Get("step");
  if (range && values) {
    Error(v.key_mark, v.path, "exactly one of 'range' or 'values'", "both");
    return;
  }
  if (!range && !values) {
    Error(v.key_mark, v.path, "exactly one of 'range' or 'values'", "neither");
    return;
  }
  if (step && !range) {
    Error(step->key_mark, step->path, "'step' only together with 'range'",
          "'values'");
    ok = false;
  }
  std::vector<Val> items;
  if (range) {
    std::vector<Val> bounds;
    if (!ReadList(*range, &bounds, "a list [lo, hi]")) return;
    if (bounds.size() != 2) {
      Error(*range, "a list [lo, hi] of two numbers");
      return;
    }
    double lo = 0, hi = 0, by = 1;
    if (!ReadNumber(bounds[0], &lo, {}) || !ReadNumber(bounds[1], &hi, {})) {
      return;
    }
    if (step && !ReadNumber(*step, &by, Bounds::Positive())) return;
    if (lo > hi) {
      Error(range->mark, range->path, "lo <= hi in [lo, hi]",
            fmt::format("[{}, {}] (an inverted range)", FormatNumber(lo),
                        FormatNumber(hi)));
      return;
    }
    const double count = RangeCount(lo, hi, by);
    if (!(count <= static_cast<double>(kMaxParameterValues))) {
      Error(range->mark, range->path,
            fmt::format("at most {} values", kMaxParameterValues),
            fmt::format("a range of {} values", FormatNumber(count)));
      return;
    }
    p.values = ExpandRange(lo, hi, by);
  } else {
    if (!ReadList(*values, &items, "a list of numbers")) return;
    if (items.empty()) {
      Error(*values, "at least one value");
      return;
    }
    if (items.size() > kMaxParameterValues) {
      Error(*values, fmt::format("at most {} values", kMaxParameterValues));
      return;
    }
    std::map<double, size_t> seen;
    for (const Val& item : items) {
      if (full()) return;
      double value = 0;
      if (!ReadNumber(item, &value, {})) {
        ok = false;
        continue;
      }
      if (seen.count(value)) {
        Error(item, "distinct values", " (a duplicate)");
        ok = false;
        continue;
      }
      seen[value] = p.values.size();
      p.values.push_back(value);
    }
    std::sort(p.values.begin(), p.values.end());
  }
  p.integer = std::all_of(p.values.begin(), p.values.end(),
                          [](double x) { return x == std::floor(x); });
  if (!ok || p.values.empty()) return;
  if (!CheckBinding(p, range ? *range : *values, range ? nullptr : &items)) {
    return;
  }
  spec_.design_space.parameters.push_back(std::move(p));
}

// The values must suit the bound target; reports the first that does not.
bool SpecReader::CheckBinding(const DesignParameter& p, const Val& at,
                              const std::vector<Val>* items) {
  Bounds bounds;
  bool integer = false;
  std::string what;
  if (p.bind == kPlatformCores) {
    bounds = Bounds::Closed(1, kMaxPlatformCores);
    integer = true;
    what = "core counts";
  } else if (p.bind == kPlatformFreq) {
    bounds = {0, kMaxPlatformFreqGhz, true, false};
    what = "frequencies, GHz";
  } else if (const KnobInfo* knob = FindStackKnob(p.bind.substr(6))) {
    bounds = Bounds::Closed(knob->min_value, knob->max_value);
    integer = knob->integer;
    what = knob->doc;
  }
  const std::string expected =
      fmt::format("values allowed for {}: {} ({})", p.bind,
                  bounds.Describe(integer ? "integers" : "numbers"), what);
  for (double value : p.values) {
    if (bounds.Contains(value) && (!integer || value == std::floor(value))) {
      continue;
    }
    // Point at the offending list item when there is one.
    const Val* where = &at;
    if (items != nullptr) {
      for (const Val& item : *items) {
        double x = 0;
        if (item.node.IsScalar() && ParseNumber(item.node.Scalar(), &x) &&
            x == value) {
          where = &item;
          break;
        }
      }
    }
    Error(where->mark, where->path, expected, FormatNumber(value));
    return false;
  }
  return true;
}

void SpecReader::ReadExpression(const Val& v,
                                const std::vector<std::string>& names,
                                const std::string& expected) {
  const std::string& text = v.node.Scalar();
  Result<Expression> e = Expression::Parse(text, names);
  if (e.ok()) return;
  const std::string& message = e.status().message();
  // With a broken design space every parameter name looks unknown; only
  // report real syntax problems then.
  if (!space_ok_ && message.rfind("unknown name", 0) == 0) return;
  const size_t suggestion = message.find(" (did you mean");
  if (suggestion != std::string::npos) {
    Error(v.mark, v.path, expected,
          Quote(text) + " with " + message.substr(0, suggestion),
          message.substr(suggestion));
  } else {
    Error(v.mark, v.path, expected, Quote(text) + " with " + message);
  }
}

bool SpecReader::ReportedByTask(const Val& v, const std::string& metric) {
  if (spec_.task.kind == world::TaskKind::kValetParking) return true;
  for (const MetricInfo& info : KnownMetrics()) {
    if (info.name != metric || !info.valet_parking_only) continue;
    Error(v.mark, v.path,
          fmt::format("metrics a {} run reports",
                      world::TaskKindToString(spec_.task.kind)),
          Quote(metric) + ", which valet_parking runs alone report");
    return false;
  }
  return true;
}

void SpecReader::ReadCost(const Val& v) {
  if (!ReadString(v, &spec_.cost, "an expression, e.g. cores * freq_ghz")) {
    return;
  }
  ReadExpression(v, CostVariableNames(spec_.design_space),
                 "an expression over design parameters, cores and freq_ghz");
}

void SpecReader::ReadObjectives(const Val& v) {
  std::vector<Val> items;
  const std::string expected =
      "a list of {minimize: <metric>} or {maximize: <metric>}";
  if (!ReadList(v, &items, expected)) return;
  if (items.empty()) {
    Error(v, "at least one objective");
    return;
  }
  const std::vector<std::string> metrics = MetricNames();
  std::set<std::string> seen;
  for (const Val& item : items) {
    if (full()) return;
    Fields f;
    if (!ReadFields(item, &kObjectiveKeys, &f,
                    "a map {minimize: <metric>} or {maximize: <metric>}")) {
      continue;
    }
    if (item.node.size() != 1) {
      Error(item, "exactly one of minimize or maximize");
      continue;
    }
    if (f.order.empty()) continue;  // its key was reported
    const Val& e = *f.Get(f.order[0]);
    Objective objective;
    objective.minimize = f.order[0] == "minimize";
    if (!ReadEnum(e, &objective.metric, metrics)) continue;
    if (!ReportedByTask(e, objective.metric)) continue;
    if (!seen.insert(objective.metric).second) {
      Error(e, "each metric in one objective only", " (a duplicate)");
      continue;
    }
    spec_.objectives.push_back(objective);
  }
}

void SpecReader::ReadConstraints(const Val& v) {
  std::vector<Val> items;
  if (!ReadList(v, &items,
                "a list of conditions, e.g. [nav_time_s <= 400, completed]")) {
    return;
  }
  const std::vector<std::string> names =
      ConstraintVariableNames(spec_.design_space);
  for (const Val& item : items) {
    if (full()) return;
    std::string text;
    if (!ReadString(item, &text, "a condition, e.g. nav_time_s <= 400")) {
      continue;
    }
    ReadExpression(item, names,
                   "a condition over metrics and design parameters");
    if (Result<Expression> e = Expression::Parse(text, names); e.ok()) {
      for (const std::string& variable : e->variables()) {
        if (!ReportedByTask(item, variable)) break;
      }
    }
    spec_.constraints.push_back(text);
  }
}

}  // namespace adse::spec::internal
