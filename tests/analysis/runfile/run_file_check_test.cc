// CheckRunFile against results-schema/run.schema.json: passes on what
// WriteRunFile writes, names the HDF5 path of each problem otherwise.
#include <gtest/gtest.h>
#include <unistd.h>

#if __has_include(<hdf5.h>)
#include <hdf5.h>
#else
#include <hdf5/serial/hdf5.h>  // Debian keeps it off the default path
#endif

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "analysis/runfile/run_file.h"
#include "stack/base/hash.h"
#include "tests/analysis/testing/temp_dir_test.h"

namespace adse::runfile {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

RunData MakeRun() {
  RunData run;
  run.termination_reason = "no_path";
  // Optional: written, so checked as documented.
  run.termination_detail = "no path: the car does not fit at the goal";
  run.scenario_name = "follow";
  run.scenario_text = "name: follow\n";
  run.scenario_hash = Sha256Hex(run.scenario_text);
  run.task_case = "nose_in";  // optional: written, so checked as documented
  run.design_point = {{"v0_mps", 10.0}};
  run.platform = {{"kind", "desktop"}};
  run.metrics = {{"collision", 0.0}};
  run.ego = {{0, 0, 0, 0, 10, 0, 0}, {0.1, 1, 0, 0, 10, 0, 0}};
  run.vehicles = {{0, "v1", 20, 0, 0, 9, 4.5, 1.8}};
  run.lanes = {{0, 0, 0}, {0, 50, 0}, {1, 50, 3.5}, {1, 0, 3.5}};
  run.node_names = {"planner"};
  run.topic_names = {"/pose"};
  run.callback_info = {
      {"planner/on_pose", 0, runfile::CallbackKind::kSubscription, 0, 0.0}};
  run.trace.callbacks.resize(3);
  run.trace.topic_events.resize(5);
  run.trace.timer_overruns = {0};
  run.controls = {{0.1, 0.05, 0.3, 0.0, 0.02}};
  // A valet run's /parking, so every dataset the writer can write is here.
  run.parking.present = true;
  run.parking.slot = "slot_r0_s3";
  run.parking.slots = {{18.25, 8.0, M_PI / 2, 5.0, 2.5, 0, 1}};
  run.parking.obstacles = {{0, 0, 0}, {0, 1, 0}, {0, 1, 1}};
  run.parking.planned_path = {{1, 2, 0, 0}, {0, 2, 0, 1}};
  return run;
}

bool Contains(const std::vector<std::string>& lines, const std::string& line) {
  return std::find(lines.begin(), lines.end(), line) != lines.end();
}

std::string Join(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& line : lines) out += line + "\n";
  return out;
}

class RunFileCheckTest : public adse::testing::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    ASSERT_FALSE(HasFatalFailure());
    good_ = Path("good.h5");
    ASSERT_TRUE(WriteRunFile(good_, MakeRun()).ok());
  }
  // A copy of the good file to damage.
  std::string Copy(const std::string& name) const {
    const std::string path = Path(name);
    fs::copy_file(good_, path);
    return path;
  }

  std::string good_;
};

// Opens a file read-write for surgery; closes on scope exit.
class Editable {
 public:
  explicit Editable(const std::string& path)
      : file_(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT)) {}
  ~Editable() {
    if (file_ >= 0) H5Fclose(file_);
  }
  hid_t get() const { return file_; }

  // Replaces a root attribute by a scalar of `type` holding `value`.
  void SetAttr(const char* name, hid_t type, const void* value) {
    if (H5Aexists(file_, name) > 0) H5Adelete(file_, name);
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t attr =
        H5Acreate2(file_, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(attr, type, value);
    H5Aclose(attr);
    H5Sclose(space);
  }
  void SetStringAttr(hid_t loc, const char* name, const char* value) {
    if (H5Aexists(loc, name) > 0) H5Adelete(loc, name);
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, H5T_VARIABLE);
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t attr =
        H5Acreate2(loc, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(attr, type, &value);
    H5Aclose(attr);
    H5Sclose(space);
    H5Tclose(type);
  }

 private:
  hid_t file_;
};

