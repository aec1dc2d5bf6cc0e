// What a traffic signal shows for one link, as the car's detector reports
// it (/perception/traffic_signal): the vocabulary the world's detector and
// the planner share. Header-only, like a message field's type.
#ifndef ADSE_STACK_ALGORITHMS_SIGNAL_STATE_H_
#define ADSE_STACK_ALGORITHMS_SIGNAL_STATE_H_

#include <cstdint>

namespace adse {

enum class SignalState : int8_t {
  kUnknown = 0,  // "unknown": seen but not readable (off, blinking, a
                 // stop-then-go arrow), or too old to trust
  kRed = 1,      // "red" (also red-yellow: not yet green)
  kYellow = 2,   // "yellow"
  kGreen = 3,    // "green", with or without priority
};

inline const char* SignalStateToString(SignalState state) {
  switch (state) {
    case SignalState::kRed:
      return "red";
    case SignalState::kYellow:
      return "yellow";
    case SignalState::kGreen:
      return "green";
    case SignalState::kUnknown:
      break;
  }
  return "unknown";
}

}  // namespace adse

#endif  // ADSE_STACK_ALGORITHMS_SIGNAL_STATE_H_
