// sbatch scripts as adse writes them, and the supervising body that passes
// Slurm's signals on to adse — run here with bash, without Slurm.
#include "harness/slurm/batch_script.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "stack/base/files.h"
#include "stack/base/subprocess.h"
#include "tests/testing/temp_files.h"

namespace adse::slurm {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

TEST(BatchScriptTest, RendersHeaderDirectivesAndBody) {
  BatchScript script;
  script.header = {"what it is", "", "how to follow it"};
  script.directives = {"--time=01:00:00", "--output=/a b/x-%j.out"};
  script.body = {"set -u", "echo hi"};
  EXPECT_EQ(RenderScript(script),
            "#!/bin/bash\n# what it is\n#\n# how to follow it\n"
            "#SBATCH --time=01:00:00\n#SBATCH --output=\"/a b/x-%j.out\"\n\n"
            "set -u\necho hi\n");
}

TEST(BatchScriptTest, ShellQuoteLeavesPlainWordsAndQuotesTheRest) {
  EXPECT_EQ(ShellQuote("/work/results/robotaxi-small"),
            "/work/results/robotaxi-small");
  EXPECT_EQ(ShellQuote("a b"), "'a b'");
  EXPECT_EQ(ShellQuote("it's"), "'it'\\''s'");
  EXPECT_EQ(ShellQuote("$HOME"), "'$HOME'");
  EXPECT_EQ(ShellQuote(""), "''");
}

// Runs a supervised body around `child` in bash; returns its output.
struct Supervised {
  pid_t pid = -1;
  std::string dir;
  std::string Output() const { return ReadFile(dir + "/out").value(); }
};

Supervised StartSupervised(const std::string& name, const std::string& child) {
  Supervised s;
  s.dir = adse::testing::FreshTempDir("adse-supervised", name);
  BatchScript script;
  // scontrol stands in for Slurm's: it records what it was asked.
  script.body = {"scontrol() { echo \"scontrol $*\"; }",
                 "SLURM_RESTART_COUNT=0"};
  for (const std::string& line : SupervisedBody(child, "$SLURM_JOB_ID", 10)) {
    script.body.push_back(line);
  }
  std::ofstream(s.dir + "/job.sh") << RenderScript(script);
  s.pid = ::fork();
  if (s.pid == 0) {
    ::setenv("SLURM_JOB_ID", "77", 1);
    const std::string out = s.dir + "/out";
    ::execl("/bin/bash", "bash", "-c",
            ("exec bash " + s.dir + "/job.sh > " + out + " 2>&1").c_str(),
            nullptr);
    ::_exit(127);
  }
  return s;
}

int WaitExit(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

void WaitForText(const Supervised& s, const std::string& text) {
  for (int i = 0; i < 500; ++i) {
    Result<std::string> out = ReadFile(s.dir + "/out");
    if (out.ok() && out->find(text) != std::string::npos) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  FAIL() << "no '" << text << "' in " << ReadFile(s.dir + "/out").value();
}

// A stand-in for adse: reports the signals it gets, exits as adse would.
// (Not bash: a background job of a non-interactive shell starts with
// SIGINT ignored, which bash cannot trap but adse, like Python, can.)
const char* kChild =
    "python3 -c '\n"
    "import signal, sys, time\n"
    "def stop(sig, code):\n"
    "    print(\"child:\", sig, flush=True); time.sleep(0.2); sys.exit(code)\n"
    "signal.signal(signal.SIGUSR1, lambda s, f: stop(\"USR1\", 138))\n"
    "signal.signal(signal.SIGINT, lambda s, f: stop(\"INT\", 130))\n"
    "signal.signal(signal.SIGTERM, lambda s, f: stop(\"TERM\", 143))\n"
    "print(\"child: started\", flush=True)\n"
    "while True: time.sleep(0.05)\n"
    "'";

TEST(BatchScriptTest, TheTimeLimitWarningReachesAdseAndTheJobRequeues) {
  Supervised s = StartSupervised("usr1", kChild);
  WaitForText(s, "child: started");
  ::kill(s.pid, SIGUSR1);  // what --signal=B:USR1@... does
  EXPECT_EQ(WaitExit(s.pid), 138);
  const std::string out = s.Output();
  EXPECT_THAT(out, HasSubstr("child: USR1"));
  EXPECT_THAT(out, HasSubstr("adse: exit status 138"));
  EXPECT_THAT(out, HasSubstr("scontrol requeue 77"));
}

TEST(BatchScriptTest, SigtermToTheShellReachesAdseAsSigintWithoutRequeue) {
  Supervised s = StartSupervised("term", kChild);
  WaitForText(s, "child: started");
  ::kill(s.pid, SIGTERM);  // what scancel does to the batch shell
  EXPECT_EQ(WaitExit(s.pid), 130);
  const std::string out = s.Output();
  EXPECT_THAT(out, HasSubstr("child: INT"));
  EXPECT_THAT(out, ::testing::Not(HasSubstr("child: TERM")));
  EXPECT_THAT(out, ::testing::Not(HasSubstr("scontrol requeue")));
}

TEST(BatchScriptTest, TheExitStatusOfAdseIsTheJobs) {
  Supervised s = StartSupervised("exit", "bash -c 'exit 3'");
  EXPECT_EQ(WaitExit(s.pid), 3);
  EXPECT_THAT(s.Output(), HasSubstr("adse: exit status 3"));
}

}  // namespace
}  // namespace adse::slurm
