// pcl_openmp.cc: an OpenMP region asked for one thread (what FLANN opens
// per kd-tree query inside PCL) runs in its caller with no team; any other
// region still gets libgomp's team. Compiled with OpenMP, so these regions
// call GOMP_parallel as PCL's do.
#include <dlfcn.h>
#include <gtest/gtest.h>
#include <omp.h>

#include <thread>
#include <vector>

extern "C" void GOMP_parallel(void (*)(void*), void*, unsigned, unsigned);

namespace {

TEST(PclOpenMpTest, SharedLibrariesBindToTheProgramsDefinition) {
  // The dynamic linker resolves PCL's calls in the global scope, which
  // starts at the program: it must export its definition, not leave
  // libgomp's to be found.
  EXPECT_EQ(::dlsym(RTLD_DEFAULT, "GOMP_parallel"),
            reinterpret_cast<void*>(&GOMP_parallel));
  EXPECT_NE(::dlsym(RTLD_NEXT, "GOMP_parallel"), nullptr) << "libgomp";
}

TEST(PclOpenMpTest, ARegionOfOneThreadRunsInItsCallerWithNoTeam) {
  int level = -1;
  int threads = 0;
  std::thread::id inside;
#pragma omp parallel num_threads(1)
  {
    level = omp_get_level();
    threads = omp_get_num_threads();
    inside = std::this_thread::get_id();
  }
  // libgomp's team of one would be at level 1.
  EXPECT_EQ(level, 0);
  EXPECT_EQ(threads, 1);
  EXPECT_EQ(inside, std::this_thread::get_id());
}

TEST(PclOpenMpTest, WorksharingInARegionOfOneThreadCoversTheWholeLoop) {
  // FLANN's shape: a region, a static loop with a reduction, per query.
  std::vector<int> seen(1000, 0);
  long sum = 0;
  for (int query = 0; query < 50; ++query) {
#pragma omp parallel num_threads(1)
    {
#pragma omp for schedule(static) reduction(+ : sum)
      for (int i = 0; i < 1000; ++i) {
        ++seen[i];
        sum += i;
      }
    }
  }
  EXPECT_EQ(sum, 50L * 999 * 1000 / 2);
  for (int count : seen) ASSERT_EQ(count, 50);
}

TEST(PclOpenMpTest, ARegionOfMoreThreadsStillFormsLibgompsTeam) {
  int level = -1;
  int threads = 0;
#pragma omp parallel num_threads(2)
  {
#pragma omp single
    {
      level = omp_get_level();
      threads = omp_get_num_threads();
    }
  }
  EXPECT_EQ(level, 1);
  EXPECT_EQ(threads, 2);
}

}  // namespace
