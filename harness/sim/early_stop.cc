#include "harness/sim/early_stop.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "harness/spec/design_point.h"

namespace adse::sim {
namespace {

// The metrics a run accumulates, whose final value is bounded part-way.
constexpr char kNavTime[] = "nav_time_s";
constexpr char kControlRate[] = "ctrl_rate_hz";
constexpr char kCollisions[] = "collisions";

// Interior points between an interval's ends at which a constraint is
// also tried (see EarlyStop::Violated).
constexpr int kInteriorSamples = 15;

// The one accumulating metric `e` uses, when everything else it uses is
// fixed for the run (design parameters, hardware_cost).
std::optional<std::string> DecidableMetric(const spec::Spec& spec,
                                           const spec::Expression& e) {
  std::optional<std::string> metric;
  for (const std::string& name : e.variables()) {
    if (name == kNavTime || name == kControlRate || name == kCollisions) {
      if (metric) return std::nullopt;
      metric = name;
    } else if (name != "hardware_cost" &&
               spec.design_space.Find(name) == nullptr) {
      return std::nullopt;
    }
  }
  return metric;
}

}  // namespace

std::vector<std::string> EarlyStoppableConstraints(const spec::Spec& spec) {
  std::vector<std::string> out;
  if (!spec.harness.early_stop) return out;
  const std::vector<std::string> names =
      spec::ConstraintVariableNames(spec.design_space);
  for (const std::string& c : spec.constraints) {
    Result<spec::Expression> e = spec::Expression::Parse(c, names);
    if (e.ok() && DecidableMetric(spec, *e)) out.push_back(c);
  }
  return out;
}

Result<EarlyStop> EarlyStop::Create(const spec::Spec& spec,
                                    const spec::DesignPoint& point,
                                    double max_control_rate_hz) {
  EarlyStop stop;
  stop.timeout_s_ = spec.task.timeout_s;
  stop.max_control_rate_hz_ = max_control_rate_hz;
  stop.fixed_ = point;
  if (Result<double> cost = spec::EvaluateCost(spec, point); cost.ok())
    stop.fixed_["hardware_cost"] = *cost;
  const std::vector<std::string> names =
      spec::ConstraintVariableNames(spec.design_space);
  for (const std::string& c : EarlyStoppableConstraints(spec)) {
    Result<spec::Expression> e = spec::Expression::Parse(c, names);
    if (!e.ok()) {
      return Status::InvalidArgument("constraint '" + c +
                                     "': " + e.status().message());
    }
    const std::string metric = *DecidableMetric(spec, *e);
    const Metric kind = metric == kNavTime       ? Metric::kNavTime
                        : metric == kControlRate ? Metric::kControlRate
                                                 : Metric::kCollisions;
    stop.checks_.push_back({std::move(e).value(), kind});
  }
  return stop;
}

std::optional<std::string> EarlyStop::Violated(
    const RunProgress& progress) const {
  const double t = progress.t_s;
  const double end = std::max(timeout_s_, t);
  // One copy per step: each check overwrites only its own metric.
  std::map<std::string, double> values = fixed_;
  for (const Check& check : checks_) {
    double lo = 0.0, hi = 0.0;
    const char* name = kNavTime;
    switch (check.metric) {
      case Metric::kNavTime:
        // The goal is not reached yet, so the run lasts longer than now.
        lo = t;
        hi = end;
        break;
      case Metric::kControlRate: {
        name = kControlRate;
        // Lowest: no further command and the longest run. Highest: a
        // command every controller period from now, over a run ending now
        // or at the timeout (the rate is monotone in the end time between).
        const double n = static_cast<double>(progress.control_commands);
        lo = n / end;
        auto most = [&](double t_end) {
          if (t_end <= 0.0) return 0.0;
          const double more = std::ceil(max_control_rate_hz_ * (t_end - t));
          return (n + 1.0 + more) / t_end;
        };
        hi = std::max(most(std::max(t, 1e-9)), most(end));
        break;
      }
      case Metric::kCollisions:
        name = kCollisions;
        lo = static_cast<double>(progress.collisions);
        // Counts only grow, one at a time: try this many and the next few.
        hi = lo + kInteriorSamples + 1;
        break;
    }
    bool satisfiable = false;
    for (int i = 0; i <= kInteriorSamples + 1 && !satisfiable; ++i) {
      const double f = static_cast<double>(i) / (kInteriorSamples + 1);
      values[name] = lo + f * (hi - lo);
      const double v = check.expression.Evaluate(values);
      satisfiable = std::isfinite(v) && v != 0.0;
    }
    if (!satisfiable) return check.expression.text();
  }
  return std::nullopt;
}

}  // namespace adse::sim
