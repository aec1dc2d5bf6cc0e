#include "stack/world/map_cloud.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

#include "stack/base/files.h"
#include "stack/base/random.h"
#include "tests/testing/temp_files.h"

namespace adse::world {
namespace {

Scene TestScene() {
  Scene scene;
  Obstacle wall;  // thin wall
  wall.footprint = {{-10, 5}, {10, 5.5}};
  wall.z_max_m = 2.5;
  scene.AddObstacle(wall);
  geometry::OrientedBox car;
  car.center = {3, -2};
  car.yaw_rad = 0.4;
  Obstacle parked;
  parked.kind = ObstacleKind::kParkedCar;
  parked.footprint = geometry::BoxCorners(car);
  parked.z_max_m = 1.5;
  scene.AddObstacle(parked);
  Obstacle pole;
  pole.kind = ObstacleKind::kPole;
  for (int k = 0; k < 6; ++k) {
    pole.footprint.push_back(
        Eigen::Vector2d(-6, -3) +
        0.15 * Eigen::Vector2d(std::cos(k * M_PI / 3), std::sin(k * M_PI / 3)));
  }
  pole.z_max_m = 4.0;
  scene.AddObstacle(pole);
  Obstacle building;  // explicitly closed ring, raised base (an overhang)
  building.kind = ObstacleKind::kBuilding;
  building.footprint = {{12, -8}, {20, -8}, {20, 0}, {15, 3}, {12, -8}};
  building.z_min_m = 0.5;
  building.z_max_m = 8.0;
  scene.AddObstacle(building);
  scene.Finalize();
  return scene;
}

// Distance from p to the nearest vertical face of the scene.
double DistanceToFaces(const Scene& scene, const Eigen::Vector3d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const Obstacle& o : scene.obstacles()) {
    const size_t n = o.footprint.size() == 2 ? 1 : o.footprint.size();
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d a = o.footprint[i];
      const Eigen::Vector2d b = o.footprint[(i + 1) % o.footprint.size()];
      const Eigen::Vector2d ab = b - a;
      const double len2 = ab.squaredNorm();
      const double u =
          len2 > 0 ? std::clamp((p.head<2>() - a).dot(ab) / len2, 0.0, 1.0)
                   : 0.0;
      const double horizontal = (p.head<2>() - (a + u * ab)).norm();
      const double vertical =
          std::max({0.0, o.z_min_m - p.z(), p.z() - o.z_max_m});
      best = std::min(best, std::hypot(horizontal, vertical));
    }
  }
  return best;
}

TEST(MapCloudTest, FacePointsLieOnFacesAndCoverThem) {
  const Scene scene = TestScene();
  MapCloudOptions opt;
  opt.ground_spacing_m = 0.0;  // faces only
  const auto cloud = SampleSceneSurface(scene, opt);
  ASSERT_GT(cloud.size(), 1000u);
  for (const auto& p : cloud) {
    ASSERT_LT(DistanceToFaces(scene, p.cast<double>()), 1e-3) << p.transpose();
  }
  // Dense: any point on any face has a sample within a grid cell's
  // half-diagonal.
  Random rng(3);
  for (const Obstacle& o : scene.obstacles()) {
    for (const auto& e : ObstacleEdges(o)) {
      for (int k = 0; k < 50; ++k) {
        const Eigen::Vector2d xy = e[0] + rng.Uniform() * (e[1] - e[0]);
        const Eigen::Vector3f q(xy.x(), xy.y(),
                                rng.Uniform(o.z_min_m, o.z_max_m));
        double nearest = std::numeric_limits<double>::infinity();
        for (const auto& p : cloud)
          nearest = std::min<double>(nearest, (p - q).norm());
        EXPECT_LE(nearest, opt.spacing_m * std::sqrt(0.5) + 1e-6);
      }
    }
  }
  // The 20 m thin wall at 0.2 m: 101 columns x 14 rows (2.5 m in 13 rows
  // of <= 0.2 m, both rims), nothing more, nothing less.
  Scene wall_only;
  wall_only.AddObstacle(scene.obstacles()[0]);
  const auto wall_cloud = SampleSceneSurface(wall_only, opt);
  const double len = std::hypot(20.0, 0.5);
  EXPECT_EQ(wall_cloud.size(),
            static_cast<size_t>((std::ceil(len / 0.2) + 1) * (13 + 1)));
}

