#include "stack/world/lidar.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <map>

namespace adse::world {
namespace {

constexpr double kDeg = M_PI / 180.0;

LidarParams NoiselessParams() {
  LidarParams p;  // 16 beams, -15..15 deg, 0.4 deg, 60 m, 1.9 m
  p.range_noise_stddev_m = 0.0;
  return p;
}

Obstacle Wall(Eigen::Vector2d a, Eigen::Vector2d b, double z_max) {
  Obstacle o;
  o.footprint = {a, b};
  o.z_min_m = 0.0;
  o.z_max_m = z_max;
  return o;
}

// Points of the azimuth-0 column (straight ahead), keyed by elevation in
// whole degrees.
std::map<int, Eigen::Vector3f> AheadColumn(const PointCloud& cloud) {
  std::map<int, Eigen::Vector3f> out;
  for (const auto& p : cloud.points) {
    if (p.x() > 0 && std::abs(p.y()) < 1e-4 * p.norm()) {
      const double e = std::atan2(p.z(), std::hypot(p.x(), p.y())) / kDeg;
      out[static_cast<int>(std::lround(e))] = p;
    }
  }
  return out;
}

TEST(LidarTest, BeamLayoutAndRayCount) {
  Scene scene;
  LidarSimulator lidar(&scene, LidarParams(), Weather::kClear, 1);
  EXPECT_EQ(lidar.rays_per_scan(), 16 * 900);
  EXPECT_EQ(lidar.azimuths(), 900);
  ASSERT_EQ(lidar.elevations_rad().size(), 16u);
  EXPECT_NEAR(lidar.elevations_rad().front(), -15 * kDeg, 1e-12);
  EXPECT_NEAR(lidar.elevations_rad().back(), 15 * kDeg, 1e-12);
  EXPECT_NEAR(lidar.elevations_rad()[1], -13 * kDeg, 1e-12);

  LidarParams one;
  one.beams = 1;
  one.horizontal_resolution_deg = 0.7;  // 360 / 0.7 is not whole: 515 columns
  LidarSimulator single(&scene, one, Weather::kClear, 1);
  ASSERT_EQ(single.elevations_rad().size(), 1u);
  EXPECT_EQ(single.elevations_rad()[0], 0.0);
  EXPECT_EQ(single.azimuths(), 515);
}

TEST(LidarTest, WallAheadGivesAnalyticRangesPerBeam) {
  const double d = 10.0, top = 3.0, h = 1.9;
  Scene scene;
  scene.AddObstacle(Wall({d, -50}, {d, 50}, top));
  scene.Finalize();
  LidarSimulator lidar(&scene, NoiselessParams(), Weather::kClear, 1);
  const auto column = AheadColumn(lidar.Scan({0, 0, 0}, 0.0, {}));
  int wall = 0, ground = 0, over = 0;
  for (int e = -15; e <= 15; e += 2) {
    const double er = e * kDeg;
    const double z_at_wall = h + d * std::tan(er);
    const auto it = column.find(e);
    if (e < 0 && h / std::tan(-er) < d) {
      ++ground;  // the ground comes first
      ASSERT_NE(it, column.end()) << e;
      EXPECT_NEAR(it->second.norm(), h / std::sin(-er), 1e-4) << e;
      EXPECT_NEAR(it->second.z(), -h, 1e-4) << e;
    } else if (z_at_wall >= 0.0 && z_at_wall <= top) {
      ++wall;
      ASSERT_NE(it, column.end()) << e;
      EXPECT_NEAR(it->second.norm(), d / std::cos(er), 1e-4) << e;
      EXPECT_NEAR(it->second.x(), d, 1e-4) << e;
    } else {
      ++over;  // passes over the wall into the empty sky
      EXPECT_EQ(it, column.end()) << e;
    }
  }
  // The case split itself is what the geometry gives: 3 / 8 / 5 beams.
  EXPECT_EQ(ground, 3);
  EXPECT_EQ(wall, 8);
  EXPECT_EQ(over, 5);
  EXPECT_NEAR(column.at(1).norm(), d / std::cos(1 * kDeg), 1e-4);
}

TEST(LidarTest, VehicleBoxShadowsTheWallBehindIt) {
  const double h = 1.9;
  Scene scene;
  scene.AddObstacle(Wall({20, -50}, {20, 50}, 4.0));
  scene.Finalize();
  geometry::OrientedBox car;
  car.center = {8.0, 0.0};
  car.length_m = 4.0;
  car.width_m = 2.0;
  car.height_m = 1.5;
  LidarSimulator lidar(&scene, NoiselessParams(), Weather::kClear, 1);
  const PointCloud cloud = lidar.Scan({0, 0, 0}, 0.0, {car});
  const auto column = AheadColumn(cloud);
  for (int e = -15; e <= 15; e += 2) {
    const double er = e * kDeg;
    const double z_face = h + 6.0 * std::tan(er);
    if (z_face >= 0.0 && z_face <= 1.5) {
      ASSERT_TRUE(column.count(e)) << e;
      EXPECT_NEAR(column.at(e).norm(), 6.0 / std::cos(er), 1e-4) << e;
    } else if (e < 0 && (h - 1.5) / std::tan(-er) <= 10.0) {
      // Comes down onto the roof.
      ASSERT_TRUE(column.count(e)) << e;
      EXPECT_NEAR(column.at(e).norm(), (h - 1.5) / std::sin(-er), 1e-4) << e;
    }
  }
  // Nothing is seen in the box's shadow: straight behind it, below its
  // roof line as seen from the sensor.
  int shadow = 0, beside = 0;
  for (const auto& p : cloud.points) {
    const double slope = (p.z() + h - 1.5) / p.x();  // rises over the roof?
    if (p.x() > 10.0 && std::abs(p.y()) < 0.5 * p.x() / 10.0 && slope < 0.0) {
      ++shadow;
    }
    if (std::abs(p.x() - 20.0) < 1e-3 && std::abs(p.y()) > 3.0) ++beside;
  }
  EXPECT_EQ(shadow, 0);
  EXPECT_GT(beside, 100);  // the wall is seen where the car does not hide it
  // With no vehicle, the same rays reach the wall.
  const auto open = AheadColumn(lidar.Scan({0, 0, 0}, 0.0, {}));
  EXPECT_NEAR(open.at(-5).x(), 20.0, 1e-4);
}

TEST(LidarTest, RotatedVehicleAndTheSensorsOwnBody) {
  geometry::OrientedBox car;  // long axis along y, centred 8 m to the left
  car.center = {0.0, 8.0};
  car.yaw_rad = M_PI / 2;
  car.length_m = 4.0;
  car.width_m = 2.0;
  car.height_m = 2.5;         // above the sensor: the 0 deg beam hits its side
  geometry::OrientedBox ego;  // a box around the sensor is its own car: ignored
  ego.center = {0.5, 0.0};
  ego.height_m = 2.0;
  LidarParams p = NoiselessParams();
  p.beams = 1;
  LidarSimulator lidar(nullptr, p, Weather::kClear, 1);
  const PointCloud cloud = lidar.Scan({0, 0, 0}, 0.0, {ego, car});
  // Only the car is seen: its near face (y = 6, x in [-1, 1]).
  ASSERT_FALSE(cloud.points.empty());
  for (const auto& pt : cloud.points) {
    EXPECT_NEAR(pt.y(), 6.0, 1e-4);
    EXPECT_LE(std::abs(pt.x()), 1.0 + 1e-4);
    EXPECT_NEAR(pt.z(), 0.0, 1e-6);
  }
  // Columns within atan(1/6) of 90 deg: about 2 * 9.46 / 0.4 = 47.
  EXPECT_EQ(cloud.points.size(), 47u);
}

// Independent reference: every ray on its own against the ground, every
// box (no culling; entry found by clipping against the box's 6 planes) and
// the scene through Scene::CastRay.
std::vector<Eigen::Vector3f> ReferenceScan(
    const LidarSimulator& lidar, const geometry::Pose2& pose,
    const std::vector<geometry::OrientedBox>& boxes,
    const Scene* scene = nullptr) {
  const double h = lidar.params().mount_height_m;
  const double limit = lidar.max_range_m();
  std::vector<Eigen::Vector3f> out;
  for (int j = 0; j < lidar.azimuths(); ++j) {
    const double az = j * lidar.params().horizontal_resolution_deg * kDeg;
    for (double e : lidar.elevations_rad()) {
      const Eigen::Vector3d d_sensor(std::cos(e) * std::cos(az),
                                     std::cos(e) * std::sin(az), std::sin(e));
      const Eigen::Vector3d d_world =
          Eigen::AngleAxisd(pose.yaw_rad, Eigen::Vector3d::UnitZ()) * d_sensor;
      double best = std::numeric_limits<double>::infinity();
      if (e < 0) best = h / -std::sin(e);
      for (const geometry::OrientedBox& b : boxes) {
        const Eigen::AngleAxisd to_box(-b.yaw_rad, Eigen::Vector3d::UnitZ());
        const Eigen::Vector3d o =
            to_box * Eigen::Vector3d(pose.x_m - b.center.x(),
                                     pose.y_m - b.center.y(), h);
        const Eigen::Vector3d d = to_box * d_world;
        const Eigen::Vector3d lo(-b.length_m / 2, -b.width_m / 2, 0);
        const Eigen::Vector3d hi(b.length_m / 2, b.width_m / 2, b.height_m);
        double enter = 0, leave = std::numeric_limits<double>::infinity();
        bool inside_start =
            (o.array() >= lo.array()).all() && (o.array() <= hi.array()).all();
        for (int k = 0; k < 3; ++k) {
          if (std::abs(d[k]) < 1e-15) {
            if (o[k] < lo[k] || o[k] > hi[k]) leave = -1;
            continue;
          }
          const double t1 = (lo[k] - o[k]) / d[k], t2 = (hi[k] - o[k]) / d[k];
          enter = std::max(enter, std::min(t1, t2));
          leave = std::min(leave, std::max(t1, t2));
        }
        if (!inside_start && enter <= leave) best = std::min(best, enter);
      }
      if (scene != nullptr) {
        const double t = scene->CastRay(Eigen::Vector3d(pose.x_m, pose.y_m, h),
                                        d_world, std::min(best, limit));
        if (t >= 0) best = std::min(best, t);
      }
      if (best <= limit) out.push_back((best * d_sensor).cast<float>());
    }
  }
  return out;
}

TEST(LidarTest, VehiclesMatchAnUnculledReference) {
  Random rng(11);
  std::vector<geometry::OrientedBox> boxes;
  for (int i = 0; i < 25; ++i) {
    geometry::OrientedBox b;
    b.center = {rng.Uniform(-40, 40), rng.Uniform(-40, 40)};
    b.yaw_rad = rng.Uniform(-M_PI, M_PI);
    b.length_m = rng.Uniform(3, 12);
    b.width_m = rng.Uniform(1.5, 2.6);
    b.height_m = rng.Uniform(1.2, 3.5);
    boxes.push_back(b);
  }
  // One straddling the sensor's azimuth 0 / 360 seam, one very close, one
  // whose centre is out of range but near face (58 m) is not, one far away.
  boxes.push_back({Eigen::Vector2d(6.5, 3.5), 0.4, 4.5, 1.8, 1.5});
  boxes.push_back(
      {Eigen::Vector2d(1.0 + 61 * std::cos(0.5), 2.0 + 61 * std::sin(0.5)), 0.5,
       6.0, 2.0, 4.5});
  boxes.push_back({Eigen::Vector2d(0.5, 2.0), 0.0, 4.5, 1.8, 1.5});
  boxes.push_back({Eigen::Vector2d(500, 0), 0.0, 4.5, 1.8, 1.5});
  LidarParams p = NoiselessParams();
  p.beams = 8;
  p.horizontal_resolution_deg = 0.25;
  LidarSimulator lidar(nullptr, p, Weather::kClear, 1);
  const geometry::Pose2 pose{1.0, 2.0, 0.5};
  const auto got = lidar.Scan(pose, 0.0, boxes).points;
  const auto want = ReferenceScan(lidar, pose, boxes);
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < got.size(); ++i) {
    ASSERT_LT((got[i] - want[i]).norm(), 1e-4) << i;
  }
}

TEST(LidarTest, SceneReturnsMatchPerRayCastRay) {
  // Clutter with raised bases (overhangs a beam can pass under), thin
  // walls and tall buildings, plus vehicles, seen from several poses.
  Scene scene;
  Random rng(21);
  for (int i = 0; i < 200; ++i) {
    Obstacle o;
    const Eigen::Vector2d c(rng.Uniform(-60, 60), rng.Uniform(-60, 60));
    if (i % 3 == 0) {
      o.footprint = {
          c, c + Eigen::Vector2d(rng.Uniform(-10, 10), rng.Uniform(-10, 10))};
    } else {
      geometry::OrientedBox b;
      b.center = c;
      b.yaw_rad = rng.Uniform(-M_PI, M_PI);
      b.length_m = rng.Uniform(0.3, 12);
      b.width_m = rng.Uniform(0.3, 6);
      o.footprint = geometry::BoxCorners(b);
    }
    o.z_min_m = rng.Uniform() < 0.3 ? rng.Uniform(0.5, 3.0) : 0.0;
    o.z_max_m = o.z_min_m + rng.Uniform(0.3, 10.0);
    scene.AddObstacle(o);
  }
  scene.Finalize();
  std::vector<geometry::OrientedBox> boxes;
  for (int i = 0; i < 8; ++i) {
    boxes.push_back(
        {Eigen::Vector2d(rng.Uniform(-20, 20), rng.Uniform(-20, 20)),
         rng.Uniform(-M_PI, M_PI), 4.5, 1.8, 1.5});
  }
  LidarParams p = NoiselessParams();
  p.beams = 24;
  p.vertical_fov_down_deg = -25.0;
  p.vertical_fov_up_deg = 20.0;
  p.horizontal_resolution_deg = 0.5;
  LidarSimulator lidar(&scene, p, Weather::kClear, 1);
  size_t compared = 0;
  for (const geometry::Pose2 pose :
       {geometry::Pose2{0, 0, 0}, geometry::Pose2{13.7, -8.2, 2.1},
        geometry::Pose2{-75, 10, 0.3}, geometry::Pose2{30, 45, -1.2}}) {
    const auto got = lidar.Scan(pose, 0.0, boxes).points;
    const auto want = ReferenceScan(lidar, pose, boxes, &scene);
    ASSERT_EQ(got.size(), want.size());
    for (size_t i = 0; i < got.size(); ++i) {
      ASSERT_LT((got[i] - want[i]).norm(), 1e-4) << i;
    }
    compared += got.size();
  }
  EXPECT_GT(compared, 20000u);
}

TEST(LidarTest, DownwardBeamsHitGroundAtHeightOverTan) {
  const double h = 1.9;
  LidarSimulator lidar(nullptr, NoiselessParams(), Weather::kClear, 1);
  const PointCloud cloud = lidar.Scan({3, -2, 0.7}, 0.0, {});
  std::map<int, int> per_beam;
  for (const auto& p : cloud.points) {
    EXPECT_NEAR(p.z(), -h, 1e-4);
    const double horizontal = std::hypot(p.x(), p.y());
    const int e =
        static_cast<int>(std::lround(std::atan2(p.z(), horizontal) / kDeg));
    EXPECT_NEAR(horizontal, h / std::tan(-e * kDeg), 1e-3) << e;
    ++per_beam[e];
  }
  // 60 m range: beams down to -1 deg reach the ground within range.
  // (-1 deg: 1.9 / sin(1 deg) = 109 m, out of range; -3 deg: 36 m, in.)
  EXPECT_EQ(per_beam.size(), 7u);
  for (const auto& [e, n] : per_beam) EXPECT_EQ(n, 900) << e;
  EXPECT_FALSE(per_beam.count(-1));
}

Scene Clutter() {
  Scene scene;
  Random rng(5);
  for (int i = 0; i < 100; ++i) {
    geometry::OrientedBox b;
    b.center = {rng.Uniform(-70, 70), rng.Uniform(-70, 70)};
    if (b.center.norm() < 4) continue;
    b.yaw_rad = rng.Uniform(-M_PI, M_PI);
    Obstacle o;
    o.footprint = geometry::BoxCorners(b);
    o.z_max_m = rng.Uniform(0.5, 6.0);
    scene.AddObstacle(o);
  }
  scene.Finalize();
  return scene;
}

TEST(LidarTest, ReturnsNeverExceedRangeInAnyWeather) {
  const Scene scene = Clutter();
  for (Weather w : {Weather::kClear, Weather::kRain, Weather::kFog}) {
    LidarParams p;
    p.range_noise_stddev_m = 0.3;  // large noise pushes ranges past the limit
    p.vertical_fov_down_deg = -2.0;
    LidarSimulator lidar(&scene, p, w, 3);
    const double limit = p.range_m * EffectsOf(w).range_factor;
    EXPECT_DOUBLE_EQ(lidar.max_range_m(), limit);
    const PointCloud cloud = lidar.Scan({0, 0, 0}, 0.0, {});
    ASSERT_GT(cloud.points.size(), 1000u);
    double farthest = 0.0;
    for (const auto& pt : cloud.points)
      farthest = std::max<double>(farthest, pt.norm());
    EXPECT_LE(farthest, limit + 1e-4) << WeatherToString(w);
    EXPECT_GT(farthest, 0.8 * limit) << WeatherToString(w);
  }
}

TEST(LidarTest, FogShortensRangeAndDropsReturns) {
  LidarParams p = NoiselessParams();
  p.beams = 1;
  // Points on a wall d metres straight ahead (the nearest is at d).
  auto wall_points = [&](double d, Weather w) {
    Scene scene;
    scene.AddObstacle(Wall({d, -100}, {d, 100}, 5.0));
    scene.Finalize();
    LidarSimulator lidar(&scene, p, w, 1);
    return lidar.Scan({0, 0, 0}, 0.0, {}).points.size();
  };
  // 60 m in clear weather, 48 m in rain, 30 m in fog.
  EXPECT_GT(wall_points(59.9, Weather::kClear), 0u);
  EXPECT_EQ(wall_points(60.1, Weather::kClear), 0u);
  EXPECT_GT(wall_points(47.9, Weather::kRain), 0u);
  EXPECT_EQ(wall_points(48.1, Weather::kRain), 0u);
  EXPECT_GT(wall_points(29.9, Weather::kFog), 0u);
  EXPECT_EQ(wall_points(30.1, Weather::kFog), 0u);
  // A wall at 40 m subtends +-41 deg within 60 m: ~200 columns.
  EXPECT_GT(wall_points(40.0, Weather::kClear), 200u);

  // Ground within fog range: ~15 % of returns are lost, noise grows.
  LidarParams g;
  g.vertical_fov_down_deg = -15.0;
  g.vertical_fov_up_deg = -5.0;
  g.beams = 6;
  LidarSimulator clear_lidar(nullptr, g, Weather::kClear, 1);
  LidarSimulator fog_lidar(nullptr, g, Weather::kFog, 1);
  const auto c = clear_lidar.Scan({0, 0, 0}, 0.0, {}).points;
  const auto f = fog_lidar.Scan({0, 0, 0}, 0.0, {}).points;
  EXPECT_EQ(c.size(), 6u * 900u);
  const double kept = static_cast<double>(f.size()) / c.size();
  EXPECT_NEAR(kept, 0.85, 0.03);
  // Range residual of the -15 deg beam against the analytic ground range.
  double sum2 = 0.0;
  int n = 0;
  for (const auto& pt : f) {
    const double horizontal = std::hypot(pt.x(), pt.y());
    if (std::atan2(-g.mount_height_m, horizontal) > -14.0 * kDeg) continue;
    const double residual = pt.norm() - g.mount_height_m / std::sin(15 * kDeg);
    sum2 += residual * residual;
    ++n;
  }
  ASSERT_GT(n, 600);
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.02 + 0.05, 0.01);
}

