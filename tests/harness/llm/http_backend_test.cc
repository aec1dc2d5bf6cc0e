// The libcurl chat backends against the fake LLM server: request shapes of
// both APIs, answers, retries, timeouts, size limits and error messages.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "harness/llm/chat.h"
#include "tests/harness/llm/testing/fake_llm_server.h"

namespace adse::llm {
namespace {

using testing::FakeAnswer;
using testing::FakeLlmServer;
using ::testing::HasSubstr;
using ::testing::Not;
using testing::ReceivedRequest;
using Clock = std::chrono::steady_clock;
using Json = nlohmann::json;

// PNG's signature plus a NUL and a 0xFF byte; base64 by Python's encoder.
const std::string kPng("\x89PNG\r\n\x1a\n\0\xff", 10);
constexpr char kPngBase64[] = "iVBORw0KGgoA/w==";

std::unique_ptr<FakeLlmServer> StartServer(FakeLlmServer::Script script) {
  Result<std::unique_ptr<FakeLlmServer>> server =
      FakeLlmServer::Start(std::move(script));
  EXPECT_TRUE(server.ok()) << server.status().ToString();
  return server.ok() ? std::move(server).value() : nullptr;
}

std::unique_ptr<FakeLlmServer> StartServer(std::vector<FakeAnswer> answers) {
  return StartServer(FakeLlmServer::Sequence(std::move(answers)));
}

HttpBackendOptions Options(const std::string& api, const std::string& url) {
  HttpBackendOptions options;
  options.api = api;
  options.endpoint = url;
  options.timeout_s = 10.0;
  options.connect_timeout_s = 5.0;
  options.retries = 2;
  options.backoff_s = 0.01;
  return options;
}

std::unique_ptr<ChatBackend> Backend(const HttpBackendOptions& options) {
  Result<std::unique_ptr<ChatBackend>> backend = NewHttpBackend(options);
  EXPECT_TRUE(backend.ok()) << backend.status().ToString();
  return backend.ok() ? std::move(backend).value() : nullptr;
}

ChatRequest Request(bool with_image = false) {
  ChatRequest request;
  request.agent = "vision";
  request.model = "llava:13b";
  request.messages.push_back({"system", "You answer in JSON.", {}});
  ChatMessage user{"user", "What is in the picture?", {}};
  if (with_image) user.images_png.push_back(kPng);
  request.messages.push_back(user);
  return request;
}

Json BodyOf(const ReceivedRequest& request) {
  return Json::parse(request.body, nullptr, false);
}

// A port nothing listens on: bound but not listening, so a connection is
// refused, and no other process can take the port while the test runs.
class DeadPort {
 public:
  DeadPort() {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    address.sin_port = 0;
    socklen_t size = sizeof(address);
    if (fd_ >= 0 &&
        ::bind(fd_, reinterpret_cast<sockaddr*>(&address), size) == 0 &&
        ::getsockname(fd_, reinterpret_cast<sockaddr*>(&address), &size) == 0) {
      port_ = ntohs(address.sin_port);
    }
  }
  ~DeadPort() {
    if (fd_ >= 0) ::close(fd_);
  }
  std::string url() const {
    return "http://127.0.0.1:" + std::to_string(port_);
  }
  int port() const { return port_; }