TEST(MapCloudTest, GroundGridCoversBoundsButNotUnderFootprints) {
  const Scene scene = TestScene();
  MapCloudOptions opt;
  opt.ground_margin_m = 5.0;
  const auto cloud = SampleSceneSurface(scene, opt);
  const auto again = SampleSceneSurface(scene, opt);
  EXPECT_EQ(cloud, again);  // deterministic

  int ground = 0;
  Eigen::Vector2f lo(1e9, 1e9), hi(-1e9, -1e9);
  for (const auto& p : cloud) {
    if (p.z() != 0.0f || DistanceToFaces(scene, p.cast<double>()) < 1e-3) {
      continue;
    }
    ++ground;
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
    // Not inside the parked car (centre (3, -2), 4.5 x 1.8).
    const Eigen::Vector2d rel = Eigen::Vector2d(p.x() - 3, p.y() + 2);
    const double along = rel.dot(Eigen::Vector2d(std::cos(0.4), std::sin(0.4)));
    const double across =
        rel.dot(Eigen::Vector2d(-std::sin(0.4), std::cos(0.4)));
    EXPECT_FALSE(std::abs(along) < 2.2 && std::abs(across) < 0.85)
        << p.transpose();
  }
  // Scene bounds x [-10, 20], y [-8, 5.5], plus 5 m, every metre.
  EXPECT_NEAR(lo.x(), -15, 1e-4);
  EXPECT_NEAR(lo.y(), -13, 1e-4);
  EXPECT_NEAR(hi.x(), 25, 1e-4);
  EXPECT_NEAR(hi.y(), 10, 1e-4);
  const int grid = 41 * 24;
  // Missing: about one point per m^2 under the car (8 m^2) and the
  // building (64 m^2).
  EXPECT_LT(ground, grid - 55);
  EXPECT_GT(ground, grid - 90);
}

TEST(MapCloudTest, ACorridorCoveringTheWholeSceneChangesNothing) {
  const Scene scene = TestScene();
  MapCloudOptions opt;
  opt.ground_margin_m = 5.0;
  const auto whole = SampleSceneSurface(scene, opt);
  opt.corridor = {{-5, 0}, {5, 0}};
  opt.corridor_half_width_m = 40.0;  // the farthest corner is 27 m away
  EXPECT_EQ(SampleSceneSurface(scene, opt), whole);
}

TEST(MapCloudTest, ACorridorKeepsWhatIsNearTheRouteAndDropsWhatIsFar) {
  // A 2 km street of poles every 20 m on both sides; the route runs along
  // its first 200 m only.
  Scene scene;
  for (int i = 0; i <= 100; ++i) {
    for (const double side : {-6.0, 6.0}) {
      Obstacle pole;
      pole.kind = ObstacleKind::kPole;
      const Eigen::Vector2d c(20.0 * i, side);
      pole.footprint = {
          c + Eigen::Vector2d(-0.1, -0.1), c + Eigen::Vector2d(0.1, -0.1),
          c + Eigen::Vector2d(0.1, 0.1), c + Eigen::Vector2d(-0.1, 0.1)};
      pole.z_max_m = 4.0;
      scene.AddObstacle(pole);
    }
  }
  scene.Finalize();
  MapCloudOptions opt;
  const auto whole = SampleSceneSurface(scene, opt);
  opt.corridor = {{0, 0}, {100, 0}, {200, 0}};
  opt.corridor_half_width_m = 50.0;
  const auto near = SampleSceneSurface(scene, opt);
  EXPECT_LT(near.size(), whole.size() / 5);
  // Every point within the half width is kept, as it was sampled; nothing
  // beyond the half width plus one cell's diagonal (8 m cells) is.
  auto distance = [](const Eigen::Vector3f& p) {
    return geometry::DistanceToSegment(p.head<2>().cast<double>(), {0, 0},
                                       {200, 0});
  };
  size_t within = 0;
  for (const Eigen::Vector3f& p : whole) within += distance(p) <= 50.0;
  size_t kept_within = 0;
  for (const Eigen::Vector3f& p : near) {
    EXPECT_LE(distance(p), 50.0 + 8.0 * std::sqrt(2.0) + 1e-6) << p.transpose();
    kept_within += distance(p) <= 50.0;
  }
  EXPECT_EQ(kept_within, within);
  EXPECT_GT(within, 0u);
}

