// The evolutionary strategies: `ga` (the reference baseline, a scalar
// fitness) and `nsga2` (non-dominated rank and crowding distance). Both are
// generational (mu + lambda): a random initial population, then each
// generation breeds children by binary tournament, uniform crossover and
// per-gene mutation, and keeps the best `population` of parents and
// children. A generation is bred only once every point of the previous one
// has been told, so Ask returns nothing while evaluations are outstanding.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <memory>
#include <numeric>
#include <utility>

#include "analysis/pareto/pareto.h"
#include "harness/explore/strategy.h"

namespace adse::explore {
namespace {

// Re-mutations tried on a child that duplicates a seen point before it is
// replaced by a random unseen point.
constexpr int kMaxRemutations = 16;

struct Individual {
  Genes genes;
  Observation observation;
  std::vector<double> objectives;  // minimisation form, NaN when unknown
  double violation = 0.0;          // 0 feasible, +inf failed
};

// Lower is better, compared lexicographically.
using SortKey = std::pair<double, double>;

class EvolutionaryStrategy : public Strategy {
 public:
  EvolutionaryStrategy(const spec::Spec& spec, std::string name)
      : spec_(&spec),
        name_(std::move(name)),
        grid_(spec.design_space),
        budget_(std::max(0, spec.exploration.budget)),
        population_size_(std::max(2, spec.exploration.population)),
        crossover_rate_(spec.exploration.crossover_rate),
        mutation_rate_(spec.exploration.mutation_rate),
        random_(Random::DeriveSeed(spec.exploration.seed,
                                   "explore." + name_ + ".operators")),
        sampler_(&grid_, Random::DeriveSeed(spec.exploration.seed,
                                            "explore." + name_ + ".sample")) {}

  std::vector<spec::DesignPoint> Ask(int k) override {
    if (queue_.empty() && pending_.empty() && proposed_ < budget_) {
      Breed();
    }
    std::vector<spec::DesignPoint> points;
    while (static_cast<int>(points.size()) < k && !queue_.empty() &&
           proposed_ < budget_) {
      points.push_back(grid_.ToPoint(queue_.front()));
      pending_.insert(queue_.front());
      queue_.pop_front();
      ++proposed_;
    }
    if (points.empty()) {
      if (!pending_.empty()) {
        rationale_ =
            fmt::format("{}: waiting for {} evaluation(s) of generation {}",
                        name_, pending_.size(), generation_ - 1);
      } else if (proposed_ >= budget_) {
        rationale_ =
            fmt::format("{}: the budget of {} is spent", name_, budget_);
      } else {
        rationale_ = fmt::format("{}: no unseen point is left", name_);
      }
    } else {
      rationale_ = breed_rationale_;
    }
    return points;
  }

  void Tell(const Observation& observation) override {
    std::optional<Genes> genes = grid_.FromPoint(observation.point);
    if (!genes || told_.count(*genes)) return;  // foreign or repeated
    told_.insert(*genes);
    seen_.insert(*genes);
    pending_.erase(*genes);
    Individual individual;
    individual.genes = *genes;
    individual.observation = observation;
    individual.objectives = MinimizationObjectives(*spec_, observation);
    if (individual.objectives.empty() && !observation.failed) {
      // No objectives: every usable run is equally good.
      individual.objectives.push_back(0.0);
    }
    individual.violation = ConstraintViolation(*spec_, observation);
    fresh_.push_back(static_cast<int>(archive_.size()));
    archive_.push_back(std::move(individual));
  }

  std::string name() const override { return name_; }
  // A generation is evaluated as one round.
  int RoundSize(int /*batch*/) const override { return population_size_; }
  std::string rationale() const override { return rationale_; }

 protected:
  // Sort keys of `pool` (indices into archive_), lower is better.
  virtual std::vector<SortKey> Score(const std::vector<int>& pool) const = 0;
  // How the selection works, for the rationale.
  virtual std::string SelectionText() const = 0;

  const spec::Spec* spec_;
  std::vector<Individual> archive_;

