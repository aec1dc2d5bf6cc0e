// The record of every exchange with a model and its replay: what is
// recorded, what is replayed for which request, and how a resumed session
// continues its own record without duplicating it.
#include "harness/llm/exchange_log.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "stack/base/hash.h"
#include "tests/harness/llm/testing/scripted_backend.h"
#include "tests/testing/temp_files.h"

namespace adse::llm {
namespace {

namespace fs = std::filesystem;
using adse::testing::Slurp;
using adse::testing::WriteRaw;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using testing::ScriptedBackend;
using ::testing::StartsWith;

std::string TempDir(const std::string& name) {
  return adse::testing::FreshTempDir("adse-llmunit-exchange", name);
}

std::vector<std::string> Lines(const std::string& path) {
  std::vector<std::string> lines;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

ChatRequest Request(const std::string& user = "next point?",
                    const std::string& agent = "dse") {
  ChatRequest r;
  r.agent = agent;
  r.model = "qwen3:8b";
  r.messages = {{"system", "You explore a design space.", {}},
                {"user", user, {}}};
  return r;
}

JsonlLog OpenLog(const std::string& path) {
  Result<JsonlLog> log = JsonlLog::Open(path);
  EXPECT_TRUE(log.ok()) << log.status().ToString();
  return log.ok() ? std::move(*log) : JsonlLog();
}

// A live backend that answers "<prefix><k>" to its k-th request (0-based).
std::unique_ptr<ScriptedBackend> Counting(const std::string& prefix,
                                          int* calls) {
  return std::make_unique<ScriptedBackend>(
      [prefix, calls](const ChatRequest&) -> Result<ChatReply> {
        return ScriptedBackend::Reply(prefix + std::to_string((*calls)++));
      });
}

// Records `answers.size()` exchanges of `requests[k]` -> answers[k] into
// `path` (empty: nowhere) and returns the session.
std::vector<ExchangeRecord> RecordSession(
    const std::string& path, const std::vector<ChatRequest>& requests,
    const std::vector<std::string>& answers) {
  size_t next = 0;
  RecordingBackend backend(
      {},
      std::make_unique<ScriptedBackend>(
          [&](const ChatRequest&) -> Result<ChatReply> {
            return ScriptedBackend::Reply(answers.at(next++));
          }),
      OpenLog(path), "");
  for (const ChatRequest& r : requests) {
    Result<ChatReply> reply = backend.Chat(r);
    EXPECT_TRUE(reply.ok()) << reply.status().ToString();
  }
  return backend.session();
}

void ExpectSameRecord(const ExchangeRecord& a, const ExchangeRecord& b) {
  EXPECT_EQ(a.seq, b.seq);
  EXPECT_EQ(a.iteration, b.iteration);
  EXPECT_EQ(a.agent, b.agent);
  EXPECT_EQ(a.model, b.model);
  EXPECT_EQ(a.backend, b.backend);
  EXPECT_EQ(a.request_sha256, b.request_sha256);
  EXPECT_EQ(a.prompt, b.prompt);
  EXPECT_EQ(a.image_sha256, b.image_sha256);
  EXPECT_EQ(a.ok, b.ok);
  EXPECT_EQ(a.answer, b.answer);
  EXPECT_EQ(a.error_code, b.error_code);
  EXPECT_EQ(a.error, b.error);
  EXPECT_EQ(a.prompt_tokens, b.prompt_tokens);
  EXPECT_EQ(a.completion_tokens, b.completion_tokens);
  EXPECT_EQ(a.latency_s, b.latency_s);
  EXPECT_EQ(a.attempts, b.attempts);
}

// --- RequestHash and Transcript ------------------------------------------

TEST(RequestHashTest, IsTheSameForEqualRequestsAndPinned) {
  ChatRequest a = Request(), b = Request();
  a.messages[1].images_png = {std::string("\x89PNG\r\n\x1a\n", 8)};
  b.messages[1].images_png = {std::string("\x89PNG\r\n\x1a\n", 8)};
  EXPECT_EQ(RequestHash(a), RequestHash(b));
  EXPECT_EQ(RequestHash(a), RequestHash(a));
  // A recorded campaign must keep replaying with a newer adse: the hash of
  // a fixed request never changes.
  EXPECT_EQ(RequestHash(Request()),
            "2f7b1768cff00f5ad58bea3674587b300897cbc04ef32aed30f0c0e07e1baca1");
  const std::string h = RequestHash(a);
  EXPECT_EQ(h.size(), 64u);
  EXPECT_EQ(h.find_first_not_of("0123456789abcdef"), std::string::npos);
}

TEST(RequestHashTest, DiffersByEveryPartOfTheRequest) {
  const ChatRequest base = Request();
  std::vector<ChatRequest> variants;
  auto vary = [&](auto change) {
    ChatRequest r = base;
    change(r);
    variants.push_back(r);
  };
  vary([](ChatRequest& r) { r.agent = "command"; });
  vary([](ChatRequest& r) { r.model = "qwen3:14b"; });
  vary([](ChatRequest& r) { r.json = false; });
  vary([](ChatRequest& r) { r.messages[0].role = "user"; });
  vary([](ChatRequest& r) { r.messages[1].text = "next point!"; });
  vary([](ChatRequest& r) { r.messages[1].images_png = {"png-1"}; });
  vary([](ChatRequest& r) { r.messages[1].images_png = {"png-2"}; });
  vary([](ChatRequest& r) { r.messages[1].images_png = {"png-1", "png-1"}; });
  vary([](ChatRequest& r) { r.messages[0].images_png = {"png-1"}; });
  vary([](ChatRequest& r) { r.messages.pop_back(); });
  vary([](ChatRequest& r) { r.messages.push_back({"assistant", "", {}}); });
  vary([](ChatRequest& r) { std::swap(r.messages[0], r.messages[1]); });
  // The same characters split differently between parts.
  vary([](ChatRequest& r) {
    r.messages[0].text += "next";
    r.messages[1].text = " point?";
  });
  vary([](ChatRequest& r) {
    r.agent = "dseq";
    r.model = "wen3:8b";
  });

  std::set<std::string> hashes = {RequestHash(base)};
  for (size_t i = 0; i < variants.size(); ++i) {
    EXPECT_NE(RequestHash(variants[i]), RequestHash(base)) << "variant " << i;
    hashes.insert(RequestHash(variants[i]));
  }
  EXPECT_EQ(hashes.size(), variants.size() + 1);
}

TEST(TranscriptTest, ShowsEachMessageWithItsRoleAndImageSizes) {
  ChatRequest r = Request("Look at this.");
  r.messages[1].images_png = {"1234", "123456"};
  EXPECT_EQ(Transcript(r),
            "[system]\nYou explore a design space.\n\n"
            "[user]\nLook at this.\n"
            "[image 1: 4 bytes PNG]\n[image 2: 6 bytes PNG]");
  EXPECT_EQ(Transcript(ChatRequest()), "");
}

TEST(ExchangesPathTest, IsInTheCampaignsLlmFolder) {
  EXPECT_EQ(ExchangesPath("/runs/c1"), "/runs/c1/llm/exchanges.jsonl");
}

// --- Recording live exchanges --------------------------------------------

TEST(RecordingBackendTest, RecordsALiveAnswerWithEveryField) {
  const std::string path = TempDir("live-answer") + "/llm/exchanges.jsonl";
  auto live = std::make_unique<ScriptedBackend>(
      [](const ChatRequest&) -> Result<ChatReply> {
        ChatReply reply = ScriptedBackend::Reply(R"({"point": {}})");
        reply.attempts = 2;
        return reply;
      });
  ScriptedBackend* scripted = live.get();
  RecordingBackend backend({}, std::move(live), OpenLog(path), "");
  EXPECT_EQ(backend.name(), "scripted");
  backend.set_iteration(4);

  ChatRequest request = Request("What do you see?", "vision");
  request.messages[1].images_png = {"png-bytes"};
  Result<ChatReply> reply = backend.Chat(request);
  ASSERT_TRUE(reply.ok()) << reply.status().ToString();
  EXPECT_EQ(reply->text, R"({"point": {}})");
  EXPECT_EQ(reply->attempts, 2);
  ASSERT_EQ(scripted->requests().size(), 1u);
  EXPECT_EQ(scripted->requests()[0].messages[1].text, "What do you see?");

  ASSERT_EQ(backend.session().size(), 1u);
  EXPECT_EQ(backend.replayed(), 0);
  const ExchangeRecord& r = backend.session()[0];
  EXPECT_EQ(r.seq, 0);
  EXPECT_EQ(r.iteration, 4);
  EXPECT_EQ(r.agent, "vision");
  EXPECT_EQ(r.model, "qwen3:8b");
  EXPECT_EQ(r.backend, "scripted");
  EXPECT_EQ(r.request_sha256, RequestHash(request));
  EXPECT_EQ(r.prompt, Transcript(request));
  EXPECT_THAT(r.image_sha256, ElementsAre(Sha256Hex("png-bytes")));
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(r.answer, R"({"point": {}})");
  EXPECT_EQ(r.error_code, "");
  EXPECT_EQ(r.error, "");
  EXPECT_EQ(r.prompt_tokens, 10);
  EXPECT_EQ(r.completion_tokens, 5);
  EXPECT_EQ(r.latency_s, 0.01);
  EXPECT_EQ(r.attempts, 2);

  // The file holds the same record.
  Result<std::vector<ExchangeRecord>> loaded = LoadExchanges(path);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  ASSERT_EQ(loaded->size(), 1u);
  ExpectSameRecord((*loaded)[0], r);
  EXPECT_EQ(Lines(path).size(), 1u);
}

TEST(RecordingBackendTest, RecordsALiveErrorWithItsCodeAndMessage) {
  const std::string path = TempDir("live-error") + "/exchanges.jsonl";
  RecordingBackend backend(
      {},
      std::make_unique<ScriptedBackend>(
          [](const ChatRequest&) -> Result<ChatReply> {
            return Status::Unavailable(
                "http://127.0.0.1:11434: connection refused");
          }),
      OpenLog(path), "");
  Result<ChatReply> reply = backend.Chat(Request());
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kUnavailable);
  EXPECT_EQ(reply.status().message(),
            "http://127.0.0.1:11434: connection refused");

  ASSERT_EQ(backend.session().size(), 1u);
  const ExchangeRecord& r = backend.session()[0];
  EXPECT_EQ(r.seq, 0);
  EXPECT_EQ(r.iteration, -1);
  EXPECT_EQ(r.agent, "dse");
  EXPECT_EQ(r.backend, "scripted");
  EXPECT_EQ(r.request_sha256, RequestHash(Request()));
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.answer, "");
  EXPECT_EQ(r.error_code, "unavailable");
  EXPECT_EQ(r.error, "http://127.0.0.1:11434: connection refused");
  EXPECT_EQ(r.prompt_tokens, -1);
  EXPECT_EQ(r.completion_tokens, -1);
  EXPECT_EQ(r.attempts, 0);

