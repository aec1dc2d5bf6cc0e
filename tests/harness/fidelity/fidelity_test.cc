// The comparison `adse fidelity` prints, on runs built by hand: medians of
// the real-time runs against the virtual run, the targets, nav times only
// between runs that reached the goal (a run that did not misses the target),
// and callbacks under 1 ms left out.
#include "harness/fidelity/fidelity.h"
#include "tests/testing/temp_files.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace adse::fidelity {
namespace {

// A run that reached the goal (or timed out) with one 10 ms callback
// ("a/work", `work_ms` each) and one 0.1 ms callback ("a/tick").
runfile::RunData MadeRun(double nav_time_s, double ctrl_rate_hz, double work_ms,
                         bool reached = true) {
  runfile::RunData run;
  run.termination_reason = reached ? "goal_reached" : "timeout";
  run.metrics = {{"nav_time_s", nav_time_s},
                 {"ctrl_rate_hz", ctrl_rate_hz},
                 {"e2e_latency_p50_s", 0.3},
                 {"dropped_messages", 10},
                 {"lidar_frames_dropped", 2}};
  run.callback_info = {
      {"a/work", 0, runfile::CallbackKind::kSubscription, 0, 0.0},
      {"a/tick", 0, runfile::CallbackKind::kTimer, -1, 0.01}};
  for (int i = 0; i < 100; ++i) {
    stack::CallbackRecord work;
    work.callback = 0;
    work.start_s = i;
    work.end_s = i + work_ms / 1000.0 * (i == 99 ? 3.0 : 1.0);
    run.trace.callbacks.push_back(work);
    stack::CallbackRecord tick;
    tick.callback = 1;
    tick.start_s = i;
    tick.end_s = i + 0.0001;
    run.trace.callbacks.push_back(tick);
  }
  return run;
}

const Comparison& Find(const std::vector<Comparison>& rows,
                       const std::string& name) {
  for (const Comparison& c : rows) {
    if (c.name == name) return c;
  }
  ADD_FAILURE() << name << " missing";
  return rows.front();
}

TEST(FidelityTest, TheMedianRealTimeRunIsHeldAgainstTheVirtualOne) {
  const PointFidelity f =
      CompareRuns(MadeRun(100.0, 30.0, 10.0),
                  {MadeRun(104.0, 27.0, 11.0), MadeRun(130.0, 20.0, 13.0),
                   MadeRun(101.0, 28.0, 12.5)});
  const Comparison& nav = Find(f.metrics, "nav_time_s");
  EXPECT_DOUBLE_EQ(nav.realtime_median, 104.0);
  EXPECT_NEAR(nav.difference, 0.04, 1e-12);
  EXPECT_TRUE(nav.met());
  const Comparison& ctrl = Find(f.metrics, "ctrl_rate_hz");
  EXPECT_DOUBLE_EQ(ctrl.realtime_median, 27.0);
  EXPECT_NEAR(ctrl.difference, -0.1, 1e-12);
  EXPECT_TRUE(ctrl.met());  // exactly at the 10 % bound
  EXPECT_EQ(ctrl.realtime.size(), 3u);
  EXPECT_FALSE(Find(f.metrics, "dropped_messages").tolerance);

  // One callback of at least 1 ms: its p50 and p99; the 0.1 ms timer is
  // left out.
  ASSERT_EQ(f.callback_p50_ms.size(), 1u);
  EXPECT_EQ(f.callback_p50_ms[0].name, "a/work");
  EXPECT_NEAR(f.callback_p50_ms[0].virtual_value, 10.0, 1e-9);
  EXPECT_NEAR(f.callback_p50_ms[0].realtime_median, 12.5, 1e-9);
  EXPECT_NEAR(f.callback_p50_ms[0].difference, 0.25, 1e-9);
  EXPECT_FALSE(f.callback_p50_ms[0].met()) << "25 % is past the 20 % target";
  EXPECT_NEAR(f.callback_p99_ms[0].virtual_value, 10.0, 1e-9);
  // How many invocations each p50 is of.
  EXPECT_EQ(f.callback_p50_ms[0].virtual_count, 100);
  EXPECT_EQ(f.callback_p50_ms[0].realtime_counts,
            (std::vector<int>{100, 100, 100}));

  const std::string table = FormatPointFidelity(f);
  EXPECT_NE(table.find("±20% missed"), std::string::npos) << table;
  EXPECT_NE(table.find("±10% met"), std::string::npos) << table;
  EXPECT_NE(
      table.find("±20% missed  n 100 / 100, 100, 100, first 100 compared"),
      std::string::npos)
      << table;
}

// "a/work" invoked `ms.size()` times, the i-th taking ms[i].
runfile::RunData WithWork(const std::vector<double>& ms) {
  runfile::RunData run = MadeRun(100.0, 30.0, 10.0);
  std::erase_if(run.trace.callbacks,
                [](const stack::CallbackRecord& r) { return r.callback == 0; });
  for (size_t i = 0; i < ms.size(); ++i) {
    stack::CallbackRecord work;
    work.callback = 0;
    work.start_s = static_cast<double>(i);
    work.end_s = work.start_s + ms[i] / 1000.0;
    work.work_units = 1000.0;
    run.trace.callbacks.push_back(work);
  }
  return run;
}

TEST(FidelityTest, InvocationsOnlyTheRealTimeRunMadeAreNotCompared) {
  // Both platforms draw the same costs in order: 10 and 20 ms alternating.
  // The real-time run kept up better and made two more invocations, whose
  // draws were 30 ms. Over all invocations its p50 would be 20 ms (+100 %);
  // over the twelve both made, 10 ms as the virtual run's.
  std::vector<double> draws;
  for (int i = 0; i < 12; ++i) draws.push_back(i % 2 == 0 ? 10.0 : 20.0);
  std::vector<double> more = draws;
  more.insert(more.end(), {30.0, 30.0});
  const PointFidelity f = CompareRuns(WithWork(draws), {WithWork(more)});
  const Comparison& p50 = Find(f.callback_p50_ms, "a/work");
  EXPECT_EQ(p50.virtual_count, 12);
  EXPECT_EQ(p50.realtime_counts, (std::vector<int>{14}));
  EXPECT_EQ(p50.compared_count, 12);
  EXPECT_NEAR(p50.virtual_value, 10.0, 1e-9);
  EXPECT_NEAR(p50.difference, 0.0, 1e-9);
  EXPECT_TRUE(p50.met());
  EXPECT_NEAR(Find(f.callback_p99_ms, "a/work").virtual_value, 20.0, 1e-9);
  EXPECT_NEAR(Find(f.callback_p99_ms, "a/work").difference, 0.0, 1e-9);
  EXPECT_NEAR(Find(f.callback_p50_ms_per_kunit, "a/work").difference, 0.0,
              1e-9);
  // Records out of start order (as a trace may hold them) are paired by
  // when each invocation started.
  runfile::RunData shuffled = WithWork(more);
  std::reverse(shuffled.trace.callbacks.begin(),
               shuffled.trace.callbacks.end());
  EXPECT_NEAR(
      Find(CompareRuns(WithWork(draws), {shuffled}).callback_p50_ms, "a/work")
          .difference,
      0.0, 1e-9);
  // A real-time run slower on the invocations both made still misses.
  std::vector<double> slower = more;
  for (double& ms : slower) ms *= 1.3;
  EXPECT_NEAR(
      Find(CompareRuns(WithWork(draws), {WithWork(slower)}).callback_p50_ms,
           "a/work")
          .difference,
      0.3, 1e-9);
}

TEST(FidelityTest, PerturbedRunsMoveEveryCostByPartsInTenThousand) {
  EXPECT_DOUBLE_EQ(PerturbedCostScale(1), 1.0001);
  EXPECT_DOUBLE_EQ(PerturbedCostScale(2), 0.9999);
  EXPECT_DOUBLE_EQ(PerturbedCostScale(3), 1.0002);
  EXPECT_DOUBLE_EQ(PerturbedCostScale(4), 0.9998);
}

// A starved closed loop answers a tiny change of costs with another
// callback order, so the run metrics are compared as the median of the
// virtual runs; the callbacks (paired by invocation) only with the
// scenario's own run.
TEST(FidelityTest, TheVirtualRunsMedianIsHeldAgainstTheRealTimeRuns) {
  const runfile::RunData own = MadeRun(100.0, 30.0, 10.0);
  const std::vector<runfile::RunData> realtime = {MadeRun(101.0, 34.0, 10.0)};
  const std::vector<runfile::RunData> perturbed = {
      MadeRun(99.0, 33.0, 20.0), MadeRun(102.0, 34.0, 20.0),
      MadeRun(98.0, 26.0, 20.0), MadeRun(100.0, 35.0, 20.0)};
  const PointFidelity alone = CompareRuns(own, realtime);
  EXPECT_FALSE(Find(alone.metrics, "ctrl_rate_hz").met()) << "+13 % of 30";
  const PointFidelity f = CompareRuns(own, realtime, perturbed);
  const Comparison& ctrl = Find(f.metrics, "ctrl_rate_hz");
  EXPECT_EQ(ctrl.virtual_runs, (std::vector<double>{30, 33, 34, 26, 35}));
  EXPECT_DOUBLE_EQ(ctrl.virtual_value, 33.0);
  EXPECT_NEAR(ctrl.difference, 1.0 / 33.0, 1e-12);
  EXPECT_TRUE(ctrl.met());
  // The callbacks: the scenario's own run alone (10 ms, not 20).
  EXPECT_NEAR(Find(f.callback_p50_ms, "a/work").virtual_value, 10.0, 1e-9);
  EXPECT_EQ(Find(f.callback_p50_ms, "a/work").virtual_runs.size(), 1u);
  const std::string table = FormatPointFidelity(f);
  EXPECT_NE(table.find("virtual (; median of 5 runs, costs x (1 ± 0.0002)) "
                       "vs real-time (median of 1 run"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("virtual runs"), std::string::npos) << table;
  EXPECT_NE(table.find("26–35"), std::string::npos) << table;
  EXPECT_EQ(FormatPointFidelity(alone).find("virtual runs"), std::string::npos);

  // A perturbed run that did not arrive: the nav time misses its target,
  // and the runs' endings differ.
  std::vector<runfile::RunData> one_late = perturbed;
  one_late[2] = MadeRun(30.0, 26.0, 20.0, false);
  const PointFidelity late = CompareRuns(own, realtime, one_late);
  const Comparison& nav = Find(late.metrics, "nav_time_s");
  EXPECT_EQ(nav.virtual_runs_without, 1);
  EXPECT_FALSE(nav.met());
  EXPECT_NE(FormatPointFidelity(late).find(
                "ended: virtual goal_reached (perturbed: goal_reached, "
                "goal_reached, timeout, goal_reached); real-time "
                "goal_reached  (differ)"),
            std::string::npos)
      << FormatPointFidelity(late);
}

TEST(FidelityTest, NavTimesOfRunsThatTimedOutAreNotCompared) {
  const PointFidelity f = CompareRuns(MadeRun(30.0, 4.0, 10.0, false),
                                      {MadeRun(30.0, 3.0, 10.0, false)});
  const Comparison& nav = Find(f.metrics, "nav_time_s");
  EXPECT_TRUE(std::isnan(nav.virtual_value));
  EXPECT_TRUE(nav.realtime.empty());
  EXPECT_TRUE(std::isnan(nav.difference));
  EXPECT_FALSE(nav.met());
  EXPECT_NEAR(Find(f.metrics, "ctrl_rate_hz").difference, -0.25, 1e-12);
}

TEST(FidelityTest, ARealTimeRunThatDidNotArriveMissesTheNavTimeTarget) {
  // The virtual run and one real-time run arrive 3 % apart; the other
  // real-time run stalls. The median of the one that arrived would meet
  // the target and hide that.
  runfile::RunData stalled = MadeRun(168.8, 4.9, 10.0, false);
  stalled.termination_reason = "stalled: localization_lost";
  const PointFidelity f = CompareRuns(MadeRun(115.0, 5.0, 10.0),
                                      {MadeRun(112.0, 4.9, 10.0), stalled});
  const Comparison& nav = Find(f.metrics, "nav_time_s");
  EXPECT_EQ(nav.realtime.size(), 1u);
  EXPECT_EQ(nav.runs_without, 1);
  EXPECT_NEAR(nav.difference, -3.0 / 115.0, 1e-12);
  EXPECT_FALSE(nav.met());
  EXPECT_TRUE(Find(f.metrics, "ctrl_rate_hz").met());
  EXPECT_EQ(f.virtual_outcome, "goal_reached");
  ASSERT_EQ(f.realtime_outcomes.size(), 2u);
  EXPECT_EQ(f.realtime_outcomes[1], "stalled: localization_lost");
  const std::string table = FormatPointFidelity(f);
  EXPECT_NE(table.find("ended: virtual goal_reached; real-time goal_reached, "
                       "stalled: localization_lost  (differ)"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("(1 without)"), std::string::npos) << table;
}

TEST(FidelityTest, ACallbackThatNeverRanInARealTimeRunMissesItsTarget) {
  runfile::RunData idle = MadeRun(100.0, 30.0, 10.0);
  std::erase_if(idle.trace.callbacks,
                [](const stack::CallbackRecord& r) { return r.callback == 0; });
  const PointFidelity f = CompareRuns(MadeRun(100.0, 30.0, 10.0),
                                      {MadeRun(100.0, 30.0, 10.0), idle});
  const Comparison& work = Find(f.callback_p50_ms, "a/work");
  EXPECT_EQ(work.runs_without, 1);
  EXPECT_EQ(work.realtime_counts, (std::vector<int>{100, 0}));
  EXPECT_NEAR(work.difference, 0.0, 1e-9);
  EXPECT_FALSE(work.met());
}

// Two dispatches held against the same real-time runs at two points: the
// summary counts each dispatch's met targets apart, and says where no run
// arrived to compare a nav time.
TEST(FidelityTest, TheSummaryCountsEachDispatchsMetTargets) {
  const std::vector<runfile::RunData> realtime = {MadeRun(100.0, 30.0, 10.0),
                                                  MadeRun(100.0, 30.0, 10.0)};
  std::vector<PointFidelity> points;
  for (const auto& [dispatch, work_ms] :
       {std::pair{"run_to_completion", 7.0},
        std::pair{"processor_sharing", 10.5}}) {
    PointFidelity arrived =
        CompareRuns(MadeRun(100.0, 30.0, work_ms), realtime);
    arrived.dispatch = dispatch;
    points.push_back(arrived);
    PointFidelity timed_out = CompareRuns(MadeRun(30.0, 30.0, work_ms, false),
                                          {MadeRun(30.0, 30.0, 10.0, false)});
    timed_out.dispatch = dispatch;
    points.push_back(timed_out);
  }
  const std::string summary = FormatDispatchSummary(points);
  // Its rows with their spacing folded: dispatch, control rate, nav time
  // (only where a run arrived), callback p50s, median |p50 difference|.
  std::vector<std::string> rows;
  std::istringstream lines(summary);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string row, word;
    while (words >> word) row += (row.empty() ? "" : " ") + word;
    rows.push_back(row);
  }
  ASSERT_EQ(rows.size(), 3u) << summary;
  // 10 ms in real time: +42.9 % from 7 ms (missed), -4.8 % from 10.5 (met).
  EXPECT_EQ(rows[1], "run_to_completion 2 of 2 1 of 1 0 of 2 42.9%");
  EXPECT_EQ(rows[2], "processor_sharing 2 of 2 1 of 1 2 of 2 4.8%");
}

TEST(FidelityTest, MoreWorkIsToldFromASlowerExecutorPerWorkUnit) {
  // The real-time run took twice as long because its callback was given
  // twice the work (as NDT's iterations grow with a worse initial guess):
  // per 1000 work units the platforms agree.
  runfile::RunData virtual_run = MadeRun(100.0, 30.0, 10.0);
  runfile::RunData realtime_run = MadeRun(100.0, 30.0, 20.0);
  for (stack::CallbackRecord& r : virtual_run.trace.callbacks) {
    if (r.callback == 0) r.work_units = 5000;
  }
  for (stack::CallbackRecord& r : realtime_run.trace.callbacks) {
    if (r.callback == 0) r.work_units = 10000;
  }
  const PointFidelity f = CompareRuns(virtual_run, {realtime_run});
  EXPECT_NEAR(Find(f.callback_p50_ms, "a/work").difference, 1.0, 1e-9);
  // The timer reported no work and is under 1 ms: not listed.
  ASSERT_EQ(f.callback_p50_ms_per_kunit.size(), 1u);
  const Comparison& unit = f.callback_p50_ms_per_kunit[0];
  EXPECT_EQ(unit.name, "a/work");
  EXPECT_NEAR(unit.virtual_value, 2.0, 1e-9);  // 10 ms per 5000 units
  EXPECT_NEAR(unit.difference, 0.0, 1e-9);
  EXPECT_NE(FormatPointFidelity(f).find("per 1000 work units"),
            std::string::npos);
}

// `adse fidelity --compare`'s reading of a folder: what is not a folder of
// its runs is an error naming the folder or file (the CLI test reads real
// runs back).
TEST(FidelityTest, AFolderWithoutFidelityRunsIsAnErrorNamingIt) {
  const std::filesystem::path dir =
      adse::testing::TestScratch() / "adse_fidelity_read_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  Result<std::vector<PointRuns>> none = ReadPointRuns(dir.string());
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.status().code(), Status::Code::kNotFound);
  EXPECT_NE(none.status().message().find((dir / "runs").string()),
            std::string::npos)
      << none.status().message();

  std::filesystem::create_directories(dir / "runs");
  EXPECT_EQ(ReadPointRuns(dir.string()).status().code(),
            Status::Code::kNotFound);
  auto touch = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / "runs" / name) << text;
  };
  touch("notes.txt", "not a run");  // other files are left alone
  touch("1-virtual.h5", "not HDF5");
  Result<std::vector<PointRuns>> lone = ReadPointRuns(dir.string());
  ASSERT_FALSE(lone.ok());
  EXPECT_NE(lone.status().message().find(
                "point 1 has 1 virtual and 0 real-time run files"),
            std::string::npos)
      << lone.status().message();

  touch("1-realtime-1.h5", "not HDF5");
  Result<std::vector<PointRuns>> corrupt = ReadPointRuns(dir.string());
  ASSERT_FALSE(corrupt.ok());
  EXPECT_NE(corrupt.status().message().find("1-virtual.h5"), std::string::npos)
      << corrupt.status().message();

  // A perturbed virtual run's name is one of its runs' (read, and found
  // damaged like the rest).
  touch("1-virtual-p1.h5", "not HDF5");
  Result<std::vector<PointRuns>> perturbed = ReadPointRuns(dir.string());
  ASSERT_FALSE(perturbed.ok());
  EXPECT_EQ(perturbed.status().message().find("expected run files named"),
            std::string::npos)
      << perturbed.status().message();
  std::filesystem::remove(dir / "runs" / "1-virtual-p1.h5");

  touch("99999999999-virtual.h5", "");
  EXPECT_EQ(ReadPointRuns(dir.string()).status().code(),
            Status::Code::kInvalidArgument);
  std::filesystem::remove(dir / "runs" / "99999999999-virtual.h5");
  touch("run.h5", "");
  Result<std::vector<PointRuns>> named = ReadPointRuns(dir.string());
  ASSERT_FALSE(named.ok());
  EXPECT_EQ(named.status().code(), Status::Code::kInvalidArgument);
  EXPECT_NE(named.status().message().find("run.h5: expected run files named"),
            std::string::npos)
      << named.status().message();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace adse::fidelity