 private:
  // Queues the next generation (or the initial population).
  void Breed() {
    const int n = std::min(population_size_, budget_ - proposed_);
    if (n <= 0) return;
    if (generation_ == 0 || (population_.empty() && fresh_.empty())) {
      int added = 0;
      if (generation_ == 0 && !spec_->exploration.start_from.empty()) {
        std::optional<Genes> start =
            grid_.FromPoint(spec_->exploration.start_from);
        if (start && Enqueue(*start)) ++added;
      }
      while (added < n) {
        std::optional<Genes> genes = sampler_.Next(seen_);
        if (!genes || !Enqueue(*genes)) break;
        ++added;
      }
      breed_rationale_ = fmt::format(
          "{}: generation {}, {} random point(s) as the initial population",
          name_, generation_, added);
      ++generation_;
      return;
    }
    SelectSurvivors();
    int added = 0;
    int replaced = 0;
    while (added < n) {
      Genes first = archive_[Tournament()].genes;
      Genes second = archive_[Tournament()].genes;
      if (random_.Bernoulli(crossover_rate_)) {
        for (size_t d = 0; d < first.size(); ++d) {
          if (random_.Bernoulli(0.5)) std::swap(first[d], second[d]);
        }
      }
      bool exhausted = false;
      for (Genes* child : {&first, &second}) {
        if (added >= n) break;
        for (size_t d = 0; d < child->size(); ++d) {
          if (random_.Bernoulli(mutation_rate_)) MutateGene(*child, d);
        }
        for (int attempt = 0; attempt < kMaxRemutations && seen_.count(*child);
             ++attempt) {
          MutateGene(*child, random_.Below(child->size()));
        }
        if (seen_.count(*child)) {
          std::optional<Genes> fresh = sampler_.Next(seen_);
          if (!fresh) {
            exhausted = true;
            break;
          }
          *child = *fresh;
          ++replaced;
        }
        Enqueue(*child);
        ++added;
      }
      if (exhausted) break;
    }
    breed_rationale_ = fmt::format(
        "{}: generation {}, {} child(ren) of binary-tournament parents ({}) "
        "from a population of {}, uniform crossover {:.2f}, mutation {:.2f}{}",
        name_, generation_, added, SelectionText(), population_.size(),
        crossover_rate_, mutation_rate_,
        replaced > 0 ? fmt::format("; {} duplicate(s) replaced by random "
                                   "unseen points",
                                   replaced)
                     : std::string());
    ++generation_;
  }

  // (mu + lambda): the best population_size_ of parents and new results.
  void SelectSurvivors() {
    std::vector<int> pool = population_;
    pool.insert(pool.end(), fresh_.begin(), fresh_.end());
    fresh_.clear();
    const std::vector<SortKey> keys = Score(pool);
    std::vector<size_t> order(pool.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&keys](size_t a, size_t b) { return keys[a] < keys[b]; });
    population_.clear();
    population_keys_.clear();
    for (size_t i = 0; i < order.size() &&
                       static_cast<int>(population_.size()) < population_size_;
         ++i) {
      population_.push_back(pool[order[i]]);
      population_keys_.push_back(keys[order[i]]);
    }
  }

  // Binary tournament on the survivors' keys; returns an archive index.
  int Tournament() {
    const uint64_t size = population_.size();
    const size_t a = random_.Below(size);
    const size_t b = random_.Below(size);
    return population_[population_keys_[b] < population_keys_[a] ? b : a];
  }

  // Moves one gene: half the time to a neighbouring value (local steps
  // suit ordered parameters like cores), else to any other allowed value.
  void MutateGene(Genes& genes, size_t d) {
    const int count = grid_.count(d);
    if (count <= 1) return;
    if (random_.Bernoulli(0.5)) {
      const bool up =
          genes[d] == 0 || (genes[d] < count - 1 && random_.Bernoulli(0.5));
      genes[d] += up ? 1 : -1;
    } else {
      int value = static_cast<int>(random_.Below(count - 1));
      if (value >= genes[d]) ++value;
      genes[d] = value;
    }
  }

  bool Enqueue(const Genes& genes) {
    if (!seen_.insert(genes).second) return false;
    queue_.push_back(genes);
    return true;
  }

  std::string name_;
  SpaceGrid grid_;
  int budget_;
  int population_size_;
  double crossover_rate_;
  double mutation_rate_;
  Random random_;
  UnseenSampler sampler_;

  int proposed_ = 0;
  int generation_ = 0;
  std::set<Genes> seen_;  // proposed, queued or told
  std::set<Genes> told_;
  std::set<Genes> pending_;      // proposed, not yet told
  std::deque<Genes> queue_;      // bred, not yet proposed
  std::vector<int> population_;  // archive indices of the survivors
  std::vector<SortKey> population_keys_;
  std::vector<int> fresh_;  // archive indices told since the last selection
  std::string rationale_;
  std::string breed_rationale_;
};

// Feasible first, then fewer violated constraints, then the smallest sum of
// objectives normalised to [0, 1] over the pool (unknown values count 1).
class GeneticStrategy : public EvolutionaryStrategy {
 public:
  explicit GeneticStrategy(const spec::Spec& spec)
      : EvolutionaryStrategy(spec, "ga") {}

