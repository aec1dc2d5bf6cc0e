// Uniform random search without replacement; `start_from`, when set, is
// proposed first.
#include <fmt/format.h>

#include <algorithm>
#include <memory>

#include "harness/explore/strategy.h"

namespace adse::explore {
namespace {

class RandomStrategy : public Strategy {
 public:
  explicit RandomStrategy(const spec::Spec& spec)
      : grid_(spec.design_space),
        budget_(std::max(0, spec.exploration.budget)),
        sampler_(&grid_,
                 Random::DeriveSeed(spec.exploration.seed, "explore.random")) {
    if (!spec.exploration.start_from.empty()) {
      start_ = grid_.FromPoint(spec.exploration.start_from);
    }
  }

  std::vector<spec::DesignPoint> Ask(int k) override {
    std::vector<spec::DesignPoint> points;
    if (start_ && static_cast<int>(points.size()) < k && proposed_ < budget_) {
      if (seen_.insert(*start_).second) {
        points.push_back(grid_.ToPoint(*start_));
        ++proposed_;
      }
      start_.reset();
    }
    while (static_cast<int>(points.size()) < k && proposed_ < budget_) {
      std::optional<Genes> genes = sampler_.Next(seen_);
      if (!genes) break;
      seen_.insert(*genes);
      points.push_back(grid_.ToPoint(*genes));
      ++proposed_;
    }
    rationale_ =
        points.empty()
            ? std::string("random: nothing left to propose (budget or space)")
            : fmt::format(
                  "random: {} point(s) drawn uniformly among unseen "
                  "ones ({} of budget {})",
                  points.size(), proposed_, budget_);
    return points;
  }

  void Tell(const Observation& observation) override {
    if (std::optional<Genes> genes = grid_.FromPoint(observation.point)) {
      seen_.insert(*genes);
    }
  }

  std::string name() const override { return "random"; }
  bool adaptive() const override { return false; }
  std::string rationale() const override { return rationale_; }

 private:
  SpaceGrid grid_;
  int budget_;
  int proposed_ = 0;
  UnseenSampler sampler_;
  std::optional<Genes> start_;
  std::set<Genes> seen_;
  std::string rationale_;
};

}  // namespace

std::unique_ptr<Strategy> NewRandomStrategy(const spec::Spec& spec) {
  return std::make_unique<RandomStrategy>(spec);
}

}  // namespace adse::explore
