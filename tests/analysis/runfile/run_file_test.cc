// WriteRunFile / ReadRunFile: exact round trips, atomic replacement, clear
// errors on damaged files, and a layout that generic HDF5 tools can read.
#include "analysis/runfile/run_file.h"

#if __has_include(<hdf5.h>)
#include <hdf5.h>
#else
#include <hdf5/serial/hdf5.h>  // Debian keeps it off the default path
#endif

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "stack/base/hash.h"
#include "tests/analysis/testing/temp_dir_test.h"

namespace adse::runfile {
namespace {

namespace fs = std::filesystem;
using stack::CallbackRecord;
using stack::TopicEvent;

// Bit-exact, so NaN, -0.0 and denormals count as round-tripped only if the
// bytes survive.
bool SameBits(double a, double b) {
  return std::memcmp(&a, &b, sizeof(double)) == 0;
}

// Describes the first difference between two runs, empty if identical.
std::string Diff(const RunData& a, const RunData& b) {
  std::ostringstream out;
  auto str = [&](const char* what, const std::string& x, const std::string& y) {
    if (x != y) out << what << ": '" << x << "' vs '" << y << "'\n";
  };
  auto num = [&](const std::string& what, double x, double y) {
    if (!SameBits(x, y)) out << what << ": " << x << " vs " << y << "\n";
  };
  auto integer = [&](const std::string& what, int64_t x, int64_t y) {
    if (x != y) out << what << ": " << x << " vs " << y << "\n";
  };
  auto size = [&](const char* what, size_t x, size_t y) {
    if (x != y) out << what << " size: " << x << " vs " << y << "\n";
    return x == y;
  };
  str("status", a.status, b.status);
  str("termination_reason", a.termination_reason, b.termination_reason);
  str("scenario_name", a.scenario_name, b.scenario_name);
  str("scenario_text", a.scenario_text, b.scenario_text);
  str("scenario_hash", a.scenario_hash, b.scenario_hash);
  str("content_key", a.content_key, b.content_key);
  str("adse_version", a.adse_version, b.adse_version);
  str("host", a.host, b.host);
  str("created_utc", a.created_utc, b.created_utc);
  if (a.seed != b.seed) out << "seed differs\n";
  num("lane_width_m", a.lane_width_m, b.lane_width_m);
  if (size("design_point", a.design_point.size(), b.design_point.size())) {
    for (auto i = a.design_point.begin(), j = b.design_point.begin();
         i != a.design_point.end(); ++i, ++j) {
      str("design_point key", i->first, j->first);
      num("design_point " + i->first, i->second, j->second);
    }
  }
  if (a.platform != b.platform) out << "platform differs\n";
  if (size("metrics", a.metrics.size(), b.metrics.size())) {
    for (auto i = a.metrics.begin(), j = b.metrics.begin();
         i != a.metrics.end(); ++i, ++j) {
      str("metric key", i->first, j->first);
      num("metric " + i->first, i->second, j->second);
    }
  }
  if (size("ego", a.ego.size(), b.ego.size())) {
    for (size_t i = 0; i < a.ego.size(); ++i) {
      const EgoSample &x = a.ego[i], &y = b.ego[i];
      const std::string at = "ego[" + std::to_string(i) + "].";
      num(at + "t_s", x.t_s, y.t_s);
      num(at + "x_m", x.x_m, y.x_m);
      num(at + "y_m", x.y_m, y.y_m);
      num(at + "yaw_rad", x.yaw_rad, y.yaw_rad);
      num(at + "v_mps", x.v_mps, y.v_mps);
      num(at + "steer_rad", x.steer_rad, y.steer_rad);
      num(at + "accel_mps2", x.accel_mps2, y.accel_mps2);
    }
  }
  if (size("ideal_path", a.ideal_path.size(), b.ideal_path.size())) {
    for (size_t i = 0; i < a.ideal_path.size(); ++i) {
      const std::string at = "ideal_path[" + std::to_string(i) + "].";
      num(at + "s_m", a.ideal_path[i].s_m, b.ideal_path[i].s_m);
      num(at + "x_m", a.ideal_path[i].x_m, b.ideal_path[i].x_m);
      num(at + "y_m", a.ideal_path[i].y_m, b.ideal_path[i].y_m);
    }
  }
  if (size("lanes", a.lanes.size(), b.lanes.size())) {
    for (size_t i = 0; i < a.lanes.size(); ++i) {
      const std::string at = "lanes[" + std::to_string(i) + "].";
      integer(at + "lane", a.lanes[i].lane, b.lanes[i].lane);
      num(at + "x_m", a.lanes[i].x_m, b.lanes[i].x_m);
      num(at + "y_m", a.lanes[i].y_m, b.lanes[i].y_m);
    }
  }
  if (size("vehicles", a.vehicles.size(), b.vehicles.size())) {
    for (size_t i = 0; i < a.vehicles.size(); ++i) {
      const VehicleSample &x = a.vehicles[i], &y = b.vehicles[i];
      const std::string at = "vehicles[" + std::to_string(i) + "].";
      num(at + "t_s", x.t_s, y.t_s);
      str("vehicles id", x.id, y.id);
      num(at + "x_m", x.x_m, y.x_m);
      num(at + "y_m", x.y_m, y.y_m);
      num(at + "yaw_rad", x.yaw_rad, y.yaw_rad);
      num(at + "speed_mps", x.speed_mps, y.speed_mps);
      num(at + "length_m", x.length_m, y.length_m);
      num(at + "width_m", x.width_m, y.width_m);
    }
  }
  if (size("collisions", a.collisions.size(), b.collisions.size())) {
    for (size_t i = 0; i < a.collisions.size(); ++i) {
      num("collision t_s", a.collisions[i].t_s, b.collisions[i].t_s);
      str("collision other_id", a.collisions[i].other_id,
          b.collisions[i].other_id);
    }
  }
  if (a.node_names != b.node_names) out << "node_names differ\n";
  if (a.topic_names != b.topic_names) out << "topic_names differ\n";
  if (size("callback_info", a.callback_info.size(), b.callback_info.size())) {
    for (size_t i = 0; i < a.callback_info.size(); ++i) {
      const NamedCallback &x = a.callback_info[i], &y = b.callback_info[i];
      const std::string at = "callback_info[" + std::to_string(i) + "].";
      str("callback_info name", x.name, y.name);
      integer(at + "node", x.node, y.node);
      str("callback_info kind", x.kind, y.kind);
      integer(at + "topic", x.topic, y.topic);
      num(at + "period_s", x.period_s, y.period_s);
    }
  }
  if (size("callbacks", a.trace.callbacks.size(), b.trace.callbacks.size())) {
    for (size_t i = 0; i < a.trace.callbacks.size(); ++i) {
      const CallbackRecord &x = a.trace.callbacks[i], &y = b.trace.callbacks[i];
      const std::string at = "callbacks[" + std::to_string(i) + "].";
      integer(at + "callback", x.callback, y.callback);
      integer(at + "node", x.node, y.node);
      num(at + "ready_s", x.ready_s, y.ready_s);
      num(at + "start_s", x.start_s, y.start_s);
      num(at + "end_s", x.end_s, y.end_s);
      num(at + "cost_s", x.cost_s, y.cost_s);
      num(at + "host_cpu_s", x.host_cpu_s, y.host_cpu_s);
      num(at + "work_units", x.work_units, y.work_units);
      integer(at + "cores", x.cores, y.cores);
      integer(at + "first_core", x.first_core, y.first_core);
    }
  }
  if (size("topic_events", a.trace.topic_events.size(),
           b.trace.topic_events.size())) {
    for (size_t i = 0; i < a.trace.topic_events.size(); ++i) {
      const TopicEvent &x = a.trace.topic_events[i],
                       &y = b.trace.topic_events[i];
      const std::string at = "topic_events[" + std::to_string(i) + "].";
      integer(at + "kind", x.kind, y.kind);
      integer(at + "topic", x.topic, y.topic);
      integer(at + "callback", x.callback, y.callback);
      num(at + "t_s", x.t_s, y.t_s);
      if (x.seq != y.seq) out << at << "seq differs\n";
      num(at + "stamp_s", x.stamp_s, y.stamp_s);
    }
  }
  if (a.trace.timer_overruns != b.trace.timer_overruns) {
    out << "timer_overruns differ\n";
  }
  if (size("controls", a.controls.size(), b.controls.size())) {
    for (size_t i = 0; i < a.controls.size(); ++i) {
      const ControlSample &x = a.controls[i], &y = b.controls[i];
      const std::string at = "controls[" + std::to_string(i) + "].";
      num(at + "t_s", x.t_s, y.t_s);
      num(at + "stamp_s", x.stamp_s, y.stamp_s);
      num(at + "accel_mps2", x.accel_mps2, y.accel_mps2);
      num(at + "steer_rad", x.steer_rad, y.steer_rad);
    }
  }
  if (size("stop_reasons", a.stop_reasons.size(), b.stop_reasons.size())) {
    for (size_t i = 0; i < a.stop_reasons.size(); ++i) {
      const StopSample &x = a.stop_reasons[i], &y = b.stop_reasons[i];
      const std::string at = "stop_reasons[" + std::to_string(i) + "].";
      num(at + "t_s", x.t_s, y.t_s);
      num(at + "stamp_s", x.stamp_s, y.stamp_s);
      if (x.reason != y.reason) {
        out << at << "reason: " << StopReasonToString(x.reason) << " vs "
            << StopReasonToString(y.reason) << "\n";
      }
      num(at + "stop_distance_m", x.stop_distance_m, y.stop_distance_m);
      integer(at + "track_id", x.track_id, y.track_id);
      num(at + "obstacle_gap_m", x.obstacle_gap_m, y.obstacle_gap_m);
      integer(at + "static_structure", x.static_structure, y.static_structure);
    }
  }
  if (size("signals", a.signals.size(), b.signals.size())) {
    for (size_t i = 0; i < a.signals.size(); ++i) {
      const SignalSample &x = a.signals[i], &y = b.signals[i];
      const std::string at = "signals[" + std::to_string(i) + "].";
      num(at + "t_s", x.t_s, y.t_s);
      num(at + "stamp_s", x.stamp_s, y.stamp_s);
      if (x.state != y.state) {
        out << at << "state: " << SignalStateToString(x.state) << " vs "
            << SignalStateToString(y.state) << "\n";
      }
      num(at + "stop_line_distance_m", x.stop_line_distance_m,
          y.stop_line_distance_m);
      if (x.tls_id != y.tls_id)
        out << at << "tls_id: " << x.tls_id << " vs " << y.tls_id << "\n";
    }
  }
  return out.str();
}

// A run with every field populated, awkward values included.
RunData MakeFullRun(size_t events = 5000) {
  RunData run;
  run.status = "complete";
  run.termination_reason = "goal_reached";
  run.scenario_name = "cut_in_ÄÖ";
  run.scenario_text =
      "name: cut_in\n# ünïcödé, tabs\tand \"quotes\"\nego:\n  v0_mps: 12.5\n" +
      std::string(100000, 'x') + "\n";
  run.scenario_hash = Sha256Hex(run.scenario_text);
  run.content_key = "k-0123456789abcdef";
  run.adse_version = "0.1.0";
  run.host = "node17; AMD EPYC 7763; 128 cores";
  run.created_utc = "2024-05-01T12:34:56Z";
  run.seed = std::numeric_limits<uint64_t>::max() - 7;
  run.design_point = {{"v0_mps", 12.5},
                      {"gap_m", -0.0},
                      {"tiny", 4.9e-324},
                      {"lidar_rate_hz", 10.0}};
  run.platform = {{"kind", "embedded"},
                  {"cores", "4"},
                  {"freq_ghz", "1.2"},
                  {"cost_model", "linear Ω"},
                  {"empty", ""}};
  run.lane_width_m = 3.25;
  for (int i = 0; i < 300; ++i) {
    const double t = 0.01 * i;
    run.ego.push_back({t, 1.5 * t, -0.1 * t, 0.001 * i, 12.0 + t,
                       (i % 7) * 0.01, -0.5 + 0.01 * i});
    run.controls.push_back({t, t - 0.05, 0.2 * std::sin(t), -0.01 * i});
  }
  // Every stop reason, an obstacle on map structure among them.
  const std::vector<std::string> reasons = StopReasonNames();
  for (size_t i = 0; i < 2 * reasons.size(); ++i) {
    StopReason reason = StopReason::kNone;
    StringToStopReason(reasons[i % reasons.size()], &reason);
    const bool obstacle = reason == StopReason::kObstacle;
    run.stop_reasons.push_back(
        {0.1 * i, 0.1 * i - 0.07, reason, obstacle ? 4.5 - i : 0.25 * i,
         obstacle ? static_cast<int32_t>(100 + i) : -1, obstacle ? 7.25 : -1.0,
         obstacle && i > 5 ? 1 : 0});
  }
  // Every signal state; none in range at the end.
  const SignalState states[] = {SignalState::kRed, SignalState::kYellow,
                                SignalState::kGreen, SignalState::kUnknown};
  for (int i = 0; i < 4; ++i) {
    run.signals.push_back(
        {0.5 + 0.2 * i, 0.4 + 0.2 * i, states[i], i == 3 ? -1.0 : 40.0 - 5 * i,
         i == 3 ? "" : "cluster_25578772_ü_" + std::to_string(i)});
  }
  run.ego[3].yaw_rad = std::numeric_limits<double>::quiet_NaN();
  run.ego[4].v_mps = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 50; ++i) {
    run.ideal_path.push_back({1.0 * i, 1.0 * i, 0.02 * i * i});
  }
  // Three lanes of different lengths, rows of a lane consecutive.
  for (int lane = 0; lane < 3; ++lane) {
    for (int i = 0; i < 4 + lane; ++i) {
      run.lanes.push_back({lane, -5.0 + 2.5 * i, 3.5 * lane - 0.125});
    }
  }
  for (int i = 0; i < 40; ++i) {
    run.vehicles.push_back({0.5 * (i / 2), "veh" + std::to_string(i % 2),
                            10.0 + i, 3.5, 0.0, 11.0 - 0.1 * i, 4.6, 1.9});
  }
  run.vehicles[5].id = std::string(kIdBytes, 'w');  // exactly the width
  run.vehicles[6].id = "φορτηγό-1";
  run.collisions = {{7.25, "veh1"}, {8.5, "pedestrian 2"}};
  run.node_names = {"lidar_driver", "localizer", "planner", "controller"};
  run.topic_names = {"/points", "/pose", "/trajectory", "/cmd"};
  run.callback_info = {{"lidar_driver/tick", 0, "timer", -1, 0.1},
                       {"localizer/on_points", 1, "subscription", 0, 0.0},
                       {"planner/on_pose", 2, "subscription", 1, 0.0},
                       {"controller/tick", 3, "timer", -1, 0.02}};
  for (int i = 0; i < 200; ++i) {
    CallbackRecord r;
    r.callback = i % 4;
    r.node = i % 4;
    r.ready_s = 0.01 * i;
    r.start_s = r.ready_s + 0.001;
    r.end_s = r.start_s + 0.004;
    r.cost_s = r.end_s - r.start_s;
    r.host_cpu_s = 0.0003 * i;
    r.work_units = 1e6 + i;
    r.cores = 1 + i % 3;
    r.first_core = i % 4;
    run.trace.callbacks.push_back(r);
  }
  for (size_t i = 0; i < events; ++i) {
    TopicEvent e;
    e.kind = static_cast<TopicEvent::Kind>(i % 3);
    e.topic = static_cast<int32_t>(i % 4);
    e.callback = (i % 11 == 0) ? -1 : static_cast<int32_t>(i % 4);
    e.t_s = 0.001 * static_cast<double>(i);
    e.seq = (uint64_t{1} << 40) + i / 3;
    e.stamp_s = e.t_s - 0.0005;
    run.trace.topic_events.push_back(e);
  }
  run.trace.timer_overruns = {3, 0, 0, 12};
  run.metrics = {{"collision", 1.0},
                 {"min_ttc_s", 0.75},
                 {"max_lateral_error_m", 0.31},
                 {"e2e_latency_p99_s", 0.087}};
  return run;
}

class RunFileTest : public adse::testing::TempDirTest {};

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
  run.collisions.push_back({0, std::string(100, 'b')});
  run.node_names.push_back(std::string(kNameBytes + 5, 'n'));
  const std::string path = Path("long.h5");
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  Result<RunData> back = ReadRunFile(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->vehicles[0].id, std::string(63, 'a'));
  EXPECT_EQ(back->collisions[0].other_id, std::string(kIdBytes, 'b'));
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

TEST_F(RunFileTest, MissingFileIsNotFound) {
  const std::string path = Path("nope.h5");
  Result<RunData> back = ReadRunFile(path);
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.status().code(), Status::Code::kNotFound);
  EXPECT_NE(back.status().message().find(path), std::string::npos);
}

