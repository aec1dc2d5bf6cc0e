// ReadCampaignIndex on damaged or foreign files: NotFound or Corruption
// naming the file and the object, never garbage; and the variable-length
// strings other writers use.
#include "analysis/runfile/campaign_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "analysis/runfile/run_file.h"

#include "tests/analysis/runfile/testing/campaign_index_impl.h"

namespace adse::runfile {
namespace {

namespace fs = std::filesystem;
using testing::CampaignFileTest;
using testing::Diff;
using testing::MakeIndex;
using testing::RawFile;
using testing::ReplaceWithDoubles;

TEST_F(CampaignFileTest, AReplicaOfAnUnknownEvaluationIsCorruption) {
  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(4)).ok());
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    // The replicas of evaluation 2 claim one that does not exist.
    const hid_t dataset = H5Dopen2(raw.get(), "/replicas/index", H5P_DEFAULT);
    ASSERT_GE(dataset, 0);
    const int64_t bad[3] = {99, 99, 99};
    ASSERT_GE(
        H5Dwrite(dataset, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, bad),
        0);
    H5Dclose(dataset);
  }
  ExpectCorruption(path, "replica of evaluation 99");
}

TEST_F(CampaignFileTest, MissingFileIsNotFound) {
  const std::string path = Path("nope.h5");
  Result<CampaignIndex> back = ReadCampaignIndex(path);
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.status().code(), Status::Code::kNotFound);
  EXPECT_NE(back.status().message().find(path), std::string::npos);
}

TEST_F(CampaignFileTest, DirectoryIsRejected) {
  Result<CampaignIndex> back = ReadCampaignIndex(dir_);
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.status().code(), Status::Code::kInvalidArgument);
}

TEST_F(CampaignFileTest, NonHdf5FileIsCorruption) {
  const std::string path = Path("campaign.h5");
  std::ofstream(path) << "index,status\n0,complete\n";
  ExpectCorruption(path, "not an HDF5 file");
  const std::string empty = Path("empty.h5");
  std::ofstream(empty).close();
  ExpectCorruption(empty, "");
}

TEST_F(CampaignFileTest, TruncatedFileIsCorruption) {
  const std::string good = Path("good.h5");
  ASSERT_TRUE(WriteCampaignIndex(good, MakeIndex(500)).ok());
  const auto size = fs::file_size(good);
  for (const auto cut : {size / 2, size - 1, size_t{1000}, size_t{100}}) {
    SCOPED_TRACE("cut at " + std::to_string(cut));
    const std::string path = Path("cut_" + std::to_string(cut) + ".h5");
    fs::copy_file(good, path);
    fs::resize_file(path, cut);
    ExpectCorruption(path, "");
  }
}

TEST_F(CampaignFileTest, FlippedBytesAreCorruptionNotGarbage) {
  // Metadata and column chunks are checksummed.
  const std::string good = Path("good.h5");
  ASSERT_TRUE(WriteCampaignIndex(good, MakeIndex(500)).ok());
  std::string bytes;
  {
    std::ifstream in(good, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  for (const size_t pos :
       {bytes.size() / 3, bytes.size() / 2, 2 * bytes.size() / 3}) {
    SCOPED_TRACE("flip at " + std::to_string(pos));
    std::string damaged = bytes;
    damaged[pos] = static_cast<char>(damaged[pos] ^ 0x5A);
    const std::string path = Path("flip_" + std::to_string(pos) + ".h5");
    std::ofstream(path, std::ios::binary) << damaged;
    ExpectCorruption(path, "");
  }
}

TEST_F(CampaignFileTest, WrongSchemaVersionIsCorruption) {
  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(10)).ok());
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    ASSERT_GE(H5Adelete(raw.get(), "schema_version"), 0);
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t attr = H5Acreate2(raw.get(), "schema_version", H5T_STD_I32LE,
                                  space, H5P_DEFAULT, H5P_DEFAULT);
    ASSERT_GE(attr, 0);
    const int32_t version = kCampaignSchemaVersion + 1;
    H5Awrite(attr, H5T_NATIVE_INT32, &version);
    H5Aclose(attr);
    H5Sclose(space);
  }
  ExpectCorruption(path, "schema_version 2");
}

