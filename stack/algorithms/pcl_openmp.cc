// OpenMP regions of one thread run in their caller, with no team.
//
// FLANN, which PCL's kd-tree is built on, opens an OpenMP parallel region
// for every query, with `SearchParams::cores` threads (1 as PCL sets it).
// NDT asks one radius search per scan point per iteration, the clustering
// one per point, so a run opens tens of thousands of regions per simulated
// second. libgomp builds a team for each and wakes the team's barrier with
// a futex system call even when no thread waits on it: measured on the
// 2-core development VM, that was 58-87 % of a closed-loop run's wall
// time (README, "Performance"). FLANN's own fix (flann-lib/flann#114) was
// never merged and Debian's PCL is built with OpenMP.
//
// The executable exports this definition (see this folder's CMakeLists),
// so the dynamic linker binds PCL's calls to it before libgomp's. A region
// asked for one thread calls its body directly: outside any team, OpenMP's
// worksharing and synchronisation constructs bind to the calling thread
// alone (omp_get_num_threads() is 1, a barrier returns at once), which is
// what a team of one would do. Any other region goes to libgomp unchanged.
// Only the wall time changes: the counted cost model's results are the
// same, and the measured one no longer charges the callback for libgomp.
#include <dlfcn.h>

namespace {

using GompParallel = void (*)(void (*)(void*), void*, unsigned, unsigned);

GompParallel Libgomp() {
  // Resolved once; libgomp is loaded by whoever calls into OpenMP.
  static const GompParallel real =
      reinterpret_cast<GompParallel>(::dlsym(RTLD_NEXT, "GOMP_parallel"));
  return real;
}

}  // namespace

// libgomp's entry for `#pragma omp parallel` (GCC >= 4.9): the outlined
// body, its data, the num_threads clause (0 when absent) and the
// proc_bind flags.
extern "C" void GOMP_parallel(void (*fn)(void*), void* data,
                              unsigned num_threads, unsigned flags) {
  const GompParallel real = num_threads == 1 ? nullptr : Libgomp();
  if (real == nullptr) {
    // One thread asked for (or no libgomp to form a team): a team may
    // always be smaller than asked, and the body must work with one.
    fn(data);
    return;
  }
  real(fn, data, num_threads, flags);
}
