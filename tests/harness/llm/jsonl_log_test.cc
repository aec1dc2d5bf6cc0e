// The append-only JSON-lines records: a resumed session writes only the
// lines the file does not hold yet, a line cut short by a crash is dropped,
// and reading tells a crash's leftover from real corruption.
#include "harness/llm/jsonl_log.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/stack/base/testing/fault_injection_env.h"
#include "tests/testing/temp_files.h"

namespace adse::llm {
namespace {

namespace fs = std::filesystem;
using adse::testing::Slurp;
using adse::testing::WriteRaw;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::StartsWith;

std::string TempDir(const std::string& name) {
  return adse::testing::FreshTempDir("adse-llmunit-jsonl", name);
}

// Parses each line as {"n": <int>} and collects the numbers.
Status ReadNumbers(const std::string& path, std::vector<int>* numbers) {
  return ReadJsonLines(path, "a number record", [&](const std::string& line) {
    numbers->push_back(nlohmann::json::parse(line).at("n").get<int>());
  });
}

TEST(JsonlLogTest, AFreshLogCreatesItsFoldersAndAppendsEveryLine) {
  const std::string dir = TempDir("fresh");
  const std::string path = dir + "/campaign/llm/log.jsonl";
  Result<JsonlLog> log = JsonlLog::Open(path);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->path(), path);
  EXPECT_EQ(log->existing(), 0);
  EXPECT_TRUE(fs::is_directory(dir + "/campaign/llm"));
  EXPECT_FALSE(fs::exists(path));  // nothing written yet

  ASSERT_TRUE(log->Append(R"({"n":0})").ok());
  ASSERT_TRUE(log->Append(R"({"n":1})").ok());
  EXPECT_EQ(Slurp(path), "{\"n\":0}\n{\"n\":1}\n");
}

TEST(JsonlLogTest, AResumedSessionWritesOnlyTheLinesTheFileDoesNotHold) {
  const std::string path = TempDir("resume") + "/log.jsonl";
  WriteRaw(path, "{\"n\":0}\n{\"n\":1}\n");
  Result<JsonlLog> log = JsonlLog::Open(path);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->existing(), 2);

  // The same history again, then two new lines.
  for (int n = 0; n < 4; ++n) {
    ASSERT_TRUE(log->Append("{\"n\":" + std::to_string(n) + "}").ok());
  }
  EXPECT_EQ(Slurp(path), "{\"n\":0}\n{\"n\":1}\n{\"n\":2}\n{\"n\":3}\n");
}

TEST(JsonlLogTest, AppendNewWritesWhateverTheFileHoldsAndCountsTheLine) {
  const std::string path = TempDir("new") + "/log.jsonl";
  WriteRaw(path, "a\nb\n");
  Result<JsonlLog> log = JsonlLog::Open(path);
  ASSERT_TRUE(log.ok());
  ASSERT_TRUE(log->AppendNew("fresh").ok());  // session line 0, written anyway
  ASSERT_TRUE(log->Append("b again").ok());   // session line 1: held already
  ASSERT_TRUE(log->Append("c").ok());         // session line 2: new
  EXPECT_EQ(Slurp(path), "a\nb\nfresh\nc\n");
}

TEST(JsonlLogTest, TheRuleCountsLinesAndNeverRewritesOnesTheFileHolds) {
  const std::string path = TempDir("count") + "/log.jsonl";
  WriteRaw(path, "held\n");
  Result<JsonlLog> log = JsonlLog::Open(path);
  ASSERT_TRUE(log.ok());
  EXPECT_EQ(log->existing(), 1);
  ASSERT_TRUE(log->Append("first of this session").ok());
  ASSERT_TRUE(log->Append("second of this session").ok());
  EXPECT_EQ(Slurp(path), "held\nsecond of this session\n");
}

TEST(JsonlLogTest, EmptyLinesCountAsLinesTheFileHolds) {
  const std::string path = TempDir("empty-lines") + "/log.jsonl";
  WriteRaw(path, "a\n\nc\n");
  Result<JsonlLog> log = JsonlLog::Open(path);
  ASSERT_TRUE(log.ok());
  EXPECT_EQ(log->existing(), 3);
}

