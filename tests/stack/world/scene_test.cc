#include "stack/world/scene.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "stack/base/random.h"

namespace adse::world {
namespace {

Obstacle Wall(Eigen::Vector2d a, Eigen::Vector2d b, double z_min = 0.0,
              double z_max = 2.0) {
  Obstacle o;
  o.kind = ObstacleKind::kWall;
  o.footprint = {a, b};
  o.z_min_m = z_min;
  o.z_max_m = z_max;
  return o;
}

// Reference answer: every face of every obstacle, no acceleration grid.
double BruteForce(const Scene& scene, const Eigen::Vector3d& o,
                  const Eigen::Vector3d& d, double max_range) {
  double best = std::numeric_limits<double>::infinity();
  for (const Obstacle& ob : scene.obstacles()) {
    const auto& fp = ob.footprint;
    const size_t n = fp.size() == 2 ? 1 : fp.size();
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d a = fp[i], b = fp[(i + 1) % fp.size()];
      // o + t d = a + u (b - a), solved with a 2x2 inverse.
      Eigen::Matrix2d m;
      m << d.x(), a.x() - b.x(), d.y(), a.y() - b.y();
      if (std::abs(m.determinant()) == 0.0) continue;
      const Eigen::Vector2d tu = m.inverse() * (a - o.head<2>());
      const double t = tu[0], u = tu[1];
      if (t < 0 || t > max_range || u < 0 || u > 1) continue;
      const double z = o.z() + t * d.z();
      if (z < ob.z_min_m || z > ob.z_max_m) continue;
      best = std::min(best, t);
    }
  }
  return std::isinf(best) ? -1.0 : best;
}

Scene RandomScene(uint64_t seed, double cell) {
  Random rng(seed);
  Scene scene;
  for (int i = 0; i < 150; ++i) {
    Obstacle o;
    const Eigen::Vector2d c(rng.Uniform(-50, 50), rng.Uniform(-30, 30));
    const int kind = static_cast<int>(rng.Below(3));
    if (kind == 0) {  // thin wall
      o = Wall(c,
               c + Eigen::Vector2d(rng.Uniform(-15, 15), rng.Uniform(-15, 15)));
    } else if (kind == 1) {  // parked car
      geometry::OrientedBox b;
      b.center = c;
      b.yaw_rad = rng.Uniform(-M_PI, M_PI);
      o.kind = ObstacleKind::kParkedCar;
      o.footprint = geometry::BoxCorners(b);
    } else {  // pole: octagon
      o.kind = ObstacleKind::kPole;
      const double r = rng.Uniform(0.05, 0.5);
      for (int k = 0; k < 8; ++k) {
        o.footprint.push_back(c + r * Eigen::Vector2d(std::cos(k * M_PI / 4),
                                                      std::sin(k * M_PI / 4)));
      }
    }
    o.z_min_m = rng.Uniform(0.0, 1.0);
    o.z_max_m = o.z_min_m + rng.Uniform(0.2, 4.0);
    scene.AddObstacle(o);
  }
  scene.Finalize(cell);
  return scene;
}

TEST(SceneTest, CastRayMatchesBruteForceOnRandomRays) {
  for (const double cell : {0.7, 4.0, 25.0}) {
    const Scene scene = RandomScene(7, cell);
    Random rng(99);
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
      // Origins inside and well outside the grid; all kinds of directions,
      // some exactly axis-aligned and some nearly vertical.
      const Eigen::Vector3d o(rng.Uniform(-80, 80), rng.Uniform(-60, 60),
                              rng.Uniform(-1.0, 6.0));
      Eigen::Vector3d d(rng.Uniform(-1, 1), rng.Uniform(-1, 1),
                        rng.Uniform(-0.5, 0.5));
      const int pick = i % 10;
      if (pick == 0) d.x() = 0.0;
      if (pick == 1) d.y() = 0.0;
      if (pick == 2) d.head<2>() *= 1e-4;
      if (pick == 3) d.z() = 0.0;
      if (d.norm() < 1e-9) continue;
      d.normalize();
      const double range = rng.Uniform(1.0, 150.0);
      const double expected = BruteForce(scene, o, d, range);
      const double got = scene.CastRay(o, d, range);
      if (expected < 0) {
        EXPECT_LT(got, 0) << "ray " << i << " cell " << cell;
      } else {
        ++hits;
        EXPECT_NEAR(got, expected, 1e-9) << "ray " << i << " cell " << cell;
      }
    }
    EXPECT_GT(hits, 1500);  // the comparison exercises real hits
  }
}

