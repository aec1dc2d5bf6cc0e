#include "harness/spec/design_point.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "harness/spec/expression.h"
#include "harness/spec/internal/spec_reader.h"
#include "harness/spec/text_util.h"
#include "stack/base/decimal.h"

namespace adse::spec {

using internal::kPlatformCores;
using internal::kPlatformFreq;

std::vector<std::string> CostVariableNames(const DesignSpace& space) {
  std::vector<std::string> names = space.Names();
  for (const char* n : {"cores", "freq_ghz"}) {
    if (std::find(names.begin(), names.end(), n) == names.end()) {
      names.push_back(n);
    }
  }
  return names;
}

std::vector<std::string> ConstraintVariableNames(const DesignSpace& space) {
  std::vector<std::string> names = internal::MetricNames();
  for (const std::string& n : space.Names()) names.push_back(n);
  return names;
}

std::string FormatPoint(const DesignSpace& space, const DesignPoint& point) {
  std::string text;
  auto add = [&text](const std::string& name, double value) {
    text += fmt::format("{}{}={}", text.empty() ? "" : ",", name, value);
  };
  for (const DesignParameter& p : space.parameters) {
    auto it = point.find(p.name);
    if (it != point.end()) add(p.name, it->second);
  }
  for (const auto& [name, value] : point) {
    if (space.Find(name) == nullptr) add(name, value);
  }
  return text;
}

Result<DesignPoint> ParsePoint(const DesignSpace& space,
                               std::string_view text) {
  std::vector<std::string> errors;
  DesignPoint point;
  const std::vector<std::string> names = space.Names();
  auto trim = [](std::string_view s) {
    const size_t b = s.find_first_not_of(" \t");
    if (b == std::string_view::npos) return std::string_view();
    const size_t e = s.find_last_not_of(" \t");
    return s.substr(b, e - b + 1);
  };
  if (trim(text).empty()) {
    return Status::InvalidArgument(
        "expected name=value pairs separated by ',' (parameters: " +
        JoinList(names) + "), found nothing");
  }
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find(',', start);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view item = trim(text.substr(start, end - start));
    start = end + 1;
    const size_t eq = item.find('=');
    if (eq == std::string_view::npos) {
      errors.push_back("expected name=value, found '" + std::string(item) +
                       "'");
      continue;
    }
    const std::string name(trim(item.substr(0, eq)));
    const std::string value_text(trim(item.substr(eq + 1)));
    const DesignParameter* p = space.Find(name);
    if (p == nullptr) {
      errors.push_back("unknown parameter '" + name + "'; parameters: " +
                       JoinList(names) + DidYouMean(name, names));
      continue;
    }
    if (point.count(name)) {
      errors.push_back(name + ": expected one value, found it twice");
      continue;
    }
    double value = 0;
    if (!ParseNumber(value_text, &value)) {
      errors.push_back(name + ": expected a number, found '" + value_text +
                       "'");
      continue;
    }
    const int index = p->IndexOf(value);
    if (index < 0) {
      errors.push_back(name + ": expected one of " + p->DescribeValues() +
                       ", found " + value_text);
      continue;
    }
    point[name] = p->values[index];
  }
  std::vector<std::string> missing;
  for (const DesignParameter& p : space.parameters) {
    if (!point.count(p.name)) {
      bool mentioned = false;  // already reported with a bad value
      for (const std::string& e : errors) {
        if (e.rfind(p.name + ":", 0) == 0) mentioned = true;
      }
      if (!mentioned) missing.push_back(p.name);
    }
  }
  if (!missing.empty()) {
    errors.push_back("missing parameter" +
                     std::string(missing.size() > 1 ? "s: " : ": ") +
                     JoinList(missing));
  }
  if (errors.empty()) return point;
  std::string message;
  for (const std::string& e : errors) {
    if (!message.empty()) message += '\n';
    message += e;
  }
  return Status::InvalidArgument(message);
}

namespace {

// Variable values for expressions: the point plus the platform's cores and
// frequency (from the point when bound).
std::map<std::string, double> PointVariables(const Spec& spec,
                                             const DesignPoint& point) {
  std::map<std::string, double> vars(point.begin(), point.end());
  const DesignSpace& space = spec.design_space;
  const DesignParameter* cores = space.FindByBind(kPlatformCores);
  const DesignParameter* freq = space.FindByBind(kPlatformFreq);
  vars["cores"] = cores ? point.at(cores->name) : spec.platform.cores;
  vars["freq_ghz"] = freq ? point.at(freq->name) : spec.platform.freq_ghz;
  return vars;
}

}  // namespace