TEST(JsonlLogTest, OpenDropsALastLineCutShortSoTheNextAppendStartsAFreshLine) {
  const std::string path = TempDir("cut") + "/log.jsonl";
  WriteRaw(path, "{\"n\":0}\n{\"n\":1}\n{\"n\":");
  Result<JsonlLog> log = JsonlLog::Open(path);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->existing(), 2);
  EXPECT_EQ(Slurp(path), "{\"n\":0}\n{\"n\":1}\n");

  for (int n = 0; n < 3; ++n) {
    ASSERT_TRUE(log->Append("{\"n\":" + std::to_string(n) + "}").ok());
  }
  EXPECT_EQ(Slurp(path), "{\"n\":0}\n{\"n\":1}\n{\"n\":2}\n");
  std::vector<int> numbers;
  ASSERT_TRUE(ReadNumbers(path, &numbers).ok());
  EXPECT_THAT(numbers, ElementsAre(0, 1, 2));
}

TEST(JsonlLogTest, AFileHoldingOnlyACutShortLineIsEmptied) {
  const std::string path = TempDir("only-cut") + "/log.jsonl";
  WriteRaw(path, "{\"n\":7");
  Result<JsonlLog> log = JsonlLog::Open(path);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->existing(), 0);
  EXPECT_EQ(Slurp(path), "");
  ASSERT_TRUE(log->Append("{\"n\":0}").ok());
  EXPECT_EQ(Slurp(path), "{\"n\":0}\n");
}

TEST(JsonlLogTest, AnEmptyFileHoldsNoLines) {
  const std::string path = TempDir("empty-file") + "/log.jsonl";
  WriteRaw(path, "");
  Result<JsonlLog> log = JsonlLog::Open(path);
  ASSERT_TRUE(log.ok());
  EXPECT_EQ(log->existing(), 0);
  ASSERT_TRUE(log->Append("x").ok());
  EXPECT_EQ(Slurp(path), "x\n");
}

TEST(JsonlLogTest, AnEmptyPathRecordsNothing) {
  Result<JsonlLog> log = JsonlLog::Open("");
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->path(), "");
  EXPECT_EQ(log->existing(), 0);
  EXPECT_TRUE(log->Append("{\"n\":0}").ok());
  EXPECT_TRUE(log->Append("{\"n\":1}").ok());
  EXPECT_EQ(log->existing(), 0);
  // A default-constructed log is the same: it records nothing.
  JsonlLog none;
  EXPECT_TRUE(none.Append("x").ok());
  EXPECT_EQ(none.path(), "");
}

TEST(JsonlLogTest, OpenFailsWhenTheFolderCannotBeCreated) {
  const std::string dir = TempDir("not-a-folder");
  WriteRaw(dir + "/file", "I am a file\n");
  Result<JsonlLog> log = JsonlLog::Open(dir + "/file/llm/log.jsonl");
  ASSERT_FALSE(log.ok());
  EXPECT_EQ(log.status().code(), Status::Code::kIoError);
  EXPECT_THAT(log.status().message(), HasSubstr(dir + "/file/llm"));
}

TEST(JsonlLogTest, AFullDiskIsAnErrorAndTheHalfLineIsDroppedOnResume) {
  const std::string path = TempDir("full") + "/log.jsonl";
  adse::testing::FaultInjectionEnv env;
  env.Inject({.op = adse::testing::FaultOp::kAppendFile,
              .path_contains = "log.jsonl",
              .error = ENOSPC,
              .after = 1,
              .times = 1});
  Result<JsonlLog> log = JsonlLog::Open(path, &env);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_TRUE(log->Append(R"({"n":0})").ok());
  const Status full = log->Append(R"({"n":1})");
  ASSERT_FALSE(full.ok());
  EXPECT_THAT(full.message(), HasSubstr(path));
  EXPECT_THAT(full.message(), HasSubstr(std::strerror(ENOSPC)));

  // The disk wrote half a line; a resumed session drops it and writes the
  // line whole.
  Result<JsonlLog> resumed = JsonlLog::Open(path);
  ASSERT_TRUE(resumed.ok()) << resumed.status().ToString();
  EXPECT_EQ(resumed->existing(), 1);
  ASSERT_TRUE(resumed->Append(R"({"n":0})").ok());
  ASSERT_TRUE(resumed->Append(R"({"n":1})").ok());
  EXPECT_EQ(Slurp(path), "{\"n\":0}\n{\"n\":1}\n");
}

TEST(ReadJsonLinesTest, AMissingFileHasNoLines) {
  const std::string path = TempDir("read-missing") + "/absent.jsonl";
  int calls = 0;
  Status s =
      ReadJsonLines(path, "anything", [&](const std::string&) { ++calls; });
  EXPECT_TRUE(s.ok()) << s.ToString();
  EXPECT_EQ(calls, 0);
  EXPECT_FALSE(fs::exists(path));
}

