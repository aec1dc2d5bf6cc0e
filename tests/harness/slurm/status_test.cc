// `adse status` of a local campaign, read from folders laid out as a
// campaign leaves them: its own runs counted by the keys its views list,
// the points it is running, views left by a process that is gone, and a
// campaign that stopped before its end.
#include "harness/slurm/status.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "tests/harness/slurm/testing/adse_commands.h"

namespace adse::slurm::testing {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

std::string Key(char c) { return std::string(64, c); }

void Touch(const std::string& path, const std::string& text = "") {
  std::ofstream(path) << text;
}

// A campaign folder: summary.json as given, a run file per key in `runs`,
// a failure record per key in `failures`, and a lock naming `holder`.
void LayOut(const std::string& folder, const json& summary,
            const std::vector<std::string>& runs,
            const std::vector<std::string>& failures,
            const std::string& holder) {
  std::filesystem::create_directories(folder + "/runs");
  Touch(folder + "/summary.json", summary.dump(2));
  for (const std::string& key : runs) Touch(folder + "/runs/" + key + ".h5");
  for (const std::string& key : failures) {
    Touch(folder + "/runs/" + key + ".failed.json", "{}");
  }
  Touch(folder + "/.lock", holder);
}

json Evaluation(const std::string& key) {
  return {{"content_key", key}, {"point_text", "cores=" + key.substr(0, 1)}};
}

std::string Here() {
  char host[256] = {};
  ::gethostname(host, sizeof(host) - 1);
  return host;
}

// The pid of a process that has ended (and been reaped).
pid_t GonePid() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return pid;
}

TEST(StatusTest, AFinishedCampaignCountsItsOwnRunsAndNotesTheOthers) {
  const TestFolder folder("status-others");
  const json summary = {
      {"scenario", "small"},
      {"scenario_file", "small.yaml"},
      {"strategy", "exhaustive"},
      {"budget", 3},
      {"replicas", 1},
      {"cases", 1},
      {"in_progress", false},
      {"complete", true},
      {"evaluations",
       {Evaluation(Key('a')), Evaluation(Key('b')), Evaluation(Key('c'))}}};
  // a and b ran, c failed; d and e are another scenario's run and failure.
  LayOut(folder.path(), summary, {Key('a'), Key('b'), Key('d')},
         {Key('c'), Key('e')}, "");
  Result<CampaignStatus> st = ReadCampaignStatus(folder.path());
  ASSERT_TRUE(st.ok()) << st.status().message();
  EXPECT_EQ(st->views, ViewsState::kComplete);
  EXPECT_EQ(st->total, 3);
  EXPECT_EQ(st->done, 2);
  EXPECT_EQ(st->failed, 1);
  EXPECT_EQ(st->running, 0);
  EXPECT_EQ(st->pending, 0);
  const std::string text = FormatStatus(*st);
  EXPECT_THAT(text, HasSubstr("runs: 2 done, 1 failed, 0 running, 0 pending "
                              "(of 3)"));
  EXPECT_THAT(text, HasSubstr("runs/ also holds 2 run file(s) that no "
                              "evaluation of this campaign uses"));
  EXPECT_THAT(text, HasSubstr("views: complete"));
}

TEST(StatusTest, ACampaignOnItsWayShowsItsRunningPointsAndWhatIsLeft) {
  const TestFolder folder("status-running");
  const json summary = {
      {"scenario", "small"},
      {"strategy", "agent"},
      {"budget", 4},
      {"confirm_runs", 3},
      {"replicas", 2},
      {"cases", 1},
      {"in_progress", true},
      {"complete", false},
      {"running", {"cores=16,freq_ghz=2.1"}},
      {"evaluations",
       {{{"content_key", Key('a')},
         {"runs",
          {{{"content_key", Key('a')}}, {{"content_key", Key('b')}}}}}}}};
  LayOut(folder.path(), summary, {Key('a'), Key('b')}, {},
         fmt::format("pid {} on {}\n", ::getpid(), Here()));
  Result<CampaignStatus> st = ReadCampaignStatus(folder.path());
  ASSERT_TRUE(st.ok()) << st.status().message();
  EXPECT_EQ(st->views, ViewsState::kInProgress);
  // Runs are counted: 4 points of 2 replicas each.
  EXPECT_EQ(st->total, 8);
  EXPECT_EQ(st->done, 2);
  EXPECT_EQ(st->running, 2);
  EXPECT_EQ(st->pending, 4);
  EXPECT_EQ(st->confirm_runs, 6);  // after the budget, at most
  const std::string text = FormatStatus(*st);
  EXPECT_THAT(text, HasSubstr("(of 8, and up to 6 confirm runs)"));
  EXPECT_THAT(text, HasSubstr("running points:\n  cores=16,freq_ghz=2.1\n"));
  EXPECT_THAT(text, HasSubstr("views: in progress"));
  const json j = json::parse(StatusJson(*st));
  EXPECT_EQ(j["views"], "in_progress");
  EXPECT_EQ(j["confirm_runs"], 6);
  EXPECT_EQ(j["running_points"], json::array({"cores=16,freq_ghz=2.1"}));
}

