// The DSE agent's memory: which past evaluations go into an instruction
// and why, how they read, and the append-only file they live in.
#include "harness/llm/memory.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/explore/strategy.h"
#include "harness/llm/jsonl_log.h"
#include "tests/harness/testing/small_scenario.h"
#include "tests/testing/temp_files.h"

namespace adse::llm {
namespace {

namespace fs = std::filesystem;
using adse::testing::SmallPoint;
using adse::testing::SmallScenario;
using ::testing::ElementsAre;
using ::testing::IsEmpty;
using ::testing::Pair;
using ::testing::StartsWith;

using Picked = std::vector<std::pair<const MemoryRecord*, std::string>>;

std::string TempDir(const std::string& name) {
  return adse::testing::FreshTempDir("adse-llmunit-memory", name);
}

struct Outcome {
  double cost = NAN;      // hardware_cost; NaN: not measured
  double nav_s = NAN;     // nav_time_s; NaN: not measured
  bool completed = true;  // the "completed" metric
  bool feasible = true;
  bool failed = false;
};

MemoryRecord Rec(int64_t index, spec::DesignPoint point, Outcome o) {
  MemoryRecord r;
  r.index = index;
  r.iteration = index;
  r.point = std::move(point);
  r.feasible = o.feasible && !o.failed;
  r.failed = o.failed;
  if (!o.failed) {
    r.metrics["completed"] = o.completed ? 1.0 : 0.0;
    if (!std::isnan(o.cost)) r.metrics["hardware_cost"] = o.cost;
    if (!std::isnan(o.nav_s)) r.metrics["nav_time_s"] = o.nav_s;
  }
  return r;
}

// Options that pick nothing: a test turns on what it checks.
CurationOptions Nothing() {
  CurationOptions o;
  o.cheapest_feasible = 0;
  o.front = 0;
  o.fastest = 0;
  o.most_recent = 0;
  o.nearest = 0;
  o.failures = 0;
  return o;
}

// The picks as (evaluation index, reasons), checking that each points
// into `records`.
std::vector<std::pair<int64_t, std::string>> Indices(
    const Picked& picked, const std::vector<MemoryRecord>& records) {
  std::vector<std::pair<int64_t, std::string>> out;
  for (const auto& [record, why] : picked) {
    EXPECT_GE(record, records.data());
    EXPECT_LT(record, records.data() + records.size());
    out.push_back({record->index, why});
  }
  return out;
}

// A design space of one parameter x = 0, 1, ..., n-1.
spec::DesignSpace Line(int n) {
  spec::DesignParameter x;
  x.name = "x";
  x.bind = "platform.cores";
  for (int i = 0; i < n; ++i) x.values.push_back(i);
  x.integer = true;
  spec::DesignSpace space;
  space.parameters = {x};
  return space;
}

TEST(CurateTest, NoHistoryPicksNothing) {
  const spec::Spec spec = SmallScenario();
  EXPECT_THAT(Curate({}, spec.design_space), IsEmpty());
  EXPECT_EQ(FormatMemory({}), "(none yet)");
}

TEST(CurateTest, TheFrontIsTheOneEveryCommandComputesAndItsCheapestArePicked) {
  const spec::Spec spec = SmallScenario();  // cost and nav time, nav <= 60
  const std::vector<MemoryRecord> records = {
      Rec(0, SmallPoint(4, 1.0, 7), {.cost = 4, .nav_s = 50}),
      Rec(1, SmallPoint(8, 1.0, 7), {.cost = 8, .nav_s = 30}),
      Rec(2, SmallPoint(4, 2.1, 7), {.cost = 8, .nav_s = 40}),  // dominated
      Rec(3, SmallPoint(1, 2.1, 7),
          {.cost = 2, .nav_s = 70, .feasible = false}),
      Rec(4, SmallPoint(16, 2.1, 14), {.failed = true}),
      Rec(5, SmallPoint(12, 1.0, 7), {.cost = 12, .nav_s = 25}),
  };
  const std::vector<int> front = ParetoFrontOfMemory(spec, records);
  EXPECT_THAT(front, ElementsAre(0, 1, 5));
  // The same as explore::ParetoFrontOf over the same observations, which
  // campaigns, replay and analysis use.
  std::vector<explore::Observation> observations;
  for (const MemoryRecord& r : records) {
    explore::Observation o;
    o.point = r.point;
    o.metrics = r.metrics;
    o.feasible = r.feasible;
    o.failed = r.failed;
    observations.push_back(o);
  }
  EXPECT_EQ(explore::ParetoFrontOf(spec, observations), front);
  CurationOptions o = Nothing();
  o.front = 2;
  EXPECT_THAT(Indices(Curate(records, spec.design_space, o, front), records),
              ElementsAre(Pair(0, "on the Pareto front"),
                          Pair(1, "on the Pareto front")));
}

TEST(CurateTest, PicksTheCheapestFeasibleByHardwareCost) {
  const spec::Spec spec = SmallScenario();
  const std::vector<MemoryRecord> records = {
      Rec(0, SmallPoint(1, 1.0, 7), {.cost = 5}),
      Rec(1, SmallPoint(4, 1.0, 7), {.cost = 1, .feasible = false}),
      Rec(2, SmallPoint(16, 2.1, 14), {.failed = true}),
      Rec(3, SmallPoint(4, 2.1, 7), {.cost = 3}),
      Rec(4, SmallPoint(4, 2.1, 14), {.cost = 3}),  // ties with #3
      Rec(5, SmallPoint(1, 2.1, 7), {}),            // cost not measured
      Rec(6, SmallPoint(16, 1.0, 7), {.cost = 4}),
  };
  CurationOptions o = Nothing();
  o.cheapest_feasible = 3;
  EXPECT_THAT(
      Indices(Curate(records, spec.design_space, o), records),
      ElementsAre(Pair(3, "cheapest feasible"), Pair(4, "cheapest feasible"),
                  Pair(6, "cheapest feasible")));
  // Asked for more than there are: every feasible one, unmeasured last.
  o.cheapest_feasible = 10;
  EXPECT_THAT(
      Indices(Curate(records, spec.design_space, o), records),
      ElementsAre(Pair(0, "cheapest feasible"), Pair(3, "cheapest feasible"),
                  Pair(4, "cheapest feasible"), Pair(5, "cheapest feasible"),
                  Pair(6, "cheapest feasible")));
}

TEST(CurateTest, ATieGoesToTheEarlierEvaluation) {
  const spec::Spec spec = SmallScenario();
  const std::vector<MemoryRecord> records = {
      Rec(0, SmallPoint(1, 1.0, 7), {.cost = 2}),
      Rec(1, SmallPoint(4, 1.0, 7), {.cost = 2}),
      Rec(2, SmallPoint(16, 1.0, 7), {.cost = 2}),
  };
  CurationOptions o = Nothing();
  o.cheapest_feasible = 1;
  EXPECT_THAT(Indices(Curate(records, spec.design_space, o), records),
              ElementsAre(Pair(0, "cheapest feasible")));
}

TEST(CurateTest, PicksTheFastestAmongCompletedRuns) {
  const spec::Spec spec = SmallScenario();
  std::vector<MemoryRecord> records = {
      Rec(0, SmallPoint(1, 1.0, 7), {.nav_s = 50}),
      // Infeasible but completed: still fast.
      Rec(1, SmallPoint(4, 1.0, 7), {.nav_s = 30, .feasible = false}),
      // Did not complete: its time says nothing.
      Rec(2, SmallPoint(16, 1.0, 7), {.nav_s = 10, .completed = false}),
      Rec(3, SmallPoint(1, 2.1, 7), {.failed = true}),
      Rec(4, SmallPoint(4, 2.1, 7), {.nav_s = 40}),
      Rec(5, SmallPoint(16, 2.1, 7), {}),  // time not measured
      Rec(6, SmallPoint(1, 1.0, 14), {.nav_s = 5}),
  };
  // Failed runs are never fastest, whatever their metrics say.
  records[3].metrics = {{"completed", 1}, {"nav_time_s", 1}};
  // No "completed" metric: not known to have completed.
  records[6].metrics.erase("completed");
  CurationOptions o = Nothing();
  o.fastest = 2;
  EXPECT_THAT(Indices(Curate(records, spec.design_space, o), records),
              ElementsAre(Pair(1, "fastest"), Pair(4, "fastest")));
}

TEST(CurateTest, PicksTheMostRecent) {
  const spec::Spec spec = SmallScenario();
  std::vector<MemoryRecord> records;
  for (int i = 0; i < 5; ++i) {
    records.push_back(Rec(i, SmallPoint(i < 3 ? 1 : 4, i % 2 ? 2.1 : 1.0, 7),
                          {.feasible = i % 2 == 0}));
  }
  CurationOptions o = Nothing();
  o.most_recent = 3;
  EXPECT_THAT(Indices(Curate(records, spec.design_space, o), records),
              ElementsAre(Pair(2, "most recent"), Pair(3, "most recent"),
                          Pair(4, "most recent")));
}

TEST(CurateTest, PicksTheNearestToTheLastPointInGridSteps) {
  const spec::Spec spec = SmallScenario();
  // The last point is (4, 1.0, 14); cores 1, 4, 16 are one step apart.
  const std::vector<MemoryRecord> records = {
      Rec(0, SmallPoint(1, 1.0, 7), {}),    // 2 steps
      Rec(1, SmallPoint(16, 2.1, 7), {}),   // 3 steps
      Rec(2, SmallPoint(4, 2.1, 14), {}),   // 1 step
      Rec(3, SmallPoint(16, 1.0, 14), {}),  // 1 step (16 is next to 4)
      Rec(4, SmallPoint(1, 2.1, 14), {}),   // 2 steps
      Rec(5, {{"cores", 4}}, {}),           // not comparable
      Rec(6, SmallPoint(4, 1.0, 14), {}),   // the last point
  };
  CurationOptions o = Nothing();
  o.nearest = 3;
  EXPECT_THAT(Indices(Curate(records, spec.design_space, o), records),
              ElementsAre(Pair(0, "near the last point"),
                          Pair(2, "near the last point"),
                          Pair(3, "near the last point")));
  // The last point is not its own neighbour.
  o.nearest = 10;
  const auto all = Indices(Curate(records, spec.design_space, o), records);
  ASSERT_EQ(all.size(), 6u);
  EXPECT_EQ(all.back().first, 5);
}

TEST(CurateTest, PicksFailedOrInfeasibleMostRecentFirst) {
  const spec::Spec spec = SmallScenario();
  const std::vector<MemoryRecord> records = {
      Rec(0, SmallPoint(1, 1.0, 7), {}),
      Rec(1, SmallPoint(4, 1.0, 7), {.feasible = false}),
      Rec(2, SmallPoint(16, 1.0, 7), {.failed = true}),
      Rec(3, SmallPoint(1, 2.1, 7), {}),
      Rec(4, SmallPoint(4, 2.1, 7), {.feasible = false}),
      Rec(5, SmallPoint(16, 2.1, 7), {}),
  };
  CurationOptions o = Nothing();
  o.failures = 2;
  EXPECT_THAT(Indices(Curate(records, spec.design_space, o), records),
              ElementsAre(Pair(2, "failed or infeasible"),
                          Pair(4, "failed or infeasible")));
}

TEST(CurateTest, JoinsEveryReasonARecordWasPickedFor) {
  const spec::Spec spec = SmallScenario();
  const std::vector<MemoryRecord> records = {
      Rec(0, SmallPoint(1, 1.0, 7), {.cost = 1, .nav_s = 50}),
      Rec(1, SmallPoint(4, 1.0, 7),
          {.cost = 2, .nav_s = 70, .feasible = false}),
      Rec(2, SmallPoint(16, 1.0, 7), {.failed = true}),
  };
  EXPECT_THAT(
      Indices(Curate(records, spec.design_space), records),
      ElementsAre(
          Pair(0,
               "cheapest feasible, fastest, most recent, near the last point"),
          Pair(1,
               "fastest, most recent, near the last point, failed or "
               "infeasible"),
          Pair(2, "most recent, failed or infeasible")));
}

// 20 evaluations where the default options pick 13 different records:
// cheapest #0-2, fastest #3-4, most recent #17-19, nearest #10-12 and
// failures #16, #15.
std::vector<MemoryRecord> ThirteenPicks() {
  std::vector<MemoryRecord> records;
  const double x[20] = {0,  1,  2,  3,  4,  5,  6,  7,  8,  9,
                        18, 17, 16, 10, 11, 12, 13, 14, 15, 19};
  for (int i = 0; i < 20; ++i) {
    Outcome o{.cost = 10, .nav_s = 100};
    if (i < 3) o.cost = i + 1;
    if (i == 3 || i == 4)
      o = {.cost = 50, .nav_s = 10.0 * (i - 2), .feasible = false};
    if (i == 15 || i == 16) o = {.failed = true};
    records.push_back(Rec(i, {{"x", x[i]}}, o));
  }
  return records;
}

TEST(CurateTest, EachCategoryPicksWhatItShouldInALongHistory) {
  const std::vector<MemoryRecord> records = ThirteenPicks();
  CurationOptions o;
  o.max_records = 100;
  EXPECT_THAT(
      Indices(Curate(records, Line(20), o), records),
      ElementsAre(
          Pair(0, "cheapest feasible"), Pair(1, "cheapest feasible"),
          Pair(2, "cheapest feasible"), Pair(3, "fastest"), Pair(4, "fastest"),
          Pair(10, "near the last point"), Pair(11, "near the last point"),
          Pair(12, "near the last point"), Pair(15, "failed or infeasible"),
          Pair(16, "failed or infeasible"), Pair(17, "most recent"),
          Pair(18, "most recent"), Pair(19, "most recent")));
}

TEST(CurateTest, OverTheBoundKeepsEachCategorysBestPicksAndTheLastEvaluation) {
  const std::vector<MemoryRecord> records = ThirteenPicks();
  // Twelve of thirteen: the last round (third picks) is cut short. The last
  // evaluation, the most recent one, is never what goes.
  EXPECT_THAT(
      Indices(Curate(records, Line(20)), records),
      ElementsAre(Pair(0, "cheapest feasible"), Pair(1, "cheapest feasible"),
                  Pair(2, "cheapest feasible"), Pair(3, "fastest"),
                  Pair(4, "fastest"), Pair(10, "near the last point"),
                  Pair(11, "near the last point"),
                  Pair(15, "failed or infeasible"),
                  Pair(16, "failed or infeasible"), Pair(17, "most recent"),
                  Pair(18, "most recent"), Pair(19, "most recent")));

  // A tight bound: each category's first pick, in category order.
  CurationOptions o;
  o.max_records = 4;
  EXPECT_THAT(
      Indices(Curate(records, Line(20), o), records),
      ElementsAre(Pair(0, "cheapest feasible"), Pair(3, "fastest"),
                  Pair(10, "near the last point"), Pair(19, "most recent")));
  o.max_records = 0;
  EXPECT_THAT(Curate(records, Line(20), o), IsEmpty());
}

TEST(CurateTest, IsBoundedWhateverTheHistory) {
  const spec::Spec spec = SmallScenario();
  std::vector<MemoryRecord> records;
  int i = 0;
  for (double cores : {1, 4, 16}) {
    for (double freq : {1.0, 2.1}) {
      for (double lidar : {7, 14}) {
        records.push_back(Rec(i, SmallPoint(cores, freq, lidar),
                              {.cost = 100.0 - i,
                               .nav_s = 10.0 + i,
                               .feasible = i % 3 != 0,
                               .failed = i % 5 == 4}));
        ++i;
      }
    }
  }
  // Unbounded, the options pick 8 different records here.
  for (int max : {1, 2, 5, 8, 12}) {
    CurationOptions o;
    o.max_records = max;
    const auto picked = Indices(Curate(records, spec.design_space, o), records);
    EXPECT_EQ(picked.size(), std::min<size_t>(max, 8)) << max;
    // In evaluation order, each once.
    for (size_t k = 1; k < picked.size(); ++k) {
      EXPECT_LT(picked[k - 1].first, picked[k].first) << max;
    }
  }
}

TEST(CurateTest, IsDeterministic) {
  const std::vector<MemoryRecord> records = ThirteenPicks();
  const std::vector<MemoryRecord> copy = records;
  const auto a = Indices(Curate(records, Line(20)), records);
  const auto b = Indices(Curate(records, Line(20)), records);
  const auto c = Indices(Curate(copy, Line(20)), copy);
  EXPECT_EQ(a, b);
  EXPECT_EQ(a, c);
  EXPECT_EQ(FormatMemory(Curate(records, Line(20))),
            FormatMemory(Curate(copy, Line(20))));
}

TEST(FormatMemoryTest,
     OneLinePerRecordWithItsOutcomeDiagnosisRationaleAndReasons) {
  MemoryRecord good;
  good.index = 7;
  good.point = SmallPoint(4, 2.1, 14);
  good.metrics = {
      {"completed", 1}, {"hardware_cost", 1250}, {"nav_time_s", 48.4321}};
  good.feasible = true;
  good.diagnosis =
      "cpu_bound ndt_scan_matcher (deficit 30 %, remedy: more cores)";
  good.rationale = "more cores for NDT";
  MemoryRecord failed;
  failed.index = 8;
  failed.point = SmallPoint(1, 1.0, 7);
  failed.failed = true;
  failed.rationale = "the cheapest point";
  MemoryRecord infeasible;
  infeasible.index = 9;
  infeasible.point = SmallPoint(16, 1.0, 7);
  infeasible.metrics = {{"completed", 0}};

  EXPECT_EQ(FormatMemory({{&good, "cheapest feasible, fastest"},
                          {&failed, "failed or infeasible"},
                          {&infeasible, "most recent"}}),
            "#7 cores=4 freq_ghz=2.1 lidar_hz=14 | feasible | completed=1 "
            "hardware_cost=1250 nav_time_s=48.43 | cpu_bound ndt_scan_matcher "
            "(deficit 30 %, remedy: more cores) | why: more cores for NDT "
            "[cheapest feasible, fastest]\n"
            "#8 cores=1 freq_ghz=1 lidar_hz=7 | run failed | why: the cheapest "
            "point [failed or infeasible]\n"
            "#9 cores=16 freq_ghz=1 lidar_hz=7 | infeasible | completed=0 "
            "[most recent]");

  MemoryRecord bare;
  bare.index = 0;
  bare.point = SmallPoint(1, 1.0, 7);
  bare.feasible = true;
  EXPECT_EQ(FormatMemory({{&bare, "most recent"}}),
            "#0 cores=1 freq_ghz=1 lidar_hz=7 | feasible [most recent]");
}

TEST(MemoryFileTest, RecordsRoundTripThroughTheFile) {
  const std::string dir = TempDir("round-trip");
  EXPECT_EQ(MemoryPath(dir), dir + "/llm/memory.jsonl");

  MemoryRecord a;
  a.index = 0;
  a.iteration = -1;
  a.point = SmallPoint(4, 2.1, 14);
  a.metrics = {{"completed", 1},
               {"nav_time_s", 48.4321},
               {"hardware_cost", 1250.125},
               {"deviation_score", std::nan("")}};
  a.feasible = true;
  a.diagnosis = "no bottleneck found";
  a.rationale = "said \"more\"\tcores\nfor NDT \xc3\xbc";
  a.proposed_by = "llm";
  MemoryRecord b;
  b.index = 1;
  b.iteration = 3;
  b.point = SmallPoint(1, 1.0, 7);
  b.failed = true;
  b.rationale = "bad \xff byte";
  b.proposed_by = "agent";

  const std::string line = MemoryLine(a);
  EXPECT_EQ(line.find('\n'), std::string::npos);
  std::set<std::string> keys;
  const nlohmann::json parsed = nlohmann::json::parse(line);
  for (const auto& item : parsed.items()) keys.insert(item.key());
  EXPECT_EQ(keys, (std::set<std::string>{
                      "index", "iteration", "point", "metrics", "feasible",
                      "failed", "diagnosis", "rationale", "proposed_by"}));

  Result<JsonlLog> log = JsonlLog::Open(MemoryPath(dir));
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_TRUE(log->Append(MemoryLine(a)).ok());
  ASSERT_TRUE(log->Append(MemoryLine(b)).ok());

  Result<std::vector<MemoryRecord>> loaded = LoadMemory(MemoryPath(dir));
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  ASSERT_EQ(loaded->size(), 2u);
  const MemoryRecord& la = (*loaded)[0];
  EXPECT_EQ(la.index, 0);
  EXPECT_EQ(la.iteration, -1);
  EXPECT_EQ(la.point, a.point);
  // Not-a-number is not written: the metric was not measured.
  EXPECT_EQ(la.metrics,
            (std::map<std::string, double>{{"completed", 1},
                                           {"nav_time_s", 48.4321},
                                           {"hardware_cost", 1250.125}}));
  EXPECT_TRUE(la.feasible);
  EXPECT_FALSE(la.failed);
  EXPECT_EQ(la.diagnosis, a.diagnosis);
  EXPECT_EQ(la.rationale, a.rationale);
  EXPECT_EQ(la.proposed_by, "llm");
  const MemoryRecord& lb = (*loaded)[1];
  EXPECT_EQ(lb.index, 1);
  EXPECT_EQ(lb.iteration, 3);
  EXPECT_EQ(lb.point, b.point);
  EXPECT_TRUE(lb.metrics.empty());
  EXPECT_FALSE(lb.feasible);
  EXPECT_TRUE(lb.failed);
  EXPECT_EQ(lb.diagnosis, "");
  // Bytes that are not UTF-8 are replaced, not lost with the record.
  EXPECT_EQ(lb.rationale, "bad \xef\xbf\xbd byte");
  EXPECT_EQ(lb.proposed_by, "agent");
  // What is loaded is written the same again.
  EXPECT_EQ(MemoryLine(lb), MemoryLine(b));
}

TEST(MemoryFileTest, LoadSkipsACutShortLastLineAndRefusesABadMiddleLine) {
  const std::string dir = TempDir("load");
  EXPECT_THAT(LoadMemory(MemoryPath(dir)).value(), IsEmpty());

  MemoryRecord r;
  r.point = SmallPoint(1, 1.0, 7);
  const std::string line = MemoryLine(r);
  fs::create_directories(dir + "/llm");
  {
    std::ofstream out(MemoryPath(dir));
    out << line << "\n" << line.substr(0, line.size() - 5);
  }
  Result<std::vector<MemoryRecord>> cut = LoadMemory(MemoryPath(dir));
  ASSERT_TRUE(cut.ok()) << cut.status().ToString();
  EXPECT_EQ(cut->size(), 1u);

  {
    std::ofstream out(MemoryPath(dir));
    out << line << "\n{\"index\": 1}\n" << line << "\n";
  }
  Result<std::vector<MemoryRecord>> bad = LoadMemory(MemoryPath(dir));
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), Status::Code::kCorruption);
  EXPECT_THAT(bad.status().message(),
              StartsWith(MemoryPath(dir) + ":2: not a memory record ("));
}

}  // namespace
}  // namespace adse::llm