  Result<std::vector<ExchangeRecord>> loaded = LoadExchanges(path);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  ASSERT_EQ(loaded->size(), 1u);
  ExpectSameRecord((*loaded)[0], r);
}

TEST(RecordingBackendTest, NumbersExchangesAndStampsTheIteration) {
  const std::string path = TempDir("seq") + "/exchanges.jsonl";
  int calls = 0;
  RecordingBackend backend({}, Counting("a", &calls), OpenLog(path), "");
  ASSERT_TRUE(backend.Chat(Request("one")).ok());
  backend.set_iteration(0);
  ASSERT_TRUE(backend.Chat(Request("two")).ok());
  backend.set_iteration(1);
  ASSERT_TRUE(backend.Chat(Request("three")).ok());
  Result<std::vector<ExchangeRecord>> loaded = LoadExchanges(path);
  ASSERT_TRUE(loaded.ok());
  ASSERT_EQ(loaded->size(), 3u);
  for (int64_t k = 0; k < 3; ++k) {
    EXPECT_EQ((*loaded)[k].seq, k);
    EXPECT_EQ((*loaded)[k].iteration, k - 1);
    EXPECT_EQ((*loaded)[k].answer, "a" + std::to_string(k));
  }
}

TEST(RecordingBackendTest, WithoutALogRecordsTheSessionOnly) {
  int calls = 0;
  RecordingBackend backend({}, Counting("a", &calls), JsonlLog(), "");
  ASSERT_TRUE(backend.Chat(Request()).ok());
  EXPECT_EQ(backend.session().size(), 1u);
}

// --- Replay ------------------------------------------------------------

TEST(RecordingBackendTest,
     ReplaysIdenticalRequestsWithTheRecordedAnswersInOrder) {
  const std::vector<ExchangeRecord> recorded =
      RecordSession("", {Request(), Request("other"), Request()},
                    {"first", "other answer", "second"});
  ASSERT_EQ(recorded.size(), 3u);

  int live_calls = 0;
  RecordingBackend backend(recorded, Counting("live", &live_calls), JsonlLog(),
                           "");
  Result<ChatReply> a = backend.Chat(Request());
  Result<ChatReply> b = backend.Chat(Request());
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->text, "first");
  EXPECT_EQ(b->text, "second");
  // Replayed replies carry the recorded numbers.
  EXPECT_EQ(a->prompt_tokens, 10);
  EXPECT_EQ(a->completion_tokens, 5);
  EXPECT_EQ(a->latency_s, 0.01);
  EXPECT_EQ(live_calls, 0);
  EXPECT_EQ(backend.replayed(), 2);

