#include "harness/explore/strategy.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <utility>

#include "harness/spec/spec_parser.h"
#include "harness/spec/types.h"

namespace adse::explore {
namespace {

// Random draws tried before a saturated (astronomically large) space is
// declared exhausted; a hit on a seen point there is already unlikely.
constexpr int kSaturatedDrawAttempts = 1000;

}  // namespace

SpaceGrid::SpaceGrid(const spec::DesignSpace& space) : space_(&space) {
  counts_.reserve(space.parameters.size());
  for (const spec::DesignParameter& parameter : space.parameters) {
    const int n = static_cast<int>(parameter.values.size());
    counts_.push_back(n);
    if (n <= 0) continue;
    const uint64_t un = static_cast<uint64_t>(n);
    // UINT64_MAX itself is reserved: "saturated" like DesignSpace::Size.
    if (saturated_ || size_ > (std::numeric_limits<uint64_t>::max() - 1) / un) {
      saturated_ = true;
    } else {
      size_ *= un;
    }
  }
}

spec::DesignPoint SpaceGrid::ToPoint(const Genes& genes) const {
  spec::DesignPoint point;
  for (size_t d = 0; d < counts_.size() && d < genes.size(); ++d) {
    const spec::DesignParameter& parameter = space_->parameters[d];
    point[parameter.name] = parameter.values[genes[d]];
  }
  return point;
}

std::optional<Genes> SpaceGrid::FromPoint(
    const spec::DesignPoint& point) const {
  Genes genes(counts_.size(), 0);
  for (size_t d = 0; d < counts_.size(); ++d) {
    const spec::DesignParameter& parameter = space_->parameters[d];
    auto it = point.find(parameter.name);
    if (it == point.end()) return std::nullopt;
    const int index = parameter.IndexOf(it->second);
    if (index < 0) return std::nullopt;
    genes[d] = index;
  }
  return genes;
}

Genes SpaceGrid::Decode(uint64_t index) const {
  Genes genes(counts_.size(), 0);
  for (size_t d = counts_.size(); d-- > 0;) {
    const uint64_t n = static_cast<uint64_t>(counts_[d]);
    genes[d] = static_cast<int>(index % n);
    index /= n;
  }
  return genes;
}

uint64_t SpaceGrid::Encode(const Genes& genes) const {
  uint64_t index = 0;
  for (size_t d = 0; d < counts_.size(); ++d) {
    index = index * static_cast<uint64_t>(counts_[d]) +
            static_cast<uint64_t>(genes[d]);
  }
  return index;
}

Genes SpaceGrid::RandomGenes(Random& random) const {
  Genes genes(counts_.size(), 0);
  for (size_t d = 0; d < counts_.size(); ++d) {
    genes[d] =
        static_cast<int>(random.Below(static_cast<uint64_t>(counts_[d])));
  }
  return genes;
}

UnseenSampler::UnseenSampler(const SpaceGrid* grid, uint64_t seed)
    : grid_(grid), random_(seed), remaining_(grid->size()) {}

std::optional<Genes> UnseenSampler::Next(const std::set<Genes>& seen) {
  if (grid_->saturated()) {
    for (int attempt = 0; attempt < kSaturatedDrawAttempts; ++attempt) {
      Genes genes = grid_->RandomGenes(random_);
      if (!seen.count(genes)) return genes;
    }
    return std::nullopt;
  }
  // Each draw retires one index, so skipping seen points terminates.
  while (remaining_ > 0) {
    const uint64_t j = random_.Below(remaining_);
    const uint64_t last = remaining_ - 1;
    auto at = [this](uint64_t i) {
      auto it = swapped_.find(i);
      return it == swapped_.end() ? i : it->second;
    };
    const uint64_t drawn = at(j);
    swapped_[j] = at(last);
    swapped_.erase(last);
    --remaining_;
    Genes genes = grid_->Decode(drawn);
    if (!seen.count(genes)) return genes;
  }
  return std::nullopt;
}

namespace {

// How badly `observation` misses the constraints; `violated_count` counts
// the ones that do not hold and is called only when the observation
// itself does not settle it (parsing constraints is most of the cost).
template <typename Count>
double ViolationOf(const Observation& observation, Count violated_count) {
  if (observation.failed) return std::numeric_limits<double>::infinity();
  if (observation.feasible) return 0.0;
  return std::max(violated_count(), 1);
}

// ParetoEvaluationOf with its violation given.
analysis::Evaluation EvaluationOf(const spec::Spec& spec,
                                  const Observation& observation,
                                  double violation) {
  analysis::Evaluation input;
  input.point = observation.point;
  input.objectives = MinimizationObjectives(spec, observation);
  input.violation = violation;
  input.feasible = observation.feasible && !observation.failed;
  for (double& v : input.objectives) {
    // Unplaceable runs still take part, ranked behind every placed one.
    if (!std::isfinite(v)) {
      input.feasible = false;
      v = std::numeric_limits<double>::max();
    }
  }
  if (!std::isfinite(input.violation)) input.violation = 1e9;
  if (!input.feasible && input.violation == 0.0) input.violation = 1.0;
  return input;
}

}  // namespace

analysis::Evaluation ParetoEvaluationOf(const spec::Spec& spec,
                                        const Observation& observation) {
  return EvaluationOf(spec, observation,
                      ConstraintViolation(spec, observation));
}

std::vector<int> ParetoFrontOf(const spec::Spec& spec,
                               const std::vector<Observation>& observations) {
  // Parsed once for all the rows.
  const spec::ConstraintChecker checker(spec);
  std::vector<analysis::Evaluation> evals;
  evals.reserve(observations.size());
  for (const Observation& o : observations) {
    const double violation = ViolationOf(
        o, [&] { return checker.ViolatedCount(o.metrics, o.point); });
    evals.push_back(EvaluationOf(spec, o, violation));
  }
  return analysis::ParetoFront(evals);
}

std::vector<double> MinimizationObjectives(const spec::Spec& spec,
                                           const Observation& observation) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> values;
  values.reserve(spec.objectives.size());
  for (const spec::Objective& objective : spec.objectives) {
    auto it = observation.metrics.find(objective.metric);
    if (observation.failed || it == observation.metrics.end()) {
      values.push_back(kNaN);
    } else {
      values.push_back(objective.minimize ? it->second : -it->second);
    }
  }
  return values;
}

