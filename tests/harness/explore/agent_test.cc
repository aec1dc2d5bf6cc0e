// The `agent` strategy: the shared contract (no repeats, budget,
// determinism, start_from, failed runs, batches, any space), its rationale,
// and a synthetic study where it must find more of the true Pareto front
// than random search within a small budget.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "harness/explore/strategy.h"
#include "harness/spec/spec_parser.h"

namespace adse::explore {
namespace {

spec::Spec Parse(const std::string& body) {
  const std::string text = R"(adse: 1
world: {map: {generate: grid}}
task: {start: {edge: E0}, goal: {edge: E5, pos_m: 20, lane: 1}}
)" + body;
  Result<spec::Spec> spec = spec::ParseSpec(text, "t.yaml", "");
  EXPECT_TRUE(spec.ok()) << spec.status().message();
  return spec.ok() ? *spec : spec::Spec();
}

// 16 x 5 x 2 = 160 points; two objectives, a navigation-time limit.
spec::Spec MakeSpec(const std::string& exploration) {
  return Parse(R"(design_space:
  cores:    {bind: platform.cores,      range: [1, 16]}
  freq_ghz: {bind: platform.freq_ghz,   values: [1.0, 1.2, 1.5, 1.8, 2.1]}
  lidar_hz: {bind: stack.lidar.rate_hz, values: [7, 14]}
objectives: [{minimize: hardware_cost}, {minimize: nav_time_s}, {maximize: ctrl_rate_hz}]
constraints: [nav_time_s <= 60, completed]
exploration: )" +
               exploration + "\n");
}

// A robotaxi-like analytic model: the stack needs compute that grows with
// the LiDAR rate; navigation time falls with compute and saturates once
// the parallel part has enough cores; one core cannot finish.
Observation Evaluate(const spec::DesignPoint& point) {
  Observation o;
  o.point = point;
  const double cores = point.at("cores");
  const double freq = point.at("freq_ghz");
  const double lidar = point.at("lidar_hz");
  const double load = lidar / 7.0;
  const double nav =
      28.0 + 70.0 * load / (std::min(cores, 10.0) * freq) + 10.0 / freq;
  const bool completed = cores >= 2;
  o.metrics["completed"] = completed ? 1 : 0;
  o.metrics["nav_time_s"] = completed ? nav : 600.0;
  o.metrics["ctrl_rate_hz"] =
      std::min(30.0, 6.0 * std::min(cores, 6.0) * freq / load);
  o.metrics["hardware_cost"] = cores * freq;
  o.feasible = completed && nav <= 60.0;
  if (!o.feasible) {
    const bool frequency = 10.0 / freq > 7.0;
    BottleneckHint hint;
    hint.kind = analysis::FindingKind::kCpuBound;
    hint.node = "ndt_scan_matcher";
    hint.severity = 0.3;
    if (frequency) {
      hint.remedies = {{analysis::RemedyKind::kHigherFrequency, hint.node}};
    } else {
      hint.remedies = {{analysis::RemedyKind::kMoreCores, hint.node},
                       {analysis::RemedyKind::kLowerSensorRate,
                        "/sensing/lidar/points_raw"}};
    }
    hint.remedy = analysis::RemediesText(hint.remedies);
    o.bottlenecks.push_back(hint);
  }
  return o;
}

std::unique_ptr<Strategy> Create(const spec::Spec& spec,
                                 const std::string& name = "agent") {
  Result<std::unique_ptr<Strategy>> strategy =
      CreateStrategy(name, StrategyContext{&spec});
  EXPECT_TRUE(strategy.ok()) << strategy.status().message();
  return strategy.ok() ? std::move(*strategy) : nullptr;
}

// Ask/tell rounds of `batch` until nothing is proposed; returns every
// proposal in order. `evaluate` may mark runs failed.
template <typename F>
std::vector<spec::DesignPoint> Drive(Strategy& strategy, int batch,
                                     F evaluate) {
  std::vector<spec::DesignPoint> all;
  for (int round = 0; round < 1000; ++round) {
    std::vector<spec::DesignPoint> points = strategy.Ask(batch);
    EXPECT_LE(static_cast<int>(points.size()), batch);
    if (points.empty()) break;
    for (const spec::DesignPoint& point : points) {
      all.push_back(point);
      strategy.Tell(evaluate(point));
    }
  }
  return all;
}

std::vector<spec::DesignPoint> Drive(Strategy& strategy, int batch) {
  return Drive(strategy, batch, Evaluate);
}

