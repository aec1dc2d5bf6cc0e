#include "analysis/runfile/run_file.h"

#include <cstring>
#include <exception>
#include <functional>
#include <iterator>
#include <new>

#include "analysis/runfile/hdf5_util_impl.h"
#include "stack/base/hash.h"

namespace adse::runfile {
namespace {

using internal::Assign;
using internal::CreateGroup;
using internal::FieldDesc;
using internal::FieldType;
using internal::Handle;
using internal::OpenGroup;

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
void PackString(const std::string& value, size_t width, char* out) {
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

Column<stack::TopicEvent> TopicKindColumn() {
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

const std::vector<Column<EgoSample>>& EgoColumns() {
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

const std::vector<Column<PathPoint>>& PathColumns() {
  static const auto* columns = new std::vector<Column<PathPoint>>{
      F64("s_m", &PathPoint::s_m), F64("x_m", &PathPoint::x_m),
      F64("y_m", &PathPoint::y_m)};
  return *columns;
}

const std::vector<Column<LanePoint>>& LaneColumns() {
  static const auto* columns = new std::vector<Column<LanePoint>>{
      I32("lane", &LanePoint::lane), F64("x_m", &LanePoint::x_m),
      F64("y_m", &LanePoint::y_m)};
  return *columns;
}

const std::vector<Column<VehicleSample>>& VehicleColumns() {
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

const std::vector<Column<CollisionEvent>>& CollisionColumns() {
  static const auto* columns = new std::vector<Column<CollisionEvent>>{
      F64("t_s", &CollisionEvent::t_s),
      Str("other_id", kIdBytes, &CollisionEvent::other_id),
      Optional(I32("ego_caused", &CollisionEvent::ego_caused))};
  return *columns;
}

const std::vector<Column<ParkingSlotRow>>& ParkingSlotColumns() {
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

const std::vector<Column<OutlinePoint>>& OutlineColumns() {
  static const auto* columns = new std::vector<Column<OutlinePoint>>{
      I32("obstacle", &OutlinePoint::obstacle), F64("x_m", &OutlinePoint::x_m),
      F64("y_m", &OutlinePoint::y_m)};
  return *columns;
}

const std::vector<Column<ParkingPathRow>>& ParkingPathColumns() {
  static const auto* columns = new std::vector<Column<ParkingPathRow>>{
      F64("x_m", &ParkingPathRow::x_m), F64("y_m", &ParkingPathRow::y_m),
      F64("yaw_rad", &ParkingPathRow::yaw_rad),
      I32("reverse", &ParkingPathRow::reverse)};
  return *columns;
}

const std::vector<Column<EarlierPlanRow>>& EarlierPlanColumns() {
  static const auto* columns = new std::vector<Column<EarlierPlanRow>>{
      I32("plan", &EarlierPlanRow::plan), F64("x_m", &EarlierPlanRow::x_m),
      F64("y_m", &EarlierPlanRow::y_m),
      F64("yaw_rad", &EarlierPlanRow::yaw_rad),
      I32("reverse", &EarlierPlanRow::reverse)};
  return *columns;
}

const std::vector<Column<IndexedName>>& IndexedNameColumns() {
  static const auto* columns = new std::vector<Column<IndexedName>>{
      I32("index", &IndexedName::index),
      Str("name", kNameBytes, &IndexedName::name)};
  return *columns;
}

const std::vector<Column<CallbackInfoRow>>& CallbackInfoColumns() {
  static const auto* columns = new std::vector<Column<CallbackInfoRow>>{
      I32("index", &CallbackInfoRow::index),
      Str("name", kNameBytes, &CallbackInfoRow::name),
      I32("node", &CallbackInfoRow::node),
      Str("kind", kKindBytes, &CallbackInfoRow::kind),
      I32("topic", &CallbackInfoRow::topic),
      F64("period_s", &CallbackInfoRow::period_s)};
  return *columns;
}

const std::vector<Column<stack::CallbackRecord>>& CallbackColumns() {
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

const std::vector<Column<stack::TopicEvent>>& TopicEventColumns() {
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

const std::vector<Column<OverrunRow>>& OverrunColumns() {
  static const auto* columns = new std::vector<Column<OverrunRow>>{
      I32("callback", &OverrunRow::callback), I64("count", &OverrunRow::count)};
  return *columns;
}

const std::vector<Column<ControlSample>>& ControlColumns() {
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

Column<StopSample> StopReasonColumn() {
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

const std::vector<Column<SignalSample>>& SignalColumns() {
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

const std::vector<Column<StopSample>>& StopReasonColumns() {
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

const std::vector<Column<ObjectSample>>& ObjectColumns() {
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

// ---------------------------------------------------------------------------
// Writing.

Status WriteContents(hid_t file, const RunData& run) {
  using internal::WriteF64Attr;
  using internal::WriteStringAttr;

  // Root attributes; `status` comes last so a file cut short never has it.
  ADSE_RETURN_IF_ERROR(
      internal::WriteI32Attr(file, "schema_version", kSchemaVersion));
  ADSE_RETURN_IF_ERROR(WriteStringAttr(file, "adse_version", run.adse_version));
  ADSE_RETURN_IF_ERROR(
      WriteStringAttr(file, "scenario_name", run.scenario_name));
  ADSE_RETURN_IF_ERROR(
      WriteStringAttr(file, "scenario_hash", run.scenario_hash));
  ADSE_RETURN_IF_ERROR(WriteStringAttr(file, "content_key", run.content_key));
  ADSE_RETURN_IF_ERROR(internal::WriteU64Attr(file, "seed", run.seed));
  ADSE_RETURN_IF_ERROR(
      WriteStringAttr(file, "termination_reason", run.termination_reason));
  ADSE_RETURN_IF_ERROR(WriteStringAttr(file, "host", run.host));
  ADSE_RETURN_IF_ERROR(WriteStringAttr(file, "created_utc", run.created_utc));
  ADSE_RETURN_IF_ERROR(WriteF64Attr(file, "lane_width_m", run.lane_width_m));
  if (!run.task_case.empty()) {
    ADSE_RETURN_IF_ERROR(WriteStringAttr(file, "task_case", run.task_case));
  }

  {
    Result<Handle> group = CreateGroup(file, "scenario");
    if (!group.ok()) return group.status();
    ADSE_RETURN_IF_ERROR(
        internal::WriteStringDataset(group->get(), "yaml", run.scenario_text));
  }
  {
    Result<Handle> group = CreateGroup(file, "design_point");
    if (!group.ok()) return group.status();
    for (const auto& [name, value] : run.design_point) {
      ADSE_RETURN_IF_ERROR(WriteF64Attr(group->get(), name, value));
    }
  }
  {
    Result<Handle> group = CreateGroup(file, "platform");
    if (!group.ok()) return group.status();
    for (const auto& [name, value] : run.platform) {
      ADSE_RETURN_IF_ERROR(WriteStringAttr(group->get(), name, value));
    }
  }
  {
    Result<Handle> group = CreateGroup(file, "ego");
    if (!group.ok()) return group.status();
    ADSE_RETURN_IF_ERROR(
        WriteTable(group->get(), "trajectory", run.ego, EgoColumns()));
  }
  {
    Result<Handle> group = CreateGroup(file, "world");
    if (!group.ok()) return group.status();
    ADSE_RETURN_IF_ERROR(
        WriteTable(group->get(), "ideal_path", run.ideal_path, PathColumns()));
    ADSE_RETURN_IF_ERROR(
        WriteTable(group->get(), "lanes", run.lanes, LaneColumns()));
    ADSE_RETURN_IF_ERROR(
        WriteTable(group->get(), "vehicles", run.vehicles, VehicleColumns()));
    ADSE_RETURN_IF_ERROR(WriteTable(group->get(), "collisions", run.collisions,
                                    CollisionColumns()));
  }
  {
    Result<Handle> group = CreateGroup(file, "trace");
    if (!group.ok()) return group.status();
    auto indexed = [](const std::vector<std::string>& names) {
      std::vector<IndexedName> rows(names.size());
      for (size_t i = 0; i < names.size(); ++i) {
        rows[i] = {static_cast<int32_t>(i), names[i]};
      }
      return rows;
    };
    ADSE_RETURN_IF_ERROR(WriteTable(
        group->get(), "nodes", indexed(run.node_names), IndexedNameColumns()));
    std::vector<CallbackInfoRow> info(run.callback_info.size());
    for (size_t i = 0; i < info.size(); ++i) {
      const NamedCallback& cb = run.callback_info[i];
      info[i] = {static_cast<int32_t>(i),
                 cb.name,
                 cb.node,
                 cb.kind,
                 cb.topic,
                 cb.period_s};
    }
    ADSE_RETURN_IF_ERROR(
        WriteTable(group->get(), "callback_info", info, CallbackInfoColumns()));
    ADSE_RETURN_IF_ERROR(WriteTable(group->get(), "topics",
                                    indexed(run.topic_names),
                                    IndexedNameColumns()));
    ADSE_RETURN_IF_ERROR(WriteTable(group->get(), "callbacks",
                                    run.trace.callbacks, CallbackColumns()));
    ADSE_RETURN_IF_ERROR(WriteTable(group->get(), "topic_events",
                                    run.trace.topic_events,
                                    TopicEventColumns()));
    std::vector<OverrunRow> overruns(run.trace.timer_overruns.size());
    for (size_t i = 0; i < overruns.size(); ++i) {
      overruns[i] = {static_cast<int32_t>(i), run.trace.timer_overruns[i]};
    }
    ADSE_RETURN_IF_ERROR(
        WriteTable(group->get(), "timer_overruns", overruns, OverrunColumns()));
  }
  {
    Result<Handle> group = CreateGroup(file, "control");
    if (!group.ok()) return group.status();
    ADSE_RETURN_IF_ERROR(
        WriteTable(group->get(), "commands", run.controls, ControlColumns()));
  }
  if (run.parking.present) {
    const ParkingRecord& p = run.parking;
    Result<Handle> group = CreateGroup(file, "parking");
    if (!group.ok()) return group.status();
    const hid_t g = group->get();
    ADSE_RETURN_IF_ERROR(WriteStringAttr(g, "slot", p.slot));
    for (const auto& [name, value] :
         {std::pair<const char*, double>{"goal_x_m", p.goal_x_m},
          {"goal_y_m", p.goal_y_m},
          {"goal_yaw_rad", p.goal_yaw_rad},
          {"tolerance_m", p.tolerance_m},
          {"yaw_tolerance_rad", p.yaw_tolerance_rad},
          {"wheelbase_m", p.wheelbase_m},
          {"length_m", p.length_m},
          {"width_m", p.width_m},
          {"planned_at_s", p.planned_at_s},
          {"first_planned_at_s", p.first_planned_at_s}}) {
      ADSE_RETURN_IF_ERROR(WriteF64Attr(g, name, value));
    }
    ADSE_RETURN_IF_ERROR(internal::WriteI32Attr(g, "path_found", p.path_found));
    ADSE_RETURN_IF_ERROR(internal::WriteI32Attr(g, "replans", p.replans));
    ADSE_RETURN_IF_ERROR(WriteTable(g, "slots", p.slots, ParkingSlotColumns()));
    ADSE_RETURN_IF_ERROR(
        WriteTable(g, "obstacles", p.obstacles, OutlineColumns()));
    ADSE_RETURN_IF_ERROR(
        WriteTable(g, "planned_path", p.planned_path, ParkingPathColumns()));
    ADSE_RETURN_IF_ERROR(
        WriteTable(g, "earlier_plans", p.earlier_plans, EarlierPlanColumns()));
  }
  {
    Result<Handle> group = CreateGroup(file, "planning");
    if (!group.ok()) return group.status();
    ADSE_RETURN_IF_ERROR(WriteTable(group->get(), "stop_reasons",
                                    run.stop_reasons, StopReasonColumns()));
  }
  {
    Result<Handle> group = CreateGroup(file, "perception");
    if (!group.ok()) return group.status();
    ADSE_RETURN_IF_ERROR(WriteTable(group->get(), "traffic_signals",
                                    run.signals, SignalColumns()));
    ADSE_RETURN_IF_ERROR(
        WriteTable(group->get(), "objects", run.objects, ObjectColumns()));
  }
  {
    Result<Handle> group = CreateGroup(file, "metrics");
    if (!group.ok()) return group.status();
    for (const auto& [name, value] : run.metrics) {
      ADSE_RETURN_IF_ERROR(WriteF64Attr(group->get(), name, value));
    }
  }
  return WriteStringAttr(file, "status", run.status);
}

Status Validate(const RunData& run) {
  if (run.status != kRunComplete && !EndedEarly(run.status) &&
      run.status != kRunFailed) {
    return Status::InvalidArgument(
        "run status must be complete, infeasible, stalled or failed, got '" +
        run.status + "'");
  }
  // The hash doubles as the checksum of /scenario/yaml (stored without one).
  if (!run.scenario_hash.empty() &&
      run.scenario_hash != Sha256Hex(run.scenario_text)) {
    return Status::InvalidArgument(
        "scenario_hash is not the sha256 of scenario_text");
  }
  for (size_t i = 0; i < run.stop_reasons.size(); ++i) {
    StopReason named = StopReason::kNone;
    const StopReason reason = run.stop_reasons[i].reason;
    if (!StringToStopReason(StopReasonToString(reason), &named) ||
        named != reason) {
      return Status::InvalidArgument(
          "stop reason " + std::to_string(i) + " has unknown code " +
          std::to_string(static_cast<int>(run.stop_reasons[i].reason)));
    }
  }
  for (size_t i = 0; i < run.signals.size(); ++i) {
    const int code = static_cast<int>(run.signals[i].state);
    if (code < static_cast<int>(kSignalStates[0]) ||
        code > static_cast<int>(std::end(kSignalStates)[-1])) {
      return Status::InvalidArgument(
          "traffic signal report " + std::to_string(i) +
          " has unknown state code " + std::to_string(code));
    }
  }
  const auto& events = run.trace.topic_events;
  for (size_t i = 0; i < events.size(); ++i) {
    const int kind = events[i].kind;
    if (kind < stack::TopicEvent::kPublish || kind > stack::TopicEvent::kDrop) {
      return Status::InvalidArgument("topic event " + std::to_string(i) +
                                     " has unknown kind " +
                                     std::to_string(kind));
    }
  }
  return Status::Ok();
}

Status WriteRunFileImpl(const std::string& path, const RunData& run, Env* env) {
  ADSE_RETURN_IF_ERROR(Validate(run));
  return internal::WriteFileAtomically(
      path, [&run](hid_t file) { return WriteContents(file, run); }, env);
}

// ---------------------------------------------------------------------------
// Reading. Every failure is a Corruption whose message names the HDF5 object;
// the caller prefixes the file name.

// Places index-table rows by their index, which must cover 0..n-1 once.
Status ByIndex(const std::string& what, std::vector<IndexedName> rows,
               std::vector<std::string>* out) {
  out->assign(rows.size(), std::string());
  std::vector<bool> seen(rows.size(), false);
  for (IndexedName& row : rows) {
    if (row.index < 0 || static_cast<size_t>(row.index) >= rows.size() ||
        seen[row.index]) {
      return Status::Corruption(what + ": bad or repeated index " +
                                std::to_string(row.index));
    }
    seen[row.index] = true;
    (*out)[row.index] = std::move(row.name);
  }
  return Status::Ok();
}

Status ReadContents(hid_t file, RunData* run) {
  using internal::ReadStringAttr;
  Result<int64_t> version = internal::ReadI64Attr(file, "schema_version");
  if (!version.ok()) return version.status();
  if (*version != kSchemaVersion) {
    return Status::Corruption("/: schema_version " + std::to_string(*version) +
                              " is not the supported " +
                              std::to_string(kSchemaVersion));
  }
  ADSE_RETURN_IF_ERROR(Assign(ReadStringAttr(file, "status"), &run->status));
  ADSE_RETURN_IF_ERROR(Assign(ReadStringAttr(file, "termination_reason"),
                              &run->termination_reason));
  ADSE_RETURN_IF_ERROR(
      Assign(ReadStringAttr(file, "adse_version"), &run->adse_version));
  ADSE_RETURN_IF_ERROR(
      Assign(ReadStringAttr(file, "scenario_name"), &run->scenario_name));
  ADSE_RETURN_IF_ERROR(
      Assign(ReadStringAttr(file, "scenario_hash"), &run->scenario_hash));
  ADSE_RETURN_IF_ERROR(
      Assign(ReadStringAttr(file, "content_key"), &run->content_key));
  ADSE_RETURN_IF_ERROR(Assign(ReadStringAttr(file, "host"), &run->host));
  ADSE_RETURN_IF_ERROR(
      Assign(ReadStringAttr(file, "created_utc"), &run->created_utc));
  ADSE_RETURN_IF_ERROR(Assign(internal::ReadU64Attr(file, "seed"), &run->seed));
  ADSE_RETURN_IF_ERROR(
      Assign(internal::ReadF64Attr(file, "lane_width_m"), &run->lane_width_m));
  {
    Result<bool> has_case = internal::HasAttr(file, "task_case");
    if (!has_case.ok()) return has_case.status();
    if (*has_case) {
      ADSE_RETURN_IF_ERROR(
          Assign(ReadStringAttr(file, "task_case"), &run->task_case));
    }
  }

  {
    Result<Handle> group = OpenGroup(file, "/scenario");
    if (!group.ok()) return group.status();
    ADSE_RETURN_IF_ERROR(
        Assign(internal::ReadStringDataset(group->get(), "yaml"),
               &run->scenario_text));
  }
  if (!run->scenario_hash.empty() &&
      run->scenario_hash != Sha256Hex(run->scenario_text)) {
    return Status::Corruption(
        "/scenario/yaml: text does not match scenario_hash (damaged)");
  }
  // Groups holding one attribute per entry.
  auto read_numbers = [file](const std::string& path,
                             std::map<std::string, double>* out) -> Status {
    Result<Handle> group = OpenGroup(file, path);
    if (!group.ok()) return group.status();
    Result<std::vector<std::string>> names =
        internal::ListAttributes(group->get());
    if (!names.ok()) return names.status();
    out->clear();
    for (const std::string& name : *names) {
      Result<double> value = internal::ReadF64Attr(group->get(), name);
      if (!value.ok()) return value.status();
      (*out)[name] = *value;
    }
    return Status::Ok();
  };
  ADSE_RETURN_IF_ERROR(read_numbers("/design_point", &run->design_point));
  ADSE_RETURN_IF_ERROR(read_numbers("/metrics", &run->metrics));
  {
    Result<Handle> group = OpenGroup(file, "/platform");
    if (!group.ok()) return group.status();
    Result<std::vector<std::string>> names =
        internal::ListAttributes(group->get());
    if (!names.ok()) return names.status();
    run->platform.clear();
    for (const std::string& name : *names) {
      Result<std::string> value = ReadStringAttr(group->get(), name);
      if (!value.ok()) return value.status();
      run->platform[name] = *value;
    }
  }
  {
    Result<Handle> group = OpenGroup(file, "/ego");
    if (!group.ok()) return group.status();
    ADSE_RETURN_IF_ERROR(
        Assign(ReadTable(group->get(), "trajectory", EgoColumns()), &run->ego));
  }
  {
    Result<Handle> group = OpenGroup(file, "/world");
    if (!group.ok()) return group.status();
    ADSE_RETURN_IF_ERROR(
        Assign(ReadTable(group->get(), "ideal_path", PathColumns()),
               &run->ideal_path));
    ADSE_RETURN_IF_ERROR(
        ReadOptionalTable(file, "/world", "lanes", LaneColumns(), &run->lanes));
    ADSE_RETURN_IF_ERROR(Assign(
        ReadTable(group->get(), "vehicles", VehicleColumns()), &run->vehicles));
    ADSE_RETURN_IF_ERROR(
        Assign(ReadTable(group->get(), "collisions", CollisionColumns()),
               &run->collisions));
  }
  // Only valet_parking runs have /parking.
  if (internal::GetObjectKind(file, "/parking") !=
      internal::ObjectKind::kMissing) {
    Result<Handle> group = OpenGroup(file, "/parking");
    if (!group.ok()) return group.status();
    const hid_t g = group->get();
    ParkingRecord& p = run->parking;
    p.present = true;
    ADSE_RETURN_IF_ERROR(Assign(ReadStringAttr(g, "slot"), &p.slot));
    for (const auto& [name, out] :
         {std::pair<const char*, double*>{"goal_x_m", &p.goal_x_m},
          {"goal_y_m", &p.goal_y_m},
          {"goal_yaw_rad", &p.goal_yaw_rad},
          {"tolerance_m", &p.tolerance_m},
          {"yaw_tolerance_rad", &p.yaw_tolerance_rad},
          {"wheelbase_m", &p.wheelbase_m},
          {"length_m", &p.length_m},
          {"width_m", &p.width_m},
          {"planned_at_s", &p.planned_at_s}}) {
      ADSE_RETURN_IF_ERROR(Assign(internal::ReadF64Attr(g, name), out));
    }
    Result<int64_t> found = internal::ReadI64Attr(g, "path_found");
    if (!found.ok()) return found.status();
    p.path_found = static_cast<int32_t>(*found);
    Result<bool> replanning = internal::HasAttr(g, "replans");
    if (!replanning.ok()) return replanning.status();
    p.first_planned_at_s = p.planned_at_s;
    if (*replanning) {
      ADSE_RETURN_IF_ERROR(
          Assign(internal::ReadF64Attr(g, "first_planned_at_s"),
                 &p.first_planned_at_s));
      Result<int64_t> replans = internal::ReadI64Attr(g, "replans");
      if (!replans.ok()) return replans.status();
      p.replans = static_cast<int32_t>(*replans);
    }
    ADSE_RETURN_IF_ERROR(
        Assign(ReadTable(g, "slots", ParkingSlotColumns()), &p.slots));
    ADSE_RETURN_IF_ERROR(
        Assign(ReadTable(g, "obstacles", OutlineColumns()), &p.obstacles));
    ADSE_RETURN_IF_ERROR(Assign(
        ReadTable(g, "planned_path", ParkingPathColumns()), &p.planned_path));
    ADSE_RETURN_IF_ERROR(ReadOptionalTable(file, "/parking", "earlier_plans",
                                           EarlierPlanColumns(),
                                           &p.earlier_plans));
  }
  {
    Result<Handle> group = OpenGroup(file, "/trace");
    if (!group.ok()) return group.status();
    Result<std::vector<IndexedName>> nodes =
        ReadTable(group->get(), "nodes", IndexedNameColumns());
    if (!nodes.ok()) return nodes.status();
    ADSE_RETURN_IF_ERROR(
        ByIndex("/trace/nodes", std::move(nodes).value(), &run->node_names));
    Result<std::vector<IndexedName>> topics =
        ReadTable(group->get(), "topics", IndexedNameColumns());
    if (!topics.ok()) return topics.status();
    ADSE_RETURN_IF_ERROR(
        ByIndex("/trace/topics", std::move(topics).value(), &run->topic_names));

    Result<std::vector<CallbackInfoRow>> info =
        ReadTable(group->get(), "callback_info", CallbackInfoColumns());
    if (!info.ok()) return info.status();
    run->callback_info.assign(info->size(), NamedCallback{});
    std::vector<bool> seen(info->size(), false);
    for (CallbackInfoRow& row : *info) {
      if (row.index < 0 || static_cast<size_t>(row.index) >= info->size() ||
          seen[row.index]) {
        return Status::Corruption(
            "/trace/callback_info: bad or repeated index " +
            std::to_string(row.index));
      }
      seen[row.index] = true;
      run->callback_info[row.index] = {std::move(row.name), row.node,
                                       std::move(row.kind), row.topic,
                                       row.period_s};
    }

    ADSE_RETURN_IF_ERROR(
        Assign(ReadTable(group->get(), "callbacks", CallbackColumns()),
               &run->trace.callbacks));
    ADSE_RETURN_IF_ERROR(
        Assign(ReadTable(group->get(), "topic_events", TopicEventColumns()),
               &run->trace.topic_events));

    Result<std::vector<OverrunRow>> overruns =
        ReadTable(group->get(), "timer_overruns", OverrunColumns());
    if (!overruns.ok()) return overruns.status();
    run->trace.timer_overruns.assign(overruns->size(), 0);
    for (const OverrunRow& row : *overruns) {
      if (row.callback < 0 ||
          static_cast<size_t>(row.callback) >= overruns->size()) {
        return Status::Corruption("/trace/timer_overruns: bad callback " +
                                  std::to_string(row.callback));
      }
      run->trace.timer_overruns[row.callback] = row.count;
    }
  }
  {
    Result<Handle> group = OpenGroup(file, "/control");
    if (!group.ok()) return group.status();
    ADSE_RETURN_IF_ERROR(Assign(
        ReadTable(group->get(), "commands", ControlColumns()), &run->controls));
  }
  ADSE_RETURN_IF_ERROR(ReadOptionalTable(file, "/planning", "stop_reasons",
                                         StopReasonColumns(),
                                         &run->stop_reasons));
  ADSE_RETURN_IF_ERROR(ReadOptionalTable(file, "/perception", "traffic_signals",
                                         SignalColumns(), &run->signals));
  return ReadOptionalTable(file, "/perception", "objects", ObjectColumns(),
                           &run->objects);
}

Result<RunData> ReadRunFileImpl(const std::string& path) {
  RunData run;
  ADSE_RETURN_IF_ERROR(internal::ReadFileContents(
      path, "a run file",
      [&run](hid_t file) { return ReadContents(file, &run); }));
  return run;
}

}  // namespace

Status WriteRunFile(const std::string& path, const RunData& run, Env* env) {
  try {
    return WriteRunFileImpl(path, run, env);
  } catch (const std::bad_alloc&) {
    return Status::Internal(path + ": out of memory writing the run file");
  } catch (const std::exception& e) {
    return Status::Internal(path + ": writing the run file: " + e.what());
  }
}

Result<RunData> ReadRunFile(const std::string& path) {
  try {
    return ReadRunFileImpl(path);
  } catch (const std::bad_alloc&) {
    // A damaged header can claim absurd sizes.
    return Status::Corruption(path +
                              ": out of memory reading (sizes in the "
                              "file are implausible?)");
  } catch (const std::exception& e) {
    return Status::Corruption(path + ": reading the run file: " + e.what());
  }
}

}  // namespace adse::runfile