TEST(ReadJsonLinesTest, ParsesEveryNonEmptyLineInOrder) {
  const std::string path = TempDir("read-all") + "/log.jsonl";
  WriteRaw(path, "{\"n\":3}\n\n{\"n\":1}\n{\"n\":2}\n");
  std::vector<int> numbers;
  Status s = ReadNumbers(path, &numbers);
  ASSERT_TRUE(s.ok()) << s.ToString();
  EXPECT_THAT(numbers, ElementsAre(3, 1, 2));
}

TEST(ReadJsonLinesTest, SkipsALastLineCutShortByACrash) {
  const std::string path = TempDir("read-cut") + "/log.jsonl";
  WriteRaw(path, "{\"n\":1}\n{\"n\":2}\n{\"n\":");
  std::vector<int> numbers;
  Status s = ReadNumbers(path, &numbers);
  ASSERT_TRUE(s.ok()) << s.ToString();
  EXPECT_THAT(numbers, ElementsAre(1, 2));
}

TEST(ReadJsonLinesTest, ABadMiddleLineIsCorruptionNamingFileLineAndWhat) {
  const std::string path = TempDir("read-bad-middle") + "/log.jsonl";
  WriteRaw(path, "{\"n\":1}\n\nnot json\n{\"n\":4}\n");
  std::vector<int> numbers;
  Status s = ReadNumbers(path, &numbers);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), Status::Code::kCorruption);
  // Line 3: the empty line 2 counts.
  EXPECT_THAT(s.message(), StartsWith(path + ":3: not a number record ("));
  EXPECT_THAT(numbers, ElementsAre(1));
}

TEST(ReadJsonLinesTest, ALineParseRefusesIsCorruptionToo) {
  // Valid JSON without the fields `parse` needs.
  const std::string path = TempDir("read-bad-schema") + "/log.jsonl";
  WriteRaw(path, "{\"m\":1}\n{\"n\":2}\n");
  std::vector<int> numbers;
  Status s = ReadNumbers(path, &numbers);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), Status::Code::kCorruption);
  EXPECT_THAT(s.message(), StartsWith(path + ":1: not a number record ("));
  EXPECT_THAT(s.message(), HasSubstr("'n'"));
}

TEST(ReadJsonLinesTest, AnyExceptionFromParseMarksTheLineBad) {
  const std::string path = TempDir("read-throw") + "/log.jsonl";
  WriteRaw(path, "ok\nbad\nok\n");
  Status s = ReadJsonLines(path, "a word", [](const std::string& line) {
    if (line != "ok") throw std::runtime_error("expected ok");
  });
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), Status::Code::kCorruption);
  EXPECT_EQ(s.message(), path + ":2: not a word (expected ok)");
}

TEST(ReadJsonLinesTest, ACompleteBadLastLineIsCorruptionNotACrashLeftover) {
  // A crash leaves a last line without its newline; a bad line that was
  // written whole is corruption, wherever it is. (JsonlLog::Open counts it
  // as a line the file holds, so skipping it would lose the exchange a
  // resumed session makes in its place.)
  const std::string path = TempDir("read-bad-last") + "/log.jsonl";
  WriteRaw(path, "{\"n\":1}\ngarbage\n");
  std::vector<int> numbers;
  Status s = ReadNumbers(path, &numbers);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), Status::Code::kCorruption);
  EXPECT_THAT(s.message(), StartsWith(path + ":2: not a number record ("));
}

TEST(ReadJsonLinesTest, ReadsWhatJsonlLogWrote) {
  const std::string path = TempDir("round-trip") + "/sub/log.jsonl";
  Result<JsonlLog> log = JsonlLog::Open(path);
  ASSERT_TRUE(log.ok());
  for (int n : {5, 6, 7}) {
    ASSERT_TRUE(log->Append("{\"n\":" + std::to_string(n) + "}").ok());
  }
  std::vector<int> numbers;
  ASSERT_TRUE(ReadNumbers(path, &numbers).ok());
  EXPECT_THAT(numbers, ElementsAre(5, 6, 7));
  // A resumed log counts them all.
  Result<JsonlLog> again = JsonlLog::Open(path);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->existing(), 3);
}

}  // namespace
}  // namespace adse::llm
