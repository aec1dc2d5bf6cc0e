// Small text helpers shared by the spec parser, the expression wrapper and
// design-point parsing: "did you mean" suggestions, numbers, lists.
#ifndef ADSE_HARNESS_SPEC_TEXT_UTIL_H_
#define ADSE_HARNESS_SPEC_TEXT_UTIL_H_

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace adse::spec {

// Edit distance (insertions, deletions, substitutions), case-insensitive.
int EditDistance(std::string_view a, std::string_view b);

// " (did you mean 'x'?)" for the closest candidate within a small edit
// distance of `word`, or "" when none is close enough.
std::string DidYouMean(std::string_view word,
                       const std::vector<std::string>& candidates);

// Parses a whole string as a finite number ("10", "-2.5", "1e3", "+4");
// false for anything else (including "inf", "0x10", "10 m").
bool ParseNumber(std::string_view text, double* value);

// Shortest text that reads back as the same double ("2.1", "10", "1e-06").
std::string FormatNumber(double value);

// "1 evaluation", "12 evaluations": a count and its regular noun.
std::string Counted(size_t count, std::string_view noun);

// "a, b, c" (each item wrapped in `quote` when given).
std::string JoinList(const std::vector<std::string>& items,
                     std::string_view quote = "");

}  // namespace adse::spec

#endif  // ADSE_HARNESS_SPEC_TEXT_UTIL_H_
