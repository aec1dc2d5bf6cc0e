// Map generation with SUMO's tools and the content-hash cache.
#include "stack/world/map_builder.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "tests/stack/base/testing/fault_injection_env.h"
#include "tests/testing/temp_files.h"

namespace adse::world {
namespace {

namespace fs = std::filesystem;

std::string FreshCache(const std::string& name) {
  const fs::path dir =
      adse::testing::TestScratch() / ("adse_map_cache_" + name);
  fs::remove_all(dir);
  return dir.string();
}

MapOptions Lot(int rows) {
  MapOptions options;
  options.generator = "parking_lot";
  options.generator_params = {{"rows", rows}, {"slots_per_row", 6}};
  return options;
}

TEST(MapBuilderTest, GeneratedMapIsBuiltOnceAndReusedByContentHash) {
  const std::string cache = FreshCache("reuse");
  Result<MapArtifacts> first = PrepareMap(Lot(2), cache);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  EXPECT_TRUE(first->generated);
  ASSERT_TRUE(fs::exists(first->net_path));
  ASSERT_TRUE(fs::exists(first->polygons_path));
  const auto built_at = fs::last_write_time(first->net_path);

  Result<MapArtifacts> again = PrepareMap(Lot(2), cache);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->key, first->key);
  EXPECT_EQ(again->net_path, first->net_path);
  EXPECT_EQ(fs::last_write_time(again->net_path), built_at);

  Result<MapArtifacts> other = PrepareMap(Lot(3), cache);
  ASSERT_TRUE(other.ok());
  EXPECT_NE(other->key, first->key);
  EXPECT_NE(other->net_path, first->net_path);
}

TEST(MapBuilderTest, GeneratedParkingLotHasTheRequestedSlots) {
  Result<MapArtifacts> map = PrepareMap(Lot(3), FreshCache("slots"));
  ASSERT_TRUE(map.ok()) << map.status().ToString();
  std::ifstream in(map->polygons_path);
  std::string text((std::istreambuf_iterator<char>(in)),
                   std::istreambuf_iterator<char>());
  size_t slots = 0;
  for (size_t at = text.find("adse.parking_slot"); at != std::string::npos;
       at = text.find("adse.parking_slot", at + 1)) {
    ++slots;
  }
  EXPECT_EQ(slots, 3u * 6u);
}

TEST(MapBuilderTest, LeftoverOfACrashedBuildIsReplaced) {
  const std::string cache = FreshCache("crash");
  Result<MapArtifacts> first = PrepareMap(Lot(2), cache);
  ASSERT_TRUE(first.ok());
  // A crash before DONE was written leaves a folder without it.
  fs::remove(first->cache_folder + "/DONE");
  fs::remove(first->net_path);
  Result<MapArtifacts> again = PrepareMap(Lot(2), cache);
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  EXPECT_TRUE(fs::exists(again->net_path));
}

// No map folder left without its DONE marker, no temporary left behind,
// the path and the reason told, and the next build succeeds.
void ExpectFailedBuildLeavesNothing(const std::string& cache,
                                    const Status& status,
                                    const std::string& reason) {
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find(reason), std::string::npos)
      << status.ToString();
  EXPECT_NE(status.message().find(cache + "/maps/"), std::string::npos)
      << status.ToString();
  if (fs::exists(cache + "/maps")) {
    for (const auto& entry : fs::directory_iterator(cache + "/maps")) {
      ADD_FAILURE() << "left behind: " << entry.path();
    }
  }
  Result<MapArtifacts> again = PrepareMap(Lot(2), cache);
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  EXPECT_TRUE(fs::exists(again->cache_folder + "/DONE"));
}

TEST(MapBuilderTest, AFullDiskWhileMarkingTheMapDoneLeavesNoMap) {
  const std::string cache = FreshCache("enospc");
  testing::FaultInjectionEnv env;
  env.Inject({testing::FaultOp::kWriteFile, "DONE", ENOSPC});
  Result<MapArtifacts> map = PrepareMap(Lot(2), cache, &env);
  ExpectFailedBuildLeavesNothing(cache, map.status(),
                                 "No space left on device");
}

TEST(MapBuilderTest, AFailedRenameIntoTheCacheLeavesNoMap) {
  const std::string cache = FreshCache("rename");
  testing::FaultInjectionEnv env;
  // The first rename under maps/ is the DONE marker's, the second the
  // folder's into place.
  env.Inject({testing::FaultOp::kRenameFile, "/maps/", EIO, 1});
  Result<MapArtifacts> map = PrepareMap(Lot(2), cache, &env);
  ExpectFailedBuildLeavesNothing(cache, map.status(), "Input/output error");
}

TEST(MapBuilderTest, GivenNetIsKeyedByItsContent) {
  const std::string cache = FreshCache("given");
  Result<MapArtifacts> generated = PrepareMap(Lot(2), cache);
  ASSERT_TRUE(generated.ok());
  const fs::path copy = adse::testing::TestScratch() / "adse_given.net.xml";
  fs::copy_file(generated->net_path, copy,
                fs::copy_options::overwrite_existing);
  MapOptions given;
  given.net_path = copy.string();
  Result<MapArtifacts> a = PrepareMap(given, cache);
  ASSERT_TRUE(a.ok()) << a.status().ToString();
  EXPECT_FALSE(a->generated);
  EXPECT_EQ(a->net_path, copy.string());
  std::ofstream(copy, std::ios::app) << "<!-- changed -->\n";
  Result<MapArtifacts> b = PrepareMap(given, cache);
  ASSERT_TRUE(b.ok());
  EXPECT_NE(a->key, b->key);
}

TEST(MapBuilderTest, MissingNetAndUnknownGeneratorAreErrors) {
  MapOptions missing;
  missing.net_path = "/nonexistent/town.net.xml";
  Result<MapArtifacts> a = PrepareMap(missing, FreshCache("missing"));
  ASSERT_FALSE(a.ok());
  EXPECT_NE(a.status().message().find("/nonexistent/town.net.xml"),
            std::string::npos);
  MapOptions unknown;
  unknown.generator = "roundabout";
  Result<MapArtifacts> b = PrepareMap(unknown, FreshCache("unknown"));
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.status().message().find("roundabout"), std::string::npos);
}

}  // namespace
}  // namespace adse::world
