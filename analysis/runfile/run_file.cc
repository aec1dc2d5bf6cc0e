// Writing run files (atomically, through the Env seam); reading is in
// run_file_read.cc, the tables' layouts in run_file_tables.h.
#include "analysis/runfile/run_file.h"

#include <cstring>
#include <exception>
#include <functional>
#include <new>

#include "analysis/runfile/run_file_tables.h"
#include "stack/base/hash.h"
#include "stack/base/vocabulary.h"

namespace adse::runfile {
namespace internal {
namespace {

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
  if (!run.termination_detail.empty()) {
    ADSE_RETURN_IF_ERROR(
        WriteStringAttr(file, "termination_detail", run.termination_detail));
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
      info[i] = {static_cast<int32_t>(i),       cb.name,  cb.node,
                 CallbackKindToString(cb.kind), cb.topic, cb.period_s};
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
  for (size_t i = 0; i < run.callback_info.size(); ++i) {
    CallbackKind named = CallbackKind::kSubscription;
    const CallbackKind kind = run.callback_info[i].kind;
    if (!StringToCallbackKind(CallbackKindToString(kind), &named) ||
        named != kind) {
      return Status::InvalidArgument("callback " + std::to_string(i) +
                                     " has unknown kind code " +
                                     std::to_string(static_cast<int>(kind)));
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

}  // namespace
}  // namespace internal

namespace {
const std::vector<Term<CallbackKind>>& CallbackKindTerms() {
  static const std::vector<Term<CallbackKind>> kTerms = {
      {CallbackKind::kSubscription, "subscription"},
      {CallbackKind::kTimer, "timer"},
  };
  return kTerms;
}
}  // namespace

const char* CallbackKindToString(CallbackKind kind) {
  return NameOf(CallbackKindTerms(), kind);
}
bool StringToCallbackKind(std::string_view name, CallbackKind* kind) {
  return ValueOf(CallbackKindTerms(), name, kind);
}
std::vector<std::string> CallbackKindNames() {
  return NamesOf(CallbackKindTerms());
}

Status WriteRunFile(const std::string& path, const RunData& run, Env* env) {
  try {
    return internal::WriteRunFileImpl(path, run, env);
  } catch (const std::bad_alloc&) {
    return Status::Internal(path + ": out of memory writing the run file");
  } catch (const std::exception& e) {
    return Status::Internal(path + ": writing the run file: " + e.what());
  }
}

}  // namespace adse::runfile
