// A worker's run file under a failing disk: WriteRunFile through a
// fault-injecting Env. Whatever fails (a full disk at the flush, EIO, a
// failed rename, the folder not created, a crash between write and rename),
// the run file already at the path stays whole, nothing half-written takes
// its name, the error names the file and the reason, and the next write
// succeeds. The worker exits non-zero on such an error and the pool retries
// the run (tests/harness/campaign).
#include <gtest/gtest.h>

#include <cerrno>
#include <filesystem>
#include <string>
#include <vector>

#include "analysis/runfile/run_file.h"
#include "tests/analysis/testing/temp_dir_test.h"
#include "tests/stack/base/testing/fault_injection_env.h"

namespace adse::runfile {
namespace {

namespace fs = std::filesystem;
using adse::testing::FaultInjectionEnv;
using adse::testing::FaultOp;

RunData RunEndingIn(const std::string& reason) {
  RunData run;
  run.termination_reason = reason;
  run.scenario_name = "fault";
  run.design_point = {{"cores", 4.0}};
  run.metrics = {{"nav_time_s", reason == "goal_reached" ? 42.0 : 0.0}};
  run.ego = {{0, 0, 0, 0, 10, 0, 0}, {0.1, 1, 0, 0, 10, 0, 0}};
  return run;
}

struct RunFileFault {
  const char* name;
  adse::testing::Fault fault;
  const char* reason;  // the system's words the error must carry
};

class RunFileFaultTest : public adse::testing::TempDirTest,
                         public ::testing::WithParamInterface<RunFileFault> {
 protected:
  // Entries of the folder whose name marks a temporary.
  std::vector<std::string> Temporaries() const {
    std::vector<std::string> found;
    for (const std::string& name : Listing(true)) {
      if (name.find(".tmp.") != std::string::npos) found.push_back(name);
    }
    return found;
  }
};

TEST_P(RunFileFaultTest, TheFileAtThePathStaysWholeAndTheErrorSaysWhy) {
  const RunFileFault& f = GetParam();
  const std::string path = Path("runs/key.h5");
  ASSERT_TRUE(WriteRunFile(path, RunEndingIn("stalled")).ok());

  FaultInjectionEnv env;
  env.Inject(f.fault);
  const Status status = WriteRunFile(path, RunEndingIn("goal_reached"), &env);
  ASSERT_FALSE(status.ok());
  EXPECT_GE(env.failures(), 1);
  EXPECT_EQ(status.code(), Status::Code::kIoError);
  EXPECT_NE(status.message().find(path), std::string::npos) << status.message();
  EXPECT_NE(status.message().find(f.reason), std::string::npos)
      << status.message();

  // The earlier run, whole; no temporary left.
  Result<RunData> kept = ReadRunFile(path);
  ASSERT_TRUE(kept.ok()) << kept.status().ToString();
  EXPECT_EQ(kept->termination_reason, "stalled");
  EXPECT_TRUE(Temporaries().empty()) << Temporaries().front();

  // The disk recovered: the run is written.
  ASSERT_TRUE(WriteRunFile(path, RunEndingIn("goal_reached")).ok());
  Result<RunData> written = ReadRunFile(path);
  ASSERT_TRUE(written.ok());
  EXPECT_EQ(written->termination_reason, "goal_reached");
}

TEST_P(RunFileFaultTest, ANewRunFileIsNotThereAtAllAfterTheFault) {
  const RunFileFault& f = GetParam();
  const std::string path = Path("runs/new.h5");
  FaultInjectionEnv env;
  env.Inject(f.fault);
  ASSERT_FALSE(WriteRunFile(path, RunEndingIn("goal_reached"), &env).ok());
  EXPECT_FALSE(fs::exists(path));
  EXPECT_TRUE(Temporaries().empty()) << Temporaries().front();
}

INSTANTIATE_TEST_SUITE_P(
    EveryFault, RunFileFaultTest,
    ::testing::Values(
        // HDF5 writes its own bytes; a full disk shows at the flush.
        RunFileFault{"full_disk",
                     {FaultOp::kSyncFile, ".h5", ENOSPC},
                     "No space left on device"},
        RunFileFault{"eio_on_flush",
                     {FaultOp::kSyncFile, ".h5", EIO},
                     "Input/output error"},
        RunFileFault{"failed_rename",
                     {FaultOp::kRenameFile, ".h5", EACCES},
                     "Permission denied"}),
    [](const ::testing::TestParamInfo<RunFileFault>& info) {
      return std::string(info.param.name);
    });

class RunFileCrashTest : public adse::testing::TempDirTest {};

TEST_F(RunFileCrashTest,
       ACrashBetweenWriteAndRenameLeavesTheEarlierRunAndATemporaryOnly) {
  const std::string path = Path("runs/key.h5");
  ASSERT_TRUE(WriteRunFile(path, RunEndingIn("stalled")).ok());
  ASSERT_EQ(adse::testing::RunUntilCrash(
                FaultOp::kRenameFile, "key.h5",
                [&](Env* env) {
                  (void)WriteRunFile(path, RunEndingIn("goal_reached"), env);
                }),
            adse::testing::kCrashExitCode);

  Result<RunData> kept = ReadRunFile(path);
  ASSERT_TRUE(kept.ok()) << kept.status().ToString();
  EXPECT_EQ(kept->termination_reason, "stalled");
  // The written temporary keeps a name no reader takes for the run's.
  bool temporary = false;
  for (const std::string& name : Listing(true)) {
    temporary |= name.rfind("runs/key.h5.tmp.", 0) == 0;
  }
  EXPECT_TRUE(temporary);
  ASSERT_TRUE(WriteRunFile(path, RunEndingIn("goal_reached")).ok());
  EXPECT_EQ(ReadRunFile(path)->termination_reason, "goal_reached");
}

}  // namespace
}  // namespace adse::runfile
