#include "stack/base/random.h"

#include <cmath>

namespace adse {

uint64_t Random::DeriveSeed(uint64_t seed, std::string_view purpose) {
  // FNV-1a over the label, mixed with the seed by splitmix64.
  uint64_t h = 1469598103934665603ull;
  for (char c : purpose) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ull;
  }
  uint64_t z = seed ^ h;
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

uint64_t Random::Below(uint64_t n) {
  if (n == 0) return 0;
  // Rejection sampling avoids modulo bias.
  const uint64_t limit = UINT64_MAX - UINT64_MAX % n;
  uint64_t x;
  do {
    x = engine_();
  } while (x >= limit);
  return x % n;
}

double Random::Normal(double mean, double stddev) {
  double u1 = Uniform();
  if (u1 < 1e-300) u1 = 1e-300;
  const double u2 = Uniform();
  return mean +
         stddev * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

}  // namespace adse
