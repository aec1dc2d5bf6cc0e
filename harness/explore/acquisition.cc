// The agent's acquisition: candidate points, joint samples of their
// predicted outcomes, and the choice by expected front gain.
#include "harness/explore/internal/agent_strategy.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "analysis/pareto/pareto.h"
#include "harness/spec/spec_parser.h"

namespace adse::explore::internal {

std::vector<Genes> AgentStrategy::Candidates(const std::vector<Genes>& chosen) {
  std::vector<Genes> out;
  auto usable = [&](const Genes& genes) {
    return !seen_.count(genes) &&
           std::find(chosen.begin(), chosen.end(), genes) == chosen.end();
  };
  if (!grid_.saturated() && grid_.size() <= kEnumerateLimit) {
    for (uint64_t i = 0; i < grid_.size(); ++i) {
      Genes genes = grid_.Decode(i);
      if (usable(genes)) out.push_back(std::move(genes));
    }
    return out;
  }
  std::set<Genes> pool;
  // Neighbours (one and two steps along each knob) of the latest runs,
  // then uniform draws.
  const size_t first =
      records_.size() > kNeighbourhoods ? records_.size() - kNeighbourhoods : 0;
  for (size_t i = first; i < records_.size(); ++i) {
    const Genes& around = records_[i].genes;
    for (size_t d = 0; d < around.size(); ++d) {
      for (int step : {-2, -1, 1, 2}) {
        Genes genes = around;
        genes[d] += step;
        if (genes[d] < 0 || genes[d] >= grid_.count(d)) continue;
        if (usable(genes)) pool.insert(genes);
      }
    }
  }
  const size_t target = pool.size() + kSampledCandidates;
  for (int i = 0; i < 4 * kSampledCandidates && pool.size() < target; ++i) {
    Genes genes = grid_.RandomGenes(random_);
    if (usable(genes)) pool.insert(genes);
  }
  out.assign(pool.begin(), pool.end());
  return out;
}

double AgentStrategy::Cost(const Genes& genes) const {
  Result<double> cost = spec::EvaluateCost(*spec_, grid_.ToPoint(genes));
  return cost.ok() ? *cost : kNaN;
}

const MetricModel* AgentStrategy::FittedObjectiveModel(size_t j) const {
  const int m = objective_model_[j];
  return m >= 0 && models_[m].fitted() ? &models_[m] : nullptr;
}

bool AgentStrategy::SampleOutcome(
    const Candidate& c, int s, std::vector<double>* objectives,
    std::map<std::string, double>* scratch) const {
  std::map<std::string, double>& values = *scratch;
  values.clear();
  for (size_t m = 0; m < models_.size(); ++m) {
    if (!models_[m].fitted()) continue;
    values[models_[m].name] =
        models_[m].ToMetric(c.mean[m] + c.sd[m] * z_[s][m]);
  }
  if (std::isfinite(c.cost)) values[kCostMetric] = c.cost;
  objectives->resize(spec_->objectives.size());
  for (size_t j = 0; j < spec_->objectives.size(); ++j) {
    const spec::Objective& objective = spec_->objectives[j];
    double v = 0.0;
    if (objective.metric == kCostMetric) {
      v = c.cost;
    } else if (const MetricModel* model = FittedObjectiveModel(j)) {
      v = model->Bounded(values[objective.metric]);
    }
    (*objectives)[j] = objective.minimize ? v : -v;
  }
  for (size_t d = 0; d < knobs_.size(); ++d) {
    values[knobs_[d].parameter->name] = knobs_[d].parameter->values[c.genes[d]];
  }
  if (c.verdict == Verdict::kFails) return false;
  for (const CapacityConstraint& capacity : constraints_) {
    const spec::Expression& constraint = capacity.expression;
    // A run with less capacity already met the metric constraints.
    if (c.verdict == Verdict::kHolds && capacity.metric_only) continue;
    // A constraint on a metric no run has shown yet cannot be predicted:
    // it is taken to hold until a run says otherwise.
    bool known = true;
    for (const std::string& variable : constraint.variables()) {
      known = known && values.count(variable) > 0;
    }
    if (!known) continue;
    const double v = constraint.Evaluate(values);
    if (!std::isfinite(v) || v == 0.0) return false;
  }
  return true;
}

std::vector<double> AgentStrategy::MeanObjectives(const Candidate& c) const {
  std::vector<double> mean(spec_->objectives.size(), 0.0);
  std::vector<double> o;
  std::map<std::string, double> scratch;
  for (int s = 0; s < kSamples; ++s) {
    SampleOutcome(c, s, &o, &scratch);
    for (size_t j = 0; j < o.size(); ++j) mean[j] += o[j] / kSamples;
  }
  return mean;
}

std::string AgentStrategy::Choose(int n, std::vector<Genes>* chosen) {
  const int wanted = n - static_cast<int>(chosen->size());
  std::vector<Genes> pool = Candidates(*chosen);
  if (pool.empty()) return {};
  int usable_runs = 0;
  for (const Record& record : records_) usable_runs += record.failed ? 0 : 1;
  FitModels();

  std::vector<Candidate> candidates(pool.size());
  for (size_t i = 0; i < pool.size(); ++i) {
    Candidate& c = candidates[i];
    c.genes = pool[i];
    c.u = Coordinates(c.genes);
    c.cost = Cost(c.genes);
    c.verdict = CapacityVerdict(c.genes);
    c.mean.assign(models_.size(), 0.0);
    c.sd.assign(models_.size(), 1.0);
    for (size_t m = 0; m < models_.size(); ++m) {
      if (models_[m].fitted()) models_[m].Predict(c.u, &c.mean[m], &c.sd[m]);
    }
  }
  ApplyFactors(&candidates);
  for (Candidate& c : candidates) c.runs = RunsProbability(c);

  if (usable_runs == 0) {
    // Nothing to model yet: spread out, away from failures, from the
    // middle of the space.
    std::string text = SpaceFilling(&candidates, wanted, chosen);
    return text;
  }

  // Joint samples of every candidate's outcome (objectives, feasible),
  // computed once.
  const size_t nobj = spec_->objectives.size();
  std::map<std::string, double> scratch;
  std::vector<std::vector<std::vector<double>>> normalised(candidates.size());
  std::vector<std::vector<bool>> feasible(candidates.size());
  std::vector<std::vector<double>> mean_objectives(candidates.size());
  for (size_t i = 0; i < candidates.size(); ++i) {
    normalised[i].resize(kSamples);
    feasible[i].resize(kSamples);
    mean_objectives[i].assign(nobj, 0.0);
    int count = 0;
    for (int s = 0; s < kSamples; ++s) {
      feasible[i][s] =
          SampleOutcome(candidates[i], s, &normalised[i][s], &scratch);
      count += feasible[i][s] ? 1 : 0;
      for (size_t j = 0; j < nobj; ++j) {
        mean_objectives[i][j] += normalised[i][s][j] / kSamples;
      }
    }
    candidates[i].p_feasible = static_cast<double>(count) / kSamples;
  }
  // A design with no less capacity than another (by the knobs' roles) is
  // no less likely to meet the constraints: far from the runs, a wide
  // prediction would otherwise make an extreme corner with a faster
  // sensor look likelier than the same computer with a slower one.
  std::vector<double> envelope(candidates.size());
  for (size_t i = 0; i < candidates.size(); ++i) {
    envelope[i] = candidates[i].p_feasible;
    for (size_t j = 0; j < candidates.size(); ++j) {
      if (candidates[j].p_feasible <= envelope[i]) continue;
      const int order =
          CompareCapacity(roles_, rate_raised_, candidates[i].genes,
                          candidates[j].genes, false);
      if (order == 0 || order == 1) envelope[i] = candidates[j].p_feasible;
    }
  }
  for (size_t i = 0; i < candidates.size(); ++i) {
    candidates[i].p_feasible = envelope[i] * candidates[i].runs;
  }

  // Objective scales: the range over feasible runs and the predictions
  // of candidates that may well be feasible.
  std::vector<double> lo(nobj, kInf), hi(nobj, -kInf);
  auto widen = [&](const std::vector<double>& o) {
    for (size_t j = 0; j < nobj; ++j) {
      if (!std::isfinite(o[j])) continue;
      lo[j] = std::min(lo[j], o[j]);
      hi[j] = std::max(hi[j], o[j]);
    }
  };
  for (const Record& record : records_) {
    if (record.feasible) widen(record.objectives);
  }
  for (size_t i = 0; i < candidates.size(); ++i) {
    if (candidates[i].p_feasible >= 0.25) widen(mean_objectives[i]);
  }
  for (size_t j = 0; j < nobj; ++j) {
    if (!(hi[j] > lo[j])) {
      if (!std::isfinite(lo[j])) lo[j] = 0.0;
      hi[j] = lo[j] + 1.0;
    }
  }
  auto normalise = [&](const std::vector<double>& o) {
    std::vector<double> out(nobj);
    for (size_t j = 0; j < nobj; ++j) {
      out[j] = std::isfinite(o[j]) ? (o[j] - lo[j]) / (hi[j] - lo[j]) : kInf;
    }
    return out;
  };
  for (size_t i = 0; i < candidates.size(); ++i) {
    for (int s = 0; s < kSamples; ++s) {
      normalised[i][s] = normalise(normalised[i][s]);
    }
  }
  const std::vector<double> ref(nobj, 1.1);

  // The current feasible front, plus pending points as predicted.
  std::vector<std::vector<double>> front;
  for (const Record& record : records_) {
    if (record.feasible) front.push_back(normalise(record.objectives));
  }
  for (const Genes& genes : pending_) {
    Candidate c = Predicted(genes);
    if (c.p_feasible >= 0.5) front.push_back(normalise(MeanObjectives(c)));
  }

  std::string text;
  std::vector<std::string> extra;

  while (static_cast<int>(chosen->size()) < n) {
    const double base = analysis::PointsHypervolume(front, ref);
    // Which candidates make the Pareto front in each sampled world: the
    // samples share their draws across candidates, so sample s is one
    // plausible version of the whole space, next to the feasible runs
    // seen and the points already chosen.
    std::vector<int> on_front(candidates.size(), 0);
    for (int s = 0; s < kSamples; ++s) {
      std::vector<int> order;
      for (size_t i = 0; i < candidates.size(); ++i) {
        if (feasible[i][s] && candidates[i].runs >= 0.5 &&
            std::find(chosen->begin(), chosen->end(), candidates[i].genes) ==
                chosen->end()) {
          order.push_back(static_cast<int>(i));
        }
      }
      // By the sum of objectives: no point is dominated by a later one.
      std::vector<double> sums(candidates.size(), 0.0);
      for (int i : order) {
        for (double v : normalised[i][s]) sums[i] += v;
      }
      std::stable_sort(order.begin(), order.end(),
                       [&sums](int a, int b) { return sums[a] < sums[b]; });
      std::vector<const std::vector<double>*> leaders;
      for (const auto& f : front) leaders.push_back(&f);
      for (int i : order) {
        const std::vector<double>& o = normalised[i][s];
        bool beaten = false;
        for (const std::vector<double>* f : leaders) {
          if (analysis::Dominates(*f, o)) {
            beaten = true;
            break;
          }
        }
        if (beaten) continue;
        ++on_front[i];
        leaders.push_back(&o);
      }
    }
    double max_gain = 0.0;
    for (size_t i = 0; i < candidates.size(); ++i) {
      Candidate& c = candidates[i];
      c.gain = 0.0;
      c.p_front = 0.0;
      if (std::find(chosen->begin(), chosen->end(), c.genes) != chosen->end()) {
        continue;
      }
      double gain = 0.0;
      for (int s = 0; s < kSamples; ++s) {
        if (!feasible[i][s]) continue;
        const std::vector<double>& o = normalised[i][s];
        bool dominated = false;
        for (const auto& f : front) {
          if (analysis::WeaklyDominates(f, o)) {
            dominated = true;
            break;
          }
        }
        if (dominated) continue;
        std::vector<std::vector<double>> with = front;
        with.push_back(o);
        gain += std::max(0.0, analysis::PointsHypervolume(with, ref) - base);
      }
      c.gain = gain / kSamples * c.runs;
      c.p_front = static_cast<double>(on_front[i]) / kSamples * c.runs;
      max_gain = std::max(max_gain, c.gain);
    }
    // What the user asked for is the cheapest feasible design: while no run
    // is feasible, on every kCheapestEvery-th pick after and on the
    // budget's last, the pick goes to the cheapest design instead of the
    // front's volume.
    const int best_cheap = CheapestPick(candidates, *chosen);
    if (best_cheap >= 0) {
      const Candidate& pick = candidates[best_cheap];
      chosen->push_back(pick.genes);
      const std::vector<double> mean = mean_objectives[best_cheap];
      if (pick.p_feasible >= 0.5) front.push_back(normalise(mean));
      if (text.empty()) {
        text = ExplainCheapest(pick, mean, usable_runs);
      } else {
        extra.push_back(Describe(grid_.ToPoint(pick.genes)));
      }
      continue;
    }
    int best = -1;
    for (size_t i = 0; i < candidates.size(); ++i) {
      Candidate& c = candidates[i];
      if (std::find(chosen->begin(), chosen->end(), c.genes) != chosen->end()) {
        continue;
      }
      // Points likely on the true front count; the hypervolume gain
      // prefers those that widen it. A tiny uncertainty bonus breaks
      // ties.
      double spread = 0.0;
      for (size_t m = 0; m < models_.size(); ++m) spread += c.sd[m];
      spread /= std::max<size_t>(1, models_.size());
      c.score = (c.p_front + kHypervolumeWeight *
                                 (max_gain > 0 ? c.gain / max_gain : 0.0)) *
                    c.factor +
                1e-4 * c.p_feasible * spread;
      // Diversity inside a batch.
      for (const Genes& other : *chosen) {
        const double d2 = Distance2(c.u, Coordinates(other));
        c.score *= 1.0 - std::exp(-d2 / (2.0 * 0.05 * 0.05));
      }
      // Likely feasible designs first (kFrontMinChance), by score.
      const bool safe = c.p_feasible >= kFrontMinChance;
      const bool best_safe =
          best >= 0 && candidates[best].p_feasible >= kFrontMinChance;
      if (best < 0 || (safe && !best_safe) ||
          (safe == best_safe && c.score > candidates[best].score)) {
        best = static_cast<int>(i);
      }
    }
    if (best < 0) break;
    const Candidate& pick = candidates[best];
    chosen->push_back(pick.genes);
    const std::vector<double> mean = mean_objectives[best];
    if (pick.p_feasible >= 0.5) front.push_back(normalise(mean));
    if (text.empty()) {
      text = ExplainChoice(pick, mean, base, usable_runs);
    } else {
      extra.push_back(Describe(grid_.ToPoint(pick.genes)));
    }
  }
  if (!extra.empty()) {
    text += fmt::format(
        " For the batch, also ({}), each scored as if the "
        "points before it had their predicted results.",
        fmt::join(extra, "), ("));
  }
  return text;
}

namespace {
// Weight of the chance of joining the front among equal expected savings.
constexpr double kFrontTieBreak = 1e-3;
}  // namespace

int AgentStrategy::CheapestPick(const std::vector<Candidate>& candidates,
                                const std::vector<Genes>& chosen) const {
  double cheapest = kInf;  // the cheapest feasible run's cost
  for (const Record& record : records_) {
    if (!record.feasible) continue;
    const double cost = Cost(record.genes);
    if (std::isfinite(cost)) cheapest = std::min(cheapest, cost);
  }
  const int pick = proposed_ + static_cast<int>(chosen.size());
  const bool none_feasible = !std::isfinite(cheapest);
  // The last run of the budget answers the question asked: no later run
  // could use what a front point would teach.
  const bool cheapest_turn =
      pick % kCheapestEvery == kCheapestEvery - 1 || pick == budget_ - 1;
  if (!none_feasible && !cheapest_turn) return -1;
  int best = -1;
  double best_score = 0.0;
  for (size_t i = 0; i < candidates.size(); ++i) {
    const Candidate& c = candidates[i];
    if (!std::isfinite(c.cost) ||
        std::find(chosen.begin(), chosen.end(), c.genes) != chosen.end()) {
      continue;
    }
    double score;
    if (none_feasible) {
      // The cheapest candidate that is probably feasible; failing that,
      // the one most likely feasible.
      score = c.p_feasible >= 0.5 ? 2.0 - c.cost / (1.0 + std::abs(c.cost))
                                  : c.p_feasible;
    } else {
      // Expected saving over the cheapest feasible run, relative, of a
      // design cheaper by more than rounding and not too unlikely to
      // be feasible: a small saving is still the answer, a long shot's
      // large one seldom is. Among equal savings, the one likelier on the
      // front.
      const double saving =
          (cheapest - c.cost) / std::max(std::abs(cheapest), 1e-12);
      if (saving <= 1e-9 || c.p_feasible < kMinCheapestChance) continue;
      score = c.p_feasible * saving + kFrontTieBreak * c.p_front;
      // Of two designs equally priced and equally likely (the chance of
      // the one with less capacity lifted to the other's), the one with
      // more capacity: its own prediction is no worse by the roles.
      if (best >= 0 && std::abs(c.cost - candidates[best].cost) <= 1e-9 &&
          std::abs(c.p_feasible - candidates[best].p_feasible) <= 1e-12) {
        const int order = CompareCapacity(roles_, rate_raised_, c.genes,
                                          candidates[best].genes, false);
        if (order == -1) continue;
        if (order == 1) {
          best_score = score;
          best = static_cast<int>(i);
          continue;
        }
      }
    }
    if (score > best_score + 1e-12) {
      best_score = score;
      best = static_cast<int>(i);
    }
  }
  return best;
}

Candidate AgentStrategy::Predicted(const Genes& genes) const {
  Candidate c;
  c.genes = genes;
  c.u = Coordinates(genes);
  c.cost = Cost(genes);
  c.verdict = CapacityVerdict(genes);
  c.mean.assign(models_.size(), 0.0);
  c.sd.assign(models_.size(), 1.0);
  for (size_t m = 0; m < models_.size(); ++m) {
    if (models_[m].fitted()) models_[m].Predict(c.u, &c.mean[m], &c.sd[m]);
  }
  std::vector<double> o;
  std::map<std::string, double> scratch;
  int count = 0;
  for (int s = 0; s < kSamples; ++s) {
    count += SampleOutcome(c, s, &o, &scratch) ? 1 : 0;
  }
  c.p_feasible = static_cast<double>(count) / kSamples;
  return c;
}

double AgentStrategy::Distance2(const std::vector<double>& a,
                                const std::vector<double>& b) {
  double d2 = 0.0;
  for (size_t i = 0; i < a.size(); ++i) d2 += (a[i] - b[i]) * (a[i] - b[i]);
  return d2;
}

double AgentStrategy::Steps(const Genes& a, const Genes& b) {
  double d2 = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double d = a[i] - b[i];
    d2 += d * d;
  }
  return std::sqrt(d2);
}

