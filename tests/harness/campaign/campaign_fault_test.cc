// A campaign on a failing disk (through a fault-injecting Env): a full
// disk, EIO on write, a failed rename, and a crash between write and
// rename each lose no finished run, leave no file that looks complete but
// is not, say which file and why, and let the campaign resume.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "analysis/runfile/campaign_file.h"
#include "analysis/runfile/run_file.h"
#include "harness/campaign/campaign.h"
#include "stack/base/files.h"
#include "tests/harness/testing/small_scenario.h"
#include "tests/stack/base/testing/fault_injection_env.h"
#include "tests/testing/temp_files.h"

namespace adse::campaign {
namespace {

namespace fs = std::filesystem;
using ::adse::testing::Fault;
using ::adse::testing::FaultInjectionEnv;
using ::adse::testing::FaultOp;
using ::testing::HasSubstr;

constexpr int kBudget = 3;

std::string TempDir(const std::string& name) {
  return adse::testing::FreshTempDir("adse-campaign-fault", name);
}

CampaignOptions Options(const std::string& out, Env* env) {
  CampaignOptions o;
  o.output_dir = out;
  o.strategy = "exhaustive";
  o.budget = kBudget;
  o.workers = 2;
  o.use_cache = false;
  o.worker_command = {std::string(ADSE_BINARY_DIR) + "/bin/adse", "worker"};
  o.env = env;
  return o;
}

// Every file in the folder that carries a final name is whole: run files
// and the index read back, JSON parses. Temporaries are named *.tmp.*.
// Returns the keys of the run files.
std::set<std::string> CheckEveryFinalFileIsWhole(const std::string& folder) {
  std::set<std::string> runs;
  for (const auto& e : fs::recursive_directory_iterator(folder)) {
    if (!e.is_regular_file()) continue;
    const std::string path = e.path().string();
    const std::string name = e.path().filename().string();
    if (name.find(".tmp.") != std::string::npos) continue;
    SCOPED_TRACE(path);
    if (name == "campaign.h5") {
      Result<runfile::CampaignIndex> index = runfile::ReadCampaignIndex(path);
      EXPECT_TRUE(index.ok()) << index.status().message();
    } else if (e.path().extension() == ".h5") {
      Result<runfile::RunData> run = runfile::ReadRunFile(path);
      EXPECT_TRUE(run.ok()) << run.status().message();
      if (run.ok()) runs.insert(run->content_key);
    } else if (e.path().extension() == ".json") {
      Result<std::string> text = ReadFile(path);
      EXPECT_TRUE(text.ok() &&
                  !nlohmann::json::parse(*text, nullptr, false).is_discarded())
          << "unreadable or cut short";
    }
  }
  return runs;
}

std::vector<std::string> Temporaries(const std::string& folder) {
  std::vector<std::string> found;
  for (const auto& e : fs::recursive_directory_iterator(folder)) {
    const std::string name = e.path().filename().string();
    if (name.find(".tmp.") != std::string::npos) found.push_back(name);
  }
  return found;
}

// Resuming on a healthy disk reuses every run the failed campaign kept,
// simulates only the rest and writes every view.
void ExpectResumeCompletes(const std::string& out,
                           const std::set<std::string>& kept) {
  const spec::Spec spec = adse::testing::SmallScenario();
  Result<CampaignSummary> resumed =
      RunCampaign(spec, Options(out, Env::Default()));
  ASSERT_TRUE(resumed.ok()) << resumed.status().message();
  EXPECT_EQ(resumed->reused, static_cast<int>(kept.size()));
  EXPECT_EQ(resumed->simulated + resumed->reused, kBudget);
  EXPECT_EQ(resumed->failed, 0);
  Result<runfile::CampaignIndex> index =
      runfile::ReadCampaignIndex(out + "/campaign.h5");
  ASSERT_TRUE(index.ok()) << index.status().message();
  EXPECT_EQ(index->evaluations.size(), static_cast<size_t>(kBudget));
  for (const char* view : {"summary.json", "report.md", "pareto.png"}) {
    EXPECT_TRUE(fs::is_regular_file(out + "/" + view)) << view;
  }
  EXPECT_EQ(CheckEveryFinalFileIsWhole(out).size(),
            static_cast<size_t>(kBudget));
}

struct DiskFault {
  const char* name;
  Fault fault;
  const char* file;    // named in the error
  const char* reason;  // strerror text in the error
};

void PrintTo(const DiskFault& f, std::ostream* os) { *os << f.name; }

class CampaignDiskFaultTest : public ::testing::TestWithParam<DiskFault> {};

TEST_P(CampaignDiskFaultTest,
       TheCampaignKeepsEveryRunSaysWhichFileFailedAndResumes) {
  const DiskFault& f = GetParam();
  const spec::Spec spec = adse::testing::SmallScenario();
  const std::string out = TempDir(f.name);
  FaultInjectionEnv env;
  env.Inject(f.fault);

  Result<CampaignSummary> failed = RunCampaign(spec, Options(out, &env));
  ASSERT_FALSE(failed.ok()) << "a view could not be written";
  EXPECT_GE(env.failures(), 1);
  EXPECT_EQ(failed.status().code(), Status::Code::kIoError);
  EXPECT_THAT(failed.status().message(), HasSubstr(f.file));
  EXPECT_THAT(failed.status().message(), HasSubstr(f.reason));

  // The workers' runs are all there and whole; nothing is half-written
  // under a final name, and no temporary is left behind.
  const std::set<std::string> kept = CheckEveryFinalFileIsWhole(out);
  EXPECT_EQ(kept.size(), static_cast<size_t>(kBudget));
  EXPECT_THAT(Temporaries(out), ::testing::IsEmpty());
  ExpectResumeCompletes(out, kept);
}

INSTANTIATE_TEST_SUITE_P(
    EveryFault, CampaignDiskFaultTest,
    ::testing::Values(
        // HDF5 writes its own bytes; a full disk shows at the fsync.
        DiskFault{"full_disk",
                  {FaultOp::kSyncFile, "campaign.h5", ENOSPC},
                  "campaign.h5",
                  "No space left on device"},
        DiskFault{"eio_on_write",
                  {FaultOp::kWriteFile, "summary.json", EIO},
                  "summary.json",
                  "Input/output error"},
        DiskFault{"failed_rename",
                  {FaultOp::kRenameFile, "report.md", EACCES},
                  "report.md",
                  "Permission denied"}),
    [](const ::testing::TestParamInfo<DiskFault>& info) {
      return std::string(info.param.name);
    });

TEST(CampaignCrashTest,
     ACrashBetweenWriteAndRenameLeavesNoCompleteLookingFileAndResumes) {
  const std::string out = TempDir("crash");
  // The coordinator dies at its second commit of campaign.h5 (the first
  // is at the first proposal, before any run ended), after the temporary
  // was written and flushed and before the rename.
  ASSERT_EQ(testing::RunUntilCrash(
                FaultOp::kRenameFile, "campaign.h5",
                [&](Env* env) {
                  (void)RunCampaign(adse::testing::SmallScenario(),
                                    Options(out, env));
                },
                /*after=*/1),
            testing::kCrashExitCode);

  // The committed index is the first one's, of no evaluation.
  Result<runfile::CampaignIndex> index =
      runfile::ReadCampaignIndex(out + "/campaign.h5");
  ASSERT_TRUE(index.ok()) << index.status().message();
  EXPECT_TRUE(index->evaluations.empty());
  bool index_temporary = false;
  for (const std::string& name : Temporaries(out)) {
    index_temporary |= name.rfind("campaign.h5.tmp.", 0) == 0;
  }
  EXPECT_TRUE(index_temporary) << "the written temporary keeps its own name";
  const std::set<std::string> kept = CheckEveryFinalFileIsWhole(out);
  EXPECT_GE(kept.size(), 1u) << "runs finished before the crash are kept";
  ExpectResumeCompletes(out, kept);
}

}  // namespace
}  // namespace adse::campaign