TEST_F(RunFileTest, TextFileIsCorruption) {
  const std::string path = Path("notes.h5");
  std::ofstream(path) << "this is not HDF5\n";
  Result<RunData> back = ReadRunFile(path);
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.status().code(), Status::Code::kCorruption);
  EXPECT_NE(back.status().message().find(path), std::string::npos);
  EXPECT_NE(back.status().message().find("not an HDF5 file"),
            std::string::npos);
}

TEST_F(RunFileTest, EmptyFileIsCorruption) {
  const std::string path = Path("zero.h5");
  std::ofstream(path).close();
  Result<RunData> back = ReadRunFile(path);
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.status().code(), Status::Code::kCorruption);
}

TEST_F(RunFileTest, TruncatedFileIsCorruption) {
  const std::string good = Path("good.h5");
  ASSERT_TRUE(WriteRunFile(good, MakeFullRun(50000)).ok());
  const auto size = fs::file_size(good);
  for (const auto cut : {size / 2, size - 1, size_t{1000}}) {
    const std::string path = Path("cut_" + std::to_string(cut) + ".h5");
    fs::copy_file(good, path);
    fs::resize_file(path, cut);
    Result<RunData> back = ReadRunFile(path);
    ASSERT_FALSE(back.ok()) << "cut at " << cut;
    EXPECT_EQ(back.status().code(), Status::Code::kCorruption);
    EXPECT_NE(back.status().message().find(path), std::string::npos)
        << back.status().message();
    EXPECT_EQ(CheckRunFile(path, nullptr).code(), Status::Code::kCorruption);
  }
}

