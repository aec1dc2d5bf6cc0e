// World costs on the bundled robotaxi map: one SUMO step with traffic (ego
// push, vehicle read-back, collision check) and one LiDAR scan of the real
// scene. libsumo allows one simulation per process: one World serves all.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <memory>

#include "stack/world/lidar.h"
#include "stack/world/world.h"

namespace adse::world {
namespace {

World& RobotaxiWorld() {
  static std::unique_ptr<World> world = [] {
    WorldSetup setup;
    setup.world.map.generator = "parking_lot";
    setup.world.map.generator_params = {
        {"rows", 6}, {"slots_per_row", 20}, {"aisle_width_m", 7.0}};
    setup.world.traffic.seed = 7;
    setup.world.traffic.parked_occupancy = 0.6;
    // Denser than the example so that steps carry real traffic.
    setup.world.traffic.flows = {{"E4_W4", "W0_E0", 900.0},
                                 {"W4_E4", "E0_W0", 900.0}};
    setup.task.start = Location::Xy(20.0, -1.75);
    setup.task.goal = Location::Xy(15.0, 63.75);
    Result<std::unique_ptr<World>> w = World::Open(setup);
    if (!w.ok()) {
      std::fprintf(stderr, "%s\n", w.status().ToString().c_str());
      std::abort();
    }
    // Let traffic fill the lot.
    for (int i = 0; i < 1200; ++i) (void)(*w)->Step(ControlCommand{});
    return std::move(w).value();
  }();
  return *world;
}

void BM_WorldStepWithTraffic(benchmark::State& state) {
  World& world = RobotaxiWorld();
  for (auto _ : state) {
    Status s = world.Step(ControlCommand{});
    benchmark::DoNotOptimize(s);
  }
  state.counters["vehicles"] = static_cast<double>(world.others().size());
}
BENCHMARK(BM_WorldStepWithTraffic)->Unit(benchmark::kMicrosecond);

void BM_LidarScanRobotaxiScene(benchmark::State& state) {
  World& world = RobotaxiWorld();
  LidarParams params;
  params.beams = static_cast<int>(state.range(0));
  LidarSimulator lidar(&world.scene(), params, Weather::kClear, 1);
  std::vector<geometry::OrientedBox> boxes;
  for (const OtherVehicle& v : world.others()) boxes.push_back(v.box);
  const geometry::Pose2 pose{world.ego().x_m, world.ego().y_m,
                             world.ego().yaw_rad};
  size_t points = 0;
  for (auto _ : state) {
    PointCloud cloud = lidar.Scan(pose, 0.0, boxes);
    points = cloud.points.size();
    benchmark::DoNotOptimize(cloud);
  }
  state.counters["points"] = static_cast<double>(points);
  state.counters["rays"] = lidar.rays_per_scan();
  state.counters["ns_per_ray"] = benchmark::Counter(
      static_cast<double>(lidar.rays_per_scan()) * state.iterations(),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_LidarScanRobotaxiScene)
    ->Arg(16)
    ->Arg(32)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace adse::world

BENCHMARK_MAIN();
