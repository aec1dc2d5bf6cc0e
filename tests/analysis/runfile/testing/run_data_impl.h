// What the run file tests share: a run with every field populated and
// awkward values (MakeFullRun), a bit-exact comparison (Diff), raw HDF5
// access as h5py sees the file, and a fixture with a scratch folder. Holds
// HDF5 types, hence _impl.h.
#ifndef ADSE_TESTS_ANALYSIS_RUNFILE_TESTING_RUN_DATA_IMPL_H_
#define ADSE_TESTS_ANALYSIS_RUNFILE_TESTING_RUN_DATA_IMPL_H_

#if __has_include(<hdf5.h>)
#include <hdf5.h>
#else
#include <hdf5/serial/hdf5.h>  // Debian keeps it off the default path
#endif

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "analysis/runfile/run_data.h"
#include "stack/base/hash.h"
#include "tests/analysis/testing/temp_dir_test.h"

namespace adse::runfile::testing {

using stack::CallbackRecord;
using stack::TopicEvent;

// Bit-exact, so NaN, -0.0 and denormals count as round-tripped only if the
// bytes survive.
inline bool SameBits(double a, double b) {
  return std::memcmp(&a, &b, sizeof(double)) == 0;
}

// Describes the first difference between two runs, empty if identical.
inline std::string Diff(const RunData& a, const RunData& b) {
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
  str("termination_detail", a.termination_detail, b.termination_detail);
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
      str("callback_info kind", CallbackKindToString(x.kind),
          CallbackKindToString(y.kind));
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
      num(at + "perception_stamp_s", x.perception_stamp_s,
          y.perception_stamp_s);
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
  if (size("objects", a.objects.size(), b.objects.size())) {
    for (size_t i = 0; i < a.objects.size(); ++i) {
      const ObjectSample &x = a.objects[i], &y = b.objects[i];
      const std::string at = "objects[" + std::to_string(i) + "].";
      num(at + "t_s", x.t_s, y.t_s);
      num(at + "stamp_s", x.stamp_s, y.stamp_s);
      integer(at + "track_id", x.track_id, y.track_id);
      num(at + "x_m", x.x_m, y.x_m);
      num(at + "y_m", x.y_m, y.y_m);
      num(at + "vx_mps", x.vx_mps, y.vx_mps);
      num(at + "vy_mps", x.vy_mps, y.vy_mps);
      num(at + "length_m", x.length_m, y.length_m);
      num(at + "width_m", x.width_m, y.width_m);
      num(at + "yaw_rad", x.yaw_rad, y.yaw_rad);
      integer(at + "age", x.age, y.age);
    }
  }
  return out.str();
}

// A run with every field populated, awkward values included.
inline RunData MakeFullRun(size_t events = 5000) {
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
    run.controls.push_back(
        {t, t - 0.05, 0.2 * std::sin(t), -0.01 * i, i % 3 ? t - 0.3 : -1.0});
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
  // Two tracks over three publishes, one born late.
  for (int i = 0; i < 3; ++i) {
    run.objects.push_back({0.1 * i, 0.1 * i - 0.04, 7, 12.5 + 0.8 * i, -3.25,
                           8.0, 0.0, 4.5, 1.8, -0.01 * i, 10 + i});
    if (i > 0) {
      run.objects.push_back({0.1 * i, 0.1 * i - 0.04, 1000 + i, -40.0, 2.0 * i,
                             0.0, -1.5, 0.6, 0.5, 1.5707963267948966, i});
    }
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
  run.callback_info = {
      {"lidar_driver/tick", 0, runfile::CallbackKind::kTimer, -1, 0.1},
      {"localizer/on_points", 1, runfile::CallbackKind::kSubscription, 0, 0.0},
      {"planner/on_pose", 2, runfile::CallbackKind::kSubscription, 1, 0.0},
      {"controller/tick", 3, runfile::CallbackKind::kTimer, -1, 0.02}};
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

class RunFileTest : public ::adse::testing::TempDirTest {};

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

inline std::vector<Member> CompoundMembers(hid_t file,
                                           const char* dataset_path) {
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

inline std::vector<std::string> Names(const std::vector<Member>& members) {
  std::vector<std::string> names;
  for (const auto& m : members) names.push_back(m.name);
  return names;
}

}  // namespace adse::runfile::testing

#endif  // ADSE_TESTS_ANALYSIS_RUNFILE_TESTING_RUN_DATA_IMPL_H_
