#include "harness/pool/child_log.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>

#include "stack/base/clock.h"

namespace adse::pool {
namespace {

std::string WriteTemp(const std::string& text) {
  char name[] = "/tmp/adse-child-log-XXXXXX";
  const int fd = ::mkstemp(name);
  EXPECT_GE(fd, 0);
  ::close(fd);
  std::ofstream(name, std::ios::binary) << text;
  return name;
}

TEST(ReadLogTailTest, ReturnsTheWholeFileWhenItFits) {
  const std::string path = WriteTemp("first\nsecond\n");
  EXPECT_EQ(ReadLogTail(path, 100), "first\nsecond\n");
  std::remove(path.c_str());
}

TEST(ReadLogTailTest, StartsAtALineStartInsideTheTail) {
  const std::string path = WriteTemp("aaaa\nbbbb\ncccc\n");
  // The last 12 bytes cut "aaaa" short; the tail starts at "bbbb".
  EXPECT_EQ(ReadLogTail(path, 12), "bbbb\ncccc\n");
  std::remove(path.c_str());
}

TEST(ReadLogTailTest, KeepsACutLineWhenNoOtherLineStartsInTheTail) {
  const std::string path = WriteTemp("0123456789\n");
  EXPECT_EQ(ReadLogTail(path, 5), "6789\n");
  std::remove(path.c_str());
}

TEST(ReadLogTailTest, AMissingFileReadsAsEmpty) {
  EXPECT_EQ(ReadLogTail("/nonexistent/adse/log", 100), "");
}

TEST(SteadyFromSecondsTest, ClampsToZeroAndOneYear) {
  using std::chrono::duration;
  EXPECT_EQ(SteadyFromSeconds(-5).count(), 0);
  EXPECT_NEAR(SteadySeconds(SteadyFromSeconds(1.5)), 1.5, 1e-9);
  EXPECT_NEAR(SteadySeconds(SteadyFromSeconds(1e300)), 365 * 86400.0, 1e-3);
}

}  // namespace
}  // namespace adse::pool