  // The record of this request is used up: the live backend answers.
  Result<ChatReply> c = backend.Chat(Request());
  ASSERT_TRUE(c.ok());
  EXPECT_EQ(c->text, "live0");
  EXPECT_EQ(live_calls, 1);
  EXPECT_EQ(backend.replayed(), 2);

  // The other request is still recorded.
  Result<ChatReply> d = backend.Chat(Request("other"));
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d->text, "other answer");
  EXPECT_EQ(backend.replayed(), 3);

  ASSERT_EQ(backend.session().size(), 4u);
  EXPECT_EQ(backend.session()[2].backend, "scripted");
  EXPECT_EQ(backend.session()[2].answer, "live0");
  for (int64_t k = 0; k < 4; ++k) EXPECT_EQ(backend.session()[k].seq, k);
}

TEST(RecordingBackendTest, AReplayedExchangeKeepsWhoAnsweredOriginally) {
  const std::vector<ExchangeRecord> recorded =
      RecordSession("", {Request()}, {"answer"});
  RecordingBackend backend(recorded, nullptr, JsonlLog(), "source.jsonl");
  EXPECT_EQ(backend.name(), "replay");
  backend.set_iteration(9);
  ASSERT_TRUE(backend.Chat(Request()).ok());
  const ExchangeRecord& r = backend.session()[0];
  EXPECT_EQ(r.backend, "scripted");
  EXPECT_EQ(r.iteration, 9);
  EXPECT_EQ(r.answer, "answer");
  EXPECT_EQ(r.attempts, recorded[0].attempts);
  EXPECT_EQ(r.request_sha256, recorded[0].request_sha256);
  EXPECT_EQ(r.prompt, recorded[0].prompt);
}