TEST(SceneTest, CrossingsAlongListsEveryFaceCrossedInOrder) {
  const Scene scene = RandomScene(7, 4.0);
  Random rng(5);
  size_t total = 0;
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector2d o(rng.Uniform(-80, 80), rng.Uniform(-60, 60));
    const double az = rng.Uniform(-M_PI, M_PI);
    Eigen::Vector2d d(std::cos(az), std::sin(az));
    if (i % 7 == 0) d = Eigen::Vector2d(i % 2 ? 1 : -1, 0);
    const double max_s = rng.Uniform(0, 150);
    std::vector<FaceCrossing> got;
    scene.CrossingsAlong(o, d, max_s, &got);
    // Brute force: each face crossed within reach, via a 2x2 solve.
    std::vector<FaceCrossing> want;
    for (const Obstacle& ob : scene.obstacles()) {
      for (const auto& e : ObstacleEdges(ob)) {
        Eigen::Matrix2d m;
        m << d.x(), e[0].x() - e[1].x(), d.y(), e[0].y() - e[1].y();
        if (m.determinant() == 0.0) continue;
        const Eigen::Vector2d su = m.inverse() * (e[0] - o);
        if (su[0] < 0 || su[0] > max_s || su[1] < 0 || su[1] > 1) continue;
        want.push_back({su[0], ob.z_min_m, ob.z_max_m});
      }
    }
    std::sort(want.begin(), want.end(),
              [](const auto& a, const auto& b) { return a.s_m < b.s_m; });
    ASSERT_EQ(got.size(), want.size()) << i;
    for (size_t k = 0; k < got.size(); ++k) {
      EXPECT_NEAR(got[k].s_m, want[k].s_m, 1e-9) << i;
      EXPECT_EQ(got[k].z_max_m - got[k].z_min_m,
                want[k].z_max_m - want[k].z_min_m)
          << i;
      if (k > 0) {
        EXPECT_LE(got[k - 1].s_m, got[k].s_m);
      }
    }
    total += got.size();
  }
  EXPECT_GT(total, 3000u);
}

TEST(SceneTest, ThinWallIsHitFromBothSidesAndPassedOver) {
  Scene scene;
  scene.AddObstacle(Wall({10, -5}, {10, 5}, 0.0, 2.0));
  scene.Finalize();
  const Eigen::Vector3d fwd(1, 0, 0);
  EXPECT_NEAR(scene.CastRay({0, 0, 1}, fwd, 50), 10.0, 1e-12);
  EXPECT_NEAR(scene.CastRay({20, 1, 1}, -fwd, 50), 10.0, 1e-12);
  // Out of range.
  EXPECT_LT(scene.CastRay({0, 0, 1}, fwd, 9.9), 0);
  // Upward ray reaches x = 10 at z = 1 + 10 tan(e): over the 2 m top.
  const double e = 0.2;
  const Eigen::Vector3d up(std::cos(e), 0, std::sin(e));
  EXPECT_LT(scene.CastRay({0, 0, 1}, up, 50), 0);
  const double e2 = 0.05;  // 1 + 10 tan(0.05) = 1.5: hits at 10 / cos(e2)
  EXPECT_NEAR(scene.CastRay({0, 0, 1}, {std::cos(e2), 0, std::sin(e2)}, 50),
              10.0 / std::cos(e2), 1e-12);
  // Vertical rays run along no face.
  EXPECT_LT(scene.CastRay({10, 0, 1}, {0, 0, 1}, 50), 0);
  EXPECT_LT(scene.CastRay({10, 0, 3}, {0, 0, -1}, 50), 0);
}