TEST(LidarTest, SameSeedSameScanOtherSeedOtherNoise) {
  const Scene scene = Clutter();
  LidarParams p;  // default 2 cm noise
  LidarSimulator a(&scene, p, Weather::kRain, 42);
  LidarSimulator b(&scene, p, Weather::kRain, 42);
  LidarSimulator c(&scene, p, Weather::kRain, 43);
  const auto pa = a.Scan({1, 2, 0.3}, 0.1, {}).points;
  const auto pb = b.Scan({1, 2, 0.3}, 0.1, {}).points;
  const auto pc = c.Scan({1, 2, 0.3}, 0.1, {}).points;
  ASSERT_GT(pa.size(), 1000u);
  EXPECT_EQ(pa, pb);
  EXPECT_NE(pa, pc);
  // Clear weather drops nothing, so scans pair up point by point and
  // differ only by noise.
  LidarSimulator d(&scene, p, Weather::kClear, 1);
  LidarSimulator e(&scene, p, Weather::kClear, 2);
  const auto pd = d.Scan({1, 2, 0.3}, 0.1, {}).points;
  const auto pe = e.Scan({1, 2, 0.3}, 0.1, {}).points;
  ASSERT_EQ(pd.size(), pe.size());
  int differ = 0;
  double max_diff = 0.0;
  for (size_t i = 0; i < pd.size(); ++i) {
    const double diff = (pd[i] - pe[i]).norm();
    differ += diff > 1e-6;
    max_diff = std::max(max_diff, diff);
  }
  EXPECT_GT(differ, static_cast<int>(pd.size()) * 9 / 10);
  EXPECT_LT(max_diff, 0.02 * 12);  // 6 sigma each side
}

