// The built-in `agent` strategy's state, with its steps split by role:
// agent.cc keeps the memory of told runs and fits the surrogates,
// acquisition.cc scores candidates and chooses, rationale.cc says why.
// Internal to harness/explore; only those files (and their tests) include
// it.
#ifndef ADSE_HARNESS_EXPLORE_INTERNAL_AGENT_STRATEGY_H_
#define ADSE_HARNESS_EXPLORE_INTERNAL_AGENT_STRATEGY_H_

#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "harness/explore/capacity.h"
#include "harness/explore/internal/surrogate.h"
#include "harness/explore/strategy.h"
#include "harness/spec/expression.h"
#include "stack/base/random.h"

namespace adse::explore::internal {

// Joint samples of the predicted metrics per candidate. At 64 the draws'
// noise decided which path a seed took near the feasibility bound; 256
// cost three times the time per pick (0.15 s) and found more of each front
// (docs/agent_development.md, "256 Monte Carlo samples").
constexpr int kSamples = 256;
// Spaces up to this size are scored exhaustively.
constexpr uint64_t kEnumerateLimit = 4096;
// Seeded draws among which each initial-design point is the farthest from
// the runs (exploration.initial_points): a spread that still varies with
// the seed.
constexpr int kInitialDraws = 8;
// Random candidates drawn in larger spaces (plus neighbours of seen points).
constexpr int kSampledCandidates = 2000;
// In larger spaces, the neighbours of this many latest runs are scored too.
constexpr size_t kNeighbourhoods = 48;
// The surrogates learn from at most this many (most recent) runs.
constexpr size_t kMaxModelPoints = 160;
// Prior elasticity of a metric to a cores- or clock-like knob (how much
// log metric per log knob), and after the diagnosis of a run (feasible or
// not) has asked for that knob on balance.
constexpr double kElasticity = 0.5;
constexpr double kVotedElasticity = 0.8;
// ... and to a sensor-rate knob, which adds load rather than capacity, or
// a downsampling knob (a voxel size), which sheds it at the cost of
// precision.
constexpr double kSensorElasticity = 0.5;
// The prior slope a sensor rate gets when the runs' diagnoses ask to raise
// it (a consumer starved of data); asked to lower it, it gets
// kVotedElasticity as a load, as a capacity knob voted for does.
constexpr double kRateVote = 0.3;
// Default GP length scales over normalised knobs: most knobs, and those
// with at most 3 values.
constexpr double kLength = 0.25;
constexpr double kFewValuesLength = 1.0;
// Failed runs: how likely a run works is a kernel vote of the runs within
// about kRunsSteps grid steps, next to a prior of kRunsPrior worth
// kRunsPriorWeight runs.
constexpr double kRunsSteps = 1.5;
constexpr double kRunsPrior = 0.9;
constexpr double kRunsPriorWeight = 0.3;
// Weight of the (normalised) expected hypervolume gain next to the
// probability of landing on the predicted front.
constexpr double kHypervolumeWeight = 0.3;
// Every kCheapestEvery-th pick, and the budget's last, goes to the cheapest
// design likely feasible (what the user asked for) rather than the front's
// volume: among designs cheaper than the cheapest feasible run that are
// feasible with probability kMinCheapestChance at least, the one of
// largest expected saving. (Measured on the recordings and landscapes in
// tests/data: it finds the cheapest design in far more seeds, at the price
// of a few front points; see docs/agent_development.md.)
constexpr int kCheapestEvery = 4;
// A front pick goes to a design feasible with at least this chance while
// any is: the cheapest-design picks already take the long shots, and a
// front pick that fails adds nothing to the front (measured on held-out
// landscapes, see docs/agent_development.md, "Three changes that held").
constexpr double kFrontMinChance = 0.5;
constexpr double kMinCheapestChance = 0.25;
// The metric computed from the cost expression rather than modelled.
constexpr char kCostMetric[] = "hardware_cost";
constexpr char kNavTimeMetric[] = "nav_time_s";
// The flag of a run that reached its goal.
constexpr char kCompletedMetric[] = "completed";
// A run stopped past its time bound having driven a share q of its route
// would, at the pace it kept, arrive at bound / q: its time's censored
// bound is taken there (docs/agent_development.md, "How far a stopped run
// got"). q is held at least this, so a car that hardly moved bounds its time at
// 20 times the bound rather than at infinity.
constexpr double kMinDrivenFraction = 0.05;

using spec::KnobRole;

struct Knob {
  const spec::DesignParameter* parameter = nullptr;
  KnobRole role = KnobRole::kNone;  // from the design space
  std::vector<double> u;  // normalised coordinate of each allowed value
  std::string sensor;     // for a rate: the bind's middle part ("lidar")
  // log(largest / smallest value) for a positive knob (normalised over
  // log scale), else 1.
  double log_range = 1.0;
};

// What a run stopped early says of its violated constraint's metric: its
// final value lies beyond `bound` (metric units), above it when side is +1
// (a time past its limit), below when -1 (a rate under its floor).
struct CensoredBound {
  std::string metric;
  double bound = 0.0;
  int side = 0;
  // A time stopped at its bound part of the way: where it would have
  // ended at the pace it kept (bound / share of the route driven), else
  // `bound`. Used once some run's value was measured: with none, the
  // trend's floor would sit past the bound and nothing could be feasible.
  double paced_bound = 0.0;
  double driven_fraction = kNaN;  // of the route, when the run says
};

struct Record {
  Genes genes;
  Observation observation;
  std::vector<double> objectives;  // minimisation form, NaN when failed
  bool feasible = false;
  bool failed = false;
  std::optional<CensoredBound> censored;  // stopped early, bound known
  // A constraint that reads only measured metrics failed here: with less
  // capacity it fails too (see AgentStrategy::CapacityVerdict).
  bool metrics_fail = false;
  // ... and one of them reads no precision metric: with finer data
  // (downsample knobs) it fails too.
  bool load_fail = false;
};

// What the runs say of a point by capacity alone: a point with no more
// capacity than a run whose metric constraints failed fails them too; one
// with no less than a feasible run's meets them. Capacity is ordered by
// the knobs' roles: more cores and clock, a slower sensor, every other
// knob equal. Coarser data (a downsample knob) counts as more capacity
// only against a run that failed a constraint on no precision metric:
// it costs precision, so it neither rescues a run that strayed nor keeps
// a feasible one feasible.
enum class Verdict { kUnknown, kFails, kHolds };

struct Candidate {
  Genes genes;
  std::vector<double> u;
  double cost = kNaN;        // exact, from the cost expression
  std::vector<double> mean;  // per model, model units
  std::vector<double> sd;
  double p_feasible = 0.0;
  double gain = 0.0;     // expected hypervolume gain (normalised)
  double p_front = 0.0;  // probability of joining the predicted front
  double factor = 1.0;   // diagnosis multiplier
  double runs = 1.0;     // probability that a run there does not fail
  Verdict verdict = Verdict::kUnknown;
  double score = 0.0;
  std::string hint;  // the remedy it follows, if any
};

class AgentStrategy : public Strategy {
 public:
  explicit AgentStrategy(const spec::Spec& spec);
  std::vector<spec::DesignPoint> Ask(int k) override;
  void Tell(const Observation& observation) override;
  std::string name() const override { return "agent"; }
  std::string rationale() const override { return rationale_; }

