// The built-in `agent` strategy: a reasoning loop that needs no network.
//
// It keeps every told point in memory and, before each round:
//  1. fits one surrogate per metric that an objective or a constraint reads
//     (hardware cost is computed exactly from the cost expression): a
//     parametric trend fitted with Ceres under a robust loss — in log space
//     for positive metrics, over knobs in log scale when positive — linear,
//     or saturating towards a floor or a ceiling (nav time stops improving
//     past some core count, the control rate caps), with prior slopes that
//     say more cores / GHz help, so one or two points already extrapolate;
//     plus a small Gaussian process on the trend's residuals, which
//     interpolates the runs and gives an uncertainty that grows with the
//     distance from them; the nav time, once 10 runs measured it, also as
//     a rate (1 / time), kept when its leave-one-out predictions fit the
//     runs better (a rate falls to zero where the computer cannot keep up,
//     as a starved stack's time climbs without bound);
//  2. scores unseen points (all of them when the space is small, a sample
//     plus the neighbours of seen points otherwise) by the expected gain in
//     hypervolume of the feasible front, over joint samples of the predicted
//     metrics pushed through the spec's own constraint expressions: cheap
//     points that are probably feasible score high, so the search walks
//     the feasibility boundary in cost;
//  3. leans towards the diagnosis' remedies for the last runs (a CPU-bound
//     node asking for "more cores" or "higher frequency", a sensor stage
//     asking for a lower rate) and away from the neighbours of failed runs;
//  4. for a batch, picks greedily, treating each chosen point as if its
//     prediction were true and penalising points close to it.
// Every Ask writes a short rationale with the numbers behind the choice.
//
// This file holds the memory of told runs and the surrogates' fit;
// internal/surrogate.cc the surrogate of one metric, acquisition.cc the
// scoring and choice, rationale.cc the words.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "analysis/metrics/run_metrics.h"
#include "harness/explore/internal/agent_strategy.h"
#include "harness/spec/spec_parser.h"

