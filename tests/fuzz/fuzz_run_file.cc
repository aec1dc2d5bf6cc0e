// libFuzzer target: run files and campaign indexes (see fuzz_entries.h,
// scripts/fuzz.sh).
#include <cstdio>
#include <cstdlib>

#include "tests/fuzz/fuzz_entries.h"

// Leaks inside libhdf5 on damaged files, which adse cannot prevent (Debian
// 12's HDF5 1.10.8; see tests/fuzz/regressions/README.md). libhdf5 has no
// frame pointers, so with the fast unwinder a leak's stack ends at its first
// libhdf5 frame and only the library, not the HDF5 function, can be named.
// adse owns no memory HDF5 allocates except variable-length strings, which
// hdf5_util.cc's ReadStrings reclaims on every path (checked by review and
// by replaying the corpus with fast_unwind_on_malloc=0, see the README).
// ADSE_FUZZ_ALL_LEAKS=1 drops the suppression for that check.
extern "C" const char* __lsan_default_suppressions() {
  if (std::getenv("ADSE_FUZZ_ALL_LEAKS") != nullptr) return "";
  return "leak:libhdf5\n";
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const adse::Status status = adse::fuzz::FuzzRunFile(data, size);
  if (!status.ok()) {
    std::fprintf(stderr, "fuzz_run_file: %s\n", status.ToString().c_str());
    std::abort();
  }
  return 0;
}