void ExpectDistinctAndAllowed(const spec::Spec& spec,
                              const std::vector<spec::DesignPoint>& points) {
  std::set<spec::DesignPoint> distinct(points.begin(), points.end());
  EXPECT_EQ(distinct.size(), points.size());
  for (const spec::DesignPoint& point : points) {
    EXPECT_TRUE(spec.design_space.Check(point).ok())
        << spec.design_space.Check(point).message();
  }
}

TEST(AgentTest, IsRegisteredAndAdaptive) {
  const std::vector<std::string>& names = StrategyNames();
  EXPECT_NE(std::find(names.begin(), names.end(), "agent"), names.end());
  const spec::Spec spec = MakeSpec("{budget: 5}");
  std::unique_ptr<Strategy> strategy = Create(spec);
  ASSERT_NE(strategy, nullptr);
  EXPECT_EQ(strategy->name(), "agent");
  EXPECT_TRUE(strategy->adaptive());
  EXPECT_EQ(strategy->RoundSize(3), 3);
  EXPECT_EQ(strategy->RoundSize(0), 1);
}

TEST(AgentTest, NeverRepeatsAndSpendsTheBudgetExactly) {
  const spec::Spec spec = MakeSpec("{budget: 25, seed: 3}");
  std::unique_ptr<Strategy> strategy = Create(spec);
  ASSERT_NE(strategy, nullptr);
  const std::vector<spec::DesignPoint> points = Drive(*strategy, 1);
  EXPECT_EQ(points.size(), 25u);
  ExpectDistinctAndAllowed(spec, points);
  EXPECT_TRUE(strategy->Ask(4).empty());
  EXPECT_NE(strategy->rationale().find("budget"), std::string::npos);
}

TEST(AgentTest, BudgetLargerThanTheSpaceCoversItOnce) {
  const spec::Spec spec = Parse(R"(design_space:
  cores:    {bind: platform.cores,    range: [1, 6]}
  freq_ghz: {bind: platform.freq_ghz, values: [1.0, 2.0]}
objectives: [{minimize: hardware_cost}, {minimize: nav_time_s}]
constraints: [nav_time_s <= 60]
exploration: {budget: 100}
)");
  std::unique_ptr<Strategy> strategy = Create(spec);
  ASSERT_NE(strategy, nullptr);
  const std::vector<spec::DesignPoint> points =
      Drive(*strategy, 5, [](const spec::DesignPoint& point) {
        spec::DesignPoint full = point;
        full["lidar_hz"] = 7;
        Observation o = Evaluate(full);
        o.point = point;
        return o;
      });
  EXPECT_EQ(points.size(), 12u);
  ExpectDistinctAndAllowed(spec, points);
}

TEST(AgentTest, DeterministicAcrossInstances) {
  const spec::Spec a = MakeSpec("{budget: 15, seed: 11}");
  std::unique_ptr<Strategy> first = Create(a);
  std::unique_ptr<Strategy> again = Create(a);
  ASSERT_TRUE(first && again);
  const std::vector<spec::DesignPoint> p1 = Drive(*first, 1);
  const std::vector<spec::DesignPoint> p2 = Drive(*again, 1);
  EXPECT_EQ(p1, p2);
  EXPECT_EQ(first->rationale(), again->rationale());
  // Batches too, and a replay that re-creates the strategy mid-way.
  const spec::Spec b = MakeSpec("{budget: 15, seed: 4, batch: 3}");
  std::unique_ptr<Strategy> third = Create(b);
  std::unique_ptr<Strategy> fourth = Create(b);
  EXPECT_EQ(Drive(*third, 3), Drive(*fourth, 3));
}

TEST(AgentTest, StartsFromStartFrom) {
  const spec::Spec spec = MakeSpec(
      "{budget: 6, start_from: {cores: 12, freq_ghz: 1.5, lidar_hz: 14}}");
  std::unique_ptr<Strategy> strategy = Create(spec);
  ASSERT_NE(strategy, nullptr);
  const std::vector<spec::DesignPoint> first = strategy->Ask(1);
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0], (spec::DesignPoint{
                          {"cores", 12}, {"freq_ghz", 1.5}, {"lidar_hz", 14}}));
  EXPECT_NE(strategy->rationale().find("start_from"), std::string::npos);
}