namespace adse::explore {
namespace internal {

AgentStrategy::AgentStrategy(const spec::Spec& spec)
    : spec_(&spec),
      grid_(spec.design_space),
      budget_(std::max(0, spec.exploration.budget)),
      random_(Random::DeriveSeed(spec.exploration.seed,
                                 "explore.agent.candidates")),
      initial_random_(
          Random::DeriveSeed(spec.exploration.seed, "explore.agent.initial")) {
  SetUpKnobs();
  SetUpMetrics();
  if (!spec.exploration.start_from.empty()) {
    start_ = grid_.FromPoint(spec.exploration.start_from);
  }
  // Stratified normal draws per model, shuffled independently.
  Random draws(
      Random::DeriveSeed(spec.exploration.seed, "explore.agent.samples"));
  z_.assign(kSamples, std::vector<double>(models_.size(), 0.0));
  for (size_t m = 0; m < models_.size(); ++m) {
    std::vector<int> order(kSamples);
    std::iota(order.begin(), order.end(), 0);
    for (int i = kSamples - 1; i > 0; --i) {
      std::swap(order[i], order[draws.Below(static_cast<uint64_t>(i + 1))]);
    }
    for (int s = 0; s < kSamples; ++s) {
      z_[s][m] = NormalQuantile((order[s] + 0.5) / kSamples);
    }
  }
}

std::vector<spec::DesignPoint> AgentStrategy::Ask(int k) {
  std::vector<spec::DesignPoint> points;
  const int n = std::min(std::max(k, 0), budget_ - proposed_);
  if (n <= 0) {
    rationale_ = proposed_ >= budget_
                     ? fmt::format("agent: the budget of {} is spent", budget_)
                     : std::string("agent: asked for no points");
    return points;
  }
  std::vector<Genes> chosen;
  std::string start_text;
  if (start_) {
    if (!seen_.count(*start_)) {
      chosen.push_back(*start_);
      start_text = fmt::format("Starts at start_from ({}).",
                               Describe(grid_.ToPoint(*start_)));
    }
    start_.reset();
  }
  std::string choice_text;
  if (static_cast<int>(chosen.size()) < n) {
    try {
      choice_text = InitialDesign(n, &chosen);
      if (static_cast<int>(chosen.size()) < n) {
        const std::string model_text = Choose(n, &chosen);
        if (!model_text.empty()) {
          choice_text += (choice_text.empty() ? "" : " ") + model_text;
        }
      }
    } catch (...) {
      // Nothing may throw: fall back to random unseen points.
      choice_text = Fallback(n, &chosen);
    }
  }
  for (const Genes& genes : chosen) {
    seen_.insert(genes);
    pending_.insert(genes);
    points.push_back(grid_.ToPoint(genes));
    ++proposed_;
  }
  std::string text = LastText();
  if (!start_text.empty()) text += (text.empty() ? "" : " ") + start_text;
  if (!choice_text.empty()) text += (text.empty() ? "" : " ") + choice_text;
  if (points.empty()) text += " No unseen point is left.";
  fresh_ = 0;
  rationale_ = text.empty() ? std::string("agent") : text;
  return points;
}

void AgentStrategy::Tell(const Observation& observation) {
  try {
    Remember(observation);
  } catch (...) {
    // Out of memory at worst; the run is then simply not remembered.
  }
}

void AgentStrategy::Remember(const Observation& observation) {
  std::optional<Genes> genes = grid_.FromPoint(observation.point);
  if (!genes || told_.count(*genes)) return;  // foreign or repeated
  told_.insert(*genes);
  seen_.insert(*genes);
  pending_.erase(*genes);
  Record record;
  record.genes = *genes;
  record.observation = observation;
  record.failed = observation.failed;
  record.feasible = observation.feasible && !observation.failed;
  record.objectives = Objectives(observation);
  if (observation.censored) record.censored = CensoredAt(observation);
  record.metrics_fail = FailsForCapacity(constraints_, observation, false);
  record.load_fail =
      record.metrics_fail && FailsForCapacity(constraints_, observation, true);
  records_.push_back(std::move(record));
  ++fresh_;
}

std::string AgentStrategy::Fallback(int n, std::vector<Genes>* chosen) {
  const size_t before = chosen->size();
  UnseenSampler sampler(&grid_, Random::DeriveSeed(spec_->exploration.seed,
                                                   "explore.agent.fallback"));
  std::set<Genes> taken = seen_;
  taken.insert(chosen->begin(), chosen->end());
  while (static_cast<int>(chosen->size()) < n) {
    std::optional<Genes> genes = sampler.Next(taken);
    if (!genes) break;
    taken.insert(*genes);
    chosen->push_back(*genes);
  }
  return fmt::format(
      "The model could not be used; {} point(s) drawn at "
      "random among unseen ones.",
      chosen->size() - before);
}

void AgentStrategy::SetUpKnobs() {
  for (const spec::DesignParameter& parameter :
       spec_->design_space.parameters) {
    Knob knob;
    knob.parameter = &parameter;
    knob.role = parameter.role;
    roles_.push_back(parameter.role);
    const std::string prefix = "stack.";
    if (knob.role == KnobRole::kSensorRate &&
        parameter.bind.compare(0, prefix.size(), prefix) == 0) {
      // stack.lidar.rate_hz: the sensor is the knob's first path part.
      const std::string rest = parameter.bind.substr(prefix.size());
      knob.sensor = rest.substr(0, rest.find('.'));
    }
    const std::vector<double>& values = parameter.values;
    bool positive = !values.empty() && values.front() > 0.0;
    auto transform = [positive](double v) {
      return positive ? std::log(v) : v;
    };
    const double lo = values.empty() ? 0.0 : transform(values.front());
    const double hi = values.empty() ? 0.0 : transform(values.back());
    knob.log_range = positive ? hi - lo : 1.0;
    for (double v : values) {
      knob.u.push_back(hi > lo ? (transform(v) - lo) / (hi - lo) : 0.0);
    }
    knobs_.push_back(std::move(knob));
    // A knob with few values (a sensor rate of 7 or 14 Hz) is a
    // modifier more than an axis: its levels share much of their
    // behaviour, so they stay correlated in the GP.
    lengths_.push_back(values.size() <= 3 ? kFewValuesLength : kLength);
    rate_raised_.push_back(false);
  }
}

void AgentStrategy::SetUpMetrics() {
  std::vector<std::string> parameter_names = spec_->design_space.Names();
  auto add = [this](const std::string& metric) -> MetricModel* {
    for (MetricModel& model : models_) {
      if (model.name == metric) return &model;
    }
    MetricModel model;
    model.name = metric;
    for (const spec::MetricInfo& info : spec::KnownMetrics()) {
      if (info.name != metric) continue;
      model.boolean_hint = info.boolean;
      model.count_hint = info.count;
      model.precision_hint = info.precision;
    }
    model.rate_hint = metric == kNavTimeMetric;
    models_.push_back(model);
    return &models_.back();
  };
  for (const spec::Objective& objective : spec_->objectives) {
    if (objective.metric == kCostMetric) continue;
    add(objective.metric)->good_direction = objective.minimize ? -1 : +1;
  }
  constraints_ = CapacityConstraintsOf(*spec_);
  for (const CapacityConstraint& constraint : constraints_) {
    for (const std::string& variable : constraint.expression.variables()) {
      if (variable == kCostMetric ||
          std::find(parameter_names.begin(), parameter_names.end(), variable) !=
              parameter_names.end()) {
        continue;
      }
      add(variable)->in_constraint = true;
    }
  }
  for (const spec::Objective& objective : spec_->objectives) {
    int index = -1;
    for (size_t m = 0; m < models_.size(); ++m) {
      if (models_[m].name == objective.metric) index = static_cast<int>(m);
    }
    objective_model_.push_back(index);
  }
}

std::vector<double> AgentStrategy::Objectives(
    const Observation& observation) const {
  std::vector<double> values = MinimizationObjectives(*spec_, observation);
  if (observation.failed) return values;
  for (size_t j = 0; j < spec_->objectives.size(); ++j) {
    if (spec_->objectives[j].metric == kCostMetric && std::isnan(values[j])) {
      // A run without the metric: the cost expression gives it.
      Result<double> cost = spec::EvaluateCost(*spec_, observation.point);
      if (cost.ok()) {
        values[j] = spec_->objectives[j].minimize ? *cost : -*cost;
      }
    }
  }
  return values;
}

std::vector<double> AgentStrategy::Coordinates(const Genes& genes) const {
  std::vector<double> u(genes.size());
  for (size_t d = 0; d < genes.size(); ++d) u[d] = knobs_[d].u[genes[d]];
  return u;
}

void AgentStrategy::ProbeDirections() {
  const Record* reference = nullptr;
  for (auto it = records_.rbegin(); it != records_.rend(); ++it) {
    if (!it->failed) {
      reference = &*it;
      break;
    }
  }
  if (reference == nullptr) return;
  for (MetricModel& model : models_) {
    if (model.good_direction != 0 || !model.in_constraint) continue;
    auto it = reference->observation.metrics.find(model.name);
    if (it == reference->observation.metrics.end()) continue;
    const double value = it->second;
    const bool flag = model.boolean_hint || value == 0.0 || value == 1.0;
    const double low = flag ? 0.0 : (value > 0 ? value * 0.5 : value - 1.0);
    const double high = flag ? 1.0 : (value > 0 ? value * 2.0 : value + 1.0);
    int score = 0;
    for (const CapacityConstraint& capacity : constraints_) {
      const spec::Expression& constraint = capacity.expression;
      const auto& vars = constraint.variables();
      if (std::find(vars.begin(), vars.end(), model.name) == vars.end()) {
        continue;
      }
      std::map<std::string, double> values = reference->observation.metrics;
      for (const auto& [name, v] : reference->observation.point) {
        values[name] = v;
      }
      values[model.name] = low;
      const double at_low = constraint.Evaluate(values);
      values[model.name] = high;
      const double at_high = constraint.Evaluate(values);
      const bool ok_low = std::isfinite(at_low) && at_low != 0.0;
      const bool ok_high = std::isfinite(at_high) && at_high != 0.0;
      if (ok_high && !ok_low) ++score;
      if (ok_low && !ok_high) --score;
    }
    model.good_direction = score > 0 ? 1 : score < 0 ? -1 : 0;
  }
}

namespace {

// Whether `topic` ("/sensing/lidar/points_raw") has `sensor` ("lidar") as
// one of its path parts.
bool TopicOfSensor(const std::string& topic, const std::string& sensor) {
  if (sensor.empty()) return false;
  const std::string part = "/" + sensor;
  for (size_t at = topic.find(part); at != std::string::npos;
       at = topic.find(part, at + 1)) {
    const size_t end = at + part.size();
    if (end == topic.size() || topic[end] == '/') return true;
  }
  return false;
}

}  // namespace

std::vector<int> AgentStrategy::RemedyDirections(const Record& record,
                                                 std::string* text) const {
  std::vector<int> direction(knobs_.size(), 0);
  std::vector<std::string> parts;
  for (const BottleneckHint& hint : record.observation.bottlenecks) {
    for (const analysis::Remedy& remedy : hint.remedies) {
      for (size_t d = 0; d < knobs_.size(); ++d) {
        const Knob& knob = knobs_[d];
        int want = 0;
        switch (remedy.kind) {
          case analysis::RemedyKind::kMoreCores:
            want = knob.role == KnobRole::kCores ? +1 : 0;
            break;
          case analysis::RemedyKind::kHigherFrequency:
            want = knob.role == KnobRole::kFrequency ? +1 : 0;
            break;
          case analysis::RemedyKind::kLowerSensorRate:
          case analysis::RemedyKind::kRaiseSensorRate:
            if (knob.role == KnobRole::kSensorRate &&
                TopicOfSensor(remedy.target, knob.sensor)) {
              want = remedy.kind == analysis::RemedyKind::kLowerSensorRate ? -1
                                                                           : +1;
            }
            break;
          case analysis::RemedyKind::kRaisePublisherRate:
          case analysis::RemedyKind::kShortenTimerPeriod:
          case analysis::RemedyKind::kRelieveNode:
          case analysis::RemedyKind::kOwnCallbackGroup:
            break;  // no design knob stands for these
        }
        if (want != 0 && direction[d] == 0) direction[d] = want;
      }
    }
    if (parts.size() < 2 && !hint.node.empty()) {
      parts.push_back(fmt::format("{} {} -> {}", hint.node,
                                  analysis::FindingKindToString(hint.kind),
                                  hint.remedy.empty() ? "?" : hint.remedy));
    }
  }
  if (text != nullptr) *text = fmt::format("{}", fmt::join(parts, ", "));
  return direction;
}

Verdict AgentStrategy::CapacityVerdict(const Genes& genes) const {
  Verdict verdict = Verdict::kUnknown;
  for (const Record& record : records_) {
    if (record.failed) continue;
    if (record.metrics_fail) {
      const int order = CompareCapacity(roles_, rate_raised_, genes,
                                        record.genes, record.load_fail);
      if (order == -1 || order == 0) return Verdict::kFails;
    }
    if (record.feasible) {
      const int order =
          CompareCapacity(roles_, rate_raised_, genes, record.genes, false);
      if (order == +1 || order == 0) verdict = Verdict::kHolds;
    }
  }
  return verdict;
}

std::optional<CensoredBound> AgentStrategy::CensoredAt(
    const Observation& observation) const {
  const spec::Expression* found = nullptr;
  for (const CapacityConstraint& c : constraints_) {
    if (c.expression.text() == observation.violated_constraint) {
      found = &c.expression;
      break;
    }
  }
  if (found == nullptr && observation.stalled) {
    // A stalled car never arrives: the first constraint on the nav time
    // alone that an endless drive fails is the one it violates.
    for (const CapacityConstraint& c : constraints_) {
      const std::vector<std::string>& variables = c.expression.variables();
      if (variables.size() != 1 || variables[0] != kNavTimeMetric) continue;
      const double v = c.expression.Evaluate({{kNavTimeMetric, 1e12}});
      if (std::isfinite(v) && v == 0.0) {
        found = &c.expression;
        break;
      }
    }
  }
  if (found == nullptr) return std::nullopt;
  const spec::Expression& constraint = *found;
  const MetricModel* model = nullptr;
  for (const std::string& variable : constraint.variables()) {
    for (const MetricModel& m : models_) {
      if (m.name != variable) continue;
      if (model != nullptr) return std::nullopt;  // two metrics: no bound
      model = &m;
    }
  }
  if (model == nullptr) return std::nullopt;
  // Where the constraint flips, with the run's point fixed: scan a wide
  // log grid of the metric for the first change of truth, then bisect.
  // Early stop decides only constraints monotone in their metric's final
  // value, so one change is expected; none means no usable bound.
  std::map<std::string, double> values = observation.point;
  Result<double> cost = spec::EvaluateCost(*spec_, observation.point);
  if (cost.ok()) values[kCostMetric] = *cost;
  auto holds = [&](double metric) {
    values[model->name] = metric;
    const double v = constraint.Evaluate(values);
    return std::isfinite(v) && v != 0.0;
  };
  std::vector<double> grid = {0.0};
  for (int k = -48; k <= 72; ++k) grid.push_back(std::pow(10.0, k / 8.0));
  for (size_t i = 1; i < grid.size(); ++i) {
    const bool low = holds(grid[i - 1]);
    if (low == holds(grid[i])) continue;
    double a = grid[i - 1];
    double b = grid[i];
    for (int iteration = 0; iteration < 60; ++iteration) {
      const double mid = 0.5 * (a + b);
      (holds(mid) == low ? a : b) = mid;
    }
    CensoredBound bound;
    bound.metric = model->name;
    bound.bound = 0.5 * (a + b);
    // The run's value lies where the constraint fails.
    bound.side = low ? +1 : -1;
    // A time stopped at its bound part of the way: past it by as much as
    // the rest of the route takes at the pace so far.
    bound.paced_bound = bound.bound;
    auto driven = observation.metrics.find(analysis::kDrivenFractionMetric);
    if (model->name == kNavTimeMetric && bound.side > 0 &&
        driven != observation.metrics.end() && driven->second < 1.0 &&
        std::isfinite(driven->second)) {
      bound.driven_fraction = driven->second;
      bound.paced_bound /= std::max(driven->second, kMinDrivenFraction);
    }
    return bound;
  }
  return std::nullopt;
}

void AgentStrategy::FitModels() {
  ProbeDirections();
  // A metric only a constraint reads, seen only past its bound, improves
  // away from where the stopped runs lie.
  for (MetricModel& model : models_) {
    for (const Record& record : records_) {
      if (model.good_direction == 0 && record.censored &&
          record.censored->metric == model.name) {
        model.good_direction = -record.censored->side;
      }
    }
  }
  // Prior slope sizes per knob: resources help; the diagnoses of the runs
  // strengthen the knobs they name on balance. A feasible run's counts
  // too: the start's diagnosis already says which resource the stack is
  // short of (docs/agent_development.md, "Diagnoses of feasible runs").
  std::vector<double> prior(knobs_.size(), 0.0);
  std::vector<int> votes(knobs_.size(), 0);
  for (const Record& record : records_) {
    if (record.failed) continue;
    const std::vector<int> direction = RemedyDirections(record, nullptr);
    for (size_t d = 0; d < knobs_.size(); ++d) votes[d] += direction[d];
  }
  rate_raised_.assign(knobs_.size(), false);
  for (size_t d = 0; d < knobs_.size(); ++d) {
    const KnobRole role = knobs_[d].role;
    rate_raised_[d] = role == KnobRole::kSensorRate && votes[d] > 0;
    if (role == KnobRole::kCores || role == KnobRole::kFrequency) {
      // Per unit of log capacity, cores and clock help alike: the prior is
      // an elasticity, so over the normalised knob it scales with the
      // knob's log range (1..28 cores spans 4.5 times 1.0..2.1 GHz).
      prior[d] =
          (votes[d] > 0 ? kVotedElasticity : kElasticity) * knobs_[d].log_range;
    } else if (role == KnobRole::kSensorRate) {
      // A faster sensor loads the whole chain behind it: it hurts, by
      // default a little; the diagnosis may say which way it goes here.
      prior[d] = votes[d] > 0   ? kRateVote
                 : votes[d] < 0 ? -kVotedElasticity * knobs_[d].log_range
                                : -kSensorElasticity * knobs_[d].log_range;
    } else if (role == KnobRole::kDownsample) {
      // Coarser data is less work, as a slower sensor is; what it costs
      // in precision is turned round per metric below.
      prior[d] = kSensorElasticity * knobs_[d].log_range;
    }
  }
  const size_t first =
      records_.size() > kMaxModelPoints ? records_.size() - kMaxModelPoints : 0;
  // Runs that did not complete (timed out) report censored metrics: when
  // a completion flag is modelled, it alone speaks for them.
  bool completion_modelled = false;
  for (const MetricModel& model : models_) {
    completion_modelled =
        completion_modelled ||
        (model.name == kCompletedMetric && model.in_constraint);
  }
  for (MetricModel& model : models_) {
    std::vector<std::vector<double>> u;
    std::vector<double> values;
    std::vector<int> sides;
    std::vector<double> paced;  // as `values`, a stopped time at its pace
    for (size_t i = first; i < records_.size(); ++i) {
      const Record& record = records_[i];
      if (record.failed) continue;
      if (completion_modelled && model.name != kCompletedMetric) {
        auto done = record.observation.metrics.find(kCompletedMetric);
        if (done != record.observation.metrics.end() && done->second == 0.0) {
          continue;
        }
      }
      if (record.censored && record.censored->metric == model.name) {
        u.push_back(Coordinates(record.genes));
        values.push_back(record.censored->bound);
        paced.push_back(record.censored->paced_bound);
        sides.push_back(record.censored->side);
        continue;
      }
      auto it = record.observation.metrics.find(model.name);
      if (it == record.observation.metrics.end() ||
          !std::isfinite(it->second)) {
        continue;
      }
      u.push_back(Coordinates(record.genes));
      values.push_back(it->second);
      paced.push_back(it->second);
      sides.push_back(0);
    }
    // Stopped times at their pace once a run has measured one (see
    // CensoredBound::paced_bound).
    if (std::count(sides.begin(), sides.end(), 0) > 0) values = paced;
    std::vector<double> slope = prior;
    if (model.precision_hint) {
      for (size_t d = 0; d < knobs_.size(); ++d) {
        if (knobs_[d].role == KnobRole::kDownsample) slope[d] = -slope[d];
      }
    }
    if (!model.in_constraint) {
      for (double& s : slope) s *= 0.4;
    }
    // Capacity and load have a sure direction; a downsampling step does
    // not: coarser data sheds load but localizes loosely, which can slow
    // the car (the voxel size's best value depends on the computer).
    model.signed_slopes.assign(knobs_.size(), false);
    for (size_t d = 0; d < knobs_.size(); ++d) {
      model.signed_slopes[d] = knobs_[d].role == KnobRole::kCores ||
                               knobs_[d].role == KnobRole::kFrequency ||
                               knobs_[d].role == KnobRole::kSensorRate;
    }
    model.Fit(u, values, sides, slope, lengths_);
  }
  any_failed_ = false;
  for (const Record& record : records_) {
    any_failed_ = any_failed_ || record.failed;
  }
}
}  // namespace internal

std::unique_ptr<Strategy> NewAgentStrategy(const spec::Spec& spec) {
  return std::make_unique<internal::AgentStrategy>(spec);
}

}  // namespace adse::explore
