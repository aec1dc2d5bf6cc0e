// The campaign folder's lock, failure records, atomic copies and the shared
// cache.
#include "harness/campaign/run_store.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>

#include "stack/base/files.h"
#include "tests/testing/temp_files.h"

namespace adse::campaign {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string TempDir(const std::string& name) {
  return adse::testing::FreshTempDir("adse-run-store", name);
}

TEST(CampaignLockTest, ASecondHolderIsRefusedWithTheFirstOnesPid) {
  const std::string dir = TempDir("lock");
  Result<CampaignLock> first = CampaignLock::Acquire(dir);
  ASSERT_TRUE(first.ok()) << first.status().message();
  Result<CampaignLock> second = CampaignLock::Acquire(dir);
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(second.status().code(), Status::Code::kUnavailable);
  EXPECT_THAT(second.status().message(),
              HasSubstr("pid " + std::to_string(::getpid())));
  EXPECT_THAT(second.status().message(), HasSubstr(dir));
  { CampaignLock released = std::move(first).value(); }
  EXPECT_TRUE(CampaignLock::Acquire(dir).ok());
}

TEST(CampaignLockTest, AHolderKilledOutrightLeavesNoStaleLock) {
  const std::string dir = TempDir("killed");
  // The child says over a pipe when it holds the lock. (Polling for it
  // with Acquire raced: a probe that took the lock for an instant made
  // the child's own Acquire fail.)
  int said[2];
  ASSERT_EQ(::pipe(said), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::close(said[0]);
    Result<CampaignLock> lock = CampaignLock::Acquire(dir);
    const char held = lock.ok() ? 1 : 0;
    if (::write(said[1], &held, 1) != 1 || !lock.ok()) ::_exit(1);
    ::pause();
    ::_exit(0);
  }
  ::close(said[1]);
  char held = 0;  // stays 0 if the child dies before it says
  ASSERT_EQ(::read(said[0], &held, 1), 1) << "the child said nothing";
  ::close(said[0]);
  ASSERT_EQ(held, 1) << "the child could not take the lock";
  EXPECT_FALSE(CampaignLock::Acquire(dir).ok());
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  EXPECT_TRUE(CampaignLock::Acquire(dir).ok());
}

TEST(FailureRecordTest, RoundTripsAndRejectsDamage) {
  const std::string dir = TempDir("failure");
  FailureRecord r;
  r.content_key = std::string(64, 'a');
  r.point = "cores=1,freq_ghz=1";
  r.seed = 7;
  r.outcome = "timeout";
  r.signal = 9;
  r.attempts = 2;
  r.wall_s = 1.5;
  r.detail = "killed after run_timeout_s = 1 s";
  r.stderr_tail = "line 1\n\xff invalid utf-8\n";
  ASSERT_TRUE(WriteFailureRecord(dir + "/f.json", r).ok());
  Result<FailureRecord> back = ReadFailureRecord(dir + "/f.json");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->outcome, "timeout");
  EXPECT_EQ(back->attempts, 2);
  EXPECT_EQ(back->signal, 9);
  EXPECT_EQ(back->point, r.point);
  ASSERT_TRUE(WriteFileAtomic(dir + "/bad.json", "{\"no\": 1}").ok());
  Result<FailureRecord> bad = ReadFailureRecord(dir + "/bad.json");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), Status::Code::kCorruption);
  EXPECT_THAT(bad.status().message(), HasSubstr("bad.json"));
}

TEST(RunCostTest, RoundTripsAndRejectsDamage) {
  const std::string dir = TempDir("cost");
  ASSERT_TRUE(
      WriteRunCost(dir + "/c.json", {std::string(64, 'b'), 2, 38.6}).ok());
  Result<RunCost> back = ReadRunCost(dir + "/c.json");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->content_key, std::string(64, 'b'));
  EXPECT_EQ(back->attempts, 2);
  EXPECT_DOUBLE_EQ(back->wall_s, 38.6);
  for (const char* damaged :
       {"{\"content_key\": \"k\", \"attempts\": 1}", "[1, 2]", "not json",
        "{\"content_key\": 3, \"attempts\": 1, \"wall_s\": 1}"}) {
    ASSERT_TRUE(WriteFileAtomic(dir + "/bad.json", damaged).ok());
    Result<RunCost> bad = ReadRunCost(dir + "/bad.json");
    ASSERT_FALSE(bad.ok()) << damaged;
    EXPECT_EQ(bad.status().code(), Status::Code::kCorruption);
    EXPECT_THAT(bad.status().message(), HasSubstr("bad.json"));
  }
}

TEST(RunCacheTest, InsertFindAndCopyOutLeaveNoTemporaries) {
  const std::string dir = TempDir("cache");
  ASSERT_TRUE(WriteFileAtomic(dir + "/run.h5", "payload").ok());
  RunCache cache(dir + "/cache");
  const std::string key(64, 'b');
  EXPECT_FALSE(cache.Find(key).has_value());
  ASSERT_TRUE(cache.Insert(key, dir + "/run.h5").ok());
  ASSERT_TRUE(cache.Find(key).has_value());
  ASSERT_TRUE(cache.CopyOut(key, dir + "/campaign/runs/" + key + ".h5").ok());
  EXPECT_EQ(ReadFile(dir + "/campaign/runs/" + key + ".h5").value(), "payload");
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    EXPECT_EQ(entry.path().string().find(".tmp."), std::string::npos)
        << entry.path();
  }
  EXPECT_FALSE(CopyFileAtomic(dir + "/missing.h5", dir + "/x.h5").ok());
  EXPECT_FALSE(fs::exists(dir + "/x.h5"));
}

}  // namespace
}  // namespace adse::campaign
