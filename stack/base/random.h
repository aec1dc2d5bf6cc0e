// Deterministic random numbers. std::*_distribution output differs between
// standard libraries, so draws are derived from the raw mt19937_64 stream,
// whose sequence the standard fixes.
#ifndef ADSE_STACK_BASE_RANDOM_H_
#define ADSE_STACK_BASE_RANDOM_H_

#include <cstdint>
#include <random>
#include <string_view>

namespace adse {

class Random {
 public:
  explicit Random(uint64_t seed) : engine_(seed) {}
  // Seed derived from a base seed and a purpose label, so independent
  // consumers of one scenario seed get independent streams.
  static uint64_t DeriveSeed(uint64_t seed, std::string_view purpose);

  uint64_t NextU64() { return engine_(); }
  // Uniform in [0, 1).
  double Uniform() { return (engine_() >> 11) * 0x1.0p-53; }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Uniform integer in [0, n).
  uint64_t Below(uint64_t n);
  bool Bernoulli(double p) { return Uniform() < p; }
  // Standard normal via Box-Muller.
  double Normal(double mean, double stddev);

 private:
  std::mt19937_64 engine_;
};

}  // namespace adse

#endif  // ADSE_STACK_BASE_RANDOM_H_