class PcdTest : public ::testing::Test {
 protected:
  static std::filesystem::path Dir() {
    return adse::testing::TestScratch() / "adse_map_cloud_test";
  }
  std::string Path(const std::string& name) {
    std::filesystem::create_directories(Dir());
    return (Dir() / name).string();
  }
  void WriteRaw(const std::string& path, const std::string& data) {
    ASSERT_TRUE(WriteFileAtomic(path, data).ok());
  }
  std::string ReadRaw(const std::string& path) { return *ReadFile(path); }
};

TEST_F(PcdTest, WriteReadRoundTripIsExact) {
  std::vector<Eigen::Vector3f> points;
  Random rng(8);
  for (int i = 0; i < 5000; ++i) {
    points.emplace_back(rng.Uniform(-1e3, 1e3), rng.Uniform(-1e3, 1e3),
                        rng.Uniform(-5, 30));
  }
  points.emplace_back(0.1f, -0.0f, std::numeric_limits<float>::denorm_min());
  const std::string path = Path("round_trip.pcd");
  ASSERT_TRUE(WritePcd(path, points).ok());
  const auto back = ReadPcd(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  ASSERT_EQ(back->size(), points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    ASSERT_EQ(std::memcmp(&points[i], &(*back)[i], sizeof(points[i])), 0) << i;
  }
  // The header is the plain PCD v0.7 binary form other tools read.
  const std::string raw = ReadRaw(path);
  const std::string n = std::to_string(points.size());
  EXPECT_NE(raw.find("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n"
                     "COUNT 1 1 1\nWIDTH " +
                     n +
                     "\nHEIGHT 1\n"
                     "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS " +
                     n + "\nDATA binary\n"),
            std::string::npos);
  EXPECT_EQ(raw.size() - raw.find("DATA binary\n") - 12, points.size() * 12);

  // An empty cloud round-trips too.
  ASSERT_TRUE(WritePcd(Path("empty.pcd"), {}).ok());
  const auto empty = ReadPcd(Path("empty.pcd"));
  ASSERT_TRUE(empty.ok()) << empty.status().ToString();
  EXPECT_TRUE(empty->empty());
}

TEST_F(PcdTest, TruncatedFilesAreCorruption) {
  const std::vector<Eigen::Vector3f> points(100, Eigen::Vector3f(1, 2, 3));
  const std::string good = Path("good.pcd");
  ASSERT_TRUE(WritePcd(good, points).ok());
  const std::string raw = ReadRaw(good);
  const size_t data_at = raw.find("DATA binary\n") + 12;
  for (const size_t keep : {raw.size() - 1, raw.size() - 12, data_at,
                            data_at - 3, size_t{40}, size_t{0}}) {
    const std::string path = Path("cut.pcd");
    WriteRaw(path, raw.substr(0, keep));
    const auto r = ReadPcd(path);
    ASSERT_FALSE(r.ok()) << keep;
    EXPECT_EQ(r.status().code(), Status::Code::kCorruption) << keep;
    EXPECT_NE(r.status().message().find(path), std::string::npos)
        << r.status().message();
  }
  WriteRaw(Path("cut.pcd"), raw.substr(0, raw.size() - 5));
  EXPECT_NE(ReadPcd(Path("cut.pcd")).status().message().find("truncated"),
            std::string::npos);
  // Extra bytes are as suspicious as missing ones.
  WriteRaw(Path("long.pcd"), raw + "xyz");
  EXPECT_EQ(ReadPcd(Path("long.pcd")).status().code(),
            Status::Code::kCorruption);
  EXPECT_EQ(ReadPcd(Path("missing.pcd")).status().code(),
            Status::Code::kNotFound);
}

TEST_F(PcdTest, MalformedHeadersAreCorruption) {
  const std::string head =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";
  const std::string tail = "VIEWPOINT 0 0 0 1 0 0 0\nDATA ascii\n1 2 3\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"points_mismatch", head + "WIDTH 2\nHEIGHT 1\nPOINTS 1\n" + tail},
      {"no_width", head + "HEIGHT 1\nPOINTS 1\n" + tail},
      {"bad_width", head + "WIDTH two\nHEIGHT 1\nPOINTS 1\n" + tail},
      {"no_z",
       "FIELDS x y\nSIZE 4 4\nTYPE F F\nWIDTH 1\nHEIGHT 1\n"
       "DATA ascii\n1 2\n"},
      {"int_x",
       "FIELDS x y z\nSIZE 4 4 4\nTYPE I F F\nWIDTH 1\nHEIGHT 1\n"
       "DATA ascii\n1 2 3\n"},
      {"size_count",
       "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\n"
       "HEIGHT 1\nDATA ascii\n1 2 3\n"},
      {"unknown_key", head + "WIDTH 1\nHEIGHT 1\nCOLOUR red\n" + tail},
      {"data_kind", head + "WIDTH 1\nHEIGHT 1\nDATA zipped\n1 2 3\n"},
      {"bad_number", head + "WIDTH 1\nHEIGHT 1\nDATA ascii\n1 2 x3\n"},
      {"few_values", head + "WIDTH 1\nHEIGHT 1\nDATA ascii\n1 2\n"},
      {"few_points", head + "WIDTH 3\nHEIGHT 1\nDATA ascii\n1 2 3\n4 5 6\n"},
      {"many_points", head + "WIDTH 1\nHEIGHT 1\nDATA ascii\n1 2 3\n4 5 6\n"},
      {"huge_points", head + "WIDTH 18446744073709551615\nHEIGHT 1\n"
                             "DATA binary\n"},
      {"overflow", head + "WIDTH 4294967296\nHEIGHT 4294967296\n"
                          "DATA binary\n"},
      {"not_pcd", std::string("\x89PNG\r\n\x1a\n\0\0\0", 11)},
  };
  for (const auto& [name, text] : cases) {
    const std::string path = Path(name + ".pcd");
    WriteRaw(path, text);
    const auto r = ReadPcd(path);
    ASSERT_FALSE(r.ok()) << name;
    EXPECT_EQ(r.status().code(), Status::Code::kCorruption)
        << name << ": " << r.status().ToString();
    EXPECT_NE(r.status().message().find(path), std::string::npos) << name;
  }
  WriteRaw(Path("compressed.pcd"), head +
                                       "WIDTH 1\nHEIGHT 1\n"
                                       "DATA binary_compressed\n");
  EXPECT_EQ(ReadPcd(Path("compressed.pcd")).status().code(),
            Status::Code::kInvalidArgument);
}