TEST(RecordingBackendTest, ReplaysARecordedErrorAsTheSameCodeAndMessage) {
  const Status errors[] = {
      Status::InvalidArgument("HTTP 400: model 'x' not found"),
      Status::NotFound("no such thing"),
      Status::Corruption("answer is not JSON"),
      Status::IoError("disk full"),
      Status::Unavailable("http://127.0.0.1:11434: timed out"),
      Status::Internal("a bug"),
  };
  const std::string path = TempDir("replay-errors") + "/exchanges.jsonl";
  {
    size_t next = 0;
    RecordingBackend backend({},
                             std::make_unique<ScriptedBackend>(
                                 [&](const ChatRequest&) -> Result<ChatReply> {
                                   return errors[next++];
                                 }),
                             OpenLog(path), "");
    for (size_t k = 0; k < std::size(errors); ++k) {
      EXPECT_FALSE(backend.Chat(Request("q" + std::to_string(k))).ok());
    }
  }
  Result<std::vector<ExchangeRecord>> recorded = LoadExchanges(path);
  ASSERT_TRUE(recorded.ok()) << recorded.status().ToString();
  ASSERT_EQ(recorded->size(), std::size(errors));
  EXPECT_EQ((*recorded)[0].error_code, "invalid_argument");
  EXPECT_EQ((*recorded)[1].error_code, "not_found");
  EXPECT_EQ((*recorded)[2].error_code, "corruption");
  EXPECT_EQ((*recorded)[3].error_code, "io_error");
  EXPECT_EQ((*recorded)[4].error_code, "unavailable");
  EXPECT_EQ((*recorded)[5].error_code, "internal");

  RecordingBackend replay(std::move(*recorded), nullptr, JsonlLog(), path);
  for (size_t k = 0; k < std::size(errors); ++k) {
    Result<ChatReply> reply = replay.Chat(Request("q" + std::to_string(k)));
    ASSERT_FALSE(reply.ok()) << k;
    EXPECT_EQ(reply.status().code(), errors[k].code()) << k;
    EXPECT_EQ(reply.status().message(), errors[k].message()) << k;
    EXPECT_FALSE(replay.session()[k].ok);
    EXPECT_EQ(replay.session()[k].error, errors[k].message());
  }
  EXPECT_EQ(replay.replayed(), static_cast<int>(std::size(errors)));
}