TEST_F(RunFileTest, FlippedBytesAreCorruptionNotGarbage) {
  // Most of the file is compressed table chunks, each checksummed.
  const std::string good = Path("good.h5");
  ASSERT_TRUE(WriteRunFile(good, MakeFullRun(50000)).ok());
  std::string bytes;
  {
    std::ifstream in(good, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  for (const size_t pos :
       {bytes.size() / 3, bytes.size() / 2, 2 * bytes.size() / 3}) {
    std::string damaged = bytes;
    damaged[pos] = static_cast<char>(damaged[pos] ^ 0x5A);
    const std::string path = Path("flip_" + std::to_string(pos) + ".h5");
    std::ofstream(path, std::ios::binary) << damaged;
    Result<RunData> back = ReadRunFile(path);
    ASSERT_FALSE(back.ok()) << "flip at " << pos;
    EXPECT_EQ(back.status().code(), Status::Code::kCorruption);
    EXPECT_NE(back.status().message().find(path), std::string::npos);
  }
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

TEST_F(RunFileTest, DirectoryIsRejected) {
  Result<RunData> back = ReadRunFile(dir_);
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.status().code(), Status::Code::kInvalidArgument);
}

// Raw HDF5 access, as h5py and pandas see the file.
class RawHdf5 {
 public:
  explicit RawHdf5(const std::string& path, unsigned flags = H5F_ACC_RDONLY)
      : file_(H5Fopen(path.c_str(), flags, H5P_DEFAULT)) {}
  ~RawHdf5() {
    if (file_ >= 0) H5Fclose(file_);
  }
  hid_t file() const { return file_; }

 private:
  hid_t file_;
};

struct Member {
  std::string name;
  H5T_class_t type_class;
  size_t size;
};

std::vector<Member> CompoundMembers(hid_t file, const char* dataset_path) {
  std::vector<Member> members;
  const hid_t dataset = H5Dopen2(file, dataset_path, H5P_DEFAULT);
  if (dataset < 0) return members;
  const hid_t type = H5Dget_type(dataset);
  const int n = H5Tget_nmembers(type);
  for (int i = 0; i < n; ++i) {
    char* name = H5Tget_member_name(type, i);
    const hid_t member = H5Tget_member_type(type, i);
    members.push_back(
        {name, H5Tget_member_class(type, i), H5Tget_size(member)});
    H5Tclose(member);
    H5free_memory(name);
  }
  H5Tclose(type);
  H5Dclose(dataset);
  return members;
}

std::vector<std::string> Names(const std::vector<Member>& members) {
  std::vector<std::string> names;
  for (const auto& m : members) names.push_back(m.name);
  return names;
}

TEST_F(RunFileTest, RawApiSeesDocumentedFieldsAndStorage) {
  const std::string path = Path("run.h5");
  ASSERT_TRUE(WriteRunFile(path, MakeFullRun(10000)).ok());
  RawHdf5 raw(path);
  ASSERT_GE(raw.file(), 0);

  EXPECT_EQ(Names(CompoundMembers(raw.file(), "/ego/trajectory")),
            (std::vector<std::string>{"t_s", "x_m", "y_m", "yaw_rad", "v_mps",
                                      "steer_rad", "accel_mps2"}));
  EXPECT_EQ(Names(CompoundMembers(raw.file(), "/world/vehicles")),
            (std::vector<std::string>{"t_s", "id", "x_m", "y_m", "yaw_rad",
                                      "speed_mps", "length_m", "width_m"}));
  EXPECT_EQ(Names(CompoundMembers(raw.file(), "/trace/callbacks")),
            (std::vector<std::string>{"callback", "node", "ready_s", "start_s",
                                      "end_s", "cost_s", "host_cpu_s",
                                      "work_units", "cores", "first_core"}));
  const std::vector<Member> events =
      CompoundMembers(raw.file(), "/trace/topic_events");
  EXPECT_EQ(Names(events),
            (std::vector<std::string>{"kind", "topic", "callback", "t_s", "seq",
                                      "stamp_s"}));
  ASSERT_EQ(events.size(), 6u);
  EXPECT_EQ(events[0].type_class, H5T_ENUM);
  EXPECT_EQ(events[0].size, 1u);
  EXPECT_EQ(events[4].type_class, H5T_INTEGER);
  const std::vector<Member> vehicles =
      CompoundMembers(raw.file(), "/world/vehicles");
  ASSERT_EQ(vehicles.size(), 8u);
  EXPECT_EQ(vehicles[1].type_class, H5T_STRING);
  EXPECT_EQ(vehicles[1].size, kIdBytes);

  // The enum codes, the chunked + shuffled + deflated storage, one row per
  // event.
  const hid_t dataset =
      H5Dopen2(raw.file(), "/trace/topic_events", H5P_DEFAULT);
  ASSERT_GE(dataset, 0);
  const hid_t type = H5Dget_type(dataset);
  const hid_t kind = H5Tget_member_type(type, 0);
  for (const auto& [name, code] : std::vector<std::pair<const char*, int8_t>>{
           {"publish", 0}, {"take", 1}, {"drop", 2}}) {
    int8_t value = -1;
    EXPECT_GE(H5Tenum_valueof(kind, name, &value), 0) << name;
    EXPECT_EQ(value, code) << name;
  }
  const hid_t space = H5Dget_space(dataset);
  hsize_t dims[1] = {0};
  H5Sget_simple_extent_dims(space, dims, nullptr);
  EXPECT_EQ(dims[0], 10000u);
  const hid_t dcpl = H5Dget_create_plist(dataset);
  EXPECT_EQ(H5Pget_layout(dcpl), H5D_CHUNKED);
  bool deflate = false, shuffle = false;
  for (int i = 0; i < H5Pget_nfilters(dcpl); ++i) {
    unsigned flags = 0;
    size_t nelmts = 0;
    unsigned config = 0;
    const H5Z_filter_t filter =
        H5Pget_filter2(dcpl, i, &flags, &nelmts, nullptr, 0, nullptr, &config);
    deflate |= filter == H5Z_FILTER_DEFLATE;
    shuffle |= filter == H5Z_FILTER_SHUFFLE;
  }
  EXPECT_TRUE(deflate);
  EXPECT_TRUE(shuffle);
  H5Pclose(dcpl);
  H5Sclose(space);
  H5Tclose(kind);
  H5Tclose(type);
  H5Dclose(dataset);
}

TEST_F(RunFileTest, MissingDatasetIsCorruptionNamingIt) {
  const std::string path = Path("run.h5");
  ASSERT_TRUE(WriteRunFile(path, MakeFullRun(10)).ok());
  {
    RawHdf5 raw(path, H5F_ACC_RDWR);
    ASSERT_GE(H5Ldelete(raw.file(), "/trace/callbacks", H5P_DEFAULT), 0);
  }
  Result<RunData> back = ReadRunFile(path);
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.status().code(), Status::Code::kCorruption);
  EXPECT_NE(back.status().message().find(path), std::string::npos);
  EXPECT_NE(back.status().message().find("/trace/callbacks"), std::string::npos)
      << back.status().message();
}

TEST_F(RunFileTest, LanesAreStoredAsOneRowPerVertex) {
  const std::string path = Path("run.h5");
  const RunData run = MakeFullRun(10);
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  RawHdf5 raw(path);
  ASSERT_GE(raw.file(), 0);
  const std::vector<Member> members =
      CompoundMembers(raw.file(), "/world/lanes");
  EXPECT_EQ(Names(members), (std::vector<std::string>{"lane", "x_m", "y_m"}));
  ASSERT_EQ(members.size(), 3u);
  EXPECT_EQ(members[0].type_class, H5T_INTEGER);
  EXPECT_EQ(members[0].size, 4u);
  EXPECT_EQ(members[1].type_class, H5T_FLOAT);
  const hid_t dataset = H5Dopen2(raw.file(), "/world/lanes", H5P_DEFAULT);
  ASSERT_GE(dataset, 0);
  const hid_t space = H5Dget_space(dataset);
  hsize_t dims[1] = {0};
  H5Sget_simple_extent_dims(space, dims, nullptr);
  EXPECT_EQ(dims[0], run.lanes.size());
  H5Sclose(space);
  H5Dclose(dataset);
}

// A full run written to `path`, `link` then deleted as in files written
// before it existed (same schema version): it reads back as the run with
// `clear` applied.
void ExpectReadsWithout(const std::string& path, const char* link,
                        const std::function<void(RunData*)>& clear) {
  RunData run = MakeFullRun(10);
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  {
    RawHdf5 raw(path, H5F_ACC_RDWR);
    ASSERT_GE(H5Ldelete(raw.file(), link, H5P_DEFAULT), 0);
  }
  Result<RunData> back = ReadRunFile(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  clear(&run);
  EXPECT_EQ(Diff(run, *back), "");
}

TEST_F(RunFileTest, AParkingRecordWrittenBeforeReplanningReadsAsOnePlan) {
  RunData run = MakeFullRun(10);
  run.parking.present = true;
  run.parking.planned_at_s = 20.0;
  run.parking.first_planned_at_s = 12.5;
  run.parking.replans = 2;
  const std::string path = Path("valet.h5");
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  {
    RawHdf5 raw(path, H5F_ACC_RDWR);
    for (const char* name : {"replans", "first_planned_at_s"}) {
      ASSERT_GE(H5Adelete_by_name(raw.file(), "/parking", name, H5P_DEFAULT), 0)
          << name;
    }
  }
  Result<RunData> older = ReadRunFile(path);
  ASSERT_TRUE(older.ok()) << older.status().ToString();
  EXPECT_EQ(older->parking.first_planned_at_s, 20.0);
  EXPECT_EQ(older->parking.replans, 0);
}

TEST_F(RunFileTest, FileWithoutLanesReadsAsNoLanes) {
  ExpectReadsWithout(Path("run.h5"), "/world/lanes",
                     [](RunData* run) { run->lanes.clear(); });
}

// Member `member` of the rows of `path` is an HDF5 enum with these names
// and codes.
void ExpectEnumCodes(hid_t file, const char* path, unsigned member,
                     const std::vector<std::pair<std::string, int8_t>>& codes) {
  const hid_t dataset = H5Dopen2(file, path, H5P_DEFAULT);
  ASSERT_GE(dataset, 0) << path;
  const hid_t type = H5Dget_type(dataset);
  const hid_t values = H5Tget_member_type(type, member);
  for (const auto& [name, code] : codes) {
    int8_t value = -1;
    EXPECT_GE(H5Tenum_valueof(values, name.c_str(), &value), 0) << name;
    EXPECT_EQ(value, code) << name;
  }
  H5Tclose(values);
  H5Tclose(type);
  H5Dclose(dataset);
}

TEST_F(RunFileTest, StopReasonsAreAnEnumOfTheVocabulary) {
  const std::string path = Path("run.h5");
  const RunData run = MakeFullRun(10);
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  RawHdf5 raw(path);
  ASSERT_GE(raw.file(), 0);
  const std::vector<Member> members =
      CompoundMembers(raw.file(), "/planning/stop_reasons");
  EXPECT_EQ(Names(members),
            (std::vector<std::string>{"t_s", "stamp_s", "reason",
                                      "stop_distance_m", "track_id",
                                      "obstacle_gap_m", "static_structure"}));
  ASSERT_EQ(members.size(), 7u);
  EXPECT_EQ(members[2].type_class, H5T_ENUM);
  // The enum's names are the vocabulary's, with its codes.
  std::vector<std::pair<std::string, int8_t>> codes;
  for (const std::string& name : StopReasonNames()) {
    StopReason expected = StopReason::kNone;
    ASSERT_TRUE(StringToStopReason(name, &expected));
    codes.emplace_back(name, static_cast<int8_t>(expected));
  }
  ExpectEnumCodes(raw.file(), "/planning/stop_reasons", 2, codes);
}

TEST_F(RunFileTest, FileWithoutStopReasonsReadsAsNone) {
  ExpectReadsWithout(Path("run.h5"), "/planning",
                     [](RunData* run) { run->stop_reasons.clear(); });
}

TEST_F(RunFileTest, SignalReportsAreStoredWithTheirStatesNamed) {
  const std::string path = Path("run.h5");
  const RunData run = MakeFullRun(10);
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  RawHdf5 raw(path);
  ASSERT_GE(raw.file(), 0);
  const std::vector<Member> members =
      CompoundMembers(raw.file(), "/perception/traffic_signals");
  EXPECT_EQ(Names(members),
            (std::vector<std::string>{"t_s", "stamp_s", "state",
                                      "stop_line_distance_m", "tls_id"}));
  ASSERT_EQ(members.size(), 5u);
  EXPECT_EQ(members[2].type_class, H5T_ENUM);
  ExpectEnumCodes(raw.file(), "/perception/traffic_signals", 2,
                  {{"unknown", 0}, {"red", 1}, {"yellow", 2}, {"green", 3}});
}

TEST_F(RunFileTest, FileWithoutSignalReportsReadsAsNone) {
  ExpectReadsWithout(Path("run.h5"), "/perception",
                     [](RunData* run) { run->signals.clear(); });
}

TEST_F(RunFileTest, ASignalStateOutsideTheVocabularyIsRefused) {
  RunData run = MakeFullRun(10);
  run.signals[2].state = static_cast<SignalState>(9);
  const Status written = WriteRunFile(Path("run.h5"), run);
  EXPECT_EQ(written.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(written.message().find(
                "traffic signal report 2 has unknown state code 9"),
            std::string::npos)
      << written.message();
}

TEST_F(RunFileTest, AStopReasonCodeOutsideTheVocabularyIsRefused) {
  RunData run = MakeFullRun(10);
  run.stop_reasons[1].reason = static_cast<StopReason>(42);
  const Status written = WriteRunFile(Path("run.h5"), run);
  EXPECT_EQ(written.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(written.message().find("stop reason 1 has unknown code 42"),
            std::string::npos)
      << written.message();
}

// Found by fuzz_run_file: libhdf5 1.10 loops forever on a global heap whose
// free-space object is empty, and copies overlapping (or negative-size)
// memory for an object that claims more than its collection, up to 2^64 - 1
// bytes. Every reader refuses them first.
TEST(RunFileDamageTest, ADamagedGlobalHeapIsRefusedBeforeHdf5ReadsIt) {
  const std::string dir =
      std::string(ADSE_SOURCE_DIR) + "/tests/fuzz/regressions/run_file/";
  const std::pair<const char*, const char*> kCases[] = {
      {"hdf5_global_heap_loop.h5", "an empty free-space object"},
      {"hdf5_global_heap_object_past_collection.h5",
       "more than its collection"},
      {"hdf5_global_heap_object_size_wraps.h5",
       "claims 18446744073709551615 bytes, more than its collection"},
  };
  for (const auto& [file, why] : kCases) {
    SCOPED_TRACE(file);
    const std::string path = dir + file;
    Result<RunData> run = ReadRunFile(path);
    ASSERT_FALSE(run.ok());
    EXPECT_EQ(run.status().code(), Status::Code::kCorruption);
    EXPECT_NE(run.status().message().find(path + ": damaged HDF5 global heap"),
              std::string::npos)
        << run.status().message();
    EXPECT_NE(run.status().message().find(why), std::string::npos)
        << run.status().message();
    std::vector<std::string> problems;
    EXPECT_FALSE(CheckRunFile(path, &problems).ok());
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_NE(problems[0].find("damaged HDF5 global heap"), std::string::npos);
  }
}

TEST_F(RunFileTest, FileWithoutStatusNeverLooksComplete) {
  // What a writer that died before its last step would leave (under its
  // temporary name): everything but the final `status` attribute.
  const std::string path = Path("run.h5");
  ASSERT_TRUE(WriteRunFile(path, MakeFullRun(10)).ok());
  {
    RawHdf5 raw(path, H5F_ACC_RDWR);
    ASSERT_GE(H5Adelete(raw.file(), "status"), 0);
  }
  Result<RunData> back = ReadRunFile(path);
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.status().message().find("status"), std::string::npos);
  std::vector<std::string> problems;
  EXPECT_EQ(CheckRunFile(path, &problems).code(), Status::Code::kCorruption);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0], "/: missing attribute 'status'");
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

// h5py/pandas read the file with no adse code. scripts/setup.sh installs
// Debian's python3-h5py and python3-pandas for /usr/bin/python3 (another
// python3 may come first on PATH); skipped when neither has h5py.
TEST_F(RunFileTest, H5pyAndPandasReadTheFile) {
  std::string python;
  for (const char* candidate : {"/usr/bin/python3", "python3"}) {
    const std::string probe =
        std::string(candidate) + " -c 'import h5py, numpy' >/dev/null 2>&1";
    if (std::system(probe.c_str()) == 0) {
      python = candidate;
      break;
    }
  }
  if (python.empty()) GTEST_SKIP() << "no python3 with h5py is installed";
  const std::string path = Path("run.h5");
  ASSERT_TRUE(WriteRunFile(path, MakeFullRun(1000)).ok());
  const std::string script = Path("read.py");
  std::ofstream(script) << R"(import sys, h5py
f = h5py.File(sys.argv[1], "r")
# String attributes are fixed-length: numpy bytes.
assert f.attrs["status"] == b"complete", f.attrs["status"]
assert f.attrs["scenario_name"].decode() == "cut_in_ÄÖ"
assert f["platform"].attrs["kind"] == b"embedded"
assert int(f.attrs["schema_version"]) == 1
ego = f["ego/trajectory"][:]
assert ego.dtype.names == ("t_s", "x_m", "y_m", "yaw_rad", "v_mps",
                           "steer_rad", "accel_mps2"), ego.dtype.names
assert len(ego) == 300
ev = f["trace/topic_events"][:]
assert len(ev) == 1000 and set(ev["kind"].tolist()) == {0, 1, 2}
assert h5py.check_enum_dtype(f["trace/topic_events"].dtype["kind"]) == \
    {"publish": 0, "take": 1, "drop": 2}
assert f["world/vehicles"][:]["id"][0] == b"veh0"
lanes = f["world/lanes"][:]
assert lanes.dtype.names == ("lane", "x_m", "y_m"), lanes.dtype.names
assert lanes["lane"].tolist() == [0] * 4 + [1] * 5 + [2] * 6
stops = f["planning/stop_reasons"][:]
assert h5py.check_enum_dtype(f["planning/stop_reasons"].dtype["reason"]) == \
    {"none": 0, "goal": 1, "obstacle": 2, "localization_lost": 3,
     "no_trajectory": 4, "red_light": 5}
assert stops["reason"].tolist() == [0, 1, 2, 3, 4, 5] * 2, stops["reason"]
assert f["scenario/yaml"].asstr()[()].startswith("name: cut_in")
assert f["metrics"].attrs["min_ttc_s"] == 0.75
try:
    import pandas as pd
except ImportError:
    sys.exit(0)
df = pd.DataFrame(f["ego/trajectory"][:])
assert list(df.columns)[:2] == ["t_s", "x_m"] and len(df) == 300
veh = pd.DataFrame(f["world/vehicles"][:])
assert veh["id"].str.decode("utf-8")[0] == "veh0"
)";
  const std::string command = python + " " + script + " " + path;
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
}

}  // namespace
}  // namespace adse::runfile