TEST(LidarTest, PointsAreInTheSensorFrameOfARotatedPose) {
  const double h = 1.9;
  Scene scene;
  scene.AddObstacle(Wall({-50, 13}, {50, 13}, 4.0));  // north of the sensor
  scene.Finalize();
  geometry::OrientedBox car;  // west of the sensor
  car.center = {-5.0, 3.0};
  car.yaw_rad = 0.3;
  const geometry::Pose2 pose{5.0, 3.0, M_PI / 2};  // facing north
  LidarSimulator lidar(&scene, NoiselessParams(), Weather::kClear, 1);
  const PointCloud cloud = lidar.Scan(pose, 0.0, {car});
  // Straight ahead of the sensor (its +x) is the wall, 10 m away.
  const auto column = AheadColumn(cloud);
  ASSERT_TRUE(column.count(1));
  EXPECT_NEAR(column.at(1).x(), 10.0, 1e-4);
  // Every point mapped back to the world lies on the ground, the wall or
  // the car.
  const double c = std::cos(pose.yaw_rad), s = std::sin(pose.yaw_rad);
  int on_car = 0;
  for (const auto& p : cloud.points) {
    const Eigen::Vector3d w(pose.x_m + c * p.x() - s * p.y(),
                            pose.y_m + s * p.x() + c * p.y(), h + p.z());
    const Eigen::Vector2d local =
        Eigen::Rotation2Dd(-car.yaw_rad) * (w.head<2>() - car.center);
    const bool ground = std::abs(w.z()) < 1e-3;
    const bool wall = std::abs(w.y() - 13.0) < 1e-3;
    const bool in_car = std::abs(local.x()) <= 0.5 * car.length_m + 1e-3 &&
                        std::abs(local.y()) <= 0.5 * car.width_m + 1e-3 &&
                        w.z() <= car.height_m + 1e-3;
    const bool on_car_surface =
        in_car && (std::abs(std::abs(local.x()) - 0.5 * car.length_m) < 1e-3 ||
                   std::abs(std::abs(local.y()) - 0.5 * car.width_m) < 1e-3 ||
                   std::abs(w.z() - car.height_m) < 1e-3);
    on_car += on_car_surface;
    EXPECT_TRUE(ground || wall || on_car_surface)
        << w.transpose() << " from " << p.transpose();
  }
  EXPECT_GT(on_car, 20);
  // West of a north-facing sensor is its left: +y in the sensor frame.
  int left = 0;
  for (const auto& p : cloud.points) left += p.y() > 6.0 && p.z() > -h + 0.1;
  EXPECT_GT(left, 20);
}

