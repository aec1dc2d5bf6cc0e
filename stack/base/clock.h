// Wall-clock time as records write it.
#ifndef ADSE_STACK_BASE_CLOCK_H_
#define ADSE_STACK_BASE_CLOCK_H_

#include <string>

namespace adse {

// The current UTC time as ISO 8601, e.g. "2026-11-21T06:51:37Z".
std::string UtcTimestamp();

}  // namespace adse

#endif  // ADSE_STACK_BASE_CLOCK_H_