TEST(RecordingBackendTest, ARecordedErrorWithoutAMessageSaysWhichRecord) {
  std::vector<ExchangeRecord> recorded =
      RecordSession("", {Request()}, {"answer"});
  recorded[0].ok = false;
  recorded[0].answer.clear();
  recorded[0].error_code = "unavailable";
  recorded[0].error.clear();  // a hand-edited "ok": false
  RecordingBackend replay(std::move(recorded), nullptr, JsonlLog(), "x");
  Result<ChatReply> reply = replay.Chat(Request());
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kUnavailable);
  EXPECT_EQ(reply.status().message(),
            "the recorded exchange 0 (dse agent) failed, and its record says "
            "no more");
}

TEST(RecordingBackendTest,
     ReplayOnlyRefusesAnUnrecordedRequestNamingTheSource) {
  const std::vector<ExchangeRecord> recorded =
      RecordSession("", {Request()}, {"recorded"});
  const std::string path = TempDir("replay-only") + "/exchanges.jsonl";
  RecordingBackend backend(recorded, nullptr, OpenLog(path),
                           "/campaigns/old/llm/exchanges.jsonl");

  const ChatRequest unrecorded = Request("something else", "command");
  Result<ChatReply> reply = backend.Chat(unrecorded);
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kNotFound);
  const std::string& m = reply.status().message();
  EXPECT_THAT(m, HasSubstr("no recorded answer for this command request"));
  EXPECT_THAT(m, HasSubstr("model qwen3:8b"));
  EXPECT_THAT(m, HasSubstr("request " + RequestHash(unrecorded).substr(0, 12)));
  EXPECT_THAT(m, HasSubstr("in /campaigns/old/llm/exchanges.jsonl"));
  // A broken replay is not an exchange: nothing is recorded.
  EXPECT_TRUE(backend.session().empty());
  EXPECT_FALSE(fs::exists(path));

  // The same text from another agent is another request.
  Result<ChatReply> other_agent = backend.Chat(Request("next point?", "text"));
  EXPECT_EQ(other_agent.status().code(), Status::Code::kNotFound);

  // The recorded request is still answered, as the session's first
  // exchange.
  Result<ChatReply> ok = backend.Chat(Request());
  ASSERT_TRUE(ok.ok()) << ok.status().ToString();
  EXPECT_EQ(ok->text, "recorded");
  ASSERT_EQ(backend.session().size(), 1u);
  EXPECT_EQ(backend.session()[0].seq, 0);
  Result<std::vector<ExchangeRecord>> logged = LoadExchanges(path);
  ASSERT_TRUE(logged.ok());
  ASSERT_EQ(logged->size(), 1u);
  EXPECT_EQ((*logged)[0].seq, 0);
}

// --- Resuming and replaying into a record --------------------------------