double AgentStrategy::RunsProbability(const Candidate& c) const {
  if (!any_failed_) return 1.0;
  double weight = kRunsPriorWeight;
  double works = kRunsPriorWeight * kRunsPrior;
  for (const Record& record : records_) {
    const double steps = Steps(c.genes, record.genes);
    const double w = std::exp(-steps * steps / (2.0 * kRunsSteps * kRunsSteps));
    weight += w;
    works += record.failed ? 0.0 : w;
  }
  return works / weight;
}

void AgentStrategy::ApplyFactors(std::vector<Candidate>* candidates) {
  struct Move {
    Genes from;
    std::vector<int> direction;
    double weight;
    std::string text;
  };
  std::vector<Move> moves;
  const size_t last_round =
      std::min(records_.size(), static_cast<size_t>(std::max(1, fresh_)));
  for (size_t i = records_.size() - last_round; i < records_.size(); ++i) {
    const Record& record = records_[i];
    if (record.failed) continue;
    std::string text;
    std::vector<int> direction = RemedyDirections(record, &text);
    bool any = false;
    for (int v : direction) any = any || v != 0;
    if (!any) continue;
    moves.push_back(
        {record.genes, direction, record.feasible ? 0.1 : 0.3, text});
  }
  for (Candidate& c : *candidates) {
    c.factor = 1.0;
    for (const Move& move : moves) {
      bool follows = true;
      bool moved = false;
      for (size_t d = 0; d < c.genes.size() && follows; ++d) {
        const int delta = c.genes[d] - move.from[d];
        if (delta == 0) continue;
        moved = true;
        follows =
            move.direction[d] != 0 && (delta > 0) == (move.direction[d] > 0);
      }
      if (follows && moved) {
        c.factor *= 1.0 + move.weight;
        if (c.hint.empty()) c.hint = move.text;
      }
    }
  }
}

