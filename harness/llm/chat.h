// Talking to a language model: one request/answer exchange with a chat
// backend (Ollama, an OpenAI-compatible server, or a recording). Everything
// a model answers is untrusted text; callers parse and validate it.
#ifndef ADSE_HARNESS_LLM_CHAT_H_
#define ADSE_HARNESS_LLM_CHAT_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "stack/base/status.h"

namespace adse::llm {

struct ChatMessage {
  std::string role;  // "system" | "user" | "assistant"
  std::string text;
  std::vector<std::string> images_png;  // raw PNG bytes (vision models)
};

struct ChatRequest {
  std::string agent;  // adse role: interpretation|dse|command|text|vision
  std::string model;
  std::vector<ChatMessage> messages;
  bool json = true;  // ask the server for a JSON answer
};

struct ChatReply {
  std::string text;            // the assistant message's content
  int64_t prompt_tokens = -1;  // -1: the server did not say
  int64_t completion_tokens = -1;
  double latency_s = 0.0;  // wall time of the successful attempt
  int attempts = 1;        // HTTP attempts made (retries + 1)
};

// One exchange at a time; not thread-safe.
class ChatBackend {
 public:
  virtual ~ChatBackend() = default;
  // The answer, or: Unavailable when the server cannot be reached or keeps
  // failing (the message names the URL and what to start), InvalidArgument
  // when it refuses the request (HTTP 4xx), Corruption when its answer is
  // not the API's JSON or exceeds the size limit, NotFound for a replay
  // backend that has no recording of this request.
  virtual Result<ChatReply> Chat(const ChatRequest& request) = 0;
  virtual std::string name() const = 0;  // "ollama" | "openai" | "replay"
};

struct HttpBackendOptions {
  // "ollama" (POST <endpoint>/api/chat) or "openai" (POST
  // <endpoint>/v1/chat/completions; an endpoint already ending in /v1 is
  // not given a second one).
  std::string api = "ollama";
  std::string endpoint = "http://127.0.0.1:11434";
  // Whole-request limit per attempt (connect + answer).
  double timeout_s = 120.0;
  double connect_timeout_s = 10.0;
  // Further attempts after a connection failure, a timeout, HTTP 429 or
  // 5xx; none after other 4xx answers.
  int retries = 2;
  // Wait before retry k (1-based): backoff_s * 2^(k-1).
  double backoff_s = 1.0;
  // Bearer token for openai (empty: no Authorization header).
  std::string api_key;
  // Answers larger than this are refused (Corruption), never parsed.
  size_t max_answer_bytes = 4u << 20;
};

// An HTTP backend over libcurl. InvalidArgument for an unknown api or an
// endpoint that is not an http(s) URL.
Result<std::unique_ptr<ChatBackend>> NewHttpBackend(
    const HttpBackendOptions& options);

}  // namespace adse::llm

#endif  // ADSE_HARNESS_LLM_CHAT_H_
