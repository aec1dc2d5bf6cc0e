// adse submit / run / shard / index / status as a user meets them without
// a cluster: the dry run's scripts, and every refusal with its exit code
// and a message naming the field or flag.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "tests/harness/slurm/testing/adse_commands.h"

namespace adse::slurm::testing {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

std::map<std::string, std::string> DryRunScripts(const AdseRun& run) {
  std::map<std::string, std::string> scripts;
  const nlohmann::json j = nlohmann::json::parse(
      run.output.substr(run.output.find('{')), nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << run.output;
  if (j.is_discarded()) return scripts;
  for (const auto& s : j["scripts"]) {
    scripts[s["kind"].get<std::string>()] = s["text"].get<std::string>();
    EXPECT_EQ(s["job_id"], "");
    EXPECT_EQ(s["path"], "");
  }
  return scripts;
}

// bash -n: the script parses.
void ExpectValidBash(const std::string& dir, const std::string& name,
                     const std::string& text) {
  const std::string path = dir + "/" + name + ".sh";
  std::ofstream(path) << text;
  Result<ProcessResult> r = RunProcess({"bash", "-n", path});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->exit_code, 0) << name << ": " << r->output;
}

TEST(SubmitTest, DryRunOfASweepPrintsAnArrayAndAnIndexJobAndTouchesNothing) {
  const TestFolder folder("dry-sweep");
  const std::string& dir = folder.path();
  const std::string scenario = SmallScenarioIn(
      dir, "{strategy: random, budget: 6}",
      "{memory_mb: 1024, slurm: {shard_size: 2, max_parallel: 2, "
      "signal_lead_s: 120, time_limit: \"00:30:00\", partition: short, "
      "extra_args: [--qos=test]}}");
  const std::string out = dir + "/campaign";
  // No sbatch needed for a dry run.
  const AdseRun run = Adse({"submit", scenario, "-o", out, "--dry-run",
                            "--json", "--sbatch-arg=--constraint=fast"},
                           {"PATH=/nonexistent"});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::map<std::string, std::string> scripts = DryRunScripts(run);
  ASSERT_EQ(scripts.size(), 2u);
  const std::string& array = scripts["array"];
  for (const char* line :
       {"#SBATCH --array=0-2%2\n", "#SBATCH --ntasks=1\n",
        "#SBATCH --cpus-per-task=1\n", "#SBATCH --mem=1536M\n",
        "#SBATCH --time=00:30:00\n", "#SBATCH --signal=B:USR1@120\n",
        "#SBATCH --requeue\n", "#SBATCH --partition=short\n",
        "#SBATCH --qos=test\n", "#SBATCH --constraint=fast\n",
        "--task \"$SLURM_ARRAY_TASK_ID\"", "scontrol requeue"}) {
    EXPECT_THAT(array, HasSubstr(line));
  }
  EXPECT_THAT(array,
              HasSubstr("--output=" + out + "/slurm/logs/shard-%A_%a.out"));
  EXPECT_THAT(array, HasSubstr("\" shard " + out));
  // sbatch stops reading #SBATCH lines at the first command.
  EXPECT_LT(array.rfind("#SBATCH"), array.find("set -u"));
  const std::string& index = scripts["index"];
  EXPECT_THAT(index,
              HasSubstr("#SBATCH --dependency=afterany:<array-job-id>\n"));
  EXPECT_THAT(index, HasSubstr("\" index " + out));
  ExpectValidBash(dir, "array", array);
  ExpectValidBash(dir, "index", index);
  EXPECT_FALSE(fs::exists(out)) << "a dry run writes nothing";
}

TEST(SubmitTest, DryRunOfAnAdaptiveCampaignSizesTheCoordinatorFromTheScenario) {
  const TestFolder folder("dry-agent");
  const std::string& dir = folder.path();
  const std::string scenario =
      SmallScenarioIn(dir, "{strategy: agent, budget: 4, batch: 2}",
                      "{workers: 2, cores_per_worker: 2, memory_mb: 1000, "
                      "slurm: {account: lab, time_limit: \"1-00:00:00\"}}");
  const AdseRun run =
      Adse({"submit", scenario, "-o", dir + "/campaign", "--dry-run", "--json",
            "--no-cache", "--confirm-runs", "3"});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::map<std::string, std::string> scripts = DryRunScripts(run);
  ASSERT_EQ(scripts.count("coordinator"), 1u) << run.output;
  const std::string& s = scripts["coordinator"];
  for (const char* line :
       {"#SBATCH --nodes=1\n", "#SBATCH --ntasks=2\n",
        "#SBATCH --cpus-per-task=2\n",
        "#SBATCH --mem=3024M\n",  // 2 steps x 1000 MB + 1024 MB
        "#SBATCH --time=1-00:00:00\n", "#SBATCH --signal=B:USR1@300\n",
        "#SBATCH --account=lab\n", "#SBATCH --requeue\n",
        "(adaptive), budget 4 and up to 3 confirm runs.",
        "--executor slurm --confirm-runs 3 --no-cache &", "kill -USR1 \"$pid\"",
        "kill -INT \"$pid\"", "scontrol requeue \"$SLURM_JOB_ID\""}) {
    EXPECT_THAT(s, HasSubstr(line));
  }
  EXPECT_THAT(s, Not(HasSubstr("--array")));
  ExpectValidBash(dir, "coordinator", s);
}

TEST(SubmitTest, WithoutSbatchOnThePathSubmitSaysWhatIsMissing) {
  const TestFolder folder("no-sbatch");
  const std::string& dir = folder.path();
  const std::string scenario =
      SmallScenarioIn(dir, "{strategy: exhaustive, budget: 2}", "{}");
  const AdseRun run = Adse({"submit", scenario, "-o", dir + "/campaign"},
                           {"PATH=/nonexistent"});
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("sbatch not found on PATH"));
  EXPECT_THAT(run.output, HasSubstr("--dry-run"));
  EXPECT_FALSE(fs::exists(dir + "/campaign"));
}