TEST_F(RunFileCheckTest, SchemaFileIsInstalled) {
  EXPECT_TRUE(fs::exists(SchemaPath())) << SchemaPath();
}

TEST_F(RunFileCheckTest, PassesOnAWrittenFile) {
  std::vector<std::string> problems;
  const Status status = CheckRunFile(good_, &problems);
  EXPECT_TRUE(status.ok()) << status.ToString();
  EXPECT_TRUE(problems.empty()) << Join(problems);
}

TEST_F(RunFileCheckTest, ReportsADeletedDataset) {
  const std::string path = Copy("deleted.h5");
  {
    Editable file(path);
    ASSERT_GE(H5Ldelete(file.get(), "/world/vehicles", H5P_DEFAULT), 0);
  }
  std::vector<std::string> problems;
  const Status status = CheckRunFile(path, &problems);
  EXPECT_EQ(status.code(), Status::Code::kCorruption);
  EXPECT_NE(status.message().find(path), std::string::npos);
  EXPECT_EQ(problems,
            std::vector<std::string>{"/world/vehicles: missing dataset"});
}

TEST_F(RunFileCheckTest, ReportsMissingLanes) {
  // Readers accept older files without /world/lanes, but the schema says a
  // file written now always has it.
  const std::string path = Copy("no_lanes.h5");
  {
    Editable file(path);
    ASSERT_GE(H5Ldelete(file.get(), "/world/lanes", H5P_DEFAULT), 0);
  }
  std::vector<std::string> problems;
  EXPECT_EQ(CheckRunFile(path, &problems).code(), Status::Code::kCorruption);
  EXPECT_EQ(problems,
            std::vector<std::string>{"/world/lanes: missing dataset"});
}

TEST_F(RunFileCheckTest, ReportsADeletedGroupAndEverythingBelowIt) {
  const std::string path = Copy("no_trace.h5");
  {
    Editable file(path);
    ASSERT_GE(H5Ldelete(file.get(), "/trace", H5P_DEFAULT), 0);
  }
  std::vector<std::string> problems;
  EXPECT_EQ(CheckRunFile(path, &problems).code(), Status::Code::kCorruption);
  EXPECT_TRUE(Contains(problems, "/trace: missing group")) << Join(problems);
  EXPECT_TRUE(Contains(problems, "/trace/topic_events: missing dataset"));
  EXPECT_EQ(problems.size(), 7u) << Join(problems);
}

TEST_F(RunFileCheckTest, ReportsAWrongFieldType) {
  const std::string path = Copy("wrong_type.h5");
  {
    // /ego/trajectory rebuilt with x_m as an integer and kind-less events.
    Editable file(path);
    ASSERT_GE(H5Ldelete(file.get(), "/ego/trajectory", H5P_DEFAULT), 0);
    const char* names[] = {"t_s",   "x_m",       "y_m",       "yaw_rad",
                           "v_mps", "steer_rad", "accel_mps2"};
    const hid_t type = H5Tcreate(H5T_COMPOUND, 7 * 8);
    for (int i = 0; i < 7; ++i) {
      H5Tinsert(type, names[i], 8 * i, i == 1 ? H5T_STD_I64LE : H5T_IEEE_F64LE);
    }
    const hsize_t dims[1] = {0};
    const hid_t space = H5Screate_simple(1, dims, nullptr);
    const hid_t dataset = H5Dcreate2(file.get(), "/ego/trajectory", type, space,
                                     H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    ASSERT_GE(dataset, 0);
    H5Dclose(dataset);
    H5Sclose(space);
    H5Tclose(type);
  }
  std::vector<std::string> problems;
  EXPECT_EQ(CheckRunFile(path, &problems).code(), Status::Code::kCorruption);
  EXPECT_EQ(problems,
            std::vector<std::string>{
                "/ego/trajectory: field 'x_m' is int, expected float"});
  // The reader refuses it too, naming the field.
  Result<RunData> back = ReadRunFile(path);
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.status().message().find("/ego/trajectory: field 'x_m'"),
            std::string::npos)
      << back.status().message();
}