std::vector<std::vector<double>> AgentStrategy::Anchors(
    const std::vector<Genes>& chosen) const {
  std::vector<std::vector<double>> anchors;
  for (const Genes& genes : chosen) anchors.push_back(Coordinates(genes));
  for (const Record& record : records_) {
    anchors.push_back(Coordinates(record.genes));
  }
  return anchors;
}

std::string AgentStrategy::InitialDesign(int n, std::vector<Genes>* chosen) {
  // Pick 0 is the start (start_from, or the middle of the space).
  auto pick = [&] { return proposed_ + static_cast<int>(chosen->size()); };
  const int last = spec_->exploration.initial_points;
  if (pick() < 1 || pick() > last) return {};
  std::vector<Candidate> candidates;
  for (Genes& genes : Candidates(*chosen)) {
    Candidate c;
    c.genes = std::move(genes);
    c.u = Coordinates(c.genes);
    c.runs = RunsProbability(c);
    candidates.push_back(std::move(c));
  }
  std::vector<std::vector<double>> anchors = Anchors(*chosen);
  const int first = pick();
  std::vector<std::string> drawn;
  while (!candidates.empty() && static_cast<int>(chosen->size()) < n &&
         pick() <= last) {
    int best = -1;
    double best_score = -1.0;
    for (int draw = 0; draw < kInitialDraws; ++draw) {
      const int i = static_cast<int>(initial_random_.Below(candidates.size()));
      const Candidate& c = candidates[i];
      if (std::find(chosen->begin(), chosen->end(), c.genes) != chosen->end()) {
        continue;
      }
      double nearest = kInf;
      for (const auto& a : anchors) {
        nearest = std::min(nearest, Distance2(c.u, a));
      }
      const double score = nearest * c.runs;
      if (score > best_score) {
        best_score = score;
        best = i;
      }
    }
    if (best < 0) break;
    chosen->push_back(candidates[best].genes);
    anchors.push_back(candidates[best].u);
    drawn.push_back(Describe(grid_.ToPoint(candidates[best].genes)));
  }
  if (drawn.empty()) return {};
  const int through = first + static_cast<int>(drawn.size()) - 1;
  return fmt::format(
      "Initial design, point{} {} of {} (exploration.initial_points): "
      "seeded space-filling draw{} at ({}).",
      drawn.size() > 1 ? "s" : "",
      through > first ? fmt::format("{}-{}", first, through)
                      : fmt::format("{}", first),
      last, drawn.size() > 1 ? "s" : "", fmt::join(drawn, "), ("));
}