 private:
  void Remember(const Observation& observation);

  std::string Fallback(int n, std::vector<Genes>* chosen);

  void SetUpKnobs();

  void SetUpMetrics();

  std::vector<double> Objectives(const Observation& observation) const;

  std::vector<double> Coordinates(const Genes& genes) const;

  // Which way constraint-only metrics should move: probe each constraint
  // with the metric halved and doubled around the latest usable run.
  void ProbeDirections();

  // Remedy directions (per knob, -1/0/+1) from one run's diagnosis.
  std::vector<int> RemedyDirections(const Record& record,
                                    std::string* text) const;

  // The bound a censored run puts on its violated constraint's metric;
  // nothing when the constraint is unknown or not a bound on one metric.
  std::optional<CensoredBound> CensoredAt(const Observation& observation) const;

  void FitModels();

  Verdict CapacityVerdict(const Genes& genes) const;

  std::vector<Genes> Candidates(const std::vector<Genes>& chosen);

  double Cost(const Genes& genes) const;

  // Objectives (minimisation form) and feasibility of sample s.
  bool SampleOutcome(const Candidate& c, int s, std::vector<double>* objectives,
                     std::map<std::string, double>* scratch) const;

  // Objective j's model once it has runs to learn from, else nullptr (the
  // cost has none: it comes from the cost expression).
  const MetricModel* FittedObjectiveModel(size_t j) const;

