// The record of every exchange with a model, and its replay. Each exchange
// (agent, model, prompt, image hashes, answer or error, tokens, latency)
// is appended to <campaign>/llm/exchanges.jsonl as it happens. Replaying
// answers a request from the record when an identical request (same agent,
// model, messages and images) was recorded, in recorded order, so an LLM
// campaign can be re-run, resumed or tested without a server.
#ifndef ADSE_HARNESS_LLM_EXCHANGE_LOG_H_
#define ADSE_HARNESS_LLM_EXCHANGE_LOG_H_

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "harness/llm/chat.h"
#include "harness/llm/jsonl_log.h"
#include "harness/spec/spec.h"
#include "stack/base/env.h"
#include "stack/base/status.h"

namespace adse::llm {

struct ExchangeRecord {
  int64_t seq = 0;         // 0-based, in the order the exchanges happened
  int64_t iteration = -1;  // exploration iteration; -1 outside one
  std::string agent;       // interpretation|dse|command|text|vision
  std::string model;
  std::string backend;         // ollama|openai (who answered originally)
  std::string request_sha256;  // RequestHash of the request
  std::string prompt;          // the messages as readable text
  std::vector<std::string> image_sha256;
  bool ok = true;
  std::string answer;      // the model's text (when ok)
  std::string error_code;  // when !ok: "unavailable", "invalid_argument", ...
  std::string error;       // when !ok: the message
  int64_t prompt_tokens = -1;
  int64_t completion_tokens = -1;
  double latency_s = 0.0;
  int attempts = 0;
};

// Identifies a request by content: agent, model, json flag, every
// message's role and text, and its images' SHA-256.
std::string RequestHash(const ChatRequest& request);

// The messages as a readable transcript ("[system]\n...\n\n[user]\n...").
std::string Transcript(const ChatRequest& request);

// Reads exchanges.jsonl. A missing file is an empty record. A last line cut
// short by a crash is ignored; any other bad line is Corruption naming the
// file and line.
Result<std::vector<ExchangeRecord>> LoadExchanges(const std::string& path);

// <folder>/llm/exchanges.jsonl
std::string ExchangesPath(const std::string& campaign_folder);

// A backend that answers from a record first and asks `live` only for
// requests the record does not hold. Live exchanges (answers and errors)
// are always appended to the log; the session's n-th exchange, when
// replayed, only if the log does not hold n exchanges already. So resuming
// a campaign from its own log appends only what is new, and replaying
// another campaign's log into a fresh folder records the whole session.
class RecordingBackend : public ChatBackend {
 public:
  // `recorded`: answers to replay (may be empty). `live`: null means
  // replay only, and an unrecorded request is NotFound naming
  // `replay_source`. `log`: where exchanges are recorded.
  RecordingBackend(std::vector<ExchangeRecord> recorded,
                   std::unique_ptr<ChatBackend> live, JsonlLog log,
                   std::string replay_source);

  Result<ChatReply> Chat(const ChatRequest& request) override;
  std::string name() const override;

  // Iteration stamped on the exchanges that follow.
  void set_iteration(int64_t iteration) { iteration_ = iteration; }
  // This session's exchanges (replayed and live), in order.
  const std::vector<ExchangeRecord>& session() const { return session_; }
  int replayed() const { return replayed_; }

 private:
  std::map<std::string, std::deque<ExchangeRecord>> recorded_;
  std::unique_ptr<ChatBackend> live_;
  JsonlLog log_;
  std::string replay_source_;
  int64_t next_seq_ = 0;
  int64_t iteration_ = -1;
  int replayed_ = 0;
  std::vector<ExchangeRecord> session_;
};

// The backend `llm` options ask for, recorded into `log_file` (empty: not
// recorded). Requests recorded in `replay_file` (empty: none) are answered
// from it first; with `backend: replay` only from it, and it must hold
// exchanges (NotFound otherwise). `where` prefixes errors about the options
// ("scenario.yaml:12:3: ").
Result<std::unique_ptr<RecordingBackend>> OpenRecordingBackend(
    const spec::LlmOptions& llm, const std::string& replay_file,
    const std::string& log_file, const std::string& where = "",
    Env* env = Env::Default());

}  // namespace adse::llm

#endif  // ADSE_HARNESS_LLM_EXCHANGE_LOG_H_