TEST(SubmitTest,
     RunWithExecutorSlurmOutsideAnAllocationIsRefusedBeforeWriting) {
  const TestFolder folder("no-allocation");
  const std::string& dir = folder.path();
  const std::string scenario =
      SmallScenarioIn(dir, "{strategy: exhaustive, budget: 1}", "{}");
  AdseRun run =
      Adse({"run", scenario, "-o", dir + "/campaign", "--executor", "slurm"},
           {"SLURM_JOB_ID="});
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("--executor slurm"));
  EXPECT_THAT(run.output, HasSubstr("SLURM_JOB_ID is not set"));
  EXPECT_THAT(run.output, HasSubstr("adse submit"));
  EXPECT_FALSE(fs::exists(dir + "/campaign"));
  // The same from the scenario, citing its line.
  const std::string in_file = SmallScenarioIn(
      dir, "{strategy: exhaustive, budget: 1}", "{executor: slurm}");
  run = Adse({"run", in_file, "-o", dir + "/campaign"}, {"SLURM_JOB_ID="});
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("scenario.yaml:"));
  EXPECT_THAT(run.output, HasSubstr("harness.executor: 'slurm'"));
  // A bad flag value is a usage error.
  run = Adse({"run", in_file, "--executor", "pbs"});
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("--executor"));
}

TEST(SubmitTest, BadInputIsRefusedNamingTheFieldOrFlag) {
  const TestFolder folder("bad-input");
  const std::string& dir = folder.path();
  const std::string out = dir + "/campaign";
  const std::string ok =
      SmallScenarioIn(dir, "{strategy: exhaustive, budget: 2}", "{}");
  AdseRun run =
      Adse({"submit", ok, "-o", out, "--dry-run", "--sbatch-arg=--array=0-9"});
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.output, HasSubstr("--sbatch-arg: --array is set by adse "
                                    "submit itself"));
  run = Adse({"submit", ok, "-o", out, "--dry-run", "--sbatch-arg=qos"});
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.output, HasSubstr("starting with '-'"));
  run = Adse({"submit", ok, "-o", out, "--dry-run", "--strategy", "annealing"});
  EXPECT_EQ(run.exit_code, 2);
  // Refused by the flag's own check, listing the strategies (the same list
  // as the scenario's exploration.strategy and --help).
  EXPECT_THAT(run.output, HasSubstr("--strategy: annealing not in "
                                    "{exhaustive,random,ga,nsga2,agent,llm}"));

  std::string bad = SmallScenarioIn(
      dir, "{strategy: exhaustive, budget: 2}",
      "{slurm: {time_limit: \"00:05:00\", signal_lead_s: 300}}");
  run = Adse({"submit", bad, "-o", out, "--dry-run"});
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.output, HasSubstr("harness.slurm.signal_lead_s"));
  EXPECT_THAT(run.output, HasSubstr("fewer than the 300 s of time_limit"));

  bad = SmallScenarioIn(dir, "{strategy: exhaustive, budget: 2}",
                        "{slurm: {extra_args: [--dependency=afterok:1]}}");
  run = Adse({"submit", bad, "-o", out, "--dry-run"});
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.output, HasSubstr("scenario.yaml:"));
  EXPECT_THAT(run.output, HasSubstr("harness.slurm.extra_args"));
  EXPECT_THAT(run.output, HasSubstr("is set by adse submit itself"));

  bad = SmallScenarioIn(dir, "{strategy: exhaustive, budget: 2}",
                        "{isolation: cgroup}");
  run = Adse({"submit", bad, "-o", out, "--dry-run"});
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.output, HasSubstr("harness.isolation: on Slurm"));

  // A sweep plans its points before any run ends: no confirm phase.
  bad = SmallScenarioIn(dir, "{strategy: random, budget: 2, confirm_runs: 3}",
                        "{}");
  run = Adse({"submit", bad, "-o", out, "--dry-run"});
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.output, HasSubstr("scenario.yaml:"));
  EXPECT_THAT(run.output,
              HasSubstr("exploration.confirm_runs: a sweep (random) plans "
                        "its points before any run ends"));
  run = Adse({"submit", ok, "-o", out, "--dry-run", "--confirm-runs", "2"});
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.output, HasSubstr("exploration.confirm_runs"));
  EXPECT_FALSE(fs::exists(out));
}

TEST(SubmitTest, ShardIndexAndStatusRefuseFoldersTheyCannotUse) {
  const TestFolder folder("no-plan");
  const std::string& dir = folder.path();
  fs::create_directories(dir + "/campaign/runs");
  AdseRun run = Adse({"shard", dir + "/campaign", "--task", "0"});
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("no sweep plan"));
  run = Adse({"index", dir + "/campaign"});
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("no sweep plan"));
  run = Adse({"shard", dir + "/campaign"}, {"SLURM_ARRAY_TASK_ID="});
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("SLURM_ARRAY_TASK_ID is not set"));
  run = Adse({"status", dir + "/elsewhere"});
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("elsewhere: no such folder"));
  fs::create_directories(dir + "/elsewhere");
  run = Adse({"status", dir + "/elsewhere"});
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("not a campaign folder"));
  // A folder with nothing yet: all zero, no Slurm jobs.
  run = Adse({"status", dir + "/campaign", "--json"});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json j = nlohmann::json::parse(run.output);
  EXPECT_EQ(j["kind"], "local");
  EXPECT_EQ(j["counts"]["done"], 0);
  EXPECT_TRUE(j["jobs"].empty());
}

}  // namespace
}  // namespace adse::slurm::testing