  // The expected objectives at a candidate (sample means, minimisation).
  std::vector<double> MeanObjectives(const Candidate& c) const;

  // Chooses up to n points (after those already in `chosen`); returns the
  // sentence that explains the first model-based choice.
  std::string Choose(int n, std::vector<Genes>* chosen);

  // The index of the candidate to pick for the cheapest feasible design,
  // or -1 when this pick belongs to the front (see kCheapestEvery).
  int CheapestPick(const std::vector<Candidate>& candidates,
                   const std::vector<Genes>& chosen) const;

  Candidate Predicted(const Genes& genes) const;

  static double Distance2(const std::vector<double>& a,
                          const std::vector<double>& b);

  // Grid steps between two points (Euclidean over value indices).
  static double Steps(const Genes& a, const Genes& b);

  // How likely a run at the candidate is to work at all: a kernel-weighted
  // vote of the runs around it (in grid steps), next to a prior that runs
  // work.
  double RunsProbability(const Candidate& c) const;

  // Diagnosis: candidates that move from the latest runs only the way
  // their remedies say get a bonus.
  void ApplyFactors(std::vector<Candidate>* candidates);

  // The coordinates of the points chosen so far and of every run, which
  // space-filling picks keep away from.
  std::vector<std::vector<double>> Anchors(
      const std::vector<Genes>& chosen) const;

  std::string SpaceFilling(std::vector<Candidate>* candidates, int wanted,
                           std::vector<Genes>* chosen);

  // exploration.initial_points: while the pick is one of the initial
  // design's (picks 1 to initial_points), chooses the farthest from every
  // run and choice so far of kInitialDraws seeded draws among the
  // candidates (weighed by the chance that a run works there); returns the
  // sentence that says so, empty when it chose none.
  std::string InitialDesign(int n, std::vector<Genes>* chosen);

  std::string Describe(const spec::DesignPoint& point) const;

  // What the latest run showed.
  std::string LastText() const;

  // "metric value, ..." of the objectives' predicted means.
  std::string Predictions(const std::vector<double>& mean) const;

  std::string ExplainCheapest(const Candidate& pick,
                              const std::vector<double>& mean,
                              int usable_runs) const;

  std::string ExplainChoice(const Candidate& pick,
                            const std::vector<double>& mean, double base,
                            int usable_runs) const;

  const spec::Spec* spec_;
  SpaceGrid grid_;
  int budget_;
  Random random_;
  Random initial_random_;  // the initial design's draws
  std::vector<Knob> knobs_;
  std::vector<spec::KnobRole> roles_;  // per knob, for CompareCapacity
  std::vector<double> lengths_;        // GP length scale per knob
  // Per knob: a sensor rate the diagnosis asked to raise, so a faster
  // sensor is not taken for more load (FitModels).
  std::vector<bool> rate_raised_;
  std::vector<MetricModel> models_;
  bool any_failed_ = false;
  std::vector<CapacityConstraint> constraints_;
  std::vector<std::vector<double>> z_;  // [sample][model]
  std::vector<int> objective_model_;    // per objective, index or -1
  std::optional<Genes> start_;
  int proposed_ = 0;
  int fresh_ = 0;  // runs told since the last Ask
  std::set<Genes> seen_;
  std::set<Genes> told_;
  std::set<Genes> pending_;
  std::vector<Record> records_;
  std::string rationale_;
};

// A number for the rationale: 3 significant digits, "n/a" for NaN.
std::string Num(double value);

}  // namespace adse::explore::internal

#endif  // ADSE_HARNESS_EXPLORE_INTERNAL_AGENT_STRATEGY_H_
