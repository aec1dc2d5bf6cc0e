// Reading damaged run files: missing, not HDF5, empty, cut short, flipped
// bytes, a missing dataset, a global heap libhdf5 would loop on, a writer
// that died before its last step: each a clear error, never garbage.
#include "analysis/runfile/run_file.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/analysis/runfile/testing/run_data_impl.h"

namespace adse::runfile {
namespace {

namespace fs = std::filesystem;
using testing::Diff;
using testing::MakeFullRun;
using testing::RawHdf5;
using testing::RunFileTest;

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

TEST_F(RunFileTest, DirectoryIsRejected) {
  Result<RunData> back = ReadRunFile(dir_);
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.status().code(), Status::Code::kInvalidArgument);
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

TEST_F(RunFileTest, ACallbackOfUnknownKindIsCorruptionNamingIt) {
  const std::string path = Path("run.h5");
  ASSERT_TRUE(WriteRunFile(path, MakeFullRun(10)).ok());
  {
    // Rewrite the `kind` member of the table's rows alone, as h5py would.
    RawHdf5 raw(path, H5F_ACC_RDWR);
    const hid_t table =
        H5Dopen2(raw.file(), "/trace/callback_info", H5P_DEFAULT);
    ASSERT_GE(table, 0);
    const hid_t space = H5Dget_space(table);
    const hssize_t n = H5Sget_simple_extent_npoints(space);
    ASSERT_GE(n, 2);
    const hid_t row = H5Dget_type(table);
    const hid_t text =  // the file's own string type (width, charset)
        H5Tget_member_type(row, H5Tget_member_index(row, "kind"));
    const size_t width = H5Tget_size(text);
    const hid_t member = H5Tcreate(H5T_COMPOUND, width);
    H5Tinsert(member, "kind", 0, text);
    std::vector<char> kinds(static_cast<size_t>(n) * width, '\0');
    ASSERT_GE(
        H5Dread(table, member, H5S_ALL, H5S_ALL, H5P_DEFAULT, kinds.data()), 0);
    std::fill(kinds.begin() + width, kinds.begin() + 2 * width, '\0');
    const std::string bad = "interrupt";
    std::copy(bad.begin(), bad.end(), kinds.begin() + width);
    EXPECT_GE(
        H5Dwrite(table, member, H5S_ALL, H5S_ALL, H5P_DEFAULT, kinds.data()),
        0);
    H5Tclose(member);
    H5Tclose(text);
    H5Tclose(row);
    H5Sclose(space);
    H5Dclose(table);
  }
  Result<RunData> back = ReadRunFile(path);
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.status().code(), Status::Code::kCorruption);
  EXPECT_NE(back.status().message().find(
                "/trace/callback_info: callback 1 (localizer/on_points) has "
                "unknown kind 'interrupt'; valid kinds: subscription, timer"),
            std::string::npos)
      << back.status().message();
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

}  // namespace
}  // namespace adse::runfile