TEST(SceneTest, RaysFromOutsideTheGridAndBeyondIt) {
  Scene scene;
  Obstacle box;
  box.footprint = {{0, 0}, {4, 0}, {4, 2}, {0, 2}};
  box.z_max_m = 1.5;
  scene.AddObstacle(box);
  scene.Finalize(1.0);
  EXPECT_NEAR(scene.CastRay({-100, 1, 1}, {1, 0, 0}, 200), 100.0, 1e-9);
  EXPECT_NEAR(scene.CastRay({2, 100, 1}, {0, -1, 0}, 200), 98.0, 1e-9);
  // Starting inside the prism, the ray meets the far face from inside.
  EXPECT_NEAR(scene.CastRay({1, 1, 1}, {1, 0, 0}, 200), 3.0, 1e-12);
  // Pointing away from the grid.
  EXPECT_LT(scene.CastRay({-100, 1, 1}, {-1, 0, 0}, 200), 0);
  // Passing beside it.
  EXPECT_LT(scene.CastRay({-100, 2.5, 1}, {1, 0, 0}, 200), 0);
}

TEST(SceneTest, UnfinalizedAndRefinalizedScenesAgree) {
  Scene scene;
  scene.AddObstacle(Wall({5, -5}, {5, 5}));
  // No Finalize: still answers (by testing every face).
  EXPECT_NEAR(scene.CastRay({0, 0, 1}, {1, 0, 0}, 50), 5.0, 1e-12);
  scene.Finalize();
  scene.AddObstacle(Wall({3, -5}, {3, 5}));
  // The grid is stale: the new wall must still be seen.
  EXPECT_NEAR(scene.CastRay({0, 0, 1}, {1, 0, 0}, 50), 3.0, 1e-12);
  scene.Finalize();
  EXPECT_NEAR(scene.CastRay({0, 0, 1}, {1, 0, 0}, 50), 3.0, 1e-12);
  EXPECT_TRUE(scene.min_corner().isApprox(Eigen::Vector2d(3, -5)));
  EXPECT_TRUE(scene.max_corner().isApprox(Eigen::Vector2d(5, 5)));
}

TEST(SceneTest, EmptySceneAndDegenerateObstacles) {
  Scene scene;
  scene.Finalize();
  EXPECT_LT(scene.CastRay({0, 0, 1}, {1, 0, 0}, 50), 0);
  Obstacle point;
  point.footprint = {{1, 1}};
  scene.AddObstacle(point);
  Obstacle closed_ring;  // explicitly closed: repeated first point
  closed_ring.footprint = {{10, -1}, {12, -1}, {12, 1}, {10, 1}, {10, -1}};
  scene.AddObstacle(closed_ring);
  scene.Finalize();
  Obstacle broken;  // a NaN from a bad map file must not poison the grid
  broken.footprint = {{std::nan(""), 0}, {5, 5}};
  scene.AddObstacle(broken);
  scene.Finalize();
  EXPECT_EQ(ObstacleEdges(closed_ring).size(), 4u);
  EXPECT_EQ(scene.obstacles().size(), 2u);
  EXPECT_NEAR(scene.CastRay({0, 0, 1}, {1, 0, 0}, 50), 10.0, 1e-12);
}

TEST(SceneTest, HugeSparseMapsGetCoarserCells) {
  // Two walls 200 km apart: a 4 m grid would need 2.5e9 cells.
  Scene scene;
  scene.AddObstacle(Wall({0, 0}, {0, 10}));
  scene.AddObstacle(Wall({200000, 0}, {200000, 200000}));
  scene.Finalize(4.0);
  EXPECT_GT(scene.cell_size_m(), 4.0);
  EXPECT_NEAR(scene.CastRay({-5, 5, 1}, {1, 0, 0}, 100), 5.0, 1e-9);
  EXPECT_NEAR(scene.CastRay({199990, 100000, 1}, {1, 0, 0}, 100), 10.0, 1e-9);
}

}  // namespace
}  // namespace adse::world
