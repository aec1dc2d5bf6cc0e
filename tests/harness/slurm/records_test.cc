// slurm/jobs.json: every job a campaign submitted, read back typed; a job
// of a kind adse never submits is refused, naming the file and the job.
#include "harness/slurm/records.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "tests/testing/temp_files.h"

namespace adse::slurm {
namespace {
using ::testing::HasSubstr;

TEST(RecordsTest, EveryJobKindRoundTripsThroughTheJobLog) {
  const std::string dir = adse::testing::TestTempDir("adse-slurm-records");
  std::filesystem::create_directories(SlurmDir(dir));
  JobLog log;
  log.scenario = "s.yaml";
  log.strategy = "exhaustive";
  log.budget = 4;
  log.jobs = {
      {1, "2026-12-05T07:00:00Z", JobKind::kArray, "11", "a", {0, 1}},
      {1, "2026-12-05T07:00:00Z", JobKind::kIndex, "12", "b", {}},
      {2, "2026-12-05T08:00:00Z", JobKind::kCoordinator, "13", "c", {}}};
  ASSERT_TRUE(WriteJobLog(dir, log).ok());
  Result<JobLog> back = ReadJobLog(dir);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  ASSERT_EQ(back->jobs.size(), 3u);
  EXPECT_EQ(back->jobs[0].kind, JobKind::kArray);
  EXPECT_EQ(back->jobs[0].shards, (std::vector<int>{0, 1}));
  EXPECT_EQ(back->jobs[1].kind, JobKind::kIndex);
  EXPECT_EQ(back->jobs[2].kind, JobKind::kCoordinator);
  EXPECT_EQ(back->last_submission(), 2);
  EXPECT_EQ(JobKindNames(),
            (std::vector<std::string>{"coordinator", "array", "index"}));
}

TEST(RecordsTest, AJobOfAnUnknownKindIsRefusedNamingTheFileAndTheJob) {
  const std::string dir = adse::testing::TestTempDir("adse-slurm-records");
  std::filesystem::create_directories(SlurmDir(dir));
  const std::string path = SlurmDir(dir) + "/jobs.json";
  adse::testing::WriteRaw(
      path,
      R"({"scenario": "s.yaml", "strategy": "exhaustive", "budget": 2,
          "jobs": [{"submission": 1, "kind": "array", "job_id": "11"},
                   {"submission": 1, "kind": "reindex", "job_id": "12"}]})");
  Result<JobLog> back = ReadJobLog(dir);
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.status().code(), Status::Code::kCorruption);
  EXPECT_THAT(back.status().message(),
              HasSubstr(path + ": job 1: unknown kind 'reindex'; valid "
                               "kinds: coordinator, array, index"));

  adse::testing::WriteRaw(path,
                          R"({"jobs": [{"submission": 1, "job_id": "11"}]})");
  back = ReadJobLog(dir);
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.status().code(), Status::Code::kCorruption);
  EXPECT_THAT(back.status().message(), HasSubstr(path));
}

}  // namespace
}  // namespace adse::slurm