TEST(AgentTest, AnInitialDesignSpreadsItsSecondRunsBySeedThenTheModelPicks) {
  // The second and third points are the initial design's: seeded, so two
  // seeds part there, and each a spread-out draw (not a neighbour of the
  // start); from the fourth on the model picks, as its rationale says.
  auto run = [](int seed, std::vector<std::string>* rationales) {
    const spec::Spec spec =
        MakeSpec("{budget: 6, seed: " + std::to_string(seed) +
                 ", initial_points: 2, start_from: {cores: 8, freq_ghz: 1.5, "
                 "lidar_hz: 7}}");
    std::unique_ptr<Strategy> strategy = Create(spec);
    std::vector<spec::DesignPoint> points;
    while (strategy) {
      std::vector<spec::DesignPoint> asked = strategy->Ask(1);
      if (asked.empty()) break;
      rationales->push_back(strategy->rationale());
      points.push_back(asked[0]);
      strategy->Tell(Evaluate(asked[0]));
    }
    return points;
  };
  std::set<std::vector<spec::DesignPoint>> seconds;
  for (int seed = 1; seed <= 4; ++seed) {
    std::vector<std::string> rationales;
    const std::vector<spec::DesignPoint> points = run(seed, &rationales);
    ASSERT_EQ(points.size(), 6u);
    seconds.insert({points[1], points[2]});
    for (int i : {1, 2}) {
      EXPECT_NE(rationales[i].find("Initial design, point " +
                                   std::to_string(i) + " of 2"),
                std::string::npos)
          << rationales[i];
      // Farther from the start than its next core count.
      const double steps = std::abs(points[i].at("cores") - 8) / 15.0 +
                           std::abs(points[i].at("freq_ghz") - 1.5) / 1.1 +
                           std::abs(points[i].at("lidar_hz") - 7) / 7.0;
      EXPECT_GT(steps, 1.0 / 15.0 + 1e-9) << i;
    }
    for (int i = 3; i < 6; ++i) {
      EXPECT_EQ(rationales[i].find("Initial design"), std::string::npos)
          << rationales[i];
    }
  }
  EXPECT_GE(seconds.size(), 3u);
  // The same seed, the same initial design.
  std::vector<std::string> a, b;
  EXPECT_EQ(run(2, &a), run(2, &b));
  // In a batch, the start and both draws in the first round, then the
  // model's picks.
  const spec::Spec batch = MakeSpec(
      "{budget: 6, batch: 3, initial_points: 2, start_from: {cores: 8, "
      "freq_ghz: 1.5, lidar_hz: 7}}");
  std::unique_ptr<Strategy> strategy = Create(batch);
  ASSERT_NE(strategy, nullptr);
  const std::vector<spec::DesignPoint> first = strategy->Ask(3);
  ASSERT_EQ(first.size(), 3u);
  EXPECT_NE(strategy->rationale().find("Initial design, points 1-2 of 2"),
            std::string::npos)
      << strategy->rationale();
  for (const spec::DesignPoint& point : first) strategy->Tell(Evaluate(point));
  ASSERT_EQ(strategy->Ask(3).size(), 3u);
  EXPECT_EQ(strategy->rationale().find("Initial design"), std::string::npos)
      << strategy->rationale();
}

TEST(AgentTest, WithoutStartFromItStillProposes) {
  const spec::Spec spec = MakeSpec("{budget: 6}");
  std::unique_ptr<Strategy> strategy = Create(spec);
  ASSERT_NE(strategy, nullptr);
  const std::vector<spec::DesignPoint> points = Drive(*strategy, 1);
  EXPECT_EQ(points.size(), 6u);
  ExpectDistinctAndAllowed(spec, points);
}

TEST(AgentTest, ToldPointsAreNeverProposed) {
  const spec::Spec spec = MakeSpec("{budget: 40, seed: 2}");
  std::unique_ptr<Strategy> strategy = Create(spec);
  ASSERT_NE(strategy, nullptr);
  std::set<spec::DesignPoint> told;
  for (double cores : {2.0, 4.0, 8.0}) {
    for (double freq : {1.0, 1.2, 1.5, 1.8, 2.1}) {
      spec::DesignPoint point{
          {"cores", cores}, {"freq_ghz", freq}, {"lidar_hz", 7}};
      told.insert(point);
      strategy->Tell(Evaluate(point));
    }
  }
  const std::vector<spec::DesignPoint> points = Drive(*strategy, 2);
  EXPECT_EQ(points.size(), 40u);
  for (const spec::DesignPoint& point : points) {
    EXPECT_EQ(told.count(point), 0u);
  }
}

