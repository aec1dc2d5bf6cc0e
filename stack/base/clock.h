// Wall-clock time as records write it, and steady-clock durations.
#ifndef ADSE_STACK_BASE_CLOCK_H_
#define ADSE_STACK_BASE_CLOCK_H_

#include <chrono>
#include <string>

namespace adse {

// The current UTC time as ISO 8601, e.g. "2026-11-21T06:51:37Z".
std::string UtcTimestamp();

// `s` seconds as a steady-clock duration, clamped to [0, one year] so that
// huge limits (a timeout of 1e300 s) cannot overflow the clock.
std::chrono::steady_clock::duration SteadyFromSeconds(double s);

// A steady-clock duration in seconds.
double SteadySeconds(std::chrono::steady_clock::duration d);

}  // namespace adse

#endif  // ADSE_STACK_BASE_CLOCK_H_
