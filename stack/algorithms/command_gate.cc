#include "stack/algorithms/command_gate.h"

#include <algorithm>

namespace adse::algorithms {

const char* GateReasonName(GateReason reason) {
  switch (reason) {
    case GateReason::kNone:
      return "none";
    case GateReason::kNoCommand:
      return "no_command";
    case GateReason::kStale:
      return "stale";
    case GateReason::kLocalizationLost:
      return "localization_lost";
  }
  return "unknown";
}

void CommandGate::OnCommand(double t_s, double accel_mps2, double steer_rad,
                            bool reverse) {
  // A late-arriving older command must not replace a newer one.
  if (has_command_ && t_s < command_t_s_) return;
  has_command_ = true;
  command_t_s_ = t_s;
  accel_mps2_ = accel_mps2;
  steer_rad_ = steer_rad;
  reverse_ = reverse;
}

void CommandGate::OnLocalization(double t_s, bool valid) {
  if (t_s < localization_t_s_) return;
  localization_t_s_ = t_s;
  localization_lost_ = !valid;
}

GateOutput CommandGate::Output(double t_s) const {
  GateOutput out;
  out.command_age_s = has_command_ ? std::max(0.0, t_s - command_t_s_) : -1.0;
  out.steer_rad = has_command_ ? steer_rad_ : 0.0;
  out.reverse = has_command_ && reverse_;
  if (!has_command_) {
    out.reason = GateReason::kNoCommand;
  } else if (out.command_age_s > params_.stale_after_s) {
    out.reason = GateReason::kStale;
  } else if (localization_lost_) {
    out.reason = GateReason::kLocalizationLost;
  } else {
    out.accel_mps2 = accel_mps2_;
    return out;
  }
  out.braking = true;
  out.accel_mps2 = -params_.emergency_decel_mps2;
  return out;
}

}  // namespace adse::algorithms