// Replaces the table at `path` with an empty one of compound `type`.
void ReplaceWithEmptyTable(hid_t file, const char* path, hid_t type) {
  ASSERT_GE(H5Ldelete(file, path, H5P_DEFAULT), 0);
  const hsize_t dims[1] = {0};
  const hid_t space = H5Screate_simple(1, dims, nullptr);
  const hid_t dataset = H5Dcreate2(file, path, type, space, H5P_DEFAULT,
                                   H5P_DEFAULT, H5P_DEFAULT);
  H5Sclose(space);
  ASSERT_GE(dataset, 0);
  H5Dclose(dataset);
}

TEST_F(RunFileCheckTest, ReportsAPlainIntegerWhereTheEnumBelongs) {
  const std::string path = Copy("enum.h5");
  {
    Editable file(path);
    const hid_t type = H5Tcreate(H5T_COMPOUND, 1 + 4 + 4 + 8 + 8 + 8);
    H5Tinsert(type, "kind", 0, H5T_STD_I8LE);
    H5Tinsert(type, "topic", 1, H5T_STD_I32LE);
    H5Tinsert(type, "callback", 5, H5T_STD_I32LE);
    H5Tinsert(type, "t_s", 9, H5T_IEEE_F64LE);
    H5Tinsert(type, "seq", 17, H5T_STD_U64LE);
    H5Tinsert(type, "stamp_s", 25, H5T_IEEE_F64LE);
    ReplaceWithEmptyTable(file.get(), "/trace/topic_events", type);
    H5Tclose(type);
  }
  std::vector<std::string> problems;
  EXPECT_EQ(CheckRunFile(path, &problems).code(), Status::Code::kCorruption);
  EXPECT_EQ(problems,
            std::vector<std::string>{
                "/trace/topic_events: field 'kind' is int, expected enum"});
}

// /planning/stop_reasons rebuilt with a `reason` enum of the given codes.
void RebuildStopReasons(
    const std::string& path,
    const std::vector<std::pair<const char*, int8_t>>& codes) {
  Editable file(path);
  const hid_t reason = H5Tenum_create(H5T_NATIVE_INT8);
  for (const auto& [name, code] : codes) H5Tenum_insert(reason, name, &code);
  const hid_t type = H5Tcreate(H5T_COMPOUND, 8 + 8 + 1 + 8 + 4 + 8 + 4);
  H5Tinsert(type, "t_s", 0, H5T_IEEE_F64LE);
  H5Tinsert(type, "stamp_s", 8, H5T_IEEE_F64LE);
  H5Tinsert(type, "reason", 16, reason);
  H5Tinsert(type, "stop_distance_m", 17, H5T_IEEE_F64LE);
  H5Tinsert(type, "track_id", 25, H5T_STD_I32LE);
  H5Tinsert(type, "obstacle_gap_m", 29, H5T_IEEE_F64LE);
  H5Tinsert(type, "static_structure", 37, H5T_STD_I32LE);
  ReplaceWithEmptyTable(file.get(), "/planning/stop_reasons", type);
  H5Tclose(type);
  H5Tclose(reason);
}

