// Row layouts of the run file's tables and the templates that write and
// read a table through them: shared by run_file.cc (writing) and
// run_file_read.cc (reading). Internal to analysis/runfile; includes HDF5.
#ifndef ADSE_ANALYSIS_RUNFILE_RUN_FILE_TABLES_H_
#define ADSE_ANALYSIS_RUNFILE_RUN_FILE_TABLES_H_

#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "analysis/runfile/hdf5_util_impl.h"
#include "analysis/runfile/run_data.h"

namespace adse::runfile::internal {

// ---------------------------------------------------------------------------
// Row layouts. Each table is a list of columns that know how to pack a field
// of a C++ row into the packed HDF5 row and back; names, types and order are
// those of results-schema/run.schema.json.

template <typename Row>
struct Column {
  FieldDesc desc;
  std::function<void(const Row&, char*)> pack;
  std::function<void(const char*, Row*)> unpack;
};

template <typename Row, typename T>
Column<Row> Scalar(const char* name, FieldType type, T Row::*member) {
  return {FieldDesc{name, type, 0, {}},
          [member](const Row& row, char* out) {
            std::memcpy(out, &(row.*member), sizeof(T));
          },
          [member](const char* in, Row* row) {
            std::memcpy(&(row->*member), in, sizeof(T));
          }};
}

template <typename Row>
Column<Row> F64(const char* name, double Row::*member) {
  return Scalar(name, FieldType::kFloat64, member);
}
template <typename Row>
Column<Row> I32(const char* name, int32_t Row::*member) {
  return Scalar(name, FieldType::kInt32, member);
}
template <typename Row>
Column<Row> I64(const char* name, int64_t Row::*member) {
  return Scalar(name, FieldType::kInt64, member);
}
template <typename Row>
Column<Row> U64(const char* name, uint64_t Row::*member) {
  return Scalar(name, FieldType::kUInt64, member);
}

// A column added after files of the same schema version were written
// (results-schema/README.md, "Versioning").
template <typename Row>
Column<Row> Optional(Column<Row> column) {
  column.desc.optional = true;
  return column;
}

// Copies at most `width` bytes, backing off so a UTF-8 character is never
// split; the rest of the field stays NUL (the buffer is zeroed).
inline void PackString(const std::string& value, size_t width, char* out) {
  size_t n = std::min(value.size(), width);
  if (n < value.size()) {
    while (n > 0 && (static_cast<unsigned char>(value[n]) & 0xC0) == 0x80) --n;
  }
  std::memcpy(out, value.data(), n);
}

template <typename Row>
Column<Row> Str(const char* name, size_t width, std::string Row::*member) {
  return {FieldDesc{name, FieldType::kString, width, {}},
          [member, width](const Row& row, char* out) {
            PackString(row.*member, width, out);
          },
          [member, width](const char* in, Row* row) {
            (row->*member).assign(in, ::strnlen(in, width));
          }};
}

inline Column<stack::TopicEvent> TopicKindColumn() {
  using stack::TopicEvent;
  return {FieldDesc{"kind",
                    FieldType::kEnum8,
                    0,
                    {{"publish", TopicEvent::kPublish},
                     {"take", TopicEvent::kTake},
                     {"drop", TopicEvent::kDrop}}},
          [](const TopicEvent& row, char* out) {
            const int8_t kind = row.kind;
            std::memcpy(out, &kind, 1);
          },
          [](const char* in, TopicEvent* row) {
            int8_t kind = 0;
            std::memcpy(&kind, in, 1);
            row->kind = static_cast<TopicEvent::Kind>(kind);
          }};
}

// Rows of the small index tables.
struct IndexedName {
  int32_t index = 0;
  std::string name;
};
struct CallbackInfoRow {
  int32_t index = 0;
  std::string name;
  int32_t node = -1;
  std::string kind;
  int32_t topic = -1;
  double period_s = 0.0;
};
struct OverrunRow {
  int32_t callback = 0;
  int64_t count = 0;
};

inline const std::vector<Column<EgoSample>>& EgoColumns() {
  static const auto* columns = new std::vector<Column<EgoSample>>{
      F64("t_s", &EgoSample::t_s),
      F64("x_m", &EgoSample::x_m),
      F64("y_m", &EgoSample::y_m),
      F64("yaw_rad", &EgoSample::yaw_rad),
      F64("v_mps", &EgoSample::v_mps),
      F64("steer_rad", &EgoSample::steer_rad),
      F64("accel_mps2", &EgoSample::accel_mps2)};
  return *columns;
}

inline const std::vector<Column<PathPoint>>& PathColumns() {
  static const auto* columns = new std::vector<Column<PathPoint>>{
      F64("s_m", &PathPoint::s_m), F64("x_m", &PathPoint::x_m),
      F64("y_m", &PathPoint::y_m)};
  return *columns;
}

inline const std::vector<Column<LanePoint>>& LaneColumns() {
  static const auto* columns = new std::vector<Column<LanePoint>>{
      I32("lane", &LanePoint::lane), F64("x_m", &LanePoint::x_m),
      F64("y_m", &LanePoint::y_m)};
  return *columns;
}

inline const std::vector<Column<VehicleSample>>& VehicleColumns() {
  static const auto* columns = new std::vector<Column<VehicleSample>>{
      F64("t_s", &VehicleSample::t_s),
      Str("id", kIdBytes, &VehicleSample::id),
      F64("x_m", &VehicleSample::x_m),
      F64("y_m", &VehicleSample::y_m),
      F64("yaw_rad", &VehicleSample::yaw_rad),
      F64("speed_mps", &VehicleSample::speed_mps),
      F64("length_m", &VehicleSample::length_m),
      F64("width_m", &VehicleSample::width_m)};
  return *columns;
}

inline const std::vector<Column<CollisionEvent>>& CollisionColumns() {
  static const auto* columns = new std::vector<Column<CollisionEvent>>{
      F64("t_s", &CollisionEvent::t_s),
      Str("other_id", kIdBytes, &CollisionEvent::other_id),
      Optional(I32("ego_caused", &CollisionEvent::ego_caused))};
  return *columns;
}

inline const std::vector<Column<ParkingSlotRow>>& ParkingSlotColumns() {
  static const auto* columns = new std::vector<Column<ParkingSlotRow>>{
      F64("x_m", &ParkingSlotRow::x_m),
      F64("y_m", &ParkingSlotRow::y_m),
      F64("yaw_rad", &ParkingSlotRow::yaw_rad),
      F64("length_m", &ParkingSlotRow::length_m),
      F64("width_m", &ParkingSlotRow::width_m),
      I32("occupied", &ParkingSlotRow::occupied),
      I32("target", &ParkingSlotRow::target)};
  return *columns;
}

inline const std::vector<Column<OutlinePoint>>& OutlineColumns() {
  static const auto* columns = new std::vector<Column<OutlinePoint>>{
      I32("obstacle", &OutlinePoint::obstacle), F64("x_m", &OutlinePoint::x_m),
      F64("y_m", &OutlinePoint::y_m)};
  return *columns;
}

inline const std::vector<Column<ParkingPathRow>>& ParkingPathColumns() {
  static const auto* columns = new std::vector<Column<ParkingPathRow>>{
      F64("x_m", &ParkingPathRow::x_m), F64("y_m", &ParkingPathRow::y_m),
      F64("yaw_rad", &ParkingPathRow::yaw_rad),
      I32("reverse", &ParkingPathRow::reverse)};
  return *columns;
}

inline const std::vector<Column<EarlierPlanRow>>& EarlierPlanColumns() {
  static const auto* columns = new std::vector<Column<EarlierPlanRow>>{
      I32("plan", &EarlierPlanRow::plan), F64("x_m", &EarlierPlanRow::x_m),
      F64("y_m", &EarlierPlanRow::y_m),
      F64("yaw_rad", &EarlierPlanRow::yaw_rad),
      I32("reverse", &EarlierPlanRow::reverse)};
  return *columns;
}

inline const std::vector<Column<IndexedName>>& IndexedNameColumns() {
  static const auto* columns = new std::vector<Column<IndexedName>>{
      I32("index", &IndexedName::index),
      Str("name", kNameBytes, &IndexedName::name)};
  return *columns;
}

inline const std::vector<Column<CallbackInfoRow>>& CallbackInfoColumns() {
  static const auto* columns = new std::vector<Column<CallbackInfoRow>>{
      I32("index", &CallbackInfoRow::index),
      Str("name", kNameBytes, &CallbackInfoRow::name),
      I32("node", &CallbackInfoRow::node),
      Str("kind", kKindBytes, &CallbackInfoRow::kind),
      I32("topic", &CallbackInfoRow::topic),
      F64("period_s", &CallbackInfoRow::period_s)};
  return *columns;
}

inline const std::vector<Column<stack::CallbackRecord>>& CallbackColumns() {
  using stack::CallbackRecord;
  static const auto* columns = new std::vector<Column<CallbackRecord>>{
      I32("callback", &CallbackRecord::callback),
      I32("node", &CallbackRecord::node),
      F64("ready_s", &CallbackRecord::ready_s),
      F64("start_s", &CallbackRecord::start_s),
      F64("end_s", &CallbackRecord::end_s),
      F64("cost_s", &CallbackRecord::cost_s),
      F64("host_cpu_s", &CallbackRecord::host_cpu_s),
      F64("work_units", &CallbackRecord::work_units),
      I32("cores", &CallbackRecord::cores),
      I32("first_core", &CallbackRecord::first_core)};
  return *columns;
}

inline const std::vector<Column<stack::TopicEvent>>& TopicEventColumns() {
  using stack::TopicEvent;
  static const auto* columns = new std::vector<Column<TopicEvent>>{
      TopicKindColumn(),
      I32("topic", &TopicEvent::topic),
      I32("callback", &TopicEvent::callback),
      F64("t_s", &TopicEvent::t_s),
      U64("seq", &TopicEvent::seq),
      F64("stamp_s", &TopicEvent::stamp_s)};
  return *columns;
}

inline const std::vector<Column<OverrunRow>>& OverrunColumns() {
  static const auto* columns = new std::vector<Column<OverrunRow>>{
      I32("callback", &OverrunRow::callback), I64("count", &OverrunRow::count)};
  return *columns;
}

inline const std::vector<Column<ControlSample>>& ControlColumns() {
  static const auto* columns = new std::vector<Column<ControlSample>>{
      F64("t_s", &ControlSample::t_s), F64("stamp_s", &ControlSample::stamp_s),
      F64("accel_mps2", &ControlSample::accel_mps2),
      F64("steer_rad", &ControlSample::steer_rad),
      Optional(F64("perception_stamp_s", &ControlSample::perception_stamp_s))};
  return *columns;
}

// The planner's stop reason as an HDF5 enum whose codes are the
// vocabulary's (stack/algorithms/stop_reason.h), so readers see names.
// A one-byte enum column whose codes and names come from the enum's own
// vocabulary, so that h5py shows the names.
template <typename Row, typename E>
Column<Row> Enum8(const char* name, E Row::*member,
                  std::vector<std::pair<std::string, int8_t>> codes) {
  return {FieldDesc{name, FieldType::kEnum8, 0, std::move(codes)},
          [member](const Row& row, char* out) {
            const int8_t code = static_cast<int8_t>(row.*member);
            std::memcpy(out, &code, 1);
          },
          [member](const char* in, Row* row) {
            int8_t code = 0;
            std::memcpy(&code, in, 1);
            row->*member = static_cast<E>(code);
          }};
}

inline Column<StopSample> StopReasonColumn() {
  std::vector<std::pair<std::string, int8_t>> codes;
  for (const std::string& name : StopReasonNames()) {
    StopReason reason = StopReason::kNone;
    StringToStopReason(name, &reason);
    codes.emplace_back(name, static_cast<int8_t>(reason));
  }
  return Enum8("reason", &StopSample::reason, std::move(codes));
}

// Every signal state, from its lowest code to its highest.
constexpr SignalState kSignalStates[] = {
    SignalState::kUnknown, SignalState::kRed, SignalState::kYellow,
    SignalState::kGreen};

inline const std::vector<Column<SignalSample>>& SignalColumns() {
  static const auto* columns = [] {
    std::vector<std::pair<std::string, int8_t>> codes;
    for (SignalState state : kSignalStates) {
      codes.emplace_back(SignalStateToString(state),
                         static_cast<int8_t>(state));
    }
    return new std::vector<Column<SignalSample>>{
        F64("t_s", &SignalSample::t_s), F64("stamp_s", &SignalSample::stamp_s),
        Enum8("state", &SignalSample::state, std::move(codes)),
        F64("stop_line_distance_m", &SignalSample::stop_line_distance_m),
        Str("tls_id", kNameBytes, &SignalSample::tls_id)};
  }();
  return *columns;
}

inline const std::vector<Column<StopSample>>& StopReasonColumns() {
  static const auto* columns = new std::vector<Column<StopSample>>{
      F64("t_s", &StopSample::t_s),
      F64("stamp_s", &StopSample::stamp_s),
      StopReasonColumn(),
      F64("stop_distance_m", &StopSample::stop_distance_m),
      I32("track_id", &StopSample::track_id),
      F64("obstacle_gap_m", &StopSample::obstacle_gap_m),
      I32("static_structure", &StopSample::static_structure)};
  return *columns;
}

inline const std::vector<Column<ObjectSample>>& ObjectColumns() {
  static const auto* columns = new std::vector<Column<ObjectSample>>{
      F64("t_s", &ObjectSample::t_s),
      F64("stamp_s", &ObjectSample::stamp_s),
      I32("track_id", &ObjectSample::track_id),
      F64("x_m", &ObjectSample::x_m),
      F64("y_m", &ObjectSample::y_m),
      F64("vx_mps", &ObjectSample::vx_mps),
      F64("vy_mps", &ObjectSample::vy_mps),
      F64("length_m", &ObjectSample::length_m),
      F64("width_m", &ObjectSample::width_m),
      F64("yaw_rad", &ObjectSample::yaw_rad),
      I32("age", &ObjectSample::age)};
  return *columns;
}

template <typename Row>
std::vector<FieldDesc> Descs(const std::vector<Column<Row>>& columns) {
  std::vector<FieldDesc> descs;
  descs.reserve(columns.size());
  for (const auto& column : columns) descs.push_back(column.desc);
  return descs;
}

// Packs all rows into one buffer and writes it with a single H5Dwrite.
template <typename Row>
Status WriteTable(hid_t parent, const std::string& name,
                  const std::vector<Row>& rows,
                  const std::vector<Column<Row>>& columns) {
  const std::vector<FieldDesc> descs = Descs(columns);
  const size_t row_size = internal::RowSize(descs);
  std::vector<size_t> offsets;
  size_t offset = 0;
  for (const auto& desc : descs) {
    offsets.push_back(offset);
    offset += internal::FieldSize(desc);
  }
  std::vector<char> buffer(rows.size() * row_size, '\0');
  // An empty buffer's data() may be null, and null + offset is undefined.
  for (size_t c = 0; c < columns.size() && !rows.empty(); ++c) {
    const auto& pack = columns[c].pack;
    char* out = buffer.data() + offsets[c];
    for (const Row& row : rows) {
      pack(row, out);
      out += row_size;
    }
  }
  return internal::WriteRows(parent, name, descs, rows.size(), buffer.data());
}

template <typename Row>
Result<std::vector<Row>> ReadTable(hid_t parent, const std::string& name,
                                   const std::vector<Column<Row>>& columns) {
  const std::vector<FieldDesc> descs = Descs(columns);
  Result<internal::PackedRows> packed = internal::ReadRows(parent, name, descs);
  if (!packed.ok()) return packed.status();
  const size_t row_size = internal::RowSize(packed->fields);
  std::vector<Row> rows(packed->rows);
  // An empty table's bytes may have a null data(), and null + offset is
  // undefined (found by fuzz_run_file on a run without collisions).
  if (rows.empty()) return rows;
  size_t offset = 0, read = 0;
  for (const auto& column : columns) {
    // An optional column the file lacks keeps the rows' default.
    if (read == packed->fields.size() ||
        packed->fields[read].name != column.desc.name) {
      continue;
    }
    ++read;
    const char* in = packed->bytes.data() + offset;
    for (Row& row : rows) {
      column.unpack(in, &row);
      in += row_size;
    }
    offset += internal::FieldSize(column.desc);
  }
  return rows;
}

// A table added after files of the same schema version were written
// (results-schema/README.md, "Versioning"): older files lack it and read as
// no rows.
template <typename Row>
Status ReadOptionalTable(hid_t file, const std::string& group_path,
                         const std::string& name,
                         const std::vector<Column<Row>>& columns,
                         std::vector<Row>* out) {
  if (internal::GetObjectKind(file, group_path + "/" + name) ==
      internal::ObjectKind::kMissing) {
    return Status::Ok();
  }
  Result<Handle> group = OpenGroup(file, group_path);
  if (!group.ok()) return group.status();
  return Assign(ReadTable(group->get(), name, columns), out);
}

}  // namespace adse::runfile::internal

#endif  // ADSE_ANALYSIS_RUNFILE_RUN_FILE_TABLES_H_