TEST(RecordingBackendTest,
     AResumedSessionThatAsksSomethingNewRecordsItEvenBeforeTheLogsEnd) {
  const std::string path = TempDir("diverge") + "/llm/exchanges.jsonl";
  {
    int calls = 0;
    RecordingBackend first({}, Counting("a", &calls), OpenLog(path), "");
    ASSERT_TRUE(first.Chat(Request("one")).ok());
    ASSERT_TRUE(first.Chat(Request("two")).ok());
  }
  JsonlLog log = OpenLog(path);
  Result<std::vector<ExchangeRecord>> recorded = LoadExchanges(path);
  ASSERT_TRUE(recorded.ok());
  int live_calls = 0;
  RecordingBackend second(std::move(*recorded), Counting("b", &live_calls),
                          std::move(log), path);
  // The session's first request is not the recorded one: a live answer,
  // which the log must keep although it holds two lines already.
  Result<ChatReply> other = second.Chat(Request("other"));
  ASSERT_TRUE(other.ok());
  EXPECT_EQ(other->text, "b0");
  Result<std::vector<ExchangeRecord>> all = LoadExchanges(path);
  ASSERT_TRUE(all.ok());
  ASSERT_EQ(all->size(), 3u);
  EXPECT_EQ((*all)[2].answer, "b0");
}

TEST(RecordingBackendTest,
     AResumedSessionReplaysItsRecordAndAppendsOnlyNewExchanges) {
  const std::string path = TempDir("resume") + "/llm/exchanges.jsonl";
  {
    int calls = 0;
    RecordingBackend first({}, Counting("a", &calls), OpenLog(path), "");
    ASSERT_TRUE(first.Chat(Request("one")).ok());
    first.set_iteration(0);
    ASSERT_TRUE(first.Chat(Request("two")).ok());
  }
  const std::vector<std::string> before = Lines(path);
  ASSERT_EQ(before.size(), 2u);

  // The second session opens the log first, then reads it (as
  // OpenRecordingBackend does).
  JsonlLog log = OpenLog(path);
  EXPECT_EQ(log.existing(), 2);
  Result<std::vector<ExchangeRecord>> recorded = LoadExchanges(path);
  ASSERT_TRUE(recorded.ok()) << recorded.status().ToString();
  int live_calls = 0;
  RecordingBackend second(std::move(*recorded), Counting("b", &live_calls),
                          std::move(log), path);
  Result<ChatReply> one = second.Chat(Request("one"));
  second.set_iteration(0);
  Result<ChatReply> two = second.Chat(Request("two"));
  second.set_iteration(1);
  Result<ChatReply> three = second.Chat(Request("three"));
  ASSERT_TRUE(one.ok() && two.ok() && three.ok());
  EXPECT_EQ(one->text, "a0");
  EXPECT_EQ(two->text, "a1");
  EXPECT_EQ(three->text, "b0");
  EXPECT_EQ(live_calls, 1);
  EXPECT_EQ(second.replayed(), 2);

  // No duplicates: the first two lines are untouched, one line is new.
  const std::vector<std::string> after = Lines(path);
  ASSERT_EQ(after.size(), 3u);
  EXPECT_EQ(after[0], before[0]);
  EXPECT_EQ(after[1], before[1]);
  Result<std::vector<ExchangeRecord>> all = LoadExchanges(path);
  ASSERT_TRUE(all.ok());
  ASSERT_EQ(all->size(), 3u);
  std::vector<std::string> answers;
  for (const ExchangeRecord& r : *all) answers.push_back(r.answer);
  EXPECT_THAT(answers, ElementsAre("a0", "a1", "b0"));
  EXPECT_EQ((*all)[2].seq, 2);
  EXPECT_EQ((*all)[2].iteration, 1);
  ExpectSameRecord((*all)[2], second.session()[2]);
}