TEST_F(PcdTest, ReadsAsciiAndExtraFields) {
  // PCL-style ascii with an intensity field and a NaN "no return" point.
  const std::string text =
      "# .PCD v0.7 - Point Cloud Data file format\r\n"
      "VERSION 0.7\r\nFIELDS x y z intensity\r\nSIZE 4 4 4 4\r\n"
      "TYPE F F F F\r\nCOUNT 1 1 1 1\r\nWIDTH 3\r\nHEIGHT 1\r\n"
      "VIEWPOINT 0 0 0 1 0 0 0\r\nPOINTS 3\r\nDATA ascii\r\n"
      "1.5 -2 3e1 7\r\nnan nan nan 0\r\n0.25 0.5 0.75 1\r\n";
  WriteRaw(Path("ascii.pcd"), text);
  const auto r = ReadPcd(Path("ascii.pcd"));
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->size(), 2u);
  EXPECT_EQ((*r)[0], Eigen::Vector3f(1.5f, -2.0f, 30.0f));
  EXPECT_EQ((*r)[1], Eigen::Vector3f(0.25f, 0.5f, 0.75f));

  // Binary with a leading uint8 label and double-precision xyz.
  std::string bin =
      "FIELDS label x y z\nSIZE 1 8 8 8\nTYPE U F F F\nWIDTH 2\nHEIGHT 1\n"
      "DATA binary\n";
  for (int i = 0; i < 2; ++i) {
    const char label = static_cast<char>(i);
    const double xyz[3] = {i + 0.5, -1.0, 2.0 * i};
    bin.append(&label, 1);
    bin.append(reinterpret_cast<const char*>(xyz), sizeof(xyz));
  }
  WriteRaw(Path("mixed.pcd"), bin);
  const auto m = ReadPcd(Path("mixed.pcd"));
  ASSERT_TRUE(m.ok()) << m.status().ToString();
  ASSERT_EQ(m->size(), 2u);
  EXPECT_EQ((*m)[1], Eigen::Vector3f(1.5f, -1.0f, 2.0f));
}

TEST_F(PcdTest, MapCloudOfASceneRoundTrips) {
  const auto cloud = SampleSceneSurface(TestScene(), MapCloudOptions());
  ASSERT_TRUE(WritePcd(Path("map.pcd"), cloud).ok());
  const auto back = ReadPcd(Path("map.pcd"));
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(*back, cloud);
}

}  // namespace
}  // namespace adse::world