std::string AgentStrategy::SpaceFilling(std::vector<Candidate>* candidates,
                                        int wanted,
                                        std::vector<Genes>* chosen) {
  std::vector<std::vector<double>> anchors = Anchors(*chosen);
  std::vector<double> middle(knobs_.size(), 0.5);
  int added = 0;
  while (added < wanted) {
    int best = -1;
    double best_score = -kInf;
    for (size_t i = 0; i < candidates->size(); ++i) {
      const Candidate& c = (*candidates)[i];
      if (std::find(chosen->begin(), chosen->end(), c.genes) != chosen->end()) {
        continue;
      }
      double score;
      if (anchors.empty()) {
        score = -Distance2(c.u, middle);
      } else {
        double nearest = kInf;
        for (const auto& a : anchors) {
          nearest = std::min(nearest, Distance2(c.u, a));
        }
        score = nearest;
      }
      score *= c.runs;
      if (score > best_score + 1e-12) {
        best_score = score;
        best = static_cast<int>(i);
      }
    }
    if (best < 0) break;
    chosen->push_back((*candidates)[best].genes);
    anchors.push_back((*candidates)[best].u);
    ++added;
  }
  if (added == 0) return {};
  return fmt::format(
      "No usable run to model yet: proposes {} spread-out point(s) starting "
      "with ({}), away from failed runs.",
      added, Describe(grid_.ToPoint(chosen->at(chosen->size() - added))));
}
}  // namespace adse::explore::internal
