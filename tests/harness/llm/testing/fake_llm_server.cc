#include "tests/harness/llm/testing/fake_llm_server.h"

#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>
#include <utility>

#include <httplib.h>
#include <nlohmann/json.hpp>

namespace adse::llm::testing {
namespace {

using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

constexpr char kOllamaPath[] = "/api/chat";
constexpr char kOpenAiPath[] = "/v1/chat/completions";
constexpr char kCreatedAt[] = "2024-01-01T00:00:00Z";
// Bodies go out in pieces of this size, so that body_bytes_sent() follows
// the client's reading closely.
constexpr size_t kPieceBytes = size_t{64} << 10;
// A delayed answer checks this often whether the server is shutting down.
constexpr auto kDelayStep = std::chrono::milliseconds(10);

std::string DecodeBase64(std::string_view text) {
  std::string out;
  uint32_t bits = 0;
  int count = 0;
  for (char c : text) {
    int v;
    if (c >= 'A' && c <= 'Z') {
      v = c - 'A';
    } else if (c >= 'a' && c <= 'z') {
      v = c - 'a' + 26;
    } else if (c >= '0' && c <= '9') {
      v = c - '0' + 52;
    } else if (c == '+') {
      v = 62;
    } else if (c == '/') {
      v = 63;
    } else {
      continue;  // padding
    }
    bits = (bits << 6) | static_cast<uint32_t>(v);
    count += 6;
    if (count >= 8) {
      count -= 8;
      out += static_cast<char>((bits >> count) & 0xFF);
    }
  }
  return out;
}

std::string Dump(const Json& doc) {
  return doc.dump(-1, ' ', false, Json::error_handler_t::replace);
}

int64_t TokensFor(size_t bytes) { return static_cast<int64_t>(bytes / 4 + 1); }

// Reads model and messages from a body of either API's shape.
void ParseChat(ReceivedRequest& request) {
  const Json doc = Json::parse(request.body, nullptr, false);
  if (!doc.is_object()) return;
  request.json_ok = true;
  if (doc.contains("model") && doc["model"].is_string()) {
    request.model = doc["model"].get<std::string>();
  }
  if (!doc.contains("messages") || !doc["messages"].is_array()) return;
  for (const Json& m : doc["messages"]) {
    if (!m.is_object()) continue;
    ReceivedMessage message;
    if (m.contains("role") && m["role"].is_string()) {
      message.role = m["role"].get<std::string>();
    }
    const Json content = m.value("content", Json());
    if (content.is_string()) {
      message.text = content.get<std::string>();
    } else if (content.is_array()) {  // OpenAI content parts
      for (const Json& part : content) {
        if (!part.is_object()) continue;
        if (part.value("type", "") == "text" && part.contains("text") &&
            part["text"].is_string()) {
          if (!message.text.empty()) message.text += "\n";
          message.text += part["text"].get<std::string>();
        } else if (part.value("type", "") == "image_url" &&
                   part.contains("image_url") &&
                   part["image_url"].is_object()) {
          const std::string url = part["image_url"].value("url", "");
          const size_t comma = url.find("base64,");
          if (comma != std::string::npos) {
            message.images_png.push_back(DecodeBase64(url.substr(comma + 7)));
          }
        }
      }
    }
    if (m.contains("images") && m["images"].is_array()) {  // Ollama
      for (const Json& image : m["images"]) {
        if (image.is_string()) {
          message.images_png.push_back(DecodeBase64(image.get<std::string>()));
        }
      }
    }
    request.messages.push_back(std::move(message));
  }
}

}  // namespace

std::string ReceivedRequest::TextOf(std::string_view role) const {
  std::string text;
  for (const ReceivedMessage& message : messages) {
    if (message.role != role) continue;
    if (!text.empty()) text += "\n";
    text += message.text;
  }
  return text;
}

bool ReceivedRequest::Mentions(std::string_view needle) const {
  return std::any_of(messages.begin(), messages.end(),
                     [&](const ReceivedMessage& message) {
                       return message.text.find(needle) != std::string::npos;
                     });
}

struct FakeLlmServer::Impl {
  httplib::Server server;
  std::thread thread;
  int port = 0;
  std::atomic<bool> stopping{false};
  std::atomic<size_t> bytes_sent{0};
  mutable std::mutex mutex;  // guards requests
  std::vector<ReceivedRequest> requests;
  std::mutex script_mutex;  // serialises script calls
  Script script;

