// Exhaustive enumeration in lexicographic order (parameters in file order,
// the first varying slowest), starting at `start_from` when set and
// wrapping around so the whole space is still covered once.
#include <fmt/format.h>

#include <algorithm>
#include <memory>

#include "harness/explore/strategy.h"

namespace adse::explore {
namespace {

class ExhaustiveStrategy : public Strategy {
 public:
  explicit ExhaustiveStrategy(const spec::Spec& spec)
      : grid_(spec.design_space),
        budget_(std::max(0, spec.exploration.budget)),
        cursor_(grid_.dimensions(), 0) {
    if (!spec.exploration.start_from.empty()) {
      std::optional<Genes> start = grid_.FromPoint(spec.exploration.start_from);
      if (start) cursor_ = *start;
    }
    start_ = cursor_;
  }

  std::vector<spec::DesignPoint> Ask(int k) override {
    std::vector<spec::DesignPoint> points;
    const int first = proposed_ + 1;
    while (static_cast<int>(points.size()) < k && proposed_ < budget_ &&
           !done_) {
      Genes genes = cursor_;
      Advance();
      if (seen_.insert(genes).second) {
        points.push_back(grid_.ToPoint(genes));
        ++proposed_;
      }
    }
    if (points.empty()) {
      rationale_ = done_ ? "exhaustive: the whole space has been proposed"
                         : "exhaustive: the budget is spent";
    } else {
      rationale_ = fmt::format(
          "exhaustive: points {}-{} in lexicographic order{}", first, proposed_,
          grid_.saturated() ? std::string()
                            : fmt::format(" of {}", grid_.size()));
    }
    return points;
  }

  void Tell(const Observation& observation) override {
    // Told points are skipped when the enumeration reaches them.
    if (std::optional<Genes> genes = grid_.FromPoint(observation.point)) {
      seen_.insert(*genes);
    }
  }

  std::string name() const override { return "exhaustive"; }
  bool adaptive() const override { return false; }
  std::string rationale() const override { return rationale_; }

 private:
  // Odometer step: the last parameter varies fastest; wraps around and
  // stops when it is back at the start.
  void Advance() {
    for (size_t d = cursor_.size(); d-- > 0;) {
      if (++cursor_[d] < grid_.count(d)) break;
      cursor_[d] = 0;
    }
    done_ = cursor_ == start_;
  }

  SpaceGrid grid_;
  int budget_;
  int proposed_ = 0;
  Genes cursor_;
  Genes start_;
  bool done_ = false;
  std::set<Genes> seen_;
  std::string rationale_;
};

}  // namespace

std::unique_ptr<Strategy> NewExhaustiveStrategy(const spec::Spec& spec) {
  return std::make_unique<ExhaustiveStrategy>(spec);
}

}  // namespace adse::explore