TEST(RecordingBackendTest,
     ResumingAfterACrashDropsTheCutLineAndRecordsItAgain) {
  const std::string path = TempDir("resume-crash") + "/exchanges.jsonl";
  RecordSession(path, {Request("one"), Request("two")}, {"a0", "a1"});
  const std::vector<std::string> whole = Lines(path);
  ASSERT_EQ(whole.size(), 2u);
  // The crash cut the second line short.
  WriteRaw(path, whole[0] + "\n" + whole[1].substr(0, whole[1].size() / 2));

  Result<std::unique_ptr<RecordingBackend>> resumed = [&] {
    spec::LlmOptions llm;  // ollama: never asked below
    return OpenRecordingBackend(llm, path, path);
  }();
  ASSERT_TRUE(resumed.ok()) << resumed.status().ToString();
  Result<ChatReply> one = (*resumed)->Chat(Request("one"));
  ASSERT_TRUE(one.ok()) << one.status().ToString();
  EXPECT_EQ(one->text, "a0");
  EXPECT_EQ((*resumed)->replayed(), 1);
  // The file again holds exactly one complete line.
  EXPECT_EQ(Slurp(path), whole[0] + "\n");
}

TEST(RecordingBackendTest,
     AGarbledCompleteLastLineIsCorruptionNotALostExchange) {
  // Were the line skipped, JsonlLog would still count it: the resumed
  // session's next exchange would not be recorded, and the garbage would
  // end up in the middle of the record.
  const std::string path = TempDir("garbled") + "/exchanges.jsonl";
  RecordSession(path, {Request("one")}, {"a0"});
  { std::ofstream(path, std::ios::app) << "{\"seq\": 1, garbage}\n"; }
  spec::LlmOptions llm;
  Result<std::unique_ptr<RecordingBackend>> resumed =
      OpenRecordingBackend(llm, path, path);
  ASSERT_FALSE(resumed.ok());
  EXPECT_EQ(resumed.status().code(), Status::Code::kCorruption);
  EXPECT_THAT(resumed.status().message(),
              StartsWith(path + ":2: not an exchange record"));
}

TEST(RecordingBackendTest,
     ReplayingAnotherRecordIntoAFreshLogRecordsTheWholeSession) {
  const std::string dir = TempDir("replay-into");
  const std::string source = dir + "/old/llm/exchanges.jsonl";
  const std::string fresh = dir + "/new/llm/exchanges.jsonl";
  RecordSession(source, {Request("one"), Request("two")}, {"a0", "a1"});
  Result<std::vector<ExchangeRecord>> recorded = LoadExchanges(source);
  ASSERT_TRUE(recorded.ok());
  RecordingBackend backend(std::move(*recorded), nullptr, OpenLog(fresh),
                           source);
  ASSERT_TRUE(backend.Chat(Request("one")).ok());
  ASSERT_TRUE(backend.Chat(Request("two")).ok());
  EXPECT_EQ(Slurp(fresh), Slurp(source));
}

// --- LoadExchanges -------------------------------------------------------

TEST(LoadExchangesTest, AMissingFileIsAnEmptyRecord) {
  Result<std::vector<ExchangeRecord>> loaded =
      LoadExchanges(TempDir("load-missing") + "/exchanges.jsonl");
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  EXPECT_TRUE(loaded->empty());
}

TEST(LoadExchangesTest, IgnoresALastLineCutShortAndRefusesABadMiddleLine) {
  const std::string path = TempDir("load-bad") + "/exchanges.jsonl";
  RecordSession(path, {Request("one"), Request("two")}, {"a0", "a1"});
  const std::vector<std::string> lines = Lines(path);
  ASSERT_EQ(lines.size(), 2u);

  WriteRaw(path, lines[0] + "\n" + lines[1].substr(0, 20));
  Result<std::vector<ExchangeRecord>> cut = LoadExchanges(path);
  ASSERT_TRUE(cut.ok()) << cut.status().ToString();
  ASSERT_EQ(cut->size(), 1u);
  EXPECT_EQ((*cut)[0].answer, "a0");

  // Valid JSON that is not an exchange record, in the middle.
  WriteRaw(path, lines[0] + "\n{\"seq\": 1}\n" + lines[1] + "\n");
  Result<std::vector<ExchangeRecord>> bad = LoadExchanges(path);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), Status::Code::kCorruption);
  EXPECT_THAT(bad.status().message(),
              StartsWith(path + ":2: not an exchange record ("));
}

// --- OpenRecordingBackend ------------------------------------------------