 private:
  int fd_ = -1;
  int port_ = 0;
};

// ---- Ollama ---------------------------------------------------------------

TEST(HttpBackendTest, OllamaRoundTrip) {
  FakeAnswer answer;
  answer.content = R"({"objects": ["car"]})";
  answer.prompt_tokens = 31;
  answer.completion_tokens = 7;
  auto server = StartServer({answer});
  ASSERT_NE(server, nullptr);
  auto backend = Backend(Options("ollama", server->url()));
  ASSERT_NE(backend, nullptr);
  EXPECT_EQ(backend->name(), "ollama");

  Result<ChatReply> reply = backend->Chat(Request(/*with_image=*/true));
  ASSERT_TRUE(reply.ok()) << reply.status().ToString();
  EXPECT_EQ(reply->text, answer.content);
  EXPECT_EQ(reply->prompt_tokens, 31);
  EXPECT_EQ(reply->completion_tokens, 7);
  EXPECT_EQ(reply->attempts, 1);
  EXPECT_GT(reply->latency_s, 0.0);

  const std::vector<ReceivedRequest> requests = server->requests();
  ASSERT_EQ(requests.size(), 1u);
  const ReceivedRequest& received = requests[0];
  EXPECT_EQ(received.path, "/api/chat");
  EXPECT_EQ(received.authorization, "");
  const Json body = BodyOf(received);
  ASSERT_TRUE(body.is_object()) << received.body;
  EXPECT_EQ(body["model"], "llava:13b");
  EXPECT_EQ(body["stream"], false);
  EXPECT_EQ(body["format"], "json");
  EXPECT_FALSE(body.contains("response_format"));
  ASSERT_EQ(body["messages"].size(), 2u);
  EXPECT_EQ(body["messages"][0]["role"], "system");
  EXPECT_EQ(body["messages"][0]["content"], "You answer in JSON.");
  EXPECT_FALSE(body["messages"][0].contains("images"));
  EXPECT_EQ(body["messages"][1]["content"], "What is in the picture?");
  EXPECT_EQ(body["messages"][1]["images"], Json::array({kPngBase64}));
  // The fake's own reading of the request.
  ASSERT_EQ(received.messages.size(), 2u);
  EXPECT_EQ(received.messages[1].images_png, std::vector<std::string>{kPng});
  EXPECT_EQ(received.TextOf("system"), "You answer in JSON.");
  EXPECT_TRUE(received.Mentions("picture"));
}

TEST(HttpBackendTest, OllamaPlainTextRequestSendsNoFormat) {
  auto server = StartServer({FakeAnswer{.content = "hello"}});
  ASSERT_NE(server, nullptr);
  HttpBackendOptions options = Options("ollama", server->url() + "/");
  options.api_key = "sk-not-for-ollama";
  auto backend = Backend(options);
  ASSERT_NE(backend, nullptr);
  ChatRequest request = Request();
  request.json = false;
  Result<ChatReply> reply = backend->Chat(request);
  ASSERT_TRUE(reply.ok()) << reply.status().ToString();
  EXPECT_EQ(reply->text, "hello");
  // Derived by the fake from the texts.
  EXPECT_GT(reply->prompt_tokens, 0);
  EXPECT_GT(reply->completion_tokens, 0);
  ASSERT_EQ(server->request_count(), 1u);
  const ReceivedRequest received = server->requests()[0];
  EXPECT_EQ(received.path, "/api/chat");
  EXPECT_FALSE(BodyOf(received).contains("format"));
  EXPECT_EQ(received.authorization, "");  // the key is for openai only
}

TEST(HttpBackendTest, OllamaStreamedAnswerIsConcatenated) {
  FakeAnswer answer;
  answer.content = R"({"advice": "brake früh, then steer"})";
  answer.stream = true;
  answer.prompt_tokens = 12;
  answer.completion_tokens = 9;
  auto server = StartServer({answer});
  ASSERT_NE(server, nullptr);
  auto backend = Backend(Options("ollama", server->url()));
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_TRUE(reply.ok()) << reply.status().ToString();
  EXPECT_EQ(reply->text, answer.content);
  EXPECT_EQ(reply->prompt_tokens, 12);
  EXPECT_EQ(reply->completion_tokens, 9);
}

TEST(HttpBackendTest, OllamaStreamWithoutItsLastChunkIsCorruption) {
  FakeAnswer answer;
  answer.raw_body =
      R"({"message":{"role":"assistant","content":"{\"a\""},"done":false})"
      "\n"
      R"({"message":{"role":"assistant","content":": 1}"},"done":false})"
      "\n";
  answer.chunked = true;
  auto server = StartServer({answer});
  ASSERT_NE(server, nullptr);
  auto backend = Backend(Options("ollama", server->url()));
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kCorruption);
  EXPECT_THAT(reply.status().message(), HasSubstr("ended before"));
}

TEST(HttpBackendTest, OllamaAnswerWithoutCountsHasUnknownTokens) {
  FakeAnswer answer;
  answer.raw_body =
      R"({"model":"m","message":{"role":"assistant","content":"hi"},)"
      R"("done":true})";
  auto server = StartServer({answer});
  ASSERT_NE(server, nullptr);
  auto backend = Backend(Options("ollama", server->url()));
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_TRUE(reply.ok()) << reply.status().ToString();
  EXPECT_EQ(reply->text, "hi");
  EXPECT_EQ(reply->prompt_tokens, -1);
  EXPECT_EQ(reply->completion_tokens, -1);
}

