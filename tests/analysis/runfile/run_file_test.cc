// WriteRunFile / ReadRunFile: exact round trips, validation before
// writing, atomic replacement, identical bytes for identical runs, and
// concurrent writers.
#include "analysis/runfile/run_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/analysis/runfile/testing/run_data_impl.h"

namespace adse::runfile {
namespace {

namespace fs = std::filesystem;
using stack::TopicEvent;
using testing::Diff;
using testing::MakeFullRun;
using testing::RunFileTest;

TEST_F(RunFileTest, FullRunRoundTripsExactly) {
  const RunData run = MakeFullRun();
  const std::string path = Path("run.h5");
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  Result<RunData> back = ReadRunFile(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(Diff(run, *back), "");
}

TEST_F(RunFileTest, ParkingRecordRoundTripsAndIsAbsentOtherwise) {
  RunData run = MakeFullRun();
  ParkingRecord& p = run.parking;
  p.present = true;
  p.slot = "slot_r1_s4";
  p.goal_x_m = 20.75;
  p.goal_y_m = 21.35;
  p.goal_yaw_rad = -M_PI / 2;
  p.tolerance_m = 0.5;
  p.yaw_tolerance_rad = 0.17;
  p.planned_at_s = 20.0;
  p.path_found = 1;
  p.first_planned_at_s = 12.5;
  p.replans = 2;
  p.slots = {{20.75, 20.0, M_PI / 2, 5.0, 2.5, 0, 1},
             {18.25, 20.0, M_PI / 2, 5.0, 2.5, 1, 0}};
  p.obstacles = {{0, 0, 0}, {0, 10, 0}, {1, 5, 5}, {1, 6, 5}, {1, 6, 6}};
  p.planned_path = {{20.0, 15.75, M_PI, 0}, {24.0, 15.75, M_PI, 1}};
  p.earlier_plans = {{0, 19.0, 15.0, M_PI, 0}, {1, 19.5, 15.5, -M_PI, 1}};
  const std::string path = Path("valet.h5");
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  Result<RunData> back = ReadRunFile(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(Diff(run, *back), "");
  const ParkingRecord& q = back->parking;
  ASSERT_TRUE(q.present);
  EXPECT_EQ(q.slot, p.slot);
  EXPECT_EQ(q.goal_y_m, p.goal_y_m);
  EXPECT_EQ(q.goal_yaw_rad, p.goal_yaw_rad);
  EXPECT_EQ(q.yaw_tolerance_rad, p.yaw_tolerance_rad);
  EXPECT_EQ(q.planned_at_s, 20.0);
  EXPECT_EQ(q.path_found, 1);
  EXPECT_EQ(q.first_planned_at_s, 12.5);
  EXPECT_EQ(q.replans, 2);
  ASSERT_EQ(q.slots.size(), 2u);
  EXPECT_EQ(q.slots[1].occupied, 1);
  EXPECT_EQ(q.slots[0].target, 1);
  ASSERT_EQ(q.obstacles.size(), 5u);
  EXPECT_EQ(q.obstacles[4].obstacle, 1);
  EXPECT_EQ(q.obstacles[4].y_m, 6.0);
  ASSERT_EQ(q.planned_path.size(), 2u);
  EXPECT_EQ(q.planned_path[1].reverse, 1);
  ASSERT_EQ(q.earlier_plans.size(), 2u);
  EXPECT_EQ(q.earlier_plans[1].plan, 1);
  EXPECT_EQ(q.earlier_plans[1].yaw_rad, -M_PI);
  EXPECT_EQ(q.earlier_plans[1].reverse, 1);
  EXPECT_EQ(q.earlier_plans[0].x_m, 19.0);
  std::vector<std::string> problems;
  EXPECT_TRUE(CheckRunFile(path, &problems).ok()) << problems.size();
  // A lane-driving run has no /parking and reads back without one.
  ASSERT_TRUE(WriteRunFile(Path("plain.h5"), MakeFullRun()).ok());
  Result<RunData> plain = ReadRunFile(Path("plain.h5"));
  ASSERT_TRUE(plain.ok());
  EXPECT_FALSE(plain->parking.present);
}

TEST_F(RunFileTest, EmptyRunRoundTripsAndKeepsEmptyDatasets) {
  RunData run;  // defaults: no rows anywhere, empty strings
  const std::string path = Path("empty.h5");
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  Result<RunData> back = ReadRunFile(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(Diff(run, *back), "");
  std::vector<std::string> problems;
  EXPECT_TRUE(CheckRunFile(path, &problems).ok());
  EXPECT_TRUE(problems.empty());
}

TEST_F(RunFileTest, FailedRunRoundTripsAndIsMarkedFailed) {
  RunData run = MakeFullRun(30);
  run.status = "failed";
  // Error texts can be long (a backtrace): beyond HDF5's 64 KiB compact
  // attribute limit.
  run.termination_reason = "stack crashed: planner threw std::out_of_range\n";
  for (int i = 0; i < 2000; ++i) {
    run.termination_reason += "  #" + std::to_string(i) +
                              " adse::stack::Planner::Step() planner.cc:123\n";
  }
  const std::string path = Path("failed.h5");
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  Result<RunData> back = ReadRunFile(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->status, "failed");
  EXPECT_EQ(back->termination_reason, run.termination_reason);
  EXPECT_EQ(Diff(run, *back), "");
  EXPECT_TRUE(CheckRunFile(path, nullptr).ok());
}

TEST_F(RunFileTest, ANoPathRunKeepsThePlannersWordsAndOthersHaveNone) {
  RunData run = MakeFullRun(30);
  run.termination_reason = "no_path";
  run.termination_detail =
      "no path: the search ended after 20000 expansions without reaching the "
      "goal";
  const std::string path = Path("no_path.h5");
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  Result<RunData> back = ReadRunFile(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->termination_detail, run.termination_detail);
  EXPECT_EQ(Diff(run, *back), "");
  // A run without it (as files written before it existed) reads empty.
  run.termination_detail.clear();
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  back = ReadRunFile(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->termination_detail, "");
}

TEST_F(RunFileTest, RejectsUnknownStatusAndWritesNothing) {
  RunData run;
  run.status = "done";
  const Status status = WriteRunFile(Path("bad.h5"), run);
  EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
  EXPECT_TRUE(Listing().empty());
}

TEST_F(RunFileTest, RejectsUnknownTopicEventKind) {
  RunData run;
  run.trace.topic_events.resize(2);
  run.trace.topic_events[1].kind = static_cast<TopicEvent::Kind>(7);
  EXPECT_EQ(WriteRunFile(Path("bad.h5"), run).code(),
            Status::Code::kInvalidArgument);
  EXPECT_TRUE(Listing().empty());
}

TEST_F(RunFileTest, RejectsUnknownCallbackKind) {
  RunData run;
  run.callback_info.resize(2);
  run.callback_info[1].kind = static_cast<CallbackKind>(7);
  const Status status = WriteRunFile(Path("bad.h5"), run);
  EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(status.message().find("callback 1 has unknown kind code 7"),
            std::string::npos)
      << status.message();
  EXPECT_TRUE(Listing().empty());
}

TEST_F(RunFileTest, RejectsAScenarioHashThatDoesNotMatchTheText) {
  RunData run;
  run.scenario_text = "name: a\n";
  run.scenario_hash = Sha256Hex("name: b\n");
  EXPECT_EQ(WriteRunFile(Path("bad.h5"), run).code(),
            Status::Code::kInvalidArgument);
  EXPECT_TRUE(Listing().empty());
}

TEST_F(RunFileTest, LongStringsAreCutAtACharacterBoundary) {
  RunData run;
  // 63 ASCII bytes then a 2-byte character: 65 bytes, the cut must not keep
  // half of the character.
  run.vehicles.push_back({0, std::string(63, 'a') + "é", 0, 0, 0, 0, 0, 0});
  run.collisions.push_back({0, std::string(100, 'b'), 0});
  run.node_names.push_back(std::string(kNameBytes + 5, 'n'));
  const std::string path = Path("long.h5");
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  Result<RunData> back = ReadRunFile(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->vehicles[0].id, std::string(63, 'a'));
  EXPECT_EQ(back->collisions[0].other_id, std::string(kIdBytes, 'b'));
  EXPECT_EQ(back->collisions[0].ego_caused, 0);
  EXPECT_EQ(back->node_names[0], std::string(kNameBytes, 'n'));
}

TEST_F(RunFileTest, WritesAtomicallyAndReplacesAnExistingFileWhole) {
  const std::string path = Path("run.h5");
  {
    // Junk that is larger than the run file, so a partial overwrite would
    // leave a tail behind.
    std::ofstream junk(path, std::ios::binary);
    junk << std::string(4 << 20, 'J');
  }
  RunData first = MakeFullRun(20000);
  ASSERT_TRUE(WriteRunFile(path, first).ok());
  EXPECT_EQ(Listing(), std::vector<std::string>{"run.h5"});
  Result<RunData> back = ReadRunFile(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(Diff(first, *back), "");

  RunData second = MakeFullRun(10);
  second.scenario_name = "second";
  ASSERT_TRUE(WriteRunFile(path, second).ok());
  EXPECT_EQ(Listing(), std::vector<std::string>{"run.h5"});  // no *.tmp.*
  back = ReadRunFile(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(Diff(second, *back), "");
}

TEST_F(RunFileTest, CreatesParentFolders) {
  const std::string path = Path("a/b/run.h5");
  ASSERT_TRUE(WriteRunFile(path, MakeFullRun(10)).ok());
  EXPECT_TRUE(ReadRunFile(path).ok());
}

TEST_F(RunFileTest, FailedWriteLeavesNoTemporary) {
  // The target is an existing folder: the rename must fail.
  fs::create_directories(Path("run.h5/inside"));
  const Status status = WriteRunFile(Path("run.h5"), MakeFullRun(10));
  EXPECT_EQ(status.code(), Status::Code::kIoError);
  EXPECT_NE(status.message().find("run.h5"), std::string::npos);
  EXPECT_EQ(Listing(), std::vector<std::string>{"run.h5"});
}

TEST_F(RunFileTest, SameRunGivesTheSameBytes) {
  // No timestamps inside: reruns can be compared or deduplicated by hash.
  const RunData run = MakeFullRun(1000);
  ASSERT_TRUE(WriteRunFile(Path("a.h5"), run).ok());
  ASSERT_TRUE(WriteRunFile(Path("b.h5"), run).ok());
  std::ifstream a(Path("a.h5"), std::ios::binary),
      b(Path("b.h5"), std::ios::binary);
  const std::string bytes_a(std::istreambuf_iterator<char>(a), {});
  const std::string bytes_b(std::istreambuf_iterator<char>(b), {});
  EXPECT_EQ(bytes_a.size(), bytes_b.size());
  EXPECT_TRUE(bytes_a == bytes_b);
}

TEST_F(RunFileTest, ConcurrentWritersDoNotInterfere) {
  // HDF5 use is serialized inside; writers on different paths must all
  // succeed.
  std::vector<std::thread> threads;
  std::vector<Status> results(4);
  for (int i = 0; i < 4; ++i) {
    threads.emplace_back([&, i] {
      results[i] = WriteRunFile(Path("t" + std::to_string(i) + ".h5"),
                                MakeFullRun(2000 + i));
    });
  }
  for (auto& t : threads) t.join();
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(results[i].ok()) << results[i].ToString();
    Result<RunData> back = ReadRunFile(Path("t" + std::to_string(i) + ".h5"));
    ASSERT_TRUE(back.ok());
    EXPECT_EQ(back->trace.topic_events.size(), 2000u + i);
  }
}

}  // namespace
}  // namespace adse::runfile