double ConstraintViolation(const spec::Spec& spec,
                           const Observation& observation) {
  return ViolationOf(observation, [&] {
    return spec::ViolatedConstraintCount(spec, observation.metrics,
                                         observation.point);
  });
}

const std::vector<std::string>& StrategyNames() {
  // The format's list without the one harness/llm builds.
  static const std::vector<std::string> kNames = [] {
    std::vector<std::string> names;
    for (const std::string& n : spec::StrategyNames()) {
      if (n != spec::kLlmStrategy) names.push_back(n);
    }
    return names;
  }();
  return kNames;
}

Result<std::unique_ptr<Strategy>> CreateStrategy(
    const std::string& name, const StrategyContext& context) {
  const std::vector<std::string>& names = StrategyNames();
  bool known = false;
  for (const std::string& n : names) known = known || n == name;
  if (!known) {
    return Status::InvalidArgument(
        fmt::format("unknown exploration strategy '{}'; valid: {}", name,
                    fmt::join(names, ", ")));
  }
  if (context.spec == nullptr) {
    return Status::InvalidArgument("exploration strategy needs a spec");
  }
  const spec::Spec& spec = *context.spec;
  if (spec.design_space.parameters.empty()) {
    return Status::InvalidArgument(
        "exploration needs a design space with at least one parameter");
  }
  for (const spec::DesignParameter& parameter : spec.design_space.parameters) {
    if (parameter.values.empty()) {
      return Status::InvalidArgument(fmt::format(
          "design parameter '{}' has no allowed values", parameter.name));
    }
  }
  if (name == "exhaustive") return NewExhaustiveStrategy(spec);
  if (name == "random") return NewRandomStrategy(spec);
  if (name == "ga") return NewGeneticStrategy(spec);
  if (name == "agent") return NewAgentStrategy(spec);
  return NewNsga2Strategy(spec);
}

}  // namespace adse::explore