TEST(HttpBackendTest, OllamaMissingModelNamesThePullCommand) {
  FakeAnswer answer;
  answer.status = 404;
  answer.content = "model \"llava:13b\" not found, try pulling it first";
  auto server = StartServer({answer});
  ASSERT_NE(server, nullptr);
  auto backend = Backend(Options("ollama", server->url()));
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kInvalidArgument);
  EXPECT_THAT(reply.status().message(), HasSubstr("ollama pull llava:13b"));
  EXPECT_THAT(reply.status().message(), HasSubstr("'llava:13b'"));
  EXPECT_EQ(server->request_count(), 1u);
}

// ---- OpenAI-compatible ----------------------------------------------------

TEST(HttpBackendTest, OpenAiRoundTrip) {
  FakeAnswer answer;
  answer.content = R"({"speed": 12.5})";
  answer.prompt_tokens = 40;
  answer.completion_tokens = 6;
  auto server = StartServer({answer});
  ASSERT_NE(server, nullptr);
  HttpBackendOptions options = Options("openai", server->url());
  options.api_key = "sk-test-123";
  auto backend = Backend(options);
  ASSERT_NE(backend, nullptr);
  EXPECT_EQ(backend->name(), "openai");

  Result<ChatReply> reply = backend->Chat(Request(/*with_image=*/true));
  ASSERT_TRUE(reply.ok()) << reply.status().ToString();
  EXPECT_EQ(reply->text, answer.content);
  EXPECT_EQ(reply->prompt_tokens, 40);
  EXPECT_EQ(reply->completion_tokens, 6);
  EXPECT_EQ(reply->attempts, 1);

  const std::vector<ReceivedRequest> requests = server->requests();
  ASSERT_EQ(requests.size(), 1u);
  const ReceivedRequest& received = requests[0];
  EXPECT_EQ(received.path, "/v1/chat/completions");
  EXPECT_EQ(received.authorization, "Bearer sk-test-123");
  const Json body = BodyOf(received);
  ASSERT_TRUE(body.is_object()) << received.body;
  EXPECT_EQ(body["model"], "llava:13b");
  EXPECT_EQ(body["stream"], false);
  EXPECT_EQ(body["response_format"], Json({{"type", "json_object"}}));
  EXPECT_FALSE(body.contains("format"));
  ASSERT_EQ(body["messages"].size(), 2u);
  EXPECT_EQ(body["messages"][0]["content"], "You answer in JSON.");
  const Json& parts = body["messages"][1]["content"];
  ASSERT_TRUE(parts.is_array()) << parts.dump();
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(parts[0],
            Json({{"type", "text"}, {"text", "What is in the picture?"}}));
  EXPECT_EQ(parts[1]["type"], "image_url");
  EXPECT_EQ(parts[1]["image_url"]["url"],
            std::string("data:image/png;base64,") + kPngBase64);
  EXPECT_FALSE(body["messages"][1].contains("images"));
  ASSERT_EQ(received.messages.size(), 2u);
  EXPECT_EQ(received.messages[1].text, "What is in the picture?");
  EXPECT_EQ(received.messages[1].images_png, std::vector<std::string>{kPng});
}

TEST(HttpBackendTest, OpenAiEndpointEndingInV1GetsNoSecondOne) {
  auto server = StartServer({FakeAnswer{.content = "ok"}});
  ASSERT_NE(server, nullptr);
  for (const std::string suffix : {"/v1", "/v1/"}) {
    auto backend = Backend(Options("openai", server->url() + suffix));
    ASSERT_NE(backend, nullptr);
    ChatRequest request = Request();
    request.json = false;
    Result<ChatReply> reply = backend->Chat(request);
    ASSERT_TRUE(reply.ok()) << suffix << ": " << reply.status().ToString();
    EXPECT_EQ(reply->text, "ok");
  }
  const std::vector<ReceivedRequest> requests = server->requests();
  ASSERT_EQ(requests.size(), 2u);
  for (const ReceivedRequest& received : requests) {
    EXPECT_EQ(received.path, "/v1/chat/completions");
    EXPECT_EQ(received.authorization, "");  // no key, no header
    EXPECT_FALSE(BodyOf(received).contains("response_format"));
  }
}

TEST(HttpBackendTest, OpenAiAnswerOfTheWrongShapeIsCorruption) {
  FakeAnswer answer;
  answer.raw_body = R"({"choices": [], "usage": {"prompt_tokens": 3}})";
  auto server = StartServer({answer});
  ASSERT_NE(server, nullptr);
  auto backend = Backend(Options("openai", server->url()));
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kCorruption);
  EXPECT_THAT(reply.status().message(), HasSubstr("choices"));
  EXPECT_EQ(server->request_count(), 1u);  // not retried
}

