// The vehicle-side safety gate. It runs on the vehicle's own safety
// controller, not on the computer being sized: it passes the stack's
// commands through while they are fresh and brakes to a stop when they go
// stale or the stack reports localization lost. Plain std types.
#ifndef ADSE_STACK_ALGORITHMS_COMMAND_GATE_H_
#define ADSE_STACK_ALGORITHMS_COMMAND_GATE_H_

namespace adse::algorithms {

struct CommandGateParams {
  double stale_after_s = 0.5;         // command age that triggers braking
  double emergency_decel_mps2 = 3.0;  // braking then (positive number)
};

enum class GateReason {
  kNone = 0,          // passing the last command through
  kNoCommand,         // nothing received yet
  kStale,             // last command older than stale_after_s
  kLocalizationLost,  // the stack says it does not know where it is
};
const char* GateReasonName(GateReason reason);

struct GateOutput {
  double accel_mps2 = 0.0;
  double steer_rad = 0.0;  // held at the last command while braking
  bool reverse = false;    // gear of the last command, held while braking
  bool braking = false;    // true: emergency braking instead of the command
  GateReason reason = GateReason::kNone;
  double command_age_s = 0.0;  // now - time of the last command (-1: none)
};

class CommandGate {
 public:
  explicit CommandGate(const CommandGateParams& params = {})
      : params_(params) {}

  // A command as it arrives at time t_s; `reverse` is its gear.
  void OnCommand(double t_s, double accel_mps2, double steer_rad,
                 bool reverse = false);
  // The stack's localization status as it arrives (lost = !valid).
  void OnLocalization(double t_s, bool valid);
  // What to apply at time t_s.
  GateOutput Output(double t_s) const;

  const CommandGateParams& params() const { return params_; }

 private:
  CommandGateParams params_;
  bool has_command_ = false;
  double command_t_s_ = 0.0;
  double accel_mps2_ = 0.0;
  double steer_rad_ = 0.0;
  bool reverse_ = false;
  bool localization_lost_ = false;
  double localization_t_s_ = -1e300;
};

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_COMMAND_GATE_H_