TEST(AgentTest, FailedRunsAreSurvivedAndTheirNeighboursAvoided) {
  const spec::Spec spec = MakeSpec(
      "{budget: 15, seed: 5, start_from: {cores: 8, freq_ghz: 1.5, "
      "lidar_hz: 7}}");
  std::unique_ptr<Strategy> strategy = Create(spec);
  ASSERT_NE(strategy, nullptr);
  // Every run with 3 or fewer cores crashes.
  auto evaluate = [](const spec::DesignPoint& point) {
    if (point.at("cores") <= 3) {
      Observation o;
      o.point = point;
      o.failed = true;
      return o;
    }
    return Evaluate(point);
  };
  const std::vector<spec::DesignPoint> points = Drive(*strategy, 1, evaluate);
  EXPECT_EQ(points.size(), 15u);
  ExpectDistinctAndAllowed(spec, points);
  int failed = 0;
  for (const spec::DesignPoint& point : points) {
    failed += point.at("cores") <= 3 ? 1 : 0;
  }
  // Cheap points are tempting, but once some crashed their neighbours are
  // avoided.
  EXPECT_LE(failed, 5);
  // Everything failing is no problem either.
  std::unique_ptr<Strategy> doomed = Create(spec);
  std::vector<spec::DesignPoint> all_failed;
  for (int round = 0; round < 20; ++round) {
    const std::vector<spec::DesignPoint> points = doomed->Ask(2);
    if (points.empty()) break;
    if (round > 0) {
      EXPECT_NE(doomed->rationale().find("failed"), std::string::npos)
          << doomed->rationale();
    }
    for (const spec::DesignPoint& point : points) {
      all_failed.push_back(point);
      Observation o;
      o.point = point;
      o.failed = true;
      doomed->Tell(o);
    }
  }
  EXPECT_EQ(all_failed.size(), 15u);
  ExpectDistinctAndAllowed(spec, all_failed);
}

// Drives the agent from a starved start whose slow runs (over 60 s) are
// ended early, infeasible with their metrics withheld but hardware_cost:
// stopped at the time bound (`stalled` false) or stalled, their reason
// naming no constraint. Either way the agent must read each as "slower
// than 60 s here" and find feasible designs, not walk the cheapest corner.
void ExpectEndedEarlyRunsSendItToMoreCapacity(bool stalled) {
  const spec::Spec spec = MakeSpec(
      "{budget: 12, seed: 4, start_from: {cores: 2, freq_ghz: 1.0, "
      "lidar_hz: 14}}");
  std::unique_ptr<Strategy> strategy = Create(spec);
  ASSERT_NE(strategy, nullptr);
  int ended = 0;
  auto evaluate = [&](const spec::DesignPoint& point) {
    Observation o = Evaluate(point);
    if (o.metrics.at("completed") == 1 && o.metrics.at("nav_time_s") > 60) {
      ++ended;
      const double cost = o.metrics.at("hardware_cost");
      o.metrics = {{"hardware_cost", cost}, {"censored", 1}};
      o.censored = true;
      if (stalled) {
        o.stalled = true;
      } else {
        o.violated_constraint = "nav_time_s <= 60";
      }
    }
    return o;
  };
  const std::vector<spec::DesignPoint> points = Drive(*strategy, 1, evaluate);
  ASSERT_EQ(points.size(), 12u);
  ExpectDistinctAndAllowed(spec, points);
  int feasible = 0;
  for (const spec::DesignPoint& point : points) {
    feasible += Evaluate(point).feasible ? 1 : 0;
  }
  EXPECT_GE(ended, 1);
  EXPECT_GE(feasible, 6) << "runs ended early: " << ended;
  // The second proposal already moves to more capacity than the start.
  EXPECT_GT(points[1].at("cores") * points[1].at("freq_ghz"), 2.0);
}

TEST(AgentTest, RunsStoppedEarlyTeachTheBoundAndSendItToMoreCapacity) {
  ExpectEndedEarlyRunsSendItToMoreCapacity(/*stalled=*/false);
}

TEST(AgentTest, StalledRunsTeachTheTimeBoundToo) {
  // A car that never arrives is past the nav-time bound.
  ExpectEndedEarlyRunsSendItToMoreCapacity(/*stalled=*/true);
}