  void Handle(const httplib::Request& http, httplib::Response& response);
  // Waits `seconds`, or less when the server is stopping; false then.
  bool Delay(double seconds) const;
  // Sends `piece` `repeat` times, in kPieceBytes writes, counting bytes.
  void Send(httplib::Response& response, int status,
            const std::string& content_type, std::string piece, size_t repeat,
            bool chunked);
  // Sends the lines one write each, chunked (Ollama's NDJSON stream).
  void SendLines(httplib::Response& response, std::vector<std::string> lines);
};

bool FakeLlmServer::Impl::Delay(double seconds) const {
  const Clock::time_point end =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(
                         std::chrono::duration<double>(seconds));
  while (Clock::now() < end) {
    if (stopping.load()) return false;
    std::this_thread::sleep_for(
        std::min<Clock::duration>(kDelayStep, end - Clock::now()));
  }
  return !stopping.load();
}

void FakeLlmServer::Impl::Send(httplib::Response& response, int status,
                               const std::string& content_type,
                               std::string piece, size_t repeat, bool chunked) {
  response.status = status;
  auto data = std::make_shared<const std::string>(std::move(piece));
  const size_t total = data->size() * repeat;
  if (total == 0) {
    response.set_content("", content_type);
    return;
  }
  // httplib passes the count of bytes written so far as `offset`.
  const auto write_at = [this, data](size_t offset, httplib::DataSink& sink) {
    const size_t at = offset % data->size();
    const size_t n = std::min(kPieceBytes, data->size() - at);
    if (!sink.write(data->data() + at, n)) return false;
    bytes_sent += n;
    return true;
  };
  if (chunked) {
    response.set_chunked_content_provider(
        content_type,
        [write_at, total](size_t offset, httplib::DataSink& sink) {
          if (offset < total) return write_at(offset, sink);
          sink.done();
          return true;
        });
  } else {
    response.set_content_provider(
        total, content_type,
        [write_at](size_t offset, size_t /*length*/, httplib::DataSink& sink) {
          return write_at(offset, sink);
        });
  }
}

void FakeLlmServer::Impl::SendLines(httplib::Response& response,
                                    std::vector<std::string> lines) {
  response.status = 200;
  auto data = std::make_shared<std::vector<std::string>>(std::move(lines));
  auto next = std::make_shared<size_t>(0);
  response.set_chunked_content_provider(
      "application/x-ndjson",
      [this, data, next](size_t /*offset*/, httplib::DataSink& sink) {
        if (*next == data->size()) {
          sink.done();
          return true;
        }
        const std::string& line = (*data)[(*next)++];
        if (!sink.write(line.data(), line.size())) return false;
        bytes_sent += line.size();
        return true;
      });
}

void FakeLlmServer::Impl::Handle(const httplib::Request& http,
                                 httplib::Response& response) {
  ReceivedRequest request;
  request.path = http.path;
  request.body = http.body;
  request.authorization = http.get_header_value("Authorization");
  ParseChat(request);
  {
    std::lock_guard<std::mutex> lock(mutex);
    requests.push_back(request);
  }
  const bool ollama = request.path == kOllamaPath;
  if (!ollama && request.path != kOpenAiPath) {
    Send(response, 404, "text/plain", "404 page not found", 1, false);
    return;
  }
  FakeAnswer answer;
  {
    std::lock_guard<std::mutex> lock(script_mutex);
    answer = script(request);
  }
  if (!Delay(answer.delay_s)) {
    response.status = 503;  // shutting down; the client has likely gone
    return;
  }
  if (answer.raw_body.has_value()) {
    Send(response, answer.status, "application/json",
         std::move(*answer.raw_body), answer.raw_body_repeat, answer.chunked);
    return;
  }
  if (answer.status < 200 || answer.status >= 300) {
    const Json error = ollama ? Json{{"error", answer.content}}
                              : Json{{"error",
                                      {{"message", answer.content},
                                       {"type", "fake_error"},
                                       {"code", answer.status}}}};
    Send(response, answer.status, "application/json", Dump(error), 1,
         answer.chunked);
    return;
  }

  size_t prompt_bytes = 0;
  for (const ReceivedMessage& message : request.messages) {
    prompt_bytes += message.text.size() + 16;  // role and template overhead
  }
  const int64_t prompt_tokens = answer.prompt_tokens >= 0
                                    ? answer.prompt_tokens
                                    : TokensFor(prompt_bytes);
  const int64_t completion_tokens = answer.completion_tokens >= 0
                                        ? answer.completion_tokens
                                        : TokensFor(answer.content.size());
  if (!ollama) {
    const Json body = {
        {"id", "chatcmpl-fake"},
        {"object", "chat.completion"},
        {"created", 1704067200},
        {"model", request.model},
        {"choices",
         Json::array({{{"index", 0},
                       {"message",
                        {{"role", "assistant"}, {"content", answer.content}}},
                       {"finish_reason", "stop"}}})},
        {"usage",
         {{"prompt_tokens", prompt_tokens},
          {"completion_tokens", completion_tokens},
          {"total_tokens", prompt_tokens + completion_tokens}}}};
    Send(response, 200, "application/json", Dump(body), 1, answer.chunked);
    return;
  }

  const auto chunk = [&](const std::string& content, bool done) {
    Json body = {{"model", request.model},
                 {"created_at", kCreatedAt},
                 {"message", {{"role", "assistant"}, {"content", content}}},
                 {"done", done}};
    if (done) {
      body["done_reason"] = "stop";
      body["prompt_eval_count"] = prompt_tokens;
      body["eval_count"] = completion_tokens;
    }
    return body;
  };
  // Like Ollama: a stream unless the request says "stream": false.
  const Json doc = Json::parse(request.body, nullptr, false);
  const bool stream_off =
      doc.is_object() && doc.contains("stream") && doc["stream"] == false;
  if (!answer.stream && stream_off) {
    Send(response, 200, "application/json", Dump(chunk(answer.content, true)),
         1, answer.chunked);
    return;
  }
  // A few pieces per answer, split at UTF-8 character starts.
  std::vector<std::string> lines;
  const std::string& text = answer.content;
  const size_t step = std::max<size_t>(1, text.size() / 3);
  size_t begin = 0;
  while (begin < text.size()) {
    size_t end = std::min(text.size(), begin + step);
    while (end < text.size() &&
           (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) {
      ++end;
    }
    lines.push_back(Dump(chunk(text.substr(begin, end - begin), false)) + "\n");
    begin = end;
  }
  lines.push_back(Dump(chunk("", true)) + "\n");
  SendLines(response, std::move(lines));
}

FakeLlmServer::FakeLlmServer(std::unique_ptr<Impl> impl)
    : impl_(std::move(impl)) {}

Result<std::unique_ptr<FakeLlmServer>> FakeLlmServer::Start(Script script) {
  // A client that hangs up mid-answer must not kill the test with SIGPIPE.
  ::signal(SIGPIPE, SIG_IGN);
  auto impl = std::make_unique<Impl>();
  impl->script = std::move(script);
  Impl* raw = impl.get();
  const auto handler = [raw](const httplib::Request& request,
                             httplib::Response& response) {
    raw->Handle(request, response);
  };
  impl->server.Post(".*", handler);
  // Idle keep-alive connections hold up stop() for this long.
  impl->server.set_keep_alive_timeout(1);
  // Like real model servers: no Nagle delay between headers and body.
  impl->server.set_tcp_nodelay(true);
  impl->port = impl->server.bind_to_any_port("127.0.0.1");
  if (impl->port <= 0) {
    return Status::Unavailable("fake LLM server: cannot bind 127.0.0.1");
  }
  impl->thread = std::thread([raw] { raw->server.listen_after_bind(); });
  // httplib's stop() does nothing before the server runs, so a server
  // stopped at once would never end: wait until it runs.
  const Clock::time_point deadline = Clock::now() + std::chrono::seconds(10);
  while (!impl->server.is_running() && Clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::unique_ptr<FakeLlmServer> server(new FakeLlmServer(std::move(impl)));
  if (!server->impl_->server.is_running()) {
    return Status::Unavailable("fake LLM server: did not start listening");
  }
  return server;
}

FakeLlmServer::Script FakeLlmServer::Sequence(std::vector<FakeAnswer> answers) {
  auto next = std::make_shared<size_t>(0);
  return [answers = std::move(answers), next](const ReceivedRequest&) {
    if (answers.empty()) return FakeAnswer{};
    const size_t i = std::min(*next, answers.size() - 1);
    ++*next;
    return answers[i];
  };
}

FakeLlmServer::~FakeLlmServer() {
  impl_->stopping = true;
  impl_->server.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

std::string FakeLlmServer::url() const {
  return "http://127.0.0.1:" + std::to_string(impl_->port);
}

int FakeLlmServer::port() const { return impl_->port; }

std::vector<ReceivedRequest> FakeLlmServer::requests() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->requests;
}

size_t FakeLlmServer::request_count() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->requests.size();
}

size_t FakeLlmServer::body_bytes_sent() const {
  return impl_->bytes_sent.load();
}

}  // namespace adse::llm::testing
