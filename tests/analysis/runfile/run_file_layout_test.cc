// The run file's layout as generic HDF5 tools see it: documented fields
// and storage, enums named by the project's vocabularies, files written
// before a dataset or attribute existed, and h5py/pandas reading it.
#include "analysis/runfile/run_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "tests/analysis/runfile/testing/run_data_impl.h"

namespace adse::runfile {
namespace {

using testing::CompoundMembers;
using testing::Diff;
using testing::MakeFullRun;
using testing::Member;
using testing::Names;
using testing::RawHdf5;
using testing::RunFileTest;

TEST_F(RunFileTest, RawApiSeesDocumentedFieldsAndStorage) {
  const std::string path = Path("run.h5");
  ASSERT_TRUE(WriteRunFile(path, MakeFullRun(10000)).ok());
  RawHdf5 raw(path);
  ASSERT_GE(raw.file(), 0);

  EXPECT_EQ(Names(CompoundMembers(raw.file(), "/ego/trajectory")),
            (std::vector<std::string>{"t_s", "x_m", "y_m", "yaw_rad", "v_mps",
                                      "steer_rad", "accel_mps2"}));
  EXPECT_EQ(Names(CompoundMembers(raw.file(), "/world/vehicles")),
            (std::vector<std::string>{"t_s", "id", "x_m", "y_m", "yaw_rad",
                                      "speed_mps", "length_m", "width_m"}));
  EXPECT_EQ(Names(CompoundMembers(raw.file(), "/trace/callbacks")),
            (std::vector<std::string>{"callback", "node", "ready_s", "start_s",
                                      "end_s", "cost_s", "host_cpu_s",
                                      "work_units", "cores", "first_core"}));
  const std::vector<Member> events =
      CompoundMembers(raw.file(), "/trace/topic_events");
  EXPECT_EQ(Names(events),
            (std::vector<std::string>{"kind", "topic", "callback", "t_s", "seq",
                                      "stamp_s"}));
  ASSERT_EQ(events.size(), 6u);
  EXPECT_EQ(events[0].type_class, H5T_ENUM);
  EXPECT_EQ(events[0].size, 1u);
  EXPECT_EQ(events[4].type_class, H5T_INTEGER);
  const std::vector<Member> vehicles =
      CompoundMembers(raw.file(), "/world/vehicles");
  ASSERT_EQ(vehicles.size(), 8u);
  EXPECT_EQ(vehicles[1].type_class, H5T_STRING);
  EXPECT_EQ(vehicles[1].size, kIdBytes);

  // The enum codes, the chunked + shuffled + deflated storage, one row per
  // event.
  const hid_t dataset =
      H5Dopen2(raw.file(), "/trace/topic_events", H5P_DEFAULT);
  ASSERT_GE(dataset, 0);
  const hid_t type = H5Dget_type(dataset);
  const hid_t kind = H5Tget_member_type(type, 0);
  for (const auto& [name, code] : std::vector<std::pair<const char*, int8_t>>{
           {"publish", 0}, {"take", 1}, {"drop", 2}}) {
    int8_t value = -1;
    EXPECT_GE(H5Tenum_valueof(kind, name, &value), 0) << name;
    EXPECT_EQ(value, code) << name;
  }
  const hid_t space = H5Dget_space(dataset);
  hsize_t dims[1] = {0};
  H5Sget_simple_extent_dims(space, dims, nullptr);
  EXPECT_EQ(dims[0], 10000u);
  const hid_t dcpl = H5Dget_create_plist(dataset);
  EXPECT_EQ(H5Pget_layout(dcpl), H5D_CHUNKED);
  bool deflate = false, shuffle = false;
  for (int i = 0; i < H5Pget_nfilters(dcpl); ++i) {
    unsigned flags = 0;
    size_t nelmts = 0;
    unsigned config = 0;
    const H5Z_filter_t filter =
        H5Pget_filter2(dcpl, i, &flags, &nelmts, nullptr, 0, nullptr, &config);
    deflate |= filter == H5Z_FILTER_DEFLATE;
    shuffle |= filter == H5Z_FILTER_SHUFFLE;
  }
  EXPECT_TRUE(deflate);
  EXPECT_TRUE(shuffle);
  H5Pclose(dcpl);
  H5Sclose(space);
  H5Tclose(kind);
  H5Tclose(type);
  H5Dclose(dataset);
}

TEST_F(RunFileTest, LanesAreStoredAsOneRowPerVertex) {
  const std::string path = Path("run.h5");
  const RunData run = MakeFullRun(10);
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  RawHdf5 raw(path);
  ASSERT_GE(raw.file(), 0);
  const std::vector<Member> members =
      CompoundMembers(raw.file(), "/world/lanes");
  EXPECT_EQ(Names(members), (std::vector<std::string>{"lane", "x_m", "y_m"}));
  ASSERT_EQ(members.size(), 3u);
  EXPECT_EQ(members[0].type_class, H5T_INTEGER);
  EXPECT_EQ(members[0].size, 4u);
  EXPECT_EQ(members[1].type_class, H5T_FLOAT);
  const hid_t dataset = H5Dopen2(raw.file(), "/world/lanes", H5P_DEFAULT);
  ASSERT_GE(dataset, 0);
  const hid_t space = H5Dget_space(dataset);
  hsize_t dims[1] = {0};
  H5Sget_simple_extent_dims(space, dims, nullptr);
  EXPECT_EQ(dims[0], run.lanes.size());
  H5Sclose(space);
  H5Dclose(dataset);
}

// A full run written to `path`, `link` then deleted as in files written
// before it existed (same schema version): it reads back as the run with
// `clear` applied.
void ExpectReadsWithout(const std::string& path, const char* link,
                        const std::function<void(RunData*)>& clear) {
  RunData run = MakeFullRun(10);
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  {
    RawHdf5 raw(path, H5F_ACC_RDWR);
    ASSERT_GE(H5Ldelete(raw.file(), link, H5P_DEFAULT), 0);
  }
  Result<RunData> back = ReadRunFile(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  clear(&run);
  EXPECT_EQ(Diff(run, *back), "");
}

TEST_F(RunFileTest, AParkingRecordWrittenBeforeReplanningReadsAsOnePlan) {
  RunData run = MakeFullRun(10);
  run.parking.present = true;
  run.parking.planned_at_s = 20.0;
  run.parking.first_planned_at_s = 12.5;
  run.parking.replans = 2;
  const std::string path = Path("valet.h5");
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  {
    RawHdf5 raw(path, H5F_ACC_RDWR);
    for (const char* name : {"replans", "first_planned_at_s"}) {
      ASSERT_GE(H5Adelete_by_name(raw.file(), "/parking", name, H5P_DEFAULT), 0)
          << name;
    }
  }
  Result<RunData> older = ReadRunFile(path);
  ASSERT_TRUE(older.ok()) << older.status().ToString();
  EXPECT_EQ(older->parking.first_planned_at_s, 20.0);
  EXPECT_EQ(older->parking.replans, 0);
}

TEST_F(RunFileTest, AParkingRecordWrittenBeforeEarlierPlansWereKeptHasNone) {
  RunData run = MakeFullRun(10);
  run.parking.present = true;
  run.parking.earlier_plans = {{0, 1.0, 2.0, 0.0, 0}};
  const std::string path = Path("valet.h5");
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  {
    RawHdf5 raw(path, H5F_ACC_RDWR);
    ASSERT_GE(H5Ldelete(raw.file(), "/parking/earlier_plans", H5P_DEFAULT), 0);
  }
  Result<RunData> older = ReadRunFile(path);
  ASSERT_TRUE(older.ok()) << older.status().ToString();
  EXPECT_TRUE(older->parking.earlier_plans.empty());
  std::vector<std::string> problems;
  EXPECT_TRUE(CheckRunFile(path, &problems).ok()) << problems.front();
}

TEST_F(RunFileTest, FileWithoutLanesReadsAsNoLanes) {
  ExpectReadsWithout(Path("run.h5"), "/world/lanes",
                     [](RunData* run) { run->lanes.clear(); });
}

// Member `member` of the rows of `path` is an HDF5 enum with these names
// and codes.
void ExpectEnumCodes(hid_t file, const char* path, unsigned member,
                     const std::vector<std::pair<std::string, int8_t>>& codes) {
  const hid_t dataset = H5Dopen2(file, path, H5P_DEFAULT);
  ASSERT_GE(dataset, 0) << path;
  const hid_t type = H5Dget_type(dataset);
  const hid_t values = H5Tget_member_type(type, member);
  for (const auto& [name, code] : codes) {
    int8_t value = -1;
    EXPECT_GE(H5Tenum_valueof(values, name.c_str(), &value), 0) << name;
    EXPECT_EQ(value, code) << name;
  }
  H5Tclose(values);
  H5Tclose(type);
  H5Dclose(dataset);
}

TEST_F(RunFileTest, StopReasonsAreAnEnumOfTheVocabulary) {
  const std::string path = Path("run.h5");
  const RunData run = MakeFullRun(10);
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  RawHdf5 raw(path);
  ASSERT_GE(raw.file(), 0);
  const std::vector<Member> members =
      CompoundMembers(raw.file(), "/planning/stop_reasons");
  EXPECT_EQ(Names(members),
            (std::vector<std::string>{"t_s", "stamp_s", "reason",
                                      "stop_distance_m", "track_id",
                                      "obstacle_gap_m", "static_structure"}));
  ASSERT_EQ(members.size(), 7u);
  EXPECT_EQ(members[2].type_class, H5T_ENUM);
  // The enum's names are the vocabulary's, with its codes.
  std::vector<std::pair<std::string, int8_t>> codes;
  for (const std::string& name : StopReasonNames()) {
    StopReason expected = StopReason::kNone;
    ASSERT_TRUE(StringToStopReason(name, &expected));
    codes.emplace_back(name, static_cast<int8_t>(expected));
  }
  ExpectEnumCodes(raw.file(), "/planning/stop_reasons", 2, codes);
}

TEST_F(RunFileTest, FileWithoutStopReasonsReadsAsNone) {
  ExpectReadsWithout(Path("run.h5"), "/planning",
                     [](RunData* run) { run->stop_reasons.clear(); });
}

TEST_F(RunFileTest, SignalReportsAreStoredWithTheirStatesNamed) {
  const std::string path = Path("run.h5");
  const RunData run = MakeFullRun(10);
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  RawHdf5 raw(path);
  ASSERT_GE(raw.file(), 0);
  const std::vector<Member> members =
      CompoundMembers(raw.file(), "/perception/traffic_signals");
  EXPECT_EQ(Names(members),
            (std::vector<std::string>{"t_s", "stamp_s", "state",
                                      "stop_line_distance_m", "tls_id"}));
  ASSERT_EQ(members.size(), 5u);
  EXPECT_EQ(members[2].type_class, H5T_ENUM);
  ExpectEnumCodes(raw.file(), "/perception/traffic_signals", 2,
                  {{"unknown", 0}, {"red", 1}, {"yellow", 2}, {"green", 3}});
}

TEST_F(RunFileTest, FileWithoutPerceptionReadsAsNoSignalReportsAndNoObjects) {
  ExpectReadsWithout(Path("run.h5"), "/perception", [](RunData* run) {
    run->signals.clear();
    run->objects.clear();
  });
}

TEST_F(RunFileTest, FileWithoutObjectsReadsAsNone) {
  ExpectReadsWithout(Path("run.h5"), "/perception/objects",
                     [](RunData* run) { run->objects.clear(); });
}

TEST_F(RunFileTest, ASignalStateOutsideTheVocabularyIsRefused) {
  RunData run = MakeFullRun(10);
  run.signals[2].state = static_cast<SignalState>(9);
  const Status written = WriteRunFile(Path("run.h5"), run);
  EXPECT_EQ(written.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(written.message().find(
                "traffic signal report 2 has unknown state code 9"),
            std::string::npos)
      << written.message();
}

TEST_F(RunFileTest, AStopReasonCodeOutsideTheVocabularyIsRefused) {
  RunData run = MakeFullRun(10);
  run.stop_reasons[1].reason = static_cast<StopReason>(42);
  const Status written = WriteRunFile(Path("run.h5"), run);
  EXPECT_EQ(written.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(written.message().find("stop reason 1 has unknown code 42"),
            std::string::npos)
      << written.message();
}

// h5py/pandas read the file with no adse code. scripts/setup.sh installs
// Debian's python3-h5py and python3-pandas for /usr/bin/python3 (another
// python3 may come first on PATH); skipped when neither has h5py.
TEST_F(RunFileTest, H5pyAndPandasReadTheFile) {
  std::string python;
  for (const char* candidate : {"/usr/bin/python3", "python3"}) {
    const std::string probe =
        std::string(candidate) + " -c 'import h5py, numpy' >/dev/null 2>&1";
    if (std::system(probe.c_str()) == 0) {
      python = candidate;
      break;
    }
  }
  if (python.empty()) GTEST_SKIP() << "no python3 with h5py is installed";
  const std::string path = Path("run.h5");
  ASSERT_TRUE(WriteRunFile(path, MakeFullRun(1000)).ok());
  const std::string script = Path("read.py");
  std::ofstream(script) << R"(import sys, h5py
f = h5py.File(sys.argv[1], "r")
# String attributes are fixed-length: numpy bytes.
assert f.attrs["status"] == b"complete", f.attrs["status"]
assert f.attrs["scenario_name"].decode() == "cut_in_ÄÖ"
assert f["platform"].attrs["kind"] == b"embedded"
assert int(f.attrs["schema_version"]) == 1
ego = f["ego/trajectory"][:]
assert ego.dtype.names == ("t_s", "x_m", "y_m", "yaw_rad", "v_mps",
                           "steer_rad", "accel_mps2"), ego.dtype.names
assert len(ego) == 300
ev = f["trace/topic_events"][:]
assert len(ev) == 1000 and set(ev["kind"].tolist()) == {0, 1, 2}
assert h5py.check_enum_dtype(f["trace/topic_events"].dtype["kind"]) == \
    {"publish": 0, "take": 1, "drop": 2}
assert f["world/vehicles"][:]["id"][0] == b"veh0"
lanes = f["world/lanes"][:]
assert lanes.dtype.names == ("lane", "x_m", "y_m"), lanes.dtype.names
assert lanes["lane"].tolist() == [0] * 4 + [1] * 5 + [2] * 6
stops = f["planning/stop_reasons"][:]
assert h5py.check_enum_dtype(f["planning/stop_reasons"].dtype["reason"]) == \
    {"none": 0, "goal": 1, "obstacle": 2, "localization_lost": 3,
     "no_trajectory": 4, "red_light": 5, "lane_change": 6, "turnaround": 7}
assert stops["reason"].tolist() == [0, 1, 2, 3, 4, 5, 6, 7] * 2, stops["reason"]
assert f["scenario/yaml"].asstr()[()].startswith("name: cut_in")
assert f["metrics"].attrs["min_ttc_s"] == 0.75
try:
    import pandas as pd
except ImportError:
    sys.exit(0)
df = pd.DataFrame(f["ego/trajectory"][:])
assert list(df.columns)[:2] == ["t_s", "x_m"] and len(df) == 300
veh = pd.DataFrame(f["world/vehicles"][:])
assert veh["id"].str.decode("utf-8")[0] == "veh0"
)";
  const std::string command = python + " " + script + " " + path;
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
}

}  // namespace
}  // namespace adse::runfile