TEST(OpenRecordingBackendTest, ReplayWithoutARecordIsNotFound) {
  const std::string dir = TempDir("open-replay");
  spec::LlmOptions llm;
  llm.backend = "replay";

  Result<std::unique_ptr<RecordingBackend>> none =
      OpenRecordingBackend(llm, "", "", "scenario.yaml:12:3: ");
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.status().code(), Status::Code::kNotFound);
  EXPECT_THAT(
      none.status().message(),
      StartsWith("scenario.yaml:12:3: llm.replay_from: no record given"));

  const std::string missing = dir + "/missing/llm/exchanges.jsonl";
  Result<std::unique_ptr<RecordingBackend>> absent =
      OpenRecordingBackend(llm, missing, "");
  ASSERT_FALSE(absent.ok());
  EXPECT_EQ(absent.status().code(), Status::Code::kNotFound);
  EXPECT_THAT(absent.status().message(),
              HasSubstr(missing + " holds no recorded exchanges"));

  const std::string empty = dir + "/empty.jsonl";
  WriteRaw(empty, "");
  Result<std::unique_ptr<RecordingBackend>> nothing =
      OpenRecordingBackend(llm, empty, "");
  ASSERT_FALSE(nothing.ok());
  EXPECT_EQ(nothing.status().code(), Status::Code::kNotFound);
  EXPECT_THAT(nothing.status().message(),
              HasSubstr(empty + " holds no recorded exchanges"));
}

TEST(OpenRecordingBackendTest,
     ReplayAnswersOnlyFromTheRecordAndRecordsIntoTheLog) {
  const std::string dir = TempDir("open-replay-ok");
  const std::string source = dir + "/old/exchanges.jsonl";
  const std::string log = dir + "/new/llm/exchanges.jsonl";
  RecordSession(source, {Request()}, {"recorded"});
  spec::LlmOptions llm;
  llm.backend = "replay";
  Result<std::unique_ptr<RecordingBackend>> backend =
      OpenRecordingBackend(llm, source, log);
  ASSERT_TRUE(backend.ok()) << backend.status().ToString();
  EXPECT_EQ((*backend)->name(), "replay");
  Result<ChatReply> reply = (*backend)->Chat(Request());
  ASSERT_TRUE(reply.ok());
  EXPECT_EQ(reply->text, "recorded");
  Result<ChatReply> unrecorded = (*backend)->Chat(Request("new"));
  EXPECT_EQ(unrecorded.status().code(), Status::Code::kNotFound);
  EXPECT_THAT(unrecorded.status().message(), HasSubstr(source));
  EXPECT_EQ(Slurp(log), Slurp(source));
}

TEST(OpenRecordingBackendTest, AnUnknownApiIsInvalidArgument) {
  spec::LlmOptions llm;
  llm.backend = "gemini";
  Result<std::unique_ptr<RecordingBackend>> backend =
      OpenRecordingBackend(llm, "", "", "scenario.yaml:12:3: ");
  ASSERT_FALSE(backend.ok());
  EXPECT_EQ(backend.status().code(), Status::Code::kInvalidArgument);
  EXPECT_THAT(backend.status().message(),
              StartsWith("scenario.yaml:12:3: llm: "));
  EXPECT_THAT(backend.status().message(), HasSubstr("'gemini'"));
}

TEST(OpenRecordingBackendTest,
     ALiveBackendAnswersRecordedRequestsFromTheRecord) {
  const std::string path = TempDir("open-live") + "/exchanges.jsonl";
  RecordSession(path, {Request()}, {"recorded"});
  for (const char* api : {"ollama", "openai"}) {
    spec::LlmOptions llm;
    llm.backend = api;
    // Nothing listens there: only the record can answer.
    llm.endpoint = "http://127.0.0.1:9";
    Result<std::unique_ptr<RecordingBackend>> backend =
        OpenRecordingBackend(llm, path, "");
    ASSERT_TRUE(backend.ok()) << backend.status().ToString();
    EXPECT_EQ((*backend)->name(), api);
    Result<ChatReply> reply = (*backend)->Chat(Request());
    ASSERT_TRUE(reply.ok()) << reply.status().ToString();
    EXPECT_EQ(reply->text, "recorded");
    EXPECT_EQ((*backend)->replayed(), 1);
  }
}

}  // namespace
}  // namespace adse::llm
