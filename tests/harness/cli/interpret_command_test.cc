// `adse interpret` against a local server speaking the Ollama API: the
// model's scenario goes through `adse validate`, errors go back to it, the
// user is told which defaults were used, and nothing is written unless a
// valid scenario came.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "stack/base/files.h"
#include "tests/harness/llm/testing/fake_llm_server.h"
#include "tests/harness/testing/adse_command.h"
#include "tests/testing/temp_files.h"

namespace adse {
namespace {
namespace fs = std::filesystem;
using llm::testing::FakeAnswer;
using llm::testing::FakeLlmServer;
using testing::Adse;
using testing::CommandRun;
using ::testing::HasSubstr;

// The small robotaxi study without design space or objectives.
const char kValid[] = R"yaml(adse: 1
name: lot-study
world:
  map: {generate: parking_lot, params: {rows: 2, slots_per_row: 8}}
  traffic: {seed: 3, flows: [{from: E2_W2, to: W0_E0, vehicles_per_hour: 60}], parked_occupancy: 0.5}
task:
  start: {x: 8.0, y: -1.75}
  goal: {x: 10.0, y: 29.75}
  speed_limit_kmh: 30
  timeout_s: 300
platform: {kind: virtual, reference_ghz: 2.1, cost_model: counted, cost_scale: 30}
constraints: [nav_time_s <= 60, completed]
)yaml";

std::string TempDir(const std::string& name) {
  return testing::FreshTempDir("adse-interpret", name);
}

const char kRequest[] =
    "\"robotaxi from the lot entrance to the far aisle; cheapest computer that "
    "gets there "
    "within a minute\"";

TEST(InterpretCommandTest,
     ValidationErrorsGoBackToTheModelAndDefaultsAreNamed) {
  std::string without_task = kValid;
  without_task.erase(
      without_task.find("task:"),
      without_task.find("platform:") - without_task.find("task:"));
  Result<std::unique_ptr<FakeLlmServer>> server =
      FakeLlmServer::Start(FakeLlmServer::Sequence(
          {{200, without_task},
           {200, std::string(kValid) + "output: /etc/adse-evil\n"}}));
  ASSERT_TRUE(server.ok());
  const std::string dir = TempDir("ok");
  const CommandRun run =
      Adse(std::string("interpret ") + kRequest + " -o " + dir +
           "/study.yaml --model interp --endpoint " + (*server)->url());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_THAT(run.out, HasSubstr("default used: design_space"));
  EXPECT_THAT(run.out, HasSubstr("default used: objectives"));
  EXPECT_THAT(run.out, HasSubstr("dropped section 'output'"));
  EXPECT_THAT(run.out, HasSubstr("2 answers, 1 corrected"));

  // The second request told the model what the validator said.
  const std::vector<llm::testing::ReceivedRequest> requests =
      (*server)->requests();
  ASSERT_EQ(requests.size(), 2u);
  EXPECT_EQ(requests[0].model, "interp");
  EXPECT_THAT(requests[1].TextOf("user"),
              HasSubstr("adse's validator reports"));
  EXPECT_THAT(requests[1].TextOf("user"), HasSubstr("study.yaml"));
  EXPECT_THAT(requests[1].TextOf("user"), HasSubstr("task"));
  EXPECT_THAT(requests[1].TextOf("user"),
              ::testing::Not(HasSubstr("interpret-check")));

  // The file is a valid scenario with the defaults written out, and no
  // leftover from validation sits beside it.
  const CommandRun check = Adse("validate " + dir + "/study.yaml");
  EXPECT_EQ(check.exit_code, 0) << check.out;
  EXPECT_THAT(check.out, HasSubstr("design space: 30 points"));
  const std::string text = ReadFile(dir + "/study.yaml").value();
  EXPECT_THAT(text, HasSubstr("# Written by `adse interpret`"));
  EXPECT_THAT(text, ::testing::Not(HasSubstr("/etc/adse-evil")));
  std::set<std::string> files;
  for (const auto& e : fs::directory_iterator(dir))
    files.insert(e.path().filename().string());
  EXPECT_EQ(files,
            (std::set<std::string>{"study.yaml", "study.interpret.jsonl"}));

  // The recorded exchanges answer the same request again with no server.
  server->reset();
  fs::create_directories(dir + "/replayed");
  const CommandRun again =
      Adse(std::string("interpret ") + kRequest + " -o " + dir +
           "/replayed/study.yaml " +
           "--model interp --backend replay --replay-from " + dir +
           "/study.interpret.jsonl");
  ASSERT_EQ(again.exit_code, 0) << again.out;
  EXPECT_EQ(ReadFile(dir + "/replayed/study.yaml").value(), text);
  // Another request was never recorded: a clear error, nothing written.
  const CommandRun other = Adse(
      "interpret 'a grid town instead' -o " + dir + "/replayed/other.yaml " +
      "--model interp --backend replay --replay-from " + dir +
      "/study.interpret.jsonl");
  EXPECT_EQ(other.exit_code, 2) << other.out;
  EXPECT_THAT(other.out,
              HasSubstr("no recorded answer for this interpretation request"));
  EXPECT_FALSE(fs::exists(dir + "/replayed/other.yaml"));
  // Its exchanges were not recorded, so no file is named for them.
  EXPECT_FALSE(fs::exists(dir + "/replayed/other.interpret.jsonl"));
  EXPECT_THAT(other.out, ::testing::Not(HasSubstr("exchanges recorded in")));
}

TEST(InterpretCommandTest, ASectionGivenTwiceGoesBackToTheModel) {
  // YAML keeps the last of two equal keys; the model is told instead.
  Result<std::unique_ptr<FakeLlmServer>> server =
      FakeLlmServer::Start(FakeLlmServer::Sequence(
          {{200, std::string(kValid) + "task: {timeout_s: 5}\n"},
           {200, kValid}}));
  ASSERT_TRUE(server.ok());
  const std::string dir = TempDir("twice");
  const CommandRun run =
      Adse(std::string("interpret ") + kRequest + " -o " + dir +
           "/study.yaml --model interp --endpoint " + (*server)->url());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_THAT(run.out, HasSubstr("2 answers, 1 corrected"));
  const std::vector<llm::testing::ReceivedRequest> requests =
      (*server)->requests();
  ASSERT_EQ(requests.size(), 2u);
  EXPECT_THAT(requests[1].TextOf("user"),
              HasSubstr("gives the section 'task' twice (lines 6 and 13)"));
}

TEST(InterpretCommandTest, AModelThatNeverGetsItRightWritesNothing) {
  Result<std::unique_ptr<FakeLlmServer>> server = FakeLlmServer::Start(
      FakeLlmServer::Sequence({{200, "world: [unclosed"}}));
  ASSERT_TRUE(server.ok());
  const std::string dir = TempDir("never");
  const CommandRun run =
      Adse(std::string("interpret ") + kRequest + " -o " + dir +
           "/study.yaml --model interp " + "--max-corrections 1 --endpoint " +
           (*server)->url());
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_THAT(run.out, HasSubstr("no valid scenario in 2 answers"));
  EXPECT_THAT(run.out, HasSubstr("not valid YAML"));
  EXPECT_FALSE(fs::exists(dir + "/study.yaml"));
  EXPECT_EQ((*server)->requests().size(), 2u);
}

TEST(InterpretCommandTest, AFileItDidNotWriteIsNeverReplaced) {
  const std::string dir = TempDir("mine");
  std::ofstream(dir + "/study.yaml") << "my own scenario\n";
  // Refused before asking: the server has no answer to give.
  Result<std::unique_ptr<FakeLlmServer>> server =
      FakeLlmServer::Start(FakeLlmServer::Sequence({}));
  ASSERT_TRUE(server.ok());
  const CommandRun run =
      Adse(std::string("interpret ") + kRequest + " -o " + dir +
           "/study.yaml --model interp --endpoint " + (*server)->url());
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_THAT(run.out, HasSubstr("a file that is not a scenario adse "
                                 "interpret wrote is there"));
  EXPECT_TRUE((*server)->requests().empty());
  std::ifstream in(dir + "/study.yaml");
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "my own scenario");
}

TEST(InterpretCommandTest, AServerThatIsDownIsNamedWithWhatToStart) {
  const std::string dir = TempDir("down");
  const CommandRun run =
      Adse(std::string("interpret ") + kRequest + " -o " + dir +
           "/study.yaml --retries 0 --endpoint http://127.0.0.1:9");
  EXPECT_EQ(run.exit_code, 1) << run.out;
  EXPECT_THAT(run.out, HasSubstr("http://127.0.0.1:9"));
  EXPECT_THAT(run.out, HasSubstr("ollama serve"));
  EXPECT_FALSE(fs::exists(dir + "/study.yaml"));
}

TEST(InterpretCommandTest, AnEmptyRequestIsBadInput) {
  const CommandRun run = Adse("interpret '  '");
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_THAT(run.out, HasSubstr("the request is empty"));
}

}  // namespace
}  // namespace adse