TEST(StatusTest, ViewsLeftInProgressByAProcessThatIsGoneSaySoAndRunNothing) {
  const TestFolder folder("status-abandoned");
  const json summary = {{"scenario", "small"},
                        {"strategy", "agent"},
                        {"budget", 3},
                        {"in_progress", true},
                        {"complete", false},
                        {"running", {"cores=4,freq_ghz=1"}},
                        {"evaluations", {Evaluation(Key('a'))}}};
  const std::string holder = fmt::format("pid {} on {}", GonePid(), Here());
  LayOut(folder.path(), summary, {Key('a')}, {}, holder + "\n");
  Result<CampaignStatus> st = ReadCampaignStatus(folder.path());
  ASSERT_TRUE(st.ok()) << st.status().message();
  EXPECT_EQ(st->views, ViewsState::kAbandoned);
  EXPECT_EQ(st->running, 0);
  EXPECT_TRUE(st->running_points.empty());
  EXPECT_EQ(st->pending, 2);
  EXPECT_THAT(FormatStatus(*st),
              HasSubstr("views: left in progress by a campaign that is no "
                        "longer running (" +
                        holder + ", gone): run `adse run` again"));

  // A holder on another host cannot be checked: taken as running.
  LayOut(folder.path(), summary, {Key('a')}, {},
         "pid 1 on not-" + Here() + "\n");
  st = ReadCampaignStatus(folder.path());
  ASSERT_TRUE(st.ok());
  EXPECT_EQ(st->views, ViewsState::kInProgress);
}

TEST(StatusTest, ACampaignThatStoppedBeforeItsEndSaysWhy) {
  const TestFolder folder("status-stopped");
  json summary = {
      {"scenario", "small"},        {"budget", 3},
      {"in_progress", false},       {"complete", false},
      {"interrupted_by_signal", 2}, {"evaluations", {Evaluation(Key('a'))}}};
  LayOut(folder.path(), summary, {Key('a')}, {}, "");
  Result<CampaignStatus> st = ReadCampaignStatus(folder.path());
  ASSERT_TRUE(st.ok());
  EXPECT_EQ(st->views, ViewsState::kStopped);
  EXPECT_THAT(FormatStatus(*st),
              HasSubstr("views: of a campaign that stopped before its end: "
                        "stopped by signal 2"));

  summary["interrupted_by_signal"] = 0;
  summary["stopped_because"] = "its first run was refused as bad input";
  LayOut(folder.path(), summary, {}, {}, "");
  st = ReadCampaignStatus(folder.path());
  ASSERT_TRUE(st.ok());
  EXPECT_EQ(st->stopped_because, "its first run was refused as bad input");
  EXPECT_EQ(json::parse(StatusJson(*st))["views"], "stopped");
}

TEST(StatusTest, ASummaryThatIsNoJsonIsSaidToBeUnreadable) {
  const TestFolder folder("status-garbage");
  LayOut(folder.path(), json::object(), {Key('a')}, {}, "");
  Touch(folder.path() + "/summary.json", "garbage");
  Result<CampaignStatus> st = ReadCampaignStatus(folder.path());
  ASSERT_TRUE(st.ok());
  EXPECT_EQ(st->views, ViewsState::kUnreadable);
  EXPECT_THAT(FormatStatus(*st),
              HasSubstr(": summary.json is no JSON object (damaged?)"));
  EXPECT_EQ(json::parse(StatusJson(*st))["views"], "unreadable");
}

}  // namespace
}  // namespace adse::slurm::testing
