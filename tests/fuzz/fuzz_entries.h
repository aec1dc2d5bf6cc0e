// Entry points shared by the libFuzzer targets (fuzz_*.cc, built with
// -DADSE_FUZZ=ON, see scripts/fuzz.sh) and the ordinary gtest that replays
// the committed corpus and every regression input (fuzz_regression_test.cc).
//
// Each takes untrusted bytes. Rejecting them with an error is fine; a crash,
// a sanitizer report or a non-ok return is a finding. A non-ok return is an
// invariant the code broke (e.g. a normalised spec that does not parse back),
// which the fuzz targets turn into an abort so libFuzzer saves the input.
#ifndef ADSE_TESTS_FUZZ_FUZZ_ENTRIES_H_
#define ADSE_TESTS_FUZZ_FUZZ_ENTRIES_H_

#include <cstddef>
#include <cstdint>

#include "stack/base/status.h"

namespace adse::fuzz {

// Parses the bytes as a scenario file (no file checks). When they parse,
// NormalizedYaml of the spec must parse too and normalise to the same text.
Status FuzzSpecParser(const uint8_t* data, size_t size);

// Writes the bytes to a temporary file and reads it as a run file, as a
// campaign index and through the schema check. Errors are expected; it
// returns non-ok only if it cannot write the temporary file.
Status FuzzRunFile(const uint8_t* data, size_t size);

}  // namespace adse::fuzz

#endif  // ADSE_TESTS_FUZZ_FUZZ_ENTRIES_H_
