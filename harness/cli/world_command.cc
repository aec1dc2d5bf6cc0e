#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "harness/cli/cli_support.h"
#include "harness/cli/commands.h"
#include "harness/sim/simulator.h"
#include "stack/base/files.h"
#include "stack/world/ideal_driver.h"
#include "stack/world/lidar.h"
#include "stack/world/map_cloud.h"

namespace adse::cli {
namespace {

namespace fs = std::filesystem;

// Writes and flushes one file of the private folder (renamed into place
// whole at the end).
Status WriteText(const std::string& path, const std::string& text) {
  ADSE_RETURN_IF_ERROR(Env::Default()->WriteFile(path, text));
  return Env::Default()->SyncFile(path);
}

std::string PathCsv(const geometry::Path2& path) {
  std::string csv = "s_m,x_m,y_m\n";
  for (size_t i = 0; i < path.points.size(); ++i) {
    csv += fmt::format("{:.3f},{:.3f},{:.3f}\n", path.s_m[i],
                       path.points[i].x(), path.points[i].y());
  }
  return csv;
}

// ", turns round in 5 moves at 812 m, takes a corner in 4 moves at 49 m
// (onto its shoulders)":
// the route's turns in several moves.
std::string TurnaroundText(const std::vector<world::RouteTurnaround>& turns) {
  std::string text;
  for (const world::RouteTurnaround& t : turns) {
    const int moves = world::ManoeuvreMoves(t.reference);
    text += fmt::format(", {} in {} move{} at {:.0f} m{}",
                        t.corner ? "takes a corner" : "turns round", moves,
                        moves == 1 ? "" : "s", t.start_s_m,
                        t.on_shoulders ? " (onto its shoulders)" : "");
  }
  return text;
}

}  // namespace

int RunWorld(const WorldArgs& args) {
  std::optional<spec::Spec> spec =
      LoadCaseOrReport(args.scenario, args.task_case);
  if (!spec) return 2;
  world::WorldSetup setup = sim::WorldSetupFromSpec(*spec);
  if (args.seed) setup.world.traffic.seed = *args.seed;
  Result<std::unique_ptr<world::World>> opened = world::World::Open(setup);
  if (!opened.ok()) {
    ReportError(*spec, opened.status());
    return ExitCodeFor(opened.status());
  }
  world::World& w = **opened;

  nlohmann::json summary;
  summary["scenario"] = spec->name;
  summary["map"] = {{"net", w.map().net_path},
                    {"polygons", w.map().polygons_path},
                    {"key", w.map().key}};
  summary["start"] = {{"edge", w.start().edge},
                      {"lane", w.start().lane},
                      {"pos_m", w.start().pos_m},
                      {"x_m", w.start().xy.x()},
                      {"y_m", w.start().xy.y()}};
  summary["goal"] = {{"edge", w.goal().edge},
                     {"lane", w.goal().lane},
                     {"pos_m", w.goal().pos_m},
                     {"x_m", w.goal().xy.x()},
                     {"y_m", w.goal().xy.y()}};
  summary["route_edges"] = w.route_edges();
  summary["ideal_path_length_m"] = w.ideal_path().length_m();
  summary["lane_width_m"] = w.lane_width_m();
  int parked = 0;
  for (const auto& slot : w.scene().parking_slots()) parked += slot.occupied;
  summary["obstacles"] = w.scene().obstacles().size();
  summary["parking_slots"] = w.scene().parking_slots().size();
  summary["parked_cars"] = parked;
  summary["traffic_seed"] = setup.world.traffic.seed;
  // The turns in several moves: where the route turns around tighter than
  // the car can ("u_turn") or takes a corner it cannot follow ("corner").
  nlohmann::json turns = nlohmann::json::array();
  for (const world::RouteTurnaround& t : w.route_turnarounds()) {
    turns.push_back({{"start_s_m", t.start_s_m},
                     {"end_s_m", t.end_s_m},
                     {"moves", world::ManoeuvreMoves(t.reference)},
                     {"kind", t.corner ? "corner" : "u_turn"},
                     {"on_shoulders", t.on_shoulders}});
  }
  summary["turnarounds"] = turns;

  if (!args.follow_ideal) {
    std::printf(
        "%s\n",
        args.json ? summary.dump(2).c_str()
                  : fmt::format(
                        "world of {}: route {} edges, ideal path {:.1f} m, "
                        "{} obstacles, {} parked cars of {} slots{}",
                        spec->name, w.route_edges().size(),
                        w.ideal_path().length_m(), w.scene().obstacles().size(),
                        parked, w.scene().parking_slots().size(),
                        TurnaroundText(w.route_turnarounds()))
                        .c_str());
    return 0;
  }

  // Everything goes into a private folder renamed into place at the end, so
  // an interrupted check never leaves output that looks complete.
  const std::string out =
      args.out.empty()
          ? spec->output + "/world-check" +
                (spec->task_case.empty() ? "" : "/" + spec->task_case)
          : args.out;
  const OutputFolderLayout layout{
      {"trajectory.csv", "ideal_path.csv", "scans.csv", "summary.json"},
      "scans",
      ".pcd"};
  if (Status usable = CheckOutputFolder(out, layout); !usable.ok()) {
    std::fprintf(stderr, "error: %s\n", usable.message().c_str());
    return 2;
  }
  const std::string tmp = StartOutputFolder(out);
  std::error_code ec;
  Status status = MakeDirs(tmp + "/scans");
  if (!status.ok()) {
    std::fprintf(stderr, "error: %s\n", status.message().c_str());
    return 1;
  }

  world::LidarSimulator lidar(
      &w.scene(), spec->stack.Lidar(), setup.world.weather,
      Random::DeriveSeed(setup.world.traffic.seed, "lidar"));
  world::IdealDriverOptions options;
  options.speed_limit_mps = spec->task.speed_limit_kmh / 3.6;
  options.timeout_s = spec->task.timeout_s;
  options.scan = args.scan;
  // Signals are waited out as the stack's planner waits them out.
  options.max_red_wait_s = spec->stack.Get("traffic_light.max_red_wait_s");
  std::string scan_index = "t_s,x_m,y_m,yaw_rad,points,file\n";
  int scan_number = 0;
  Status scan_status;
  auto on_scan = [&](const world::PointCloud& cloud,
                     const geometry::Pose2& pose) {
    std::string file;
    if (args.save_every_nth_scan > 0 &&
        scan_number % args.save_every_nth_scan == 0) {
      file = fmt::format("scans/scan_{:05d}.pcd", scan_number);
      std::vector<Eigen::Vector3f> points = cloud.points;
      Status s = world::WritePcd(tmp + "/" + file, points);
      if (!s.ok() && scan_status.ok()) scan_status = s;
    }
    scan_index += fmt::format("{:.3f},{:.3f},{:.3f},{:.4f},{},{}\n",
                              cloud.stamp_s, pose.x_m, pose.y_m, pose.yaw_rad,
                              cloud.points.size(), file);
    ++scan_number;
  };
  std::fprintf(stderr,
               "driving %.1f m of ideal path with a perfect controller...\n",
               w.ideal_path().length_m());
  Result<world::IdealDriveReport> report =
      world::DriveIdealPath(w, args.scan ? &lidar : nullptr, options, on_scan);
  if (!report.ok() || !scan_status.ok()) {
    fs::remove_all(tmp, ec);
    std::fprintf(
        stderr, "error: %s\n",
        (!report.ok() ? report.status() : scan_status).message().c_str());
    return 1;
  }
  std::string trajectory = "t_s,x_m,y_m,yaw_rad,v_mps,steer_rad,accel_mps2\n";
  for (const auto& s : report->trajectory) {
    trajectory += fmt::format(
        "{:.3f},{:.4f},{:.4f},{:.5f},{:.4f},{:.5f},{:.4f}\n", s.t_s, s.x_m,
        s.y_m, s.yaw_rad, s.v_mps, s.steer_rad, s.accel_mps2);
  }
  summary["reached_goal"] = report->reached_goal;
  summary["time_s"] = report->time_s;
  summary["collisions"] = report->collisions;
  summary["max_lateral_error_m"] = report->max_lateral_error_m;
  summary["red_light_wait_s"] = report->red_light_wait_s;
  summary["scans"] = report->scans;
  summary["mean_points_per_scan"] = report->mean_points_per_scan;
  summary["lidar_ms_per_scan"] =
      report->scans ? 1e3 * report->lidar_wall_s / report->scans : 0.0;
  summary["world_ms_per_step"] =
      report->trajectory.empty()
          ? 0.0
          : 1e3 * report->world_wall_s / report->trajectory.size();
  for (const auto& [name, text] :
       {std::pair<std::string, std::string>{"trajectory.csv", trajectory},
        {"ideal_path.csv", PathCsv(w.ideal_path())},
        {"scans.csv", scan_index},
        {"summary.json", summary.dump(2) + "\n"}}) {
    status = WriteText(tmp + "/" + name, text);
    if (!status.ok()) break;
  }
  if (status.ok()) status = PutFolderInPlace(tmp, out);
  if (!status.ok()) {
    fs::remove_all(tmp, ec);
    std::fprintf(stderr, "error: %s\n", status.message().c_str());
    return 1;
  }
  if (args.json) {
    std::printf("%s\n", summary.dump(2).c_str());
  } else {
    std::printf(
        "%s: %s in %.1f s (%.1f s of it at red lights), %d collisions, max "
        "distance from the ideal path %.2f m, "
        "%d scans (%.0f points, %.2f ms each), world step %.2f ms\nwrote %s\n",
        spec->name.c_str(),
        report->reached_goal ? "reached the goal" : "did NOT reach the goal",
        report->time_s, report->red_light_wait_s, report->collisions,
        report->max_lateral_error_m, report->scans,
        report->mean_points_per_scan,
        summary["lidar_ms_per_scan"].get<double>(),
        summary["world_ms_per_step"].get<double>(), out.c_str());
  }
  return report->reached_goal ? 0 : 1;
}

}  // namespace adse::cli