namespace {

Result<Expression> ParseCost(const Spec& spec) {
  Result<Expression> cost =
      Expression::Parse(spec.cost, CostVariableNames(spec.design_space));
  if (!cost.ok()) {
    return Status::InvalidArgument("cost: " + cost.status().message());
  }
  return cost;
}

Result<double> CostAt(const Spec& spec, const Expression& cost,
                      const DesignPoint& point) {
  Result<double> value = cost.TryEvaluate(PointVariables(spec, point));
  if (!value.ok()) return value.status();
  if (!std::isfinite(*value)) {
    return Status::InvalidArgument(fmt::format(
        "cost: expected a finite cost at every design point, found '{}' = "
        "{} at {}",
        spec.cost, *value, FormatPoint(spec.design_space, point)));
  }
  // The knobs are short decimals: what lies past 12 digits of their
  // product is float noise, which would be stored and shown (14.7 as
  // 14.700000000000001) and order equally priced designs by chance.
  return RoundToSignificantDigits(*value, kDecimalDigits);
}

}  // namespace

Result<double> EvaluateCost(const Spec& spec, const DesignPoint& point) {
  ADSE_RETURN_IF_ERROR(spec.design_space.Check(point));
  Result<Expression> cost = ParseCost(spec);
  if (!cost.ok()) return cost.status();
  return CostAt(spec, *cost, point);
}

Status ForEachPointCost(
    const Spec& spec,
    const std::function<void(const DesignPoint& point, double cost)>& visit) {
  const std::vector<DesignParameter>& parameters = spec.design_space.parameters;
  if (parameters.empty()) return Status::Ok();
  Result<Expression> cost = ParseCost(spec);
  if (!cost.ok()) return cost.status();
  // Mixed-radix count over the value indices, first parameter slowest.
  const uint64_t size = spec.design_space.Size();
  std::vector<size_t> index(parameters.size(), 0);
  for (uint64_t n = 0; n < size; ++n) {
    DesignPoint point;
    for (size_t d = 0; d < parameters.size(); ++d) {
      point[parameters[d].name] = parameters[d].values[index[d]];
    }
    Result<double> value = CostAt(spec, *cost, point);
    if (!value.ok()) return value.status();
    visit(point, *value);
    for (size_t d = parameters.size(); d-- > 0;) {
      if (++index[d] < parameters[d].values.size()) break;
      index[d] = 0;
    }
  }
  return Status::Ok();
}

Status CheckCostOverSpace(const Spec& spec) {
  if (spec.design_space.Size() > kMaxCostCheckPoints) return Status::Ok();
  return ForEachPointCost(spec, [](const DesignPoint&, double) {});
}

Status CheckConfirmRuns(const Spec& spec) {
  const uint64_t size = spec.design_space.Size();
  if (spec.exploration.confirm_runs == 0 || size <= kMaxCostCheckPoints) {
    return Status::Ok();
  }
  return Status::InvalidArgument(fmt::format(
      "{}exploration.confirm_runs: the confirm phase runs designs cheaper "
      "than the answer, which adse enumerates in spaces of at most {} "
      "designs; this space holds {}: expected 0, found {}",
      spec.Where("exploration.confirm_runs"), kMaxCostCheckPoints, size,
      spec.exploration.confirm_runs));
}

namespace {

// Whether a parsed constraint holds for the metrics and the point.
Result<bool> Holds(const Expression& e,
                   const std::map<std::string, double>& metrics,
                   const DesignPoint& point) {
  std::map<std::string, double> vars = metrics;
  for (const auto& [name, value] : point) vars[name] = value;
  Result<double> value = e.TryEvaluate(vars);
  if (!value.ok()) return value.status();
  // NaN (a metric without a value, e.g. nav_time_s of a failed run) never
  // satisfies a constraint.
  return std::isfinite(*value) && *value != 0.0;
}

}  // namespace

Result<bool> EvaluateConstraint(const Spec& spec, const std::string& constraint,
                                const std::map<std::string, double>& metrics,
                                const DesignPoint& point) {
  Result<Expression> e =
      Expression::Parse(constraint, ConstraintVariableNames(spec.design_space));
  if (!e.ok()) {
    return Status::InvalidArgument("constraint '" + constraint +
                                   "': " + e.status().message());
  }
  return Holds(*e, metrics, point);
}

