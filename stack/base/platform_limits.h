// Limits of a simulated computer, shared by the scenario parser (which
// refuses a file past them) and the executors (which refuse options past
// them), so the two can never disagree.
#ifndef ADSE_STACK_BASE_PLATFORM_LIMITS_H_
#define ADSE_STACK_BASE_PLATFORM_LIMITS_H_

namespace adse {

// Cores of one design point; far above any real single computer, low
// enough that a typo cannot ask for an absurd allocation.
inline constexpr int kMaxPlatformCores = 1024;
// Clock frequency of one design point, GHz (exclusive upper bound of 0..).
inline constexpr double kMaxPlatformFreqGhz = 10.0;

}  // namespace adse

#endif  // ADSE_STACK_BASE_PLATFORM_LIMITS_H_
