// An in-process ChatBackend that answers from a script, for tests that do
// not need HTTP.
#ifndef ADSE_TESTS_HARNESS_LLM_TESTING_SCRIPTED_BACKEND_H_
#define ADSE_TESTS_HARNESS_LLM_TESTING_SCRIPTED_BACKEND_H_

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "harness/llm/chat.h"

namespace adse::llm::testing {

class ScriptedBackend : public ChatBackend {
 public:
  using Script = std::function<Result<ChatReply>(const ChatRequest&)>;
  explicit ScriptedBackend(Script script) : script_(std::move(script)) {}

  Result<ChatReply> Chat(const ChatRequest& request) override {
    requests_.push_back(request);
    return script_(request);
  }
  std::string name() const override { return "scripted"; }
  const std::vector<ChatRequest>& requests() const { return requests_; }

  static ChatReply Reply(std::string text) {
    ChatReply r;
    r.text = std::move(text);
    r.prompt_tokens = 10;
    r.completion_tokens = 5;
    r.latency_s = 0.01;
    return r;
  }

 private:
  Script script_;
  std::vector<ChatRequest> requests_;
};

}  // namespace adse::llm::testing

#endif  // ADSE_TESTS_HARNESS_LLM_TESTING_SCRIPTED_BACKEND_H_
