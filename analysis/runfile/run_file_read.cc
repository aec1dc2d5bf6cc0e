// Reading run files (ReadRunFile of run_file.h); writing is in run_file.cc.
#include <exception>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "analysis/runfile/run_file.h"
#include "analysis/runfile/run_file_tables.h"
#include "stack/base/hash.h"
#include "stack/base/vocabulary.h"

namespace adse::runfile {
namespace internal {
namespace {

// Every failure is a Corruption whose message names the HDF5 object; the
// caller prefixes the file name.

// An attribute files written without it lack: `out` stays empty then.
Status ReadOptionalStringAttr(hid_t loc, const std::string& name,
                              std::string* out) {
  Result<bool> has = HasAttr(loc, name);
  if (!has.ok()) return has.status();
  return *has ? Assign(ReadStringAttr(loc, name), out) : Status::Ok();
}

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
  ADSE_RETURN_IF_ERROR(
      ReadOptionalStringAttr(file, "task_case", &run->task_case));
  ADSE_RETURN_IF_ERROR(ReadOptionalStringAttr(file, "termination_detail",
                                              &run->termination_detail));

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
      CallbackKind kind = CallbackKind::kSubscription;
      if (!StringToCallbackKind(row.kind, &kind)) {
        return Status::Corruption(fmt::format(
            "/trace/callback_info: callback {} ({}) has {}", row.index,
            row.name,
            UnknownTermMessage("kind", row.kind, CallbackKindNames())));
      }
      run->callback_info[row.index] = {std::move(row.name), row.node, kind,
                                       row.topic, row.period_s};
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
}  // namespace internal

Result<RunData> ReadRunFile(const std::string& path) {
  try {
    return internal::ReadRunFileImpl(path);
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