TEST(HttpBackendTest, RefusedKeyIsNotRetriedNorShown) {
  FakeAnswer answer;
  answer.status = 401;
  answer.content = "Incorrect API key provided";
  auto server = StartServer({answer});
  ASSERT_NE(server, nullptr);
  HttpBackendOptions options = Options("openai", server->url());
  options.api_key = "sk-secret-456";
  auto backend = Backend(options);
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kInvalidArgument);
  EXPECT_THAT(reply.status().message(), HasSubstr("HTTP 401"));
  EXPECT_THAT(reply.status().message(), HasSubstr("Incorrect API key"));
  EXPECT_THAT(reply.status().message(), Not(HasSubstr("sk-secret-456")));
  EXPECT_EQ(server->request_count(), 1u);
}

// ---- Failures and retries -------------------------------------------------

TEST(HttpBackendTest, ServerErrorThenSuccessTakesTwoAttempts) {
  FakeAnswer error;
  error.status = 500;
  error.content = "model runner crashed";
  auto server = StartServer({error, FakeAnswer{.content = "fine"}});
  ASSERT_NE(server, nullptr);
  auto backend = Backend(Options("ollama", server->url()));
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_TRUE(reply.ok()) << reply.status().ToString();
  EXPECT_EQ(reply->text, "fine");
  EXPECT_EQ(reply->attempts, 2);
  EXPECT_EQ(server->request_count(), 2u);
}

TEST(HttpBackendTest, RateLimitIsRetried) {
  FakeAnswer limited;
  limited.status = 429;
  limited.content = "slow down";
  auto server = StartServer({limited, FakeAnswer{.content = "fine"}});
  ASSERT_NE(server, nullptr);
  auto backend = Backend(Options("openai", server->url()));
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_TRUE(reply.ok()) << reply.status().ToString();
  EXPECT_EQ(reply->attempts, 2);
}

TEST(HttpBackendTest, PersistentServerErrorIsUnavailableAfterAllAttempts) {
  FakeAnswer error;
  error.status = 503;
  error.content = "overloaded";
  auto server = StartServer({error});
  ASSERT_NE(server, nullptr);
  HttpBackendOptions options = Options("ollama", server->url());
  options.retries = 3;
  auto backend = Backend(options);
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kUnavailable);
  EXPECT_THAT(reply.status().message(), HasSubstr("HTTP 503"));
  EXPECT_THAT(reply.status().message(), HasSubstr("4 attempts"));
  EXPECT_THAT(reply.status().message(), HasSubstr("overloaded"));
  EXPECT_EQ(server->request_count(), 4u);
}

TEST(HttpBackendTest, BadRequestIsNotRetried) {
  FakeAnswer error;
  error.status = 400;
  error.content = "invalid format: expected \"json\"";
  auto server = StartServer({error});
  ASSERT_NE(server, nullptr);
  auto backend = Backend(Options("ollama", server->url()));
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kInvalidArgument);
  EXPECT_THAT(reply.status().message(), HasSubstr("HTTP 400"));
  EXPECT_THAT(reply.status().message(), HasSubstr("invalid format"));
  EXPECT_EQ(server->request_count(), 1u);
}

TEST(HttpBackendTest, LongErrorBodyIsShortenedInTheMessage) {
  FakeAnswer error;
  error.status = 422;
  error.raw_body = std::string(5000, 'e');
  auto server = StartServer({error});
  ASSERT_NE(server, nullptr);
  auto backend = Backend(Options("openai", server->url()));
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kInvalidArgument);
  EXPECT_THAT(reply.status().message(), HasSubstr(std::string(300, 'e')));
  EXPECT_THAT(reply.status().message(), Not(HasSubstr(std::string(301, 'e'))));
}

TEST(HttpBackendTest, SlowAnswerTimesOutWithinBoundedTime) {
  FakeAnswer slow;
  slow.content = "too late";
  slow.delay_s = 30.0;
  auto server = StartServer({slow});
  ASSERT_NE(server, nullptr);
  HttpBackendOptions options = Options("ollama", server->url());
  options.timeout_s = 0.3;
  options.retries = 1;
  auto backend = Backend(options);
  ASSERT_NE(backend, nullptr);
  const Clock::time_point start = Clock::now();
  Result<ChatReply> reply = backend->Chat(Request());
  const double elapsed =
      std::chrono::duration<double>(Clock::now() - start).count();
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kUnavailable);
  EXPECT_THAT(reply.status().message(), HasSubstr("within 0.3 s"));
  EXPECT_THAT(reply.status().message(), HasSubstr("2 attempts"));
  EXPECT_THAT(reply.status().message(), HasSubstr(server->url()));
  EXPECT_LT(elapsed, 10.0);  // two 0.3 s attempts, far from the 30 s delay
  EXPECT_EQ(server->request_count(), 2u);
  // The server's destructor cuts the pending delays short.
}

