// A scripted stand-in for an LLM server, for tests. It listens on
// 127.0.0.1 (a free port) and speaks Ollama's POST /api/chat and the
// OpenAI-compatible POST /v1/chat/completions, answering each request with
// what the test's script says: a text, an HTTP error, a delay, a raw body
// (malformed or huge), or Ollama's NDJSON stream. Any other POST path gets
// Ollama's plain "404 page not found" without calling the script.
#ifndef ADSE_TESTS_HARNESS_LLM_TESTING_FAKE_LLM_SERVER_H_
#define ADSE_TESTS_HARNESS_LLM_TESTING_FAKE_LLM_SERVER_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "stack/base/status.h"

namespace adse::llm::testing {

// One chat message as the server received it, in either API's shape.
struct ReceivedMessage {
  std::string role;
  std::string text;  // OpenAI content parts: the text parts joined by "\n"
  std::vector<std::string> images_png;  // decoded from base64
};

struct ReceivedRequest {
  std::string path;           // e.g. "/api/chat", "/v1/chat/completions"
  std::string body;           // the raw request body
  std::string authorization;  // the Authorization header; "" when absent
  // Read from the body when it is a JSON object; empty otherwise.
  bool json_ok = false;
  std::string model;
  std::vector<ReceivedMessage> messages;

  bool ollama() const { return path == "/api/chat"; }
  // The texts of all messages with this role, joined by "\n".
  std::string TextOf(std::string_view role) const;
  // Whether any message's text contains `needle`.
  bool Mentions(std::string_view needle) const;
};

struct FakeAnswer {
  int status = 200;
  // The assistant's text, wrapped in the API's answer JSON; with an error
  // status, the error message, wrapped in the API's error JSON.
  std::string content = "";
  // Reported token counts; -1: derived from the texts (~4 bytes a token).
  int64_t prompt_tokens = -1;
  int64_t completion_tokens = -1;
  // Wait before answering; cut short when the server shuts down.
  double delay_s = 0.0;
  // Sent verbatim instead of the API JSON, raw_body_repeat times in a row
  // (a huge answer without a huge string).
  std::optional<std::string> raw_body = std::nullopt;
  size_t raw_body_repeat = 1;
  // Transfer-Encoding: chunked, so the client cannot know the size ahead.
  bool chunked = false;
  // Ollama: answer as NDJSON chunks, as Ollama does whenever the request
  // does not say "stream": false.
  bool stream = false;
};

class FakeLlmServer {
 public:
  // Calls are serialised, so a script may keep state without locking.
  using Script = std::function<FakeAnswer(const ReceivedRequest&)>;

  static Result<std::unique_ptr<FakeLlmServer>> Start(Script script);
  // A script answering with `answers` in order; the last one repeats.
  static Script Sequence(std::vector<FakeAnswer> answers);

  // Stops listening, cuts delays short, and joins the server's threads.
  ~FakeLlmServer();
  FakeLlmServer(const FakeLlmServer&) = delete;
  FakeLlmServer& operator=(const FakeLlmServer&) = delete;

  std::string url() const;  // "http://127.0.0.1:<port>"
  int port() const;
  std::vector<ReceivedRequest> requests() const;  // in arrival order
  size_t request_count() const;
  // Answer body bytes handed to the sockets so far, over all requests:
  // shows that a client stopped reading.
  size_t body_bytes_sent() const;

 private:
  struct Impl;
  explicit FakeLlmServer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace adse::llm::testing

#endif  // ADSE_TESTS_HARNESS_LLM_TESTING_FAKE_LLM_SERVER_H_