std::vector<std::string> ConstraintMetrics(const Spec& spec) {
  const std::vector<std::string> parameters = spec.design_space.Names();
  const std::vector<std::string> names =
      ConstraintVariableNames(spec.design_space);
  std::vector<std::string> metrics;
  for (const std::string& text : spec.constraints) {
    Result<Expression> e = Expression::Parse(text, names);
    if (!e.ok()) continue;
    for (const std::string& name : e->variables()) {
      if (std::find(parameters.begin(), parameters.end(), name) ==
              parameters.end() &&
          std::find(metrics.begin(), metrics.end(), name) == metrics.end()) {
        metrics.push_back(name);
      }
    }
  }
  return metrics;
}

ConstraintChecker::ConstraintChecker(const Spec& spec)
    : texts_(spec.constraints) {
  const std::vector<std::string> names =
      ConstraintVariableNames(spec.design_space);
  for (const std::string& text : texts_) {
    Result<Expression> e = Expression::Parse(text, names);
    parsed_.push_back(e.ok() ? std::optional<Expression>(std::move(e).value())
                             : std::nullopt);
  }
}

std::vector<std::string> ConstraintChecker::Violated(
    const std::map<std::string, double>& metrics,
    const DesignPoint& point) const {
  std::vector<std::string> violated;
  for (size_t i = 0; i < texts_.size(); ++i) {
    Result<bool> holds =
        parsed_[i] ? Holds(*parsed_[i], metrics, point) : Result<bool>(false);
    if (!holds.ok() || !*holds) violated.push_back(texts_[i]);
  }
  return violated;
}

int ConstraintChecker::ViolatedCount(
    const std::map<std::string, double>& metrics,
    const DesignPoint& point) const {
  return static_cast<int>(Violated(metrics, point).size());
}

std::vector<std::string> ViolatedConstraints(
    const Spec& spec, const std::map<std::string, double>& metrics,
    const DesignPoint& point) {
  return ConstraintChecker(spec).Violated(metrics, point);
}

int ViolatedConstraintCount(const Spec& spec,
                            const std::map<std::string, double>& metrics,
                            const DesignPoint& point) {
  return ConstraintChecker(spec).ViolatedCount(metrics, point);
}

Result<PointConfig> ApplyPoint(const Spec& spec, const DesignPoint& point) {
  ADSE_RETURN_IF_ERROR(spec.design_space.Check(point));
  PointConfig config{spec.platform, spec.stack};
  for (const DesignParameter& p : spec.design_space.parameters) {
    const double value = point.at(p.name);
    if (p.bind == kPlatformCores) {
      config.platform.cores = static_cast<int>(std::lround(value));
    } else if (p.bind == kPlatformFreq) {
      config.platform.freq_ghz = value;
    } else if (p.bind.rfind("stack.", 0) == 0) {
      ADSE_RETURN_IF_ERROR(config.stack.Set(p.bind.substr(6), value));
    } else {
      return Status::InvalidArgument(p.name + ": unknown target " + p.bind);
    }
  }
  return config;
}

double RangeCount(double lo, double hi, double step) {
  return std::floor((hi - lo) / step + 1e-9) + 1;
}

std::vector<double> ExpandRange(double lo, double hi, double step) {
  std::vector<double> values;
  const double count = RangeCount(lo, hi, step);
  for (size_t i = 0; i < static_cast<size_t>(count); ++i) {
    // Multiply rather than accumulate, then round away binary noise.
    const double raw = lo + static_cast<double>(i) * step;
    double clean = raw;
    ParseNumber(fmt::format("{:.12g}", raw), &clean);
    values.push_back(clean);
  }
  return values;
}

bool RangeOf(const std::vector<double>& values, std::string* lo,
             std::string* hi, std::string* step) {
  if (values.size() < 3) return false;
  double by = values[1] - values[0];
  ParseNumber(fmt::format("{:.12g}", by), &by);
  if (!(by > 0)) return false;
  const std::string lo_text = FormatNumber(values.front());
  const std::string step_text = FormatNumber(by);
  double lo_value = 0, step_value = 0;
  if (!ParseNumber(lo_text, &lo_value) || !ParseNumber(step_text, &step_value))
    return false;
  // The last value as the bound, or half a step past it where rounding
  // would lose the last value.
  for (const double bound : {values.back(), values.back() + by / 2}) {
    const std::string hi_text = FormatNumber(bound);
    double hi_value = 0;
    if (!ParseNumber(hi_text, &hi_value)) continue;
    if (RangeCount(lo_value, hi_value, step_value) !=
        static_cast<double>(values.size())) {
      continue;
    }
    if (ExpandRange(lo_value, hi_value, step_value) == values) {
      *lo = lo_text;
      *hi = hi_text;
      *step = step_text;
      return true;
    }
  }
  return false;
}

}  // namespace adse::spec