TEST(HttpBackendTest, SlowAnswerWithinTheTimeoutSucceeds) {
  FakeAnswer slow;
  slow.content = "worth the wait";
  slow.delay_s = 0.2;
  auto server = StartServer({slow});
  ASSERT_NE(server, nullptr);
  auto backend = Backend(Options("openai", server->url()));
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_TRUE(reply.ok()) << reply.status().ToString();
  EXPECT_EQ(reply->text, "worth the wait");
  EXPECT_GE(reply->latency_s, 0.2);
}

TEST(HttpBackendTest, OllamaDownSaysWhatToStart) {
  DeadPort dead;
  ASSERT_GT(dead.port(), 0);
  HttpBackendOptions options = Options("ollama", dead.url());
  options.retries = 1;
  auto backend = Backend(options);
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kUnavailable);
  const std::string& message = reply.status().message();
  EXPECT_THAT(message, HasSubstr(dead.url() + "/api/chat"));
  EXPECT_THAT(message, HasSubstr("ollama serve"));
  EXPECT_THAT(message, HasSubstr("ollama pull llava:13b"));
  EXPECT_THAT(message, HasSubstr("2 attempts"));
}

TEST(HttpBackendTest, OpenAiServerDownNamesTheServer) {
  DeadPort dead;
  ASSERT_GT(dead.port(), 0);
  HttpBackendOptions options = Options("openai", dead.url() + "/v1");
  options.retries = 0;
  options.api_key = "sk-secret-789";
  auto backend = Backend(options);
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kUnavailable);
  const std::string& message = reply.status().message();
  EXPECT_THAT(message, HasSubstr(dead.url() + "/v1/chat/completions"));
  EXPECT_THAT(message,
              HasSubstr("OpenAI-compatible server running at " + dead.url()));
  EXPECT_THAT(message, HasSubstr("1 attempt"));
  EXPECT_THAT(message, Not(HasSubstr("sk-secret-789")));
}

// ---- Answers that are too large or broken ---------------------------------

TEST(HttpBackendTest, AnnouncedHugeAnswerIsRefused) {
  FakeAnswer huge;
  huge.raw_body = std::string(10u << 20, 'x');  // with a Content-Length
  auto server = StartServer({huge});
  ASSERT_NE(server, nullptr);
  auto backend = Backend(Options("ollama", server->url()));
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kCorruption);
  EXPECT_THAT(reply.status().message(), HasSubstr("larger than 4 MiB"));
  EXPECT_EQ(server->request_count(), 1u);  // not retried
}

TEST(HttpBackendTest, HugeChunkedAnswerIsCutOffWhileArriving) {
  // 256 MiB without a Content-Length: only the size limit can stop it.
  FakeAnswer huge;
  huge.raw_body = std::string(1u << 20, 'x');
  huge.raw_body_repeat = 256;
  huge.chunked = true;
  auto server = StartServer({huge});
  ASSERT_NE(server, nullptr);
  auto backend = Backend(Options("openai", server->url()));
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kCorruption);
  EXPECT_THAT(reply.status().message(), HasSubstr("larger than 4 MiB"));
  // 4 MiB read plus what the socket buffers held when the client hung up.
  EXPECT_LT(server->body_bytes_sent(), size_t{64} << 20);
  EXPECT_EQ(server->request_count(), 1u);
}

TEST(HttpBackendTest, MalformedJsonIsCorruptionWithAnExcerpt) {
  for (const std::string api : {"ollama", "openai"}) {
    FakeAnswer broken;
    broken.raw_body = "{\"message\": {\"content\": \"unterminated";
    auto server = StartServer({broken});
    ASSERT_NE(server, nullptr);
    auto backend = Backend(Options(api, server->url()));
    ASSERT_NE(backend, nullptr);
    Result<ChatReply> reply = backend->Chat(Request());
    ASSERT_FALSE(reply.ok()) << api;
    EXPECT_EQ(reply.status().code(), Status::Code::kCorruption) << api;
    EXPECT_THAT(reply.status().message(), HasSubstr("not JSON"));
    EXPECT_THAT(reply.status().message(), HasSubstr("unterminated"));
    EXPECT_EQ(server->request_count(), 1u) << api;
  }
}