TEST(LidarTest, MotionDuringTheSweepDistortsLaterColumns) {
  // A ring wall of radius 20 m around the sensor. Driving at 10 m/s, the
  // sensor has moved 1 m by the last column of a 10 Hz sweep, so the wall
  // behind-right of the start (sensed last) appears 1 m farther back, while
  // the first column (straight ahead) is unchanged.
  Scene scene;
  for (int k = 0; k < 72; ++k) {
    const double a0 = k * 5 * kDeg, a1 = (k + 1) * 5 * kDeg;
    scene.AddObstacle(Wall({20 * std::cos(a0), 20 * std::sin(a0)},
                           {20 * std::cos(a1), 20 * std::sin(a1)}, 6.0));
  }
  scene.Finalize();
  LidarSimulator still(&scene, NoiselessParams(), Weather::kClear, 1);
  LidarSimulator moving(&scene, NoiselessParams(), Weather::kClear, 1);
  const PointCloud a = still.Scan({0, 0, 0}, 0.0, {});
  const PointCloud b = moving.Scan({0, 0, 0}, 0.0, {}, {10.0, 0.0});
  ASSERT_EQ(a.points.size(), b.points.size());
  // Column j of 900 is sensed j/900 of 0.1 s in: the sensor is 1.0 * j/900
  // m ahead, so every point shifts by that much backwards along x.
  const size_t per_column = a.points.size() / 900;
  ASSERT_EQ(per_column * 900, a.points.size());  // the wall closes the ring
  for (size_t i = 0; i < a.points.size(); i += 97) {
    const double moved = 1.0 * static_cast<double>(i / per_column) / 900.0;
    EXPECT_NEAR(b.points[i].x(), a.points[i].x() - moved, 1e-4) << i;
    EXPECT_NEAR(b.points[i].y(), a.points[i].y(), 1e-4) << i;
    EXPECT_EQ(b.points[i].z(), a.points[i].z()) << i;
  }
  // No motion: bit for bit the still scan.
  LidarSimulator zero(&scene, NoiselessParams(), Weather::kClear, 1);
  EXPECT_EQ(zero.Scan({0, 0, 0}, 0.0, {}, {}).points, a.points);
}

}  // namespace
}  // namespace adse::world