TEST(AgentTest, ADesignWithLessCapacityThanAFailedRunIsNeverProposed) {
  // The model's feasibility is monotone in capacity (more cores, a faster
  // clock, a slower LiDAR), as the roles of the knobs declare: once a
  // design fails its time bound, none with no more capacity is worth a run.
  int infeasible_runs = 0;
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    const spec::Spec spec =
        MakeSpec("{budget: 20, seed: " + std::to_string(seed) + "}");
    std::unique_ptr<Strategy> strategy = Create(spec);
    ASSERT_NE(strategy, nullptr);
    std::vector<spec::DesignPoint> failed;
    const std::vector<spec::DesignPoint> points =
        Drive(*strategy, 1, [&](const spec::DesignPoint& point) {
          for (const spec::DesignPoint& f : failed) {
            EXPECT_FALSE(point.at("cores") <= f.at("cores") &&
                         point.at("freq_ghz") <= f.at("freq_ghz") &&
                         point.at("lidar_hz") >= f.at("lidar_hz"))
                << "seed " << seed << ": proposed "
                << spec::FormatPoint(spec.design_space, point) << " after "
                << spec::FormatPoint(spec.design_space, f) << " failed";
          }
          Observation o = Evaluate(point);
          if (!o.feasible) failed.push_back(point);
          return o;
        });
    EXPECT_EQ(points.size(), 20u);
    infeasible_runs += static_cast<int>(failed.size());
  }
  EXPECT_GT(infeasible_runs, 0);  // the bound was met on the way
}

TEST(AgentTest, WhileNoRunIsFeasibleASlowerSensorIsTriedBeforeAFasterOne) {
  // One slow run with no diagnosis, twice the bound: far from it the
  // model's predictions are wide, and the largest computer with the faster
  // sensor would look likelier to make the bound than the same computer
  // with the slower one unless the chance is held monotone in capacity (as
  // on tests/data/landscapes/other_cost, whose space this is).
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    const spec::Spec spec =
        Parse(R"(design_space:
  cores:    {bind: platform.cores,      range: [1, 28]}
  freq_ghz: {bind: platform.freq_ghz,   values: [1.0, 1.2, 1.5, 1.8, 2.1]}
  lidar_hz: {bind: stack.lidar.rate_hz, values: [7, 14]}
cost: cores * freq_ghz ^ 2 + 2 * lidar_hz / 7
objectives: [{minimize: hardware_cost}, {minimize: nav_time_s}]
constraints: [nav_time_s <= 400, ctrl_rate_hz >= 1, completed]
exploration: {budget: 6, seed: )" +
              std::to_string(seed) +
              R"(, start_from: {cores: 5, freq_ghz: 1.5, lidar_hz: 7}}
)");
    std::unique_ptr<Strategy> strategy = Create(spec);
    ASSERT_NE(strategy, nullptr);
    ASSERT_EQ(strategy->Ask(1).size(), 1u);
    Observation slow;
    slow.point = {{"cores", 5}, {"freq_ghz", 1.5}, {"lidar_hz", 7}};
    slow.metrics = {{"completed", 1},
                    {"nav_time_s", 801},
                    {"ctrl_rate_hz", 12},
                    {"hardware_cost", 13.25}};
    slow.feasible = false;
    strategy->Tell(slow);
    const std::vector<spec::DesignPoint> next = strategy->Ask(1);
    ASSERT_EQ(next.size(), 1u);
    EXPECT_EQ(next[0].at("lidar_hz"), 7)
        << "seed " << seed << ": "
        << spec::FormatPoint(spec.design_space, next[0]);
  }
}

TEST(AgentTest, BatchesAreDistinctAndSpread) {
  const spec::Spec spec = MakeSpec("{budget: 24, seed: 7, batch: 4}");
  std::unique_ptr<Strategy> strategy = Create(spec);
  ASSERT_NE(strategy, nullptr);
  EXPECT_EQ(strategy->RoundSize(4), 4);
  std::vector<spec::DesignPoint> all;
  for (int round = 0; round < 6; ++round) {
    const std::vector<spec::DesignPoint> points = strategy->Ask(4);
    ASSERT_EQ(points.size(), 4u) << "round " << round;
    std::set<spec::DesignPoint> distinct(points.begin(), points.end());
    EXPECT_EQ(distinct.size(), 4u);
    for (const spec::DesignPoint& point : points) {
      all.push_back(point);
      strategy->Tell(Evaluate(point));
    }
  }
  ExpectDistinctAndAllowed(spec, all);
  EXPECT_TRUE(strategy->Ask(4).empty());
}