TEST(HttpBackendTest, OllamaAnswerWithoutTextIsCorruption) {
  FakeAnswer wrong;
  wrong.raw_body = R"({"message": {"role": "assistant", "content": 5},
                       "done": true})";
  auto server = StartServer({wrong});
  ASSERT_NE(server, nullptr);
  auto backend = Backend(Options("ollama", server->url()));
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kCorruption);
}

TEST(HttpBackendTest, BackendIsReusableAfterAFailure) {
  FakeAnswer broken;
  broken.raw_body = "nonsense";
  auto server = StartServer(
      {broken, FakeAnswer{.content = "a"}, FakeAnswer{.content = "b"}});
  ASSERT_NE(server, nullptr);
  auto backend = Backend(Options("ollama", server->url()));
  ASSERT_NE(backend, nullptr);
  EXPECT_FALSE(backend->Chat(Request()).ok());
  Result<ChatReply> a = backend->Chat(Request());
  Result<ChatReply> b = backend->Chat(Request());
  ASSERT_TRUE(a.ok()) << a.status().ToString();
  ASSERT_TRUE(b.ok()) << b.status().ToString();
  EXPECT_EQ(a->text, "a");
  EXPECT_EQ(b->text, "b");
}

// ---- Options --------------------------------------------------------------

TEST(HttpBackendTest, UnknownApiOrBadEndpointIsInvalidArgument) {
  HttpBackendOptions options;
  options.api = "grpc";
  Result<std::unique_ptr<ChatBackend>> backend = NewHttpBackend(options);
  ASSERT_FALSE(backend.ok());
  EXPECT_EQ(backend.status().code(), Status::Code::kInvalidArgument);
  EXPECT_THAT(backend.status().message(), HasSubstr("'grpc'"));

  for (const std::string endpoint :
       {"", "127.0.0.1:11434", "ftp://127.0.0.1", "http://",
        "http://127.0.0.1:11434/?x=1", "not a url"}) {
    options = HttpBackendOptions();
    options.endpoint = endpoint;
    backend = NewHttpBackend(options);
    ASSERT_FALSE(backend.ok()) << endpoint;
    EXPECT_EQ(backend.status().code(), Status::Code::kInvalidArgument)
        << endpoint;
    EXPECT_THAT(backend.status().message(), HasSubstr("http://127.0.0.1"))
        << endpoint;
  }

  options = HttpBackendOptions();
  options.timeout_s = 0;
  EXPECT_FALSE(NewHttpBackend(options).ok());
  options = HttpBackendOptions();
  options.retries = -1;
  EXPECT_FALSE(NewHttpBackend(options).ok());
  options = HttpBackendOptions();
  options.endpoint = "https://llm.example.org/v1";
  options.api = "openai";
  EXPECT_TRUE(NewHttpBackend(options).ok());
}

TEST(HttpBackendTest, RequestWithoutModelIsInvalidArgument) {
  auto backend = Backend(Options("ollama", "http://127.0.0.1:9"));
  ASSERT_NE(backend, nullptr);
  ChatRequest request = Request();
  request.model = "";
  Result<ChatReply> reply = backend->Chat(request);
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kInvalidArgument);
}

TEST(HttpBackendTest, FakeServerAnswersUnknownPathsWith404) {
  auto server = StartServer({FakeAnswer{.content = "never"}});
  ASSERT_NE(server, nullptr);
  // An Ollama endpoint given with the OpenAI prefix: /v1/api/chat.
  auto backend = Backend(Options("ollama", server->url() + "/v1"));
  ASSERT_NE(backend, nullptr);
  Result<ChatReply> reply = backend->Chat(Request());
  ASSERT_FALSE(reply.ok());
  EXPECT_EQ(reply.status().code(), Status::Code::kInvalidArgument);
  EXPECT_THAT(reply.status().message(), HasSubstr("HTTP 404"));
  EXPECT_THAT(reply.status().message(),
              HasSubstr("base URL of an Ollama server"));
  ASSERT_EQ(server->request_count(), 1u);
  EXPECT_EQ(server->requests()[0].path, "/v1/api/chat");
}

}  // namespace
}  // namespace adse::llm