TEST_F(CampaignFileTest, RunFileIsNotACampaignIndex) {
  RunData run;
  run.status = "complete";
  run.termination_reason = "goal_reached";
  run.scenario_name = "follow";
  run.scenario_text = "name: follow\n";
  const std::string path = Path("run.h5");
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  ExpectCorruption(path, "kind");
}

TEST_F(CampaignFileTest, MissingDatasetIsCorruptionNamingIt) {
  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(10)).ok());
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    ASSERT_GE(H5Ldelete(raw.get(), "/evaluations/status", H5P_DEFAULT), 0);
    ASSERT_GE(
        H5Ldelete(raw.get(), "/evaluations/metrics/completed", H5P_DEFAULT), 0);
  }
  ExpectCorruption(path, "/evaluations/status: missing dataset");
}

TEST_F(CampaignFileTest, MissingMetricColumnIsCorruptionNamingIt) {
  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(10)).ok());
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    ASSERT_GE(
        H5Ldelete(raw.get(), "/evaluations/metrics/completed", H5P_DEFAULT), 0);
  }
  ExpectCorruption(path, "/evaluations/metrics/completed: missing dataset");
}

TEST_F(CampaignFileTest, UnequalColumnLengthsAreCorruption) {
  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(10)).ok());
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    ReplaceWithDoubles(raw.get(), "/evaluations/point/cores", 9);
  }
  ExpectCorruption(path, "/evaluations/point/cores: 9 rows, expected 10");

  ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(10)).ok());
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    ReplaceWithDoubles(raw.get(), "/evaluations/wall_s", 11);
  }
  ExpectCorruption(path, "/evaluations/wall_s: 11 rows, expected 10");
}

TEST_F(CampaignFileTest, WrongColumnTypeIsCorruption) {
  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(10)).ok());
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    ReplaceWithDoubles(raw.get(), "/iterations/rationale", 1);
  }
  ExpectCorruption(path, "/iterations/rationale: is float, expected string");
}

TEST_F(CampaignFileTest, ReadsVariableLengthStringsToo) {
  // What h5py writes by default, e.g. after someone edits the file.
  const std::string path = Path("campaign.h5");
  CampaignIndex index = MakeIndex(3);
  ASSERT_TRUE(WriteCampaignIndex(path, index).ok());
  const std::vector<std::string> reasons = {"ä, \"b\"", "", "timeout"};
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    ASSERT_GE(H5Ldelete(raw.get(), "/evaluations/reason", H5P_DEFAULT), 0);
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, H5T_VARIABLE);
    H5Tset_cset(type, H5T_CSET_UTF8);
    const hsize_t dims[1] = {3};
    const hid_t space = H5Screate_simple(1, dims, nullptr);
    const hid_t dataset =
        H5Dcreate2(raw.get(), "/evaluations/reason", type, space, H5P_DEFAULT,
                   H5P_DEFAULT, H5P_DEFAULT);
    ASSERT_GE(dataset, 0);
    const char* texts[3] = {reasons[0].c_str(), reasons[1].c_str(),
                            reasons[2].c_str()};
    ASSERT_GE(H5Dwrite(dataset, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, texts), 0);
    H5Dclose(dataset);
    H5Sclose(space);
    H5Tclose(type);
  }
  Result<CampaignIndex> back = ReadCampaignIndex(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back->evaluations[i].reason, reasons[i]);
    index.evaluations[i].reason = reasons[i];
  }
  EXPECT_EQ(Diff(index, *back), "");
}

}  // namespace
}  // namespace adse::runfile