TEST(AgentTest, AskWithoutTellsStillNeverRepeats) {
  // A caller that asks again before telling: pending points are seen.
  const spec::Spec spec = MakeSpec("{budget: 9}");
  std::unique_ptr<Strategy> strategy = Create(spec);
  ASSERT_NE(strategy, nullptr);
  std::vector<spec::DesignPoint> all;
  for (int i = 0; i < 5; ++i) {
    for (const spec::DesignPoint& point : strategy->Ask(2)) {
      all.push_back(point);
    }
  }
  EXPECT_EQ(all.size(), 9u);
  ExpectDistinctAndAllowed(spec, all);
}

TEST(AgentTest, OneParameterSpace) {
  const spec::Spec spec = Parse(R"(design_space:
  cores: {bind: platform.cores, range: [1, 40]}
objectives: [{minimize: hardware_cost}, {minimize: nav_time_s}]
constraints: [nav_time_s <= 60]
exploration: {budget: 10, start_from: {cores: 20}}
)");
  std::unique_ptr<Strategy> strategy = Create(spec);
  ASSERT_NE(strategy, nullptr);
  const std::vector<spec::DesignPoint> points =
      Drive(*strategy, 1, [](const spec::DesignPoint& point) {
        Observation o;
        o.point = point;
        const double cores = point.at("cores");
        const double nav = 30.0 + 200.0 / std::min(cores, 25.0);
        o.metrics = {{"nav_time_s", nav},
                     {"hardware_cost", cores * 2.1},
                     {"completed", 1}};
        o.feasible = nav <= 60.0;
        return o;
      });
  ASSERT_EQ(points.size(), 10u);
  ExpectDistinctAndAllowed(spec, points);
  // The true front is 7..25 cores; the search brackets its cheap end
  // (7 to 9 cores) and spends most of the budget on the front.
  int on_front = 0;
  bool near_boundary = false;
  for (const spec::DesignPoint& point : points) {
    const double cores = point.at("cores");
    on_front += cores >= 7 && cores <= 25 ? 1 : 0;
    near_boundary = near_boundary || (cores >= 7 && cores <= 9);
  }
  EXPECT_GE(on_front, 7);
  EXPECT_TRUE(near_boundary);
}

TEST(AgentTest, FourParameterSpaceWithAStackKnob) {
  const spec::Spec spec = Parse(R"(design_space:
  cores:    {bind: platform.cores,      range: [1, 12]}
  freq_ghz: {bind: platform.freq_ghz,   values: [1.0, 1.5, 2.0]}
  lidar_hz: {bind: stack.lidar.rate_hz, values: [5, 10, 15]}
  beams:    {bind: stack.lidar.beams,   values: [8, 16, 32]}
objectives: [{minimize: hardware_cost}, {minimize: deviation_score}]
constraints: [nav_time_s <= 80, ctrl_rate_hz >= 5]
exploration: {budget: 20, seed: 9, batch: 2}
)");
  std::unique_ptr<Strategy> strategy = Create(spec);
  ASSERT_NE(strategy, nullptr);
  const std::vector<spec::DesignPoint> points =
      Drive(*strategy, 2, [](const spec::DesignPoint& point) {
        Observation o;
        o.point = point;
        const double compute = point.at("cores") * point.at("freq_ghz");
        const double load = point.at("lidar_hz") * point.at("beams") / 80.0;
        const double nav = 30.0 + 40.0 * load / compute;
        o.metrics = {{"nav_time_s", nav},
                     {"ctrl_rate_hz", 30.0 * compute / (compute + load)},
                     {"deviation_score", 0.05 / std::sqrt(load)},
                     {"hardware_cost", compute},
                     {"completed", 1}};
        o.feasible = nav <= 80.0 && o.metrics["ctrl_rate_hz"] >= 5;
        return o;
      });
  EXPECT_EQ(points.size(), 20u);
  ExpectDistinctAndAllowed(spec, points);
}

