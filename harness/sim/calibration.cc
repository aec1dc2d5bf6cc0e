#include "harness/sim/calibration.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "stack/base/files.h"

namespace adse::sim {

Result<Calibration> FitCalibration(
    const std::vector<const runfile::RunData*>& runs) {
  struct Sums {
    double n = 0, x = 0, y = 0, xx = 0, xy = 0;
  };
  std::map<std::string, Sums> sums;
  for (const runfile::RunData* run : runs) {
    for (const stack::CallbackRecord& r : run->trace.callbacks) {
      if (r.callback < 0 ||
          r.callback >= static_cast<int>(run->callback_info.size()))
        continue;
      Sums& s = sums[run->callback_info[r.callback].name];
      s.n += 1;
      s.x += r.work_units;
      s.y += r.host_cpu_s;
      s.xx += r.work_units * r.work_units;
      s.xy += r.work_units * r.host_cpu_s;
    }
  }
  std::vector<std::string> idle;
  for (const runfile::RunData* run : runs) {
    for (const runfile::NamedCallback& callback : run->callback_info) {
      if (sums.count(callback.name) == 0 &&
          std::find(idle.begin(), idle.end(), callback.name) == idle.end()) {
        idle.push_back(callback.name);
      }
    }
  }
  if (!idle.empty()) {
    return Status::InvalidArgument(fmt::format(
        "expected every callback of the stack to run at least once, found "
        "{} that never ran in the {} calibration run(s): {}; calibrate on a "
        "point or case where they run (--point, --case)",
        idle.size(), runs.size(), fmt::join(idle, ", ")));
  }
  Calibration out;
  for (const auto& [name, s] : sums) {
    stack::CountedCost cost;
    const double mean_y = s.y / s.n;
    const double var_x = s.xx / s.n - (s.x / s.n) * (s.x / s.n);
    if (var_x > 1e-12) {
      cost.per_unit_s =
          std::max(0.0, (s.xy / s.n - (s.x / s.n) * mean_y) / var_x);
      cost.fixed_s = std::max(0.0, mean_y - cost.per_unit_s * s.x / s.n);
    } else {
      cost.fixed_s = mean_y;  // no variation in work: a constant cost
    }
    out[name] = cost;
  }
  return out;
}

Status WriteCalibration(const std::string& path, const Calibration& calibration,
                        const std::string& host) {
  nlohmann::json doc;
  doc["adse_calibration"] = 1;
  doc["host"] = host;
  doc["note"] =
      "Costs at the reference frequency: cost_s = fixed_s + per_unit_s * work "
      "units.";
  for (const auto& [name, cost] : calibration) {
    doc["callbacks"][name] = {{"fixed_s", cost.fixed_s},
                              {"per_unit_s", cost.per_unit_s}};
  }
  return WriteFileAtomic(path, doc.dump(2) + "\n");
}

Result<Calibration> LoadCalibration(const std::string& path) {
  if (path.empty()) {
    return Status::InvalidArgument(
        "cost_model counted needs a calibration file (make one with `adse "
        "calibrate`, "
        "or name the bundled scenarios/calibration/reference.json)");
  }
  Result<std::string> text = ReadFile(path, 16u << 20);
  if (!text.ok()) return text.status();
  nlohmann::json doc =
      nlohmann::json::parse(*text, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.is_object()) {
    return Status::InvalidArgument(path + ": not a JSON object");
  }
  if (!doc.contains("adse_calibration") || doc["adse_calibration"] != 1) {
    return Status::InvalidArgument(path + ": missing \"adse_calibration\": 1");
  }
  if (!doc.contains("callbacks") || !doc["callbacks"].is_object()) {
    return Status::InvalidArgument(path + ": missing the \"callbacks\" object");
  }
  // A callback (or one unit of its work) costing more than a minute is no
  // real stack's: a typo such as 1e308 would stall every run without a
  // word from the diagnosis.
  constexpr double kMaxCost_s = 60.0;
  Calibration out;
  for (const auto& [name, entry] : doc["callbacks"].items()) {
    stack::CountedCost cost;
    const auto fixed = entry.find("fixed_s");
    const auto per_unit = entry.find("per_unit_s");
    if (!entry.is_object() || fixed == entry.end() || per_unit == entry.end() ||
        !fixed->is_number() || !per_unit->is_number() ||
        !(fixed->get<double>() >= 0 && fixed->get<double>() <= kMaxCost_s) ||
        !(per_unit->get<double>() >= 0 &&
          per_unit->get<double>() <= kMaxCost_s)) {
      return Status::InvalidArgument(
          path + ": callbacks." + name +
          ": expected {fixed_s: seconds in [0, 60], per_unit_s: seconds in "
          "[0, 60]}");
    }
    cost.fixed_s = fixed->get<double>();
    cost.per_unit_s = per_unit->get<double>();
    out[name] = cost;
  }
  return out;
}

}  // namespace adse::sim
