// Decimal rounding of computed values whose inputs are short decimals.
#ifndef ADSE_STACK_BASE_DECIMAL_H_
#define ADSE_STACK_BASE_DECIMAL_H_

namespace adse {

// Significant digits past which a product or sum of a few short decimals
// (6 x 1.2 GHz-cores) carries only binary float noise: such values are
// rounded to this many before they are stored or compared.
inline constexpr int kDecimalDigits = 12;

// `value` rounded to `digits` significant decimal digits (the nearest
// double), so that 6 x 1.2 = 7.199999999999999 reads 7.2 and ties with
// 4 x 1.8. Non-finite values and 0 are returned unchanged.
double RoundToSignificantDigits(double value, int digits);

}  // namespace adse

#endif  // ADSE_STACK_BASE_DECIMAL_H_