TEST(AgentTest, OneObjectiveNoConstraintsOrNoObjectivesAtAll) {
  spec::Spec spec = Parse(R"(design_space:
  cores:    {bind: platform.cores,    range: [1, 16]}
  freq_ghz: {bind: platform.freq_ghz, values: [1.0, 1.5, 2.0]}
objectives: [{minimize: nav_time_s}]
exploration: {budget: 12, seed: 2}
)");
  auto evaluate = [](const spec::DesignPoint& point) {
    spec::DesignPoint full = point;
    full["lidar_hz"] = 7;
    Observation o = Evaluate(full);
    o.point = point;
    o.feasible = true;
    return o;
  };
  std::unique_ptr<Strategy> strategy = Create(spec);
  ASSERT_NE(strategy, nullptr);
  std::vector<spec::DesignPoint> points = Drive(*strategy, 1, evaluate);
  EXPECT_EQ(points.size(), 12u);
  ExpectDistinctAndAllowed(spec, points);
  // The fastest corner (>= 10 cores at 2 GHz) is found.
  bool fastest = false;
  for (const spec::DesignPoint& point : points) {
    fastest =
        fastest || (point.at("cores") >= 10 && point.at("freq_ghz") == 2.0);
  }
  EXPECT_TRUE(fastest);

  spec.objectives.clear();
  std::unique_ptr<Strategy> aimless = Create(spec);
  ASSERT_NE(aimless, nullptr);
  points = Drive(*aimless, 3, evaluate);
  EXPECT_EQ(points.size(), 12u);
  ExpectDistinctAndAllowed(spec, points);
}

TEST(AgentTest, LargeSpaceIsSampled) {
  // 28 x 20 x 20 x 20 x 14 = 3.1 million points: sampled, not enumerated.
  const spec::Spec spec = Parse(R"(design_space:
  cores:    {bind: platform.cores,        range: [1, 28]}
  freq_ghz: {bind: platform.freq_ghz,     range: [0.5, 2.4], step: 0.1}
  lidar_hz: {bind: stack.lidar.rate_hz,   range: [1, 20]}
  beams:    {bind: stack.lidar.beams,     range: [4, 23]}
  range_m:  {bind: stack.lidar.range_m,   range: [20, 150], step: 10}
objectives: [{minimize: hardware_cost}, {minimize: nav_time_s}]
constraints: [nav_time_s <= 80]
exploration: {budget: 12, seed: 3, batch: 3}
)");
  ASSERT_GT(spec.design_space.Size(), 3000000u);
  std::unique_ptr<Strategy> strategy = Create(spec);
  ASSERT_NE(strategy, nullptr);
  const std::vector<spec::DesignPoint> points =
      Drive(*strategy, 3, [](const spec::DesignPoint& point) {
        Observation o;
        o.point = point;
        const double compute = point.at("cores") * point.at("freq_ghz");
        const double load = point.at("lidar_hz") * point.at("beams") *
                            point.at("range_m") / 2000.0;
        const double nav = 30.0 + 40.0 * load / compute;
        o.metrics = {
            {"nav_time_s", nav}, {"hardware_cost", compute}, {"completed", 1}};
        o.feasible = nav <= 80.0;
        return o;
      });
  EXPECT_EQ(points.size(), 12u);
  ExpectDistinctAndAllowed(spec, points);
}

// The agent's rationale for its second pick, after its start
// (`start_from`) was run; `start` is checked by `check_start`.
template <typename F>
std::string RationaleAfterTheStart(const std::string& start, F check_start) {
  const spec::Spec spec = MakeSpec("{budget: 5, start_from: {" + start + "}}");
  std::unique_ptr<Strategy> strategy = Create(spec);
  if (strategy == nullptr) return {};
  const std::vector<spec::DesignPoint> first = strategy->Ask(1);
  if (first.size() != 1u) return {};
  const Observation o = Evaluate(first[0]);
  check_start(o);
  strategy->Tell(o);
  EXPECT_EQ(strategy->Ask(1).size(), 1u);
  return strategy->rationale();
}

TEST(AgentTest, RationaleNamesTheLastPointAndTheDiagnosis) {
  const std::string text = RationaleAfterTheStart(
      "cores: 3, freq_ghz: 1.0, lidar_hz: 14",
      [](const Observation& o) { EXPECT_FALSE(o.feasible); });
  EXPECT_NE(text.find("3 cores, 1 GHz, lidar_hz 14"), std::string::npos)
      << text;
  EXPECT_NE(text.find("infeasible"), std::string::npos) << text;
  EXPECT_NE(text.find("nav_time_s"), std::string::npos) << text;
  EXPECT_NE(text.find("ndt_scan_matcher"), std::string::npos) << text;
  EXPECT_NE(text.find("p="), std::string::npos) << text;
}

