// libFuzzer target: scenario files (see fuzz_entries.h, scripts/fuzz.sh).
#include <cstdio>
#include <cstdlib>

#include "tests/fuzz/fuzz_entries.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const adse::Status status = adse::fuzz::FuzzSpecParser(data, size);
  if (!status.ok()) {
    std::fprintf(stderr, "fuzz_spec_parser: %s\n", status.ToString().c_str());
    std::abort();
  }
  return 0;
}