// A file written before red_light existed lacks the code and still passes;
// a file whose red_light has another code does not.
TEST_F(RunFileCheckTest, StopReasonCodesAddedLaterMayBeMissingButNotWrong) {
  const std::string older = Copy("older.h5");
  RebuildStopReasons(older, {{"none", 0},
                             {"goal", 1},
                             {"obstacle", 2},
                             {"localization_lost", 3},
                             {"no_trajectory", 4}});
  std::vector<std::string> problems;
  EXPECT_TRUE(CheckRunFile(older, &problems).ok()) << Join(problems);
  EXPECT_TRUE(ReadRunFile(older).ok());

  const std::string wrong = Copy("wrong_code.h5");
  RebuildStopReasons(wrong, {{"none", 0},
                             {"goal", 1},
                             {"obstacle", 2},
                             {"localization_lost", 3},
                             {"no_trajectory", 4},
                             {"red_light", 9}});
  problems.clear();
  EXPECT_EQ(CheckRunFile(wrong, &problems).code(), Status::Code::kCorruption);
  EXPECT_EQ(problems, std::vector<std::string>{
                          "/planning/stop_reasons: field 'reason' enum code "
                          "'red_light' is 9, expected 5"});
}

// /control/commands as files written before perception_stamp_s had it:
// one row, the other four fields.
void WriteCommandsWithoutPerceptionStamp(const std::string& path) {
  Editable file(path);
  ASSERT_GE(H5Ldelete(file.get(), "/control/commands", H5P_DEFAULT), 0);
  const hid_t type = H5Tcreate(H5T_COMPOUND, 4 * 8);
  H5Tinsert(type, "t_s", 0, H5T_IEEE_F64LE);
  H5Tinsert(type, "stamp_s", 8, H5T_IEEE_F64LE);
  H5Tinsert(type, "accel_mps2", 16, H5T_IEEE_F64LE);
  H5Tinsert(type, "steer_rad", 24, H5T_IEEE_F64LE);
  const hsize_t dims[1] = {1};
  const hid_t space = H5Screate_simple(1, dims, nullptr);
  const hid_t dataset = H5Dcreate2(file.get(), "/control/commands", type, space,
                                   H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  const double row[4] = {0.1, 0.05, 0.3, 0.0};
  EXPECT_GE(H5Dwrite(dataset, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, row), 0);
  H5Dclose(dataset);
  H5Sclose(space);
  H5Tclose(type);
}

// A field added later (optional in the schema) may be missing: the file
// passes and reads with the field's default; a required one may not.
TEST_F(RunFileCheckTest, FieldsAddedLaterMayBeMissingFromOlderFiles) {
  const std::string older = Copy("older_commands.h5");
  WriteCommandsWithoutPerceptionStamp(older);
  std::vector<std::string> problems;
  EXPECT_TRUE(CheckRunFile(older, &problems).ok()) << Join(problems);
  Result<RunData> back = ReadRunFile(older);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  ASSERT_EQ(back->controls.size(), 1u);
  EXPECT_EQ(back->controls[0].stamp_s, 0.05);
  EXPECT_EQ(back->controls[0].accel_mps2, 0.3);
  EXPECT_EQ(back->controls[0].perception_stamp_s, -1.0);

  // What this version writes round-trips.
  Result<RunData> now = ReadRunFile(Copy("now.h5"));
  ASSERT_TRUE(now.ok());
  EXPECT_EQ(now->controls[0].perception_stamp_s, 0.02);

  const std::string broken = Copy("no_accel.h5");
  {
    Editable file(broken);
    const hid_t type = H5Tcreate(H5T_COMPOUND, 3 * 8);
    H5Tinsert(type, "t_s", 0, H5T_IEEE_F64LE);
    H5Tinsert(type, "stamp_s", 8, H5T_IEEE_F64LE);
    H5Tinsert(type, "steer_rad", 16, H5T_IEEE_F64LE);
    ReplaceWithEmptyTable(file.get(), "/control/commands", type);
    H5Tclose(type);
  }
  problems.clear();
  EXPECT_EQ(CheckRunFile(broken, &problems).code(), Status::Code::kCorruption);
  EXPECT_EQ(problems, std::vector<std::string>{
                          "/control/commands: missing field 'accel_mps2'"});
  Result<RunData> refused = ReadRunFile(broken);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find(
                "/control/commands: missing field 'accel_mps2'"),
            std::string::npos)
      << refused.status().message();
}