// A start that never arrives measures no navigation time: the next pick's
// reason says so rather than print a number the model never fitted.
TEST(AgentTest, RationaleGivesNoPredictionForAMetricNoRunMeasured) {
  const std::string text = RationaleAfterTheStart(
      "cores: 1, freq_ghz: 1.0, lidar_hz: 14",
      [](const Observation& o) { EXPECT_EQ(o.metrics.at("completed"), 0.0); });
  EXPECT_NE(text.find("nav_time_s not predicted yet (no run measured it)"),
            std::string::npos)
      << text;
  EXPECT_EQ(text.find("nav_time_s 0"), std::string::npos) << text;
  // The cost comes from the cost expression, not from a model.
  EXPECT_NE(text.find("at hardware_cost "), std::string::npos) << text;
  EXPECT_EQ(text.find("hardware_cost not predicted"), std::string::npos)
      << text;
}

// A run stopped at its time bound a quarter of the way along its route
// would, at the pace it kept, have needed four times the bound: the next
// pick's reason says so (and the model takes the bound there once a run
// has measured a time).
TEST(AgentTest, AStoppedRunIsReadByHowFarItGot) {
  const spec::Spec spec = MakeSpec(
      "{budget: 5, start_from: {cores: 2, freq_ghz: 1.0, lidar_hz: 14}}");
  std::unique_ptr<Strategy> strategy = Create(spec);
  ASSERT_NE(strategy, nullptr);
  const std::vector<spec::DesignPoint> first = strategy->Ask(1);
  ASSERT_EQ(first.size(), 1u);
  Observation o;
  o.point = first[0];
  o.metrics = {
      {"hardware_cost", 2.0}, {"censored", 1}, {"driven_fraction", 0.25}};
  o.censored = true;
  o.violated_constraint = "nav_time_s <= 60";
  strategy->Tell(o);
  ASSERT_EQ(strategy->Ask(1).size(), 1u);
  EXPECT_NE(strategy->rationale().find(
                "stopped 25 % of the way: at its pace nav_time_s 240 or more"),
            std::string::npos)
      << strategy->rationale();
}

// The constraint-aware front of the whole synthetic space.
std::set<spec::DesignPoint> TrueFront(const spec::Spec& spec) {
  SpaceGrid grid(spec.design_space);
  std::vector<std::pair<spec::DesignPoint, std::vector<double>>> feasible;
  for (uint64_t i = 0; i < grid.size(); ++i) {
    const Observation o = Evaluate(grid.ToPoint(grid.Decode(i)));
    if (o.feasible) {
      feasible.emplace_back(o.point, MinimizationObjectives(spec, o));
    }
  }
  std::set<spec::DesignPoint> front;
  for (const auto& [point, objectives] : feasible) {
    bool dominated = false;
    for (const auto& [other, theirs] : feasible) {
      bool no_worse = true, better = false;
      for (size_t j = 0; j < objectives.size(); ++j) {
        no_worse = no_worse && theirs[j] <= objectives[j];
        better = better || theirs[j] < objectives[j];
      }
      dominated = dominated || (no_worse && better);
    }
    if (!dominated) front.insert(point);
  }
  return front;
}

int FrontPointsFound(const std::vector<spec::DesignPoint>& points,
                     const std::set<spec::DesignPoint>& front) {
  int found = 0;
  for (const spec::DesignPoint& point : points) {
    found += front.count(point) ? 1 : 0;
  }
  return found;
}

TEST(AgentTest, FindsMoreOfTheTrueFrontThanRandomSearch) {
  const spec::Spec reference = MakeSpec("{budget: 15}");
  const std::set<spec::DesignPoint> front = TrueFront(reference);
  ASSERT_GE(front.size(), 10u);
  int agent_total = 0;
  int random_total = 0;
  int agent_worst = 1000;
  constexpr int kSeeds = 5;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const spec::Spec spec =
        MakeSpec("{budget: 15, seed: " + std::to_string(seed) +
                 ", start_from: {cores: 12, freq_ghz: 1.5, lidar_hz: 14}}");
    std::unique_ptr<Strategy> agent = Create(spec);
    std::unique_ptr<Strategy> random = Create(spec, "random");
    ASSERT_TRUE(agent && random);
    const int a = FrontPointsFound(Drive(*agent, 1), front);
    const int r = FrontPointsFound(Drive(*random, 1), front);
    agent_total += a;
    random_total += r;
    agent_worst = std::min(agent_worst, a);
  }
  // A third of a 15-point budget lands on the true front, far more than
  // random search finds. (Measured: 25 of 75, worst seed 4; before every
  // 4th pick went to the cheapest design, 35 and 5.)
  EXPECT_GE(agent_total, kSeeds * 4) << "random: " << random_total;
  EXPECT_GE(agent_total, 2 * random_total + kSeeds);
  EXPECT_GE(agent_worst, 3);
}

}  // namespace
}  // namespace adse::explore
