// LiDAR scan cost in a synthetic parking lot: ~200 static obstacles and 10
// moving vehicles, the load every simulated scan pays.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <vector>

#include "stack/base/random.h"
#include "stack/world/lidar.h"
#include "stack/world/scene.h"

namespace adse::world {
namespace {

Obstacle Prism(std::vector<Eigen::Vector2d> footprint, double z_max,
               ObstacleKind kind) {
  Obstacle o;
  o.kind = kind;
  o.footprint = std::move(footprint);
  o.z_max_m = z_max;
  return o;
}

// 120 x 70 m lot: perimeter walls, 6 rows of 25 slots (~80 % occupied),
// lamp posts between rows, kerbed islands, buildings outside the walls.
Scene ParkingLot() {
  Scene scene;
  Random rng(2024);
  const double w = 120, h = 70;
  const Eigen::Vector2d c[4] = {{0, 0}, {w, 0}, {w, h}, {0, h}};
  for (int i = 0; i < 4; ++i) {
    scene.AddObstacle(Prism({c[i], c[(i + 1) % 4]}, 2.5, ObstacleKind::kWall));
  }
  for (int row = 0; row < 6; ++row) {
    const double y = 8 + row * 10.5;
    for (int slot = 0; slot < 25; ++slot) {
      if (rng.Uniform() < 0.2) continue;
      geometry::OrientedBox car;
      car.center = {10 + slot * 4.0, y};
      car.yaw_rad = M_PI / 2 + rng.Uniform(-0.05, 0.05);
      scene.AddObstacle(Prism(geometry::BoxCorners(car), rng.Uniform(1.4, 1.9),
                              ObstacleKind::kParkedCar));
    }
    for (int k = 0; k < 7; ++k) {  // lamp posts: octagons, 6 m
      std::vector<Eigen::Vector2d> fp;
      const Eigen::Vector2d centre(8 + k * 17.0, y + 3.2);
      for (int j = 0; j < 8; ++j) {
        fp.push_back(centre + 0.12 * Eigen::Vector2d(std::cos(j * M_PI / 4),
                                                     std::sin(j * M_PI / 4)));
      }
      scene.AddObstacle(Prism(fp, 6.0, ObstacleKind::kPole));
    }
  }
  for (int k = 0; k < 8; ++k) {  // kerbed islands
    const double x = 15 + k * 12.0;
    scene.AddObstacle(Prism({{x, 2}, {x + 6, 2}, {x + 6, 3}, {x, 3}}, 0.15,
                            ObstacleKind::kWall));
  }
  for (int k = 0; k < 6; ++k) {  // buildings around the lot
    const double x = -30 + k * 35.0;
    scene.AddObstacle(
        Prism({{x, h + 10}, {x + 25, h + 10}, {x + 25, h + 30}, {x, h + 30}},
              12.0, ObstacleKind::kBuilding));
  }
  scene.Finalize();
  return scene;
}

std::vector<geometry::OrientedBox> MovingVehicles() {
  std::vector<geometry::OrientedBox> v;
  for (int i = 0; i < 10; ++i) {
    geometry::OrientedBox b;
    b.center = {12 + i * 10.0, 13.25 + (i % 3) * 10.5};
    b.yaw_rad = (i % 2) ? 0.0 : M_PI;
    v.push_back(b);
  }
  return v;
}

void BM_LidarScan(benchmark::State& state) {
  static const Scene scene = ParkingLot();
  const auto vehicles = MovingVehicles();
  LidarParams params;  // 0.4 deg: 900 columns
  params.beams = static_cast<int>(state.range(0));
  const auto weather = static_cast<Weather>(state.range(1));
  LidarSimulator lidar(&scene, params, weather, 7);
  // Drive along an aisle so caches see a moving sensor.
  std::vector<geometry::Pose2> poses;
  for (int i = 0; i < 16; ++i) poses.push_back({20.0 + 5 * i, 34.0, 0.1 * i});
  size_t points = 0, scans = 0;
  double seconds = 0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const PointCloud cloud =
        lidar.Scan(poses[scans % poses.size()], 0.0, vehicles);
    seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
            .count();
    points += cloud.points.size();
    ++scans;
    benchmark::DoNotOptimize(cloud.points.data());
  }
  const double rays = static_cast<double>(lidar.rays_per_scan());
  state.counters["rays"] = rays;
  state.counters["points"] = static_cast<double>(points) / scans;
  state.counters["ms_per_scan"] = 1e3 * seconds / scans;
  state.counters["ns_per_ray"] = 1e9 * seconds / (scans * rays);
  state.SetLabel(std::string(WeatherToString(weather)) + ", " +
                 std::to_string(scene.obstacles().size()) + " obstacles, " +
                 std::to_string(vehicles.size()) + " vehicles");
}
BENCHMARK(BM_LidarScan)
    ->ArgNames({"beams", "weather"})
    ->Args({16, static_cast<int>(Weather::kClear)})
    ->Args({32, static_cast<int>(Weather::kClear)})
    ->Args({16, static_cast<int>(Weather::kFog)})
    ->Unit(benchmark::kMillisecond);

// One scene ray in isolation (horizontal-ish rays through the lot).
void BM_SceneCastRay(benchmark::State& state) {
  static const Scene scene = ParkingLot();
  Random rng(1);
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> rays;
  for (int i = 0; i < 4096; ++i) {
    const double az = rng.Uniform(-M_PI, M_PI), el = rng.Uniform(-0.05, 0.26);
    rays.push_back({{rng.Uniform(5, 115), rng.Uniform(5, 65), 1.9},
                    {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                     std::sin(el)}});
  }
  size_t i = 0;
  for (auto _ : state) {
    const auto& [o, d] = rays[i++ & 4095];
    benchmark::DoNotOptimize(scene.CastRay(o, d, 60.0));
  }
}
BENCHMARK(BM_SceneCastRay);

}  // namespace
}  // namespace adse::world

BENCHMARK_MAIN();