TEST_F(RunFileCheckTest, ReportsBadRootAttributes) {
  const std::string path = Copy("attrs.h5");
  {
    Editable file(path);
    const int32_t version = 2;
    file.SetAttr("schema_version", H5T_NATIVE_INT32, &version);
    file.SetStringAttr(file.get(), "status", "done");
    file.SetStringAttr(file.get(), "seed", "42");
    ASSERT_GE(H5Adelete(file.get(), "host"), 0);
  }
  std::vector<std::string> problems;
  EXPECT_EQ(CheckRunFile(path, &problems).code(), Status::Code::kCorruption);
  EXPECT_TRUE(Contains(problems,
                       "/: schema_version 2 is not compatible with schema "
                       "version 1"))
      << Join(problems);
  EXPECT_TRUE(Contains(problems,
                       "/: attribute 'status' is 'done', expected one of "
                       "[\"complete\",\"infeasible\",\"stalled\",\"failed\"]"))
      << Join(problems);
  EXPECT_TRUE(Contains(problems, "/: attribute 'seed' is string, expected int"))
      << Join(problems);
  EXPECT_TRUE(Contains(problems, "/: missing attribute 'host'"))
      << Join(problems);
  EXPECT_EQ(problems.size(), 4u) << Join(problems);
  // A newer schema version is not read either.
  Result<RunData> back = ReadRunFile(path);
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.status().message().find("schema_version 2"),
            std::string::npos);
}

TEST_F(RunFileCheckTest, ReportsAWrongGroupAttributeClass) {
  const std::string path = Copy("design.h5");
  {
    Editable file(path);
    const hid_t group = H5Gopen2(file.get(), "/design_point", H5P_DEFAULT);
    file.SetStringAttr(group, "gap_m", "far");
    H5Gclose(group);
  }
  std::vector<std::string> problems;
  EXPECT_EQ(CheckRunFile(path, &problems).code(), Status::Code::kCorruption);
  EXPECT_EQ(problems,
            std::vector<std::string>{
                "/design_point: attribute 'gap_m' is string, expected float"});
}

TEST_F(RunFileCheckTest, ReportsAScenarioTextThatDoesNotMatchItsHash) {
  const std::string path = Copy("text.h5");
  {
    // Same length, one character changed: what a flipped byte would do.
    Editable file(path);
    const hid_t dataset = H5Dopen2(file.get(), "/scenario/yaml", H5P_DEFAULT);
    ASSERT_GE(dataset, 0);
    const hid_t type = H5Dget_type(dataset);
    const char text[] = "name: fellow\n";
    ASSERT_EQ(H5Tget_size(type), sizeof(text) - 1);
    ASSERT_GE(H5Dwrite(dataset, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, text), 0);
    H5Tclose(type);
    H5Dclose(dataset);
  }
  std::vector<std::string> problems;
  EXPECT_EQ(CheckRunFile(path, &problems).code(), Status::Code::kCorruption);
  EXPECT_EQ(problems, std::vector<std::string>{
                          "/scenario/yaml: text does not match attribute "
                          "'scenario_hash' (damaged)"});
  Result<RunData> back = ReadRunFile(path);
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.status().code(), Status::Code::kCorruption);
  EXPECT_NE(back.status().message().find("/scenario/yaml"), std::string::npos);
}

TEST_F(RunFileCheckTest, MissingFileIsNotFound) {
  std::vector<std::string> problems;
  const Status status = CheckRunFile(Path("nope.h5"), &problems);
  EXPECT_EQ(status.code(), Status::Code::kNotFound);
  EXPECT_NE(status.message().find("nope.h5"), std::string::npos);
}

TEST_F(RunFileCheckTest, NonHdf5FileIsOneProblem) {
  const std::string path = Path("text.h5");
  std::ofstream(path) << "hello\n";
  std::vector<std::string> problems;
  EXPECT_EQ(CheckRunFile(path, &problems).code(), Status::Code::kCorruption);
  EXPECT_EQ(problems, std::vector<std::string>{"/: not an HDF5 file"});
}

