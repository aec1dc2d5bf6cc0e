// Chat backends over libcurl: the Ollama and OpenAI-compatible chat APIs,
// with a timeout per attempt, bounded retries and a cap on the answer size.
// libcurl stays inside this file; its failures become a Status here.
#include <curl/curl.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "harness/llm/chat.h"

namespace adse::llm {
namespace {

using Clock = std::chrono::steady_clock;
using Json = nlohmann::json;

enum class Api { kOllama, kOpenAi };

constexpr size_t kExcerptBytes = 300;
// Never retry more often than this, whatever the options say: a typo such
// as retries=1000 must not turn a dead server into an endless wait.
constexpr int kMaxRetries = 20;

// ---- Small helpers --------------------------------------------------------

std::string Base64(std::string_view bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = (uint32_t{static_cast<uint8_t>(bytes[i])} << 16) |
                       (uint32_t{static_cast<uint8_t>(bytes[i + 1])} << 8) |
                       uint32_t{static_cast<uint8_t>(bytes[i + 2])};
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i < bytes.size()) {
    const bool two = i + 1 < bytes.size();
    const uint32_t v =
        (uint32_t{static_cast<uint8_t>(bytes[i])} << 16) |
        (two ? uint32_t{static_cast<uint8_t>(bytes[i + 1])} << 8 : 0u);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += two ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

// The start of `text` on one line, cut at a UTF-8 boundary, for messages.
std::string Excerpt(std::string_view text, size_t limit = kExcerptBytes) {
  std::string out;
  bool space = false;
  bool cut_short = false;
  for (char c : text) {
    if (std::isspace(static_cast<unsigned char>(c)) ||
        static_cast<unsigned char>(c) < 0x20) {
      space = !out.empty();
      continue;
    }
    if (out.size() > limit + 4) {  // enough to find a character boundary
      cut_short = true;
      break;
    }
    if (space) out += ' ';
    space = false;
    out += c;
  }
  if (out.size() > limit) {
    size_t cut = limit;
    // Back over UTF-8 continuation bytes: the character at `cut` is left
    // out whole.
    while (cut > 0 && (static_cast<unsigned char>(out[cut]) & 0xC0) == 0x80) {
      --cut;
    }
    out.resize(cut);
    cut_short = true;
  }
  if (cut_short) out += "...";
  if (out.empty()) out = "(empty body)";
  return out;
}

// The error text of an API error answer ({"error": "..."} for Ollama,
// {"error": {"message": "..."}} for OpenAI), else the body itself.
std::string ErrorExcerpt(const std::string& body) {
  const Json doc = Json::parse(body, nullptr, /*allow_exceptions=*/false);
  if (doc.is_object() && doc.contains("error")) {
    const Json& error = doc["error"];
    if (error.is_string()) return Excerpt(error.get<std::string>());
    if (error.is_object() && error.contains("message") &&
        error["message"].is_string()) {
      return Excerpt(error["message"].get<std::string>());
    }
  }
  return Excerpt(body);
}

bool ContainsNoCase(std::string_view text, std::string_view needle) {
  return std::search(text.begin(), text.end(), needle.begin(), needle.end(),
                     [](char a, char b) {
                       return std::tolower(static_cast<unsigned char>(a)) ==
                              std::tolower(static_cast<unsigned char>(b));
                     }) != text.end();
}

std::string SizeText(size_t bytes) {
  constexpr size_t kMiB = size_t{1} << 20;
  if (bytes % kMiB == 0) return fmt::format("{} MiB", bytes / kMiB);
  if (bytes >= kMiB) return fmt::format("{:.1f} MiB", double(bytes) / kMiB);
  return fmt::format("{} bytes", bytes);
}

std::string Attempts(int n) {
  return fmt::format("{} attempt{}", n, n == 1 ? "" : "s");
}

// Model text may hold invalid UTF-8; it must not make the request fail.
std::string Dump(const Json& doc) {
  return doc.dump(-1, ' ', false, Json::error_handler_t::replace);
}

// `url` without "user:password@", so that messages never show credentials.
std::string Redacted(const std::string& url) {
  const size_t scheme = url.find("://");
  if (scheme == std::string::npos) return url;
  const size_t host = scheme + 3;
  const size_t at = url.find('@', host);
  const size_t slash = url.find('/', host);
  if (at == std::string::npos || (slash != std::string::npos && at > slash)) {
    return url;
  }
  return url.substr(0, host) + url.substr(at + 1);
}

const Json* Member(const Json& object, const char* key) {
  if (!object.is_object()) return nullptr;
  const auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

int64_t Count(const Json& object, const char* key) {
  const Json* value = Member(object, key);
  if (value == nullptr || !value->is_number_integer()) return -1;
  return value->get<int64_t>();
}

// ---- libcurl --------------------------------------------------------------

Status InitCurlOnce() {
  static std::once_flag once;
  static CURLcode code = CURLE_OK;
  std::call_once(once, [] { code = curl_global_init(CURL_GLOBAL_DEFAULT); });
  if (code != CURLE_OK) {
    return Status::Unavailable(fmt::format("libcurl failed to initialise: {}",
                                           curl_easy_strerror(code)));
  }
  return Status::Ok();
}

struct CurlDeleter {
  void operator()(CURL* curl) const { curl_easy_cleanup(curl); }
};
struct HeadersDeleter {
  void operator()(curl_slist* list) const { curl_slist_free_all(list); }
};
struct UrlDeleter {
  void operator()(CURLU* url) const { curl_url_cleanup(url); }
};
using CurlHandle = std::unique_ptr<CURL, CurlDeleter>;
using CurlHeaders = std::unique_ptr<curl_slist, HeadersDeleter>;

// The endpoint without trailing slashes, or why it is not an http(s) base
// URL the API paths can be appended to.
Result<std::string> BaseUrl(const std::string& endpoint) {
  std::string base = endpoint;
  while (!base.empty() && base.back() == '/') base.pop_back();
  const auto invalid = [&](std::string_view why) {
    return Status::InvalidArgument(
        fmt::format("LLM endpoint '{}' {}; expected a base URL such as "
                    "http://127.0.0.1:11434",
                    Redacted(endpoint), why));
  };
  std::unique_ptr<CURLU, UrlDeleter> url(curl_url());
  if (url == nullptr) return Status::Unavailable("libcurl: out of memory");
  if (base.empty() ||
      curl_url_set(url.get(), CURLUPART_URL, base.c_str(), 0) != CURLUE_OK) {
    return invalid("is not a URL");
  }
  const auto part = [&](CURLUPart which) -> std::optional<std::string> {
    char* text = nullptr;
    if (curl_url_get(url.get(), which, &text, 0) != CURLUE_OK) {
      return std::nullopt;
    }
    std::string value = text == nullptr ? "" : text;
    curl_free(text);
    return value;
  };
  const std::optional<std::string> scheme = part(CURLUPART_SCHEME);
  if (!scheme.has_value() || (*scheme != "http" && *scheme != "https")) {
    return invalid("is not an http:// or https:// URL");
  }
  const std::optional<std::string> host = part(CURLUPART_HOST);
  if (!host.has_value() || host->empty()) return invalid("names no host");
  if (part(CURLUPART_QUERY).has_value() ||
      part(CURLUPART_FRAGMENT).has_value()) {
    return invalid("has a query or fragment");
  }
  return base;
}

// Local servers are never reached through a proxy, even when http_proxy is
// set for the outside world; the user's own no_proxy list still applies.
std::string NoProxyList() {
  std::string list = "localhost,127.0.0.1,::1";
  for (const char* name : {"no_proxy", "NO_PROXY"}) {
    const char* value = std::getenv(name);
    if (value != nullptr && *value != '\0') {
      list += ',';
      list += value;
      break;
    }
  }
  return list;
}

// What one HTTP exchange produced.
struct Exchange {
  CURLcode code = CURLE_OK;
  std::string curl_error;     // curl's reason when code != CURLE_OK
  bool request_sent = false;  // a timeout then means a slow answer
  bool too_large = false;     // aborted: the answer passed the size limit
  long http_status = 0;
  std::string body;
  double seconds = 0.0;
};

// The answer as it arrives; a transfer that would grow it past `limit` is
// aborted here, before the bytes are stored.
struct Sink {
  std::string body;
  size_t limit = 0;
  bool too_large = false;
};

size_t OnData(char* data, size_t size, size_t count, void* user) {
  Sink& sink = *static_cast<Sink*>(user);
  const size_t n = size * count;
  if (n > sink.limit - sink.body.size()) {
    sink.too_large = true;
    return 0;  // anything but n aborts the transfer (CURLE_WRITE_ERROR)
  }
  sink.body.append(data, n);
  return n;
}

bool Retryable(CURLcode code) {
  switch (code) {
    case CURLE_COULDNT_RESOLVE_PROXY:
    case CURLE_COULDNT_RESOLVE_HOST:
    case CURLE_COULDNT_CONNECT:
    case CURLE_OPERATION_TIMEDOUT:
    case CURLE_SEND_ERROR:
    case CURLE_RECV_ERROR:
    case CURLE_GOT_NOTHING:
    case CURLE_PARTIAL_FILE:
    case CURLE_SSL_CONNECT_ERROR:
    case CURLE_HTTP2:
    case CURLE_HTTP2_STREAM:
      return true;
    default:
      return false;
  }
}

// ---- Request bodies -------------------------------------------------------

std::string OllamaRequest(const ChatRequest& request) {
  Json messages = Json::array();
  for (const ChatMessage& message : request.messages) {
    Json m = {{"role", message.role}, {"content", message.text}};
    if (!message.images_png.empty()) {
      Json images = Json::array();
      for (const std::string& png : message.images_png) {
        images.push_back(Base64(png));
      }
      m["images"] = std::move(images);
    }
    messages.push_back(std::move(m));
  }
  // Ollama streams NDJSON unless told otherwise.
  Json body = {{"model", request.model},
               {"messages", std::move(messages)},
               {"stream", false}};
  if (request.json) body["format"] = "json";
  return Dump(body);
}

std::string OpenAiRequest(const ChatRequest& request) {
  Json messages = Json::array();
  for (const ChatMessage& message : request.messages) {
    Json m = {{"role", message.role}};
    if (message.images_png.empty()) {
      m["content"] = message.text;
    } else {
      Json parts = Json::array();
      if (!message.text.empty()) {
        parts.push_back({{"type", "text"}, {"text", message.text}});
      }
      for (const std::string& png : message.images_png) {
        parts.push_back(
            {{"type", "image_url"},
             {"image_url", {{"url", "data:image/png;base64," + Base64(png)}}}});
      }
      m["content"] = std::move(parts);
    }
    messages.push_back(std::move(m));
  }
  Json body = {{"model", request.model},
               {"messages", std::move(messages)},
               {"stream", false}};
  if (request.json) body["response_format"] = {{"type", "json_object"}};
  return Dump(body);
}

// ---- The backend ----------------------------------------------------------

class HttpBackend final : public ChatBackend {
 public:
  HttpBackend(Api api, HttpBackendOptions options, std::string url,
              CurlHandle curl, CurlHeaders headers)
      : api_(api),
        options_(std::move(options)),
        url_(std::move(url)),
        shown_url_(Redacted(url_)),
        shown_endpoint_(Redacted(options_.endpoint)),
        headers_(std::move(headers)),
        curl_(std::move(curl)) {}

  Result<ChatReply> Chat(const ChatRequest& request) override;
  std::string name() const override {
    return api_ == Api::kOllama ? "ollama" : "openai";
  }

 private:
  Exchange Post(const std::string& body);
  Result<ChatReply> ParseAnswer(const std::string& body) const;
  Result<ChatReply> ParseOllama(const std::string& body) const;
  Result<ChatReply> ParseOpenAi(const std::string& body) const;
  Status NotTheApi(std::string_view what, const std::string& body) const;
  // A 1xx/3xx/4xx answer: the server will not take this request as it is.
  Status Refused(const Exchange& exchange, const std::string& model) const;
  // The last failure after every attempt failed (or one that no retry can
  // fix), with what to check.
  Status GaveUp(const Exchange& exchange, int attempts,
                const std::string& model) const;

  const Api api_;
  const HttpBackendOptions options_;
  const std::string url_;
  const std::string shown_url_;
  const std::string shown_endpoint_;
  CurlHeaders headers_;  // outlives curl_, which points to it
  CurlHandle curl_;      // kept across exchanges so the connection is reused
  char curl_error_[CURL_ERROR_SIZE] = {};
};

Result<ChatReply> HttpBackend::Chat(const ChatRequest& request) {
  if (request.model.empty()) {
    return Status::InvalidArgument(fmt::format(
        "chat request of agent '{}' names no model", request.agent));
  }
  if (request.messages.empty()) {
    return Status::InvalidArgument(fmt::format(
        "chat request of agent '{}' has no messages", request.agent));
  }
  const std::string body =
      api_ == Api::kOllama ? OllamaRequest(request) : OpenAiRequest(request);
  const int retries = std::clamp(options_.retries, 0, kMaxRetries);
  for (int attempt = 1;; ++attempt) {
    Exchange exchange = Post(body);
    if (exchange.too_large) {
      return Status::Corruption(fmt::format(
          "answer larger than {} from {}: stopped receiving it (the limit "
          "is max_answer_bytes)",
          SizeText(options_.max_answer_bytes), shown_url_));
    }
    if (exchange.code != CURLE_OK) {
      if (!Retryable(exchange.code)) {
        return GaveUp(exchange, attempt, request.model);
      }
    } else if (exchange.http_status >= 200 && exchange.http_status < 300) {
      Result<ChatReply> reply = ParseAnswer(exchange.body);
      if (reply.ok()) {
        reply->latency_s = exchange.seconds;
        reply->attempts = attempt;
      }
      return reply;
    } else if (exchange.http_status != 429 && exchange.http_status < 500) {
      return Refused(exchange, request.model);
    }
    if (attempt > retries) return GaveUp(exchange, attempt, request.model);
    const double wait_s =
        std::max(0.0, std::ldexp(options_.backoff_s, attempt - 1));
    std::this_thread::sleep_for(std::chrono::duration<double>(wait_s));
  }
}

Exchange HttpBackend::Post(const std::string& body) {
  CURL* curl = curl_.get();
  Sink sink;
  sink.limit = options_.max_answer_bytes;
  curl_error_[0] = '\0';
  curl_easy_setopt(curl, CURLOPT_ERRORBUFFER, curl_error_);
  curl_easy_setopt(curl, CURLOPT_POSTFIELDS, body.data());
  curl_easy_setopt(curl, CURLOPT_POSTFIELDSIZE_LARGE,
                   static_cast<curl_off_t>(body.size()));
  curl_easy_setopt(curl, CURLOPT_WRITEDATA, &sink);

  Exchange exchange;
  const Clock::time_point start = Clock::now();
  exchange.code = curl_easy_perform(curl);
  exchange.seconds =
      std::chrono::duration<double>(Clock::now() - start).count();
  curl_easy_getinfo(curl, CURLINFO_RESPONSE_CODE, &exchange.http_status);
  long request_size = 0;
  curl_easy_getinfo(curl, CURLINFO_REQUEST_SIZE, &request_size);
  exchange.request_sent = request_size > 0;
  exchange.too_large =
      sink.too_large || exchange.code == CURLE_FILESIZE_EXCEEDED;
  if (exchange.code != CURLE_OK) {
    exchange.curl_error = curl_error_[0] != '\0'
                              ? std::string(curl_error_)
                              : curl_easy_strerror(exchange.code);
  }
  exchange.body = std::move(sink.body);
  return exchange;
}

Status HttpBackend::NotTheApi(std::string_view what,
                              const std::string& body) const {
  return Status::Corruption(fmt::format(
      "{} answered {} instead of the {} chat API's JSON: {}", shown_url_, what,
      api_ == Api::kOllama ? "Ollama" : "OpenAI", Excerpt(body)));
}

Result<ChatReply> HttpBackend::ParseAnswer(const std::string& body) const {
  return api_ == Api::kOllama ? ParseOllama(body) : ParseOpenAi(body);
}

Result<ChatReply> HttpBackend::ParseOllama(const std::string& body) const {
  // One JSON object, or NDJSON chunks when the server streams anyway.
  std::vector<Json> chunks;
  Json whole = Json::parse(body, nullptr, /*allow_exceptions=*/false);
  if (!whole.is_discarded()) {
    chunks.push_back(std::move(whole));
  } else {
    size_t begin = 0;
    while (begin < body.size()) {
      size_t end = body.find('\n', begin);
      if (end == std::string::npos) end = body.size();
      std::string_view line(body.data() + begin, end - begin);
      begin = end + 1;
      while (!line.empty() &&
             std::isspace(static_cast<unsigned char>(line.back()))) {
        line.remove_suffix(1);
      }
      if (line.empty()) continue;
      Json chunk = Json::parse(line, nullptr, /*allow_exceptions=*/false);
      if (chunk.is_discarded()) return NotTheApi("text that is not JSON", body);
      chunks.push_back(std::move(chunk));
    }
    if (chunks.empty()) return NotTheApi("an empty body", body);
  }

  ChatReply reply;
  bool has_content = false;
  for (const Json& chunk : chunks) {
    if (!chunk.is_object()) return NotTheApi("JSON of the wrong shape", body);
    if (const Json* error = Member(chunk, "error"); error != nullptr) {
      return Status::Unavailable(fmt::format(
          "Ollama at {} reported an error while answering: {}", shown_url_,
          error->is_string() ? Excerpt(error->get<std::string>())
                             : Excerpt(Dump(*error))));
    }
    const Json* message = Member(chunk, "message");
    if (message == nullptr) continue;
    const Json* content = Member(*message, "content");
    if (content == nullptr || !content->is_string()) {
      return NotTheApi("a message without text content", body);
    }
    reply.text += content->get<std::string>();
    has_content = true;
  }
  if (!has_content) return NotTheApi("JSON without message.content", body);
  const Json& last = chunks.back();
  const Json* done = Member(last, "done");
  const bool streamed =
      chunks.size() > 1 || (done != nullptr && *done == false);
  if (streamed && (done == nullptr || *done != true)) {
    return NotTheApi("a stream that ended before its last chunk", body);
  }
  reply.prompt_tokens = Count(last, "prompt_eval_count");
  reply.completion_tokens = Count(last, "eval_count");
  return reply;
}

Result<ChatReply> HttpBackend::ParseOpenAi(const std::string& body) const {
  const Json doc = Json::parse(body, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) return NotTheApi("text that is not JSON", body);
  const Json* choices = Member(doc, "choices");
  if (choices == nullptr || !choices->is_array() || choices->empty()) {
    return NotTheApi("JSON without choices", body);
  }
  const Json* message = Member((*choices)[0], "message");
  const Json* content =
      message == nullptr ? nullptr : Member(*message, "content");
  if (content == nullptr || !content->is_string()) {
    return NotTheApi("JSON without choices[0].message.content", body);
  }
  ChatReply reply;
  reply.text = content->get<std::string>();
  if (const Json* usage = Member(doc, "usage"); usage != nullptr) {
    reply.prompt_tokens = Count(*usage, "prompt_tokens");
    reply.completion_tokens = Count(*usage, "completion_tokens");
  }
  return reply;
}

Status HttpBackend::Refused(const Exchange& exchange,
                            const std::string& model) const {
  const long status = exchange.http_status;
  const std::string excerpt = ErrorExcerpt(exchange.body);
  if (api_ == Api::kOllama && status == 404 &&
      ContainsNoCase(exchange.body, "model") &&
      ContainsNoCase(exchange.body, "not found")) {
    return Status::InvalidArgument(fmt::format(
        "Ollama at {} has no model '{}' (HTTP 404: {}); pull it with "
        "`ollama pull {}`",
        shown_endpoint_, model, excerpt, model));
  }
  if (status < 400) {
    return Status::InvalidArgument(fmt::format(
        "{} answered HTTP {} instead of a chat answer (redirects are not "
        "followed; give the server's own URL): {}",
        shown_url_, status, excerpt));
  }
  std::string hint;
  if (status == 401 || status == 403) {
    hint = api_ == Api::kOpenAi ? "; check the API key"
                                : "; does a proxy in front of Ollama want "
                                  "credentials?";
  } else if (status == 404) {
    hint = api_ == Api::kOllama
               ? "; is the endpoint the base URL of an Ollama server, such as "
                 "http://127.0.0.1:11434?"
               : "; is this an OpenAI-compatible server (and the endpoint "
                 "its base URL)?";
  }
  return Status::InvalidArgument(
      fmt::format("{} refused the request of model '{}' with HTTP {}: {}{}",
                  shown_url_, model, status, excerpt, hint));
}

Status HttpBackend::GaveUp(const Exchange& exchange, int attempts,
                           const std::string& model) const {
  const std::string tries = Attempts(attempts);
  if (exchange.code == CURLE_OK) {  // HTTP 429 or 5xx every time
    return Status::Unavailable(fmt::format(
        "{} answered HTTP {} (after {}): {}{}", shown_url_,
        exchange.http_status, tries, ErrorExcerpt(exchange.body),
        exchange.http_status == 429 ? "; the server is rate-limiting requests"
                                    : ""));
  }
  const std::string start_hint =
      api_ == Api::kOllama
          ? fmt::format(
                "is Ollama running? start it with `ollama serve` and pull "
                "the model with `ollama pull {}`",
                model)
          : fmt::format("is the OpenAI-compatible server running at {}?",
                        shown_endpoint_);
  if (exchange.code == CURLE_OPERATION_TIMEDOUT && exchange.request_sent) {
    return Status::Unavailable(fmt::format(
        "{} did not answer within {:g} s (after {}): {}; a model that is "
        "still loading or a slow machine needs a longer timeout",
        shown_url_, options_.timeout_s, tries, exchange.curl_error));
  }
  const bool unreachable = exchange.code == CURLE_COULDNT_CONNECT ||
                           exchange.code == CURLE_COULDNT_RESOLVE_HOST ||
                           exchange.code == CURLE_COULDNT_RESOLVE_PROXY ||
                           exchange.code == CURLE_OPERATION_TIMEDOUT;
  const std::string what =
      unreachable ? fmt::format("cannot reach {}", shown_url_)
                  : fmt::format("the exchange with {} failed", shown_url_);
  return Status::Unavailable(fmt::format("{} (after {}): {}; {}", what, tries,
                                         exchange.curl_error, start_hint));
}

}  // namespace

Result<std::unique_ptr<ChatBackend>> NewHttpBackend(
    const HttpBackendOptions& options) {
  Api api;
  if (options.api == "ollama") {
    api = Api::kOllama;
  } else if (options.api == "openai") {
    api = Api::kOpenAi;
  } else {
    return Status::InvalidArgument(fmt::format(
        "unknown LLM api '{}'; expected 'ollama' or 'openai'", options.api));
  }
  if (!(options.timeout_s > 0) || !std::isfinite(options.timeout_s) ||
      !(options.connect_timeout_s > 0) ||
      !std::isfinite(options.connect_timeout_s)) {
    return Status::InvalidArgument(
        "LLM timeouts must be positive numbers of seconds");
  }
  if (options.retries < 0 || !(options.backoff_s >= 0) ||
      !std::isfinite(options.backoff_s)) {
    return Status::InvalidArgument(
        "LLM retries and backoff must not be negative");
  }
  if (options.max_answer_bytes == 0) {
    return Status::InvalidArgument("the LLM answer size limit must be > 0");
  }
  Result<std::string> base = BaseUrl(options.endpoint);
  if (!base.ok()) return base.status();
  std::string url = *base;
  if (api == Api::kOllama) {
    url += "/api/chat";
  } else {
    const bool has_v1 =
        url.size() >= 3 && url.compare(url.size() - 3, 3, "/v1") == 0;
    url += has_v1 ? "/chat/completions" : "/v1/chat/completions";
  }

  ADSE_RETURN_IF_ERROR(InitCurlOnce());
  CurlHandle curl(curl_easy_init());
  if (curl == nullptr) return Status::Unavailable("libcurl: out of memory");
  curl_slist* list = nullptr;
  const auto add = [&list](const std::string& header) {
    curl_slist* grown = curl_slist_append(list, header.c_str());
    if (grown != nullptr) list = grown;
    return grown != nullptr;
  };
  // "Expect:" stops curl from waiting for 100-continue before large
  // (image) bodies; not every server sends one.
  bool added = add("Content-Type: application/json") &&
               add("Accept: application/json") && add("Expect:");
  if (added && api == Api::kOpenAi && !options.api_key.empty()) {
    added = add("Authorization: Bearer " + options.api_key);
  }
  CurlHeaders headers(list);
  if (!added) return Status::Unavailable("libcurl: out of memory");

  const auto ms = [](double s) {
    return std::max(1L, static_cast<long>(std::llround(s * 1000.0)));
  };
  CURL* c = curl.get();
  curl_easy_setopt(c, CURLOPT_URL, url.c_str());
  curl_easy_setopt(c, CURLOPT_NOSIGNAL, 1L);  // adse handles signals itself
  curl_easy_setopt(c, CURLOPT_POST, 1L);
  curl_easy_setopt(c, CURLOPT_HTTPHEADER, headers.get());
  curl_easy_setopt(c, CURLOPT_TIMEOUT_MS, ms(options.timeout_s));
  curl_easy_setopt(c, CURLOPT_CONNECTTIMEOUT_MS, ms(options.connect_timeout_s));
  curl_easy_setopt(c, CURLOPT_WRITEFUNCTION, OnData);
  // Refuses an announced Content-Length over the limit before any byte;
  // OnData catches the answers that do not announce one.
  curl_easy_setopt(c, CURLOPT_MAXFILESIZE_LARGE,
                   static_cast<curl_off_t>(
                       std::min<size_t>(options.max_answer_bytes, INT64_MAX)));
  curl_easy_setopt(c, CURLOPT_NOPROXY, NoProxyList().c_str());
  curl_easy_setopt(c, CURLOPT_TCP_KEEPALIVE, 1L);
  curl_easy_setopt(c, CURLOPT_USERAGENT, "adse/" ADSE_VERSION);
  return std::unique_ptr<ChatBackend>(std::make_unique<HttpBackend>(
      api, options, std::move(url), std::move(curl), std::move(headers)));
}

}  // namespace adse::llm
