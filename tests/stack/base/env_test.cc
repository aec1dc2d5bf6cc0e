// The filesystem seam: the real Env, and atomic writes under every fault a
// disk can throw at them — the old file stays whole, no temporary is left,
// the error names the file and the reason.
#include "stack/base/env.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "stack/base/files.h"
#include "tests/stack/base/testing/fault_injection_env.h"
#include "tests/testing/temp_files.h"

namespace adse {
namespace {

namespace fs = std::filesystem;
using ::adse::testing::Fault;
using ::adse::testing::FaultInjectionEnv;
using ::adse::testing::FaultOp;
using ::testing::HasSubstr;

std::string TempDir(const std::string& name) {
  return adse::testing::FreshTempDir("adse-env", name);
}

std::vector<std::string> Names(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    names.push_back(e.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

TEST(EnvTest, TheRealEnvWritesAppendsRenamesCopiesAndRemoves) {
  Env* env = Env::Default();
  const std::string dir = TempDir("real") + "/a/b";
  ASSERT_TRUE(env->CreateDir(dir).ok());
  ASSERT_TRUE(env->CreateDir(dir).ok()) << "an existing folder is fine";
  ASSERT_TRUE(env->WriteFile(dir + "/x", "one").ok());
  ASSERT_TRUE(env->AppendFile(dir + "/x", "two").ok());
  ASSERT_TRUE(env->SyncFile(dir + "/x").ok());
  ASSERT_TRUE(env->SyncDir(dir).ok());
  EXPECT_EQ(ReadFile(dir + "/x").value(), "onetwo");
  ASSERT_TRUE(env->RenameFile(dir + "/x", dir + "/y").ok());
  ASSERT_TRUE(env->CopyFile(dir + "/y", dir + "/z").ok());
  EXPECT_EQ(ReadFile(dir + "/z").value(), "onetwo");
  ASSERT_TRUE(env->RemoveFile(dir + "/y").ok());
  ASSERT_TRUE(env->RemoveFile(dir + "/y").ok()) << "a missing file is fine";
  EXPECT_EQ(Names(dir), std::vector<std::string>{"z"});

  const Status missing = env->RenameFile(dir + "/none", dir + "/w");
  EXPECT_EQ(missing.code(), Status::Code::kIoError);
  EXPECT_THAT(missing.message(), HasSubstr("No such file or directory"));
  EXPECT_THAT(missing.message(), HasSubstr(dir + "/w"));
}

struct FaultCase {
  const char* name;
  Fault fault;
  const char* reason;  // strerror text in the message
};

void PrintTo(const FaultCase& c, std::ostream* os) { *os << c.name; }

class AtomicWriteFaultTest : public ::testing::TestWithParam<FaultCase> {};

TEST_P(AtomicWriteFaultTest, KeepsTheOldFileLeavesNoTemporaryAndSaysWhy) {
  const std::string dir = TempDir(GetParam().name);
  const std::string path = dir + "/summary.json";
  ASSERT_TRUE(WriteFileAtomic(path, "old\n").ok());

  FaultInjectionEnv env;
  env.Inject(GetParam().fault);
  const Status s = WriteFileAtomic(path, std::string(4096, 'n'), &env);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(env.failures(), 1);
  EXPECT_EQ(s.code(), Status::Code::kIoError);
  EXPECT_THAT(s.message(), HasSubstr("summary.json"));
  EXPECT_THAT(s.message(), HasSubstr(GetParam().reason));
  EXPECT_EQ(ReadFile(path).value(), "old\n");
  EXPECT_EQ(Names(dir), std::vector<std::string>{"summary.json"});

  // The fault was once; the next write goes through.
  ASSERT_TRUE(WriteFileAtomic(path, "new\n", &env).ok());
  EXPECT_EQ(ReadFile(path).value(), "new\n");
}

INSTANTIATE_TEST_SUITE_P(
    EveryFault, AtomicWriteFaultTest,
    ::testing::Values(FaultCase{"full_disk",
                                {FaultOp::kWriteFile, ".tmp.", ENOSPC, 0, 1},
                                "No space left on device"},
                      FaultCase{"eio_on_write",
                                {FaultOp::kWriteFile, "", EIO, 0, 1},
                                "Input/output error"},
                      FaultCase{"eio_on_fsync",
                                {FaultOp::kSyncFile, "", EIO, 0, 1},
                                "Input/output error"},
                      FaultCase{
                          "failed_rename",
                          {FaultOp::kRenameFile, "summary.json", EXDEV, 0, 1},
                          "Invalid cross-device link"}),
    [](const ::testing::TestParamInfo<FaultCase>& info) {
      return std::string(info.param.name);
    });

TEST(AtomicWriteFaultTest, ACrashBetweenWriteAndRenameLeavesTheOldFileWhole) {
  const std::string dir = TempDir("crash");
  const std::string path = dir + "/report.md";
  ASSERT_TRUE(WriteFileAtomic(path, "old\n").ok());
  EXPECT_EQ(testing::RunUntilCrash(
                testing::FaultOp::kRenameFile, "",
                [&](Env* env) {
                  (void)WriteFileAtomic(path, "new and never committed\n", env);
                }),
            testing::kCrashExitCode);
  EXPECT_EQ(ReadFile(path).value(), "old\n");
  // The written temporary is there, under a name that is not the file's.
  const std::vector<std::string> names = Names(dir);
  ASSERT_EQ(names.size(), 2u);
  EXPECT_EQ(names[0], "report.md");
  EXPECT_THAT(names[1], HasSubstr("report.md.tmp."));
}

TEST(AppendFaultTest, AFullDiskCutsOnlyTheLastLineAndSaysWhy) {
  const std::string dir = TempDir("append");
  const std::string path = dir + "/events.jsonl";
  ASSERT_TRUE(AppendLineDurable(path, "{\"a\":1}").ok());
  FaultInjectionEnv env;
  env.Inject({FaultOp::kAppendFile, "events", ENOSPC, 0, 1});
  const Status s = AppendLineDurable(path, "{\"b\":2}", &env);
  EXPECT_THAT(s.message(), HasSubstr("events.jsonl"));
  EXPECT_THAT(s.message(), HasSubstr("No space left on device"));
  const std::string text = ReadFile(path).value();
  EXPECT_EQ(text.substr(0, 8), "{\"a\":1}\n") << "the first line survives";
}

}  // namespace
}  // namespace adse