TEST_F(RunFileCheckTest, SchemaErrorsAreReported) {
  EXPECT_EQ(CheckRunFile(good_, Path("missing.json"), nullptr).code(),
            Status::Code::kNotFound);
  const std::string broken = Path("broken.json");
  std::ofstream(broken) << "{ not json";
  EXPECT_EQ(CheckRunFile(good_, broken, nullptr).code(),
            Status::Code::kCorruption);
  const std::string malformed = Path("malformed.json");
  std::ofstream(malformed)
      << R"({"schema_version": 1, "root_attributes": [{"nom": "x"}],
             "groups": [], "datasets": []})";
  const Status status = CheckRunFile(good_, malformed, nullptr);
  EXPECT_EQ(status.code(), Status::Code::kCorruption);
  EXPECT_NE(status.message().find("malformed.json"), std::string::npos);
}

// The parsed schema is kept between checks (callers check many files), but
// a schema changed on disk is read again.
TEST_F(RunFileCheckTest, ASchemaChangedOnDiskIsReadAgain) {
  const std::string schema = Path("changing.json");
  fs::copy_file(SchemaPath(), schema);
  EXPECT_TRUE(CheckRunFile(good_, schema, nullptr).ok());
  std::ofstream(schema, std::ios::trunc) << "{ not json";
  EXPECT_EQ(CheckRunFile(good_, schema, nullptr).code(),
            Status::Code::kCorruption);
  fs::remove(schema);
  fs::copy_file(SchemaPath(), schema);
  EXPECT_TRUE(CheckRunFile(good_, schema, nullptr).ok());
}

// The schema documents everything the writer puts in a file, with the same
// version and string widths: the two cannot drift apart silently.
TEST_F(RunFileCheckTest, SchemaDocumentsEverythingTheWriterWrites) {
  std::ifstream in(SchemaPath());
  const json schema = json::parse(in);
  EXPECT_EQ(schema.at("schema_version").get<int>(), kSchemaVersion);

  std::set<std::string> documented_attrs;
  for (const auto& attr : schema.at("root_attributes")) {
    documented_attrs.insert(attr.at("name").get<std::string>());
  }
  const hid_t file = H5Fopen(good_.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  std::vector<std::string> attrs;
  hsize_t index = 0;
  H5Aiterate2(
      file, H5_INDEX_NAME, H5_ITER_INC, &index,
      [](hid_t, const char* name, const H5A_info_t*, void* data) -> herr_t {
        static_cast<std::vector<std::string>*>(data)->push_back(name);
        return 0;
      },
      &attrs);
  EXPECT_EQ(std::set<std::string>(attrs.begin(), attrs.end()),
            documented_attrs);

  for (const auto& dataset : schema.at("datasets")) {
    if (!dataset.contains("fields")) continue;
    const std::string path = dataset.at("path").get<std::string>();
    const hid_t handle = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
    ASSERT_GE(handle, 0) << path;
    const hid_t type = H5Dget_type(handle);
    const auto& fields = dataset.at("fields");
    ASSERT_EQ(H5Tget_nmembers(type), static_cast<int>(fields.size())) << path;
    for (int i = 0; i < H5Tget_nmembers(type); ++i) {
      char* name = H5Tget_member_name(type, i);
      // Same order as documented, so pandas columns follow the README.
      EXPECT_EQ(std::string(name), fields[i].at("name").get<std::string>())
          << path;
      if (fields[i].contains("size")) {
        const hid_t member = H5Tget_member_type(type, i);
        EXPECT_EQ(H5Tget_size(member), fields[i].at("size").get<size_t>())
            << path << " " << name;
        H5Tclose(member);
      }
      H5free_memory(name);
    }
    H5Tclose(type);
    H5Dclose(handle);
  }
  H5Fclose(file);
}

}  // namespace
}  // namespace adse::runfile