 protected:
  std::vector<SortKey> Score(const std::vector<int>& pool) const override {
    const size_t m = spec_->objectives.size();
    std::vector<double> lo(m, std::numeric_limits<double>::infinity());
    std::vector<double> hi(m, -std::numeric_limits<double>::infinity());
    for (int i : pool) {
      const std::vector<double>& objectives = archive_[i].objectives;
      for (size_t j = 0; j < m && j < objectives.size(); ++j) {
        if (!std::isfinite(objectives[j])) continue;
        lo[j] = std::min(lo[j], objectives[j]);
        hi[j] = std::max(hi[j], objectives[j]);
      }
    }
    std::vector<SortKey> keys;
    keys.reserve(pool.size());
    for (int i : pool) {
      const Individual& individual = archive_[i];
      double fitness = 0.0;
      for (size_t j = 0; j < m; ++j) {
        const double v =
            j < individual.objectives.size() ? individual.objectives[j] : NAN;
        if (!std::isfinite(v)) {
          fitness += 1.0;
        } else if (hi[j] > lo[j]) {
          fitness += (v - lo[j]) / (hi[j] - lo[j]);
        }
      }
      keys.emplace_back(individual.violation, fitness);
    }
    return keys;
  }

  std::string SelectionText() const override {
    return "feasible first, then the sum of normalised objectives";
  }
};

// Non-dominated rank (constraint-aware, adse_pareto), then the larger
// crowding distance within the rank.
class Nsga2Strategy : public EvolutionaryStrategy {
 public:
  explicit Nsga2Strategy(const spec::Spec& spec)
      : EvolutionaryStrategy(spec, "nsga2") {}

 protected:
  std::vector<SortKey> Score(const std::vector<int>& pool) const override {
    std::vector<analysis::Evaluation> evaluations;
    evaluations.reserve(pool.size());
    for (int i : pool) {
      const Individual& individual = archive_[i];
      analysis::Evaluation evaluation;
      evaluation.point = individual.observation.point;
      evaluation.objectives = individual.objectives;
      evaluation.feasible = individual.violation == 0.0;
      evaluation.violation = individual.violation;
      evaluations.push_back(std::move(evaluation));
    }
    const std::vector<int> ranks = analysis::ParetoRanks(evaluations);
    std::vector<double> crowding(pool.size(), 0.0);
    std::map<int, std::vector<size_t>> fronts;
    for (size_t i = 0; i < ranks.size(); ++i) fronts[ranks[i]].push_back(i);
    for (const auto& [rank, members] : fronts) {
      (void)rank;
      AddCrowding(evaluations, members, crowding);
    }
    std::vector<SortKey> keys;
    keys.reserve(pool.size());
    for (size_t i = 0; i < pool.size(); ++i) {
      const double rank =
          i < ranks.size() ? ranks[i] : std::numeric_limits<double>::infinity();
      keys.emplace_back(rank, -crowding[i]);
    }
    return keys;
  }

  std::string SelectionText() const override {
    return "non-dominated rank, then crowding distance";
  }

 private:
  // Standard NSGA-II crowding: per objective, the normalised gap between a
  // member's neighbours; the extremes get +inf so they are kept.
  static void AddCrowding(const std::vector<analysis::Evaluation>& evaluations,
                          const std::vector<size_t>& members,
                          std::vector<double>& crowding) {
    size_t m = 0;
    for (size_t i : members) m = std::max(m, evaluations[i].objectives.size());
    for (size_t j = 0; j < m; ++j) {
      std::vector<size_t> usable;
      for (size_t i : members) {
        if (j < evaluations[i].objectives.size() &&
            std::isfinite(evaluations[i].objectives[j])) {
          usable.push_back(i);
        }
      }
      if (usable.size() < 2) continue;
      auto value = [&](size_t i) { return evaluations[i].objectives[j]; };
      std::stable_sort(usable.begin(), usable.end(),
                       [&](size_t a, size_t b) { return value(a) < value(b); });
      const double range = value(usable.back()) - value(usable.front());
      crowding[usable.front()] = std::numeric_limits<double>::infinity();
      crowding[usable.back()] = std::numeric_limits<double>::infinity();
      if (range <= 0) continue;
      for (size_t k = 1; k + 1 < usable.size(); ++k) {
        crowding[usable[k]] +=
            (value(usable[k + 1]) - value(usable[k - 1])) / range;
      }
    }
  }
};

}  // namespace

std::unique_ptr<Strategy> NewGeneticStrategy(const spec::Spec& spec) {
  return std::make_unique<GeneticStrategy>(spec);
}

std::unique_ptr<Strategy> NewNsga2Strategy(const spec::Spec& spec) {
  return std::make_unique<Nsga2Strategy>(spec);
}

}  // namespace adse::explore
