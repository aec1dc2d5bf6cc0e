#include "stack/base/decimal.h"

#include <cmath>

namespace adse {

double RoundToSignificantDigits(double value, int digits) {
  if (!std::isfinite(value) || value == 0.0) return value;
  const int exponent =
      digits - 1 - static_cast<int>(std::floor(std::log10(std::abs(value))));
  // Scale by a whole power of ten, which is exact, never by its
  // reciprocal, which is not: large values divide, small ones multiply.
  if (exponent >= 0) {
    const double scale = std::pow(10.0, exponent);
    // Below about 1e-296 the scale overflows: such a value is kept.
    if (!std::isfinite(scale) || !std::isfinite(value * scale)) return value;
    return std::round(value * scale) / scale;
  }
  const double scale = std::pow(10.0, -exponent);
  return std::round(value / scale) * scale;
}

}  // namespace adse
