#include "stack/base/decimal.h"

#include <cmath>

namespace adse {

double RoundToSignificantDigits(double value, int digits) {
  if (!std::isfinite(value) || value == 0.0) return value;
  const int exponent =
      digits - 1 - static_cast<int>(std::floor(std::log10(std::abs(value))));
  // Divide by a power of ten rather than multiply by its reciprocal: 10^k
  // is exact for the k used here, its reciprocal is not.
  if (exponent >= 0) {
    const double scale = std::pow(10.0, exponent);
    return std::round(value * scale) / scale;
  }
  const double scale = std::pow(10.0, -exponent);
  return std::round(value / scale) * scale;
}

}  // namespace adse
