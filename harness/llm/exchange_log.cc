#include "harness/llm/exchange_log.h"

#include <cstdlib>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "stack/base/files.h"
#include "stack/base/hash.h"

namespace adse::llm {
namespace {

using nlohmann::json;

const char* CodeName(Status::Code code) {
  switch (code) {
    case Status::Code::kOk:
      return "ok";
    case Status::Code::kInvalidArgument:
      return "invalid_argument";
    case Status::Code::kNotFound:
      return "not_found";
    case Status::Code::kCorruption:
      return "corruption";
    case Status::Code::kIoError:
      return "io_error";
    case Status::Code::kUnavailable:
      return "unavailable";
    case Status::Code::kInternal:
      return "internal";
  }
  return "internal";
}

Status StatusFromRecord(const ExchangeRecord& r) {
  const std::string& c = r.error_code;
  // A hand-edited or foreign record may fail without saying why.
  const std::string error =
      r.error.empty()
          ? fmt::format(
                "the recorded exchange {} ({} agent) failed, and its "
                "record says no more",
                r.seq, r.agent)
          : r.error;
  if (c == "invalid_argument") return Status::InvalidArgument(error);
  if (c == "not_found") return Status::NotFound(error);
  if (c == "corruption") return Status::Corruption(error);
  if (c == "io_error") return Status::IoError(error);
  if (c == "unavailable") return Status::Unavailable(error);
  return Status::Internal(error);
}

json ToJson(const ExchangeRecord& r) {
  json j = {{"seq", r.seq},
            {"iteration", r.iteration},
            {"agent", r.agent},
            {"model", r.model},
            {"backend", r.backend},
            {"request_sha256", r.request_sha256},
            {"prompt", r.prompt},
            {"image_sha256", r.image_sha256},
            {"ok", r.ok},
            {"prompt_tokens", r.prompt_tokens},
            {"completion_tokens", r.completion_tokens},
            {"latency_s", r.latency_s},
            {"attempts", r.attempts}};
  if (r.ok) {
    j["answer"] = r.answer;
  } else {
    j["error_code"] = r.error_code;
    j["error"] = r.error;
  }
  return j;
}

ExchangeRecord FromJson(const json& j) {
  ExchangeRecord r;
  r.seq = j.at("seq").get<int64_t>();
  r.iteration = j.at("iteration").get<int64_t>();
  r.agent = j.at("agent").get<std::string>();
  r.model = j.at("model").get<std::string>();
  r.backend = j.value("backend", "");
  r.request_sha256 = j.at("request_sha256").get<std::string>();
  r.prompt = j.value("prompt", "");
  r.image_sha256 = j.value("image_sha256", std::vector<std::string>{});
  r.ok = j.at("ok").get<bool>();
  r.answer = j.value("answer", "");
  r.error_code = j.value("error_code", "");
  r.error = j.value("error", "");
  r.prompt_tokens = j.value("prompt_tokens", int64_t{-1});
  r.completion_tokens = j.value("completion_tokens", int64_t{-1});
  r.latency_s = j.value("latency_s", 0.0);
  r.attempts = j.value("attempts", 0);
  return r;
}

}  // namespace

namespace {

// Every image's SHA-256, in message order (hashed once per request).
std::vector<std::string> ImageHashes(const ChatRequest& request) {
  std::vector<std::string> hashes;
  for (const ChatMessage& m : request.messages) {
    for (const std::string& png : m.images_png)
      hashes.push_back(Sha256Hex(png));
  }
  return hashes;
}

std::string RequestHash(const ChatRequest& request,
                        const std::vector<std::string>& images) {
  ContentHasher h;
  h.Add(std::string_view("adse-llm-request-1"))
      .Add(request.agent)
      .Add(request.model)
      .Add(static_cast<long long>(request.json));
  size_t image = 0;
  for (const ChatMessage& m : request.messages) {
    h.Add(m.role).Add(m.text).Add(static_cast<long long>(m.images_png.size()));
    for (size_t i = 0; i < m.images_png.size(); ++i) h.Add(images[image++]);
  }
  return h.Hex();
}

}  // namespace

std::string RequestHash(const ChatRequest& request) {
  return RequestHash(request, ImageHashes(request));
}

std::string Transcript(const ChatRequest& request) {
  std::string out;
  for (const ChatMessage& m : request.messages) {
    if (!out.empty()) out += "\n\n";
    out += "[" + m.role + "]\n" + m.text;
    for (size_t i = 0; i < m.images_png.size(); ++i) {
      out += "\n[image " + std::to_string(i + 1) + ": " +
             std::to_string(m.images_png[i].size()) + " bytes PNG]";
    }
  }
  return out;
}

std::string ExchangesPath(const std::string& campaign_folder) {
  return campaign_folder + "/llm/exchanges.jsonl";
}

Result<std::vector<ExchangeRecord>> LoadExchanges(const std::string& path) {
  std::vector<ExchangeRecord> records;
  ADSE_RETURN_IF_ERROR(
      ReadJsonLines(path, "an exchange record", [&](const std::string& line) {
        records.push_back(FromJson(json::parse(line)));
      }));
  return records;
}

RecordingBackend::RecordingBackend(std::vector<ExchangeRecord> recorded,
                                   std::unique_ptr<ChatBackend> live,
                                   JsonlLog log, std::string replay_source)
    : live_(std::move(live)),
      log_(std::move(log)),
      replay_source_(std::move(replay_source)) {
  for (ExchangeRecord& r : recorded) {
    recorded_[r.request_sha256].push_back(std::move(r));
  }
}

std::string RecordingBackend::name() const {
  return live_ ? live_->name() : "replay";
}

Result<ChatReply> RecordingBackend::Chat(const ChatRequest& request) {
  ExchangeRecord r;
  r.seq = next_seq_;  // counted below once it is an exchange
  r.iteration = iteration_;
  r.agent = request.agent;
  r.model = request.model;
  r.image_sha256 = ImageHashes(request);
  r.request_sha256 = RequestHash(request, r.image_sha256);
  r.prompt = Transcript(request);

  Result<ChatReply> reply = Status::Internal("no answer");
  auto it = recorded_.find(r.request_sha256);
  const bool replayed = it != recorded_.end() && !it->second.empty();
  if (replayed) {
    const ExchangeRecord old = std::move(it->second.front());
    it->second.pop_front();
    ++replayed_;
    r.backend = old.backend;
    r.ok = old.ok;
    r.answer = old.answer;
    r.error_code = old.error_code;
    r.error = old.error;
    r.prompt_tokens = old.prompt_tokens;
    r.completion_tokens = old.completion_tokens;
    r.latency_s = old.latency_s;
    r.attempts = old.attempts;
    if (old.ok) {
      ChatReply ok;
      ok.text = old.answer;
      ok.prompt_tokens = old.prompt_tokens;
      ok.completion_tokens = old.completion_tokens;
      ok.latency_s = old.latency_s;
      ok.attempts = old.attempts;
      reply = std::move(ok);
    } else {
      reply = StatusFromRecord(old);
    }
  } else if (!live_) {
    // Not an answer to record: the replay itself is broken.
    return Status::NotFound(
        "llm replay: no recorded answer for this " + request.agent +
        " request (exchange " + std::to_string(r.seq) + ", model " +
        request.model + ", request " + r.request_sha256.substr(0, 12) +
        ") in " + replay_source_ +
        "; something that shapes the request differs from the recording (the "
        "scenario, its budget, the prompts, the evaluated runs or, for `adse "
        "interpret`, the request or output file name)");
  } else {
    r.backend = live_->name();
    reply = live_->Chat(request);
    if (reply.ok()) {
      r.answer = reply->text;
      r.prompt_tokens = reply->prompt_tokens;
      r.completion_tokens = reply->completion_tokens;
      r.latency_s = reply->latency_s;
      r.attempts = reply->attempts;
    } else {
      r.ok = false;
      r.error_code = CodeName(reply.status().code());
      r.error = reply.status().message();
    }
  }

  ++next_seq_;
  // A live answer is new whatever the log holds (a resumed session that
  // asks something the record lacks); a replayed one may be there already.
  const std::string line =
      ToJson(r).dump(-1, ' ', false, json::error_handler_t::replace);
  Status logged = replayed ? log_.Append(line) : log_.AppendNew(line);
  if (!logged.ok()) return logged.WithContext("recording an llm exchange");
  session_.push_back(std::move(r));
  return reply;
}

Result<std::unique_ptr<RecordingBackend>> OpenRecordingBackend(
    const spec::LlmOptions& llm, const std::string& replay_file,
    const std::string& log_file, const std::string& where, Env* env) {
  // Opened first: it drops a line cut short by a crash before it is read.
  Result<JsonlLog> log = JsonlLog::Open(log_file, env);
  if (!log.ok()) return log.status();
  std::vector<ExchangeRecord> recorded;
  if (!replay_file.empty()) {
    Result<std::vector<ExchangeRecord>> loaded = LoadExchanges(replay_file);
    if (!loaded.ok()) return loaded.status();
    recorded = std::move(*loaded);
  }
  if (llm.backend == "replay") {
    if (recorded.empty()) {
      return Status::NotFound(
          where + "llm.replay_from: " +
          (replay_file.empty() ? std::string("no record given")
                               : replay_file + " holds no recorded exchanges") +
          " (expected the record of a run with an llm backend)");
    }
    return std::make_unique<RecordingBackend>(std::move(recorded), nullptr,
                                              std::move(*log), replay_file);
  }
  HttpBackendOptions http;
  http.api = llm.backend;
  http.endpoint = llm.endpoint;
  http.timeout_s = llm.timeout_s;
  http.retries = llm.retries;
  if (llm.backend == "openai") {
    if (const char* key = std::getenv(llm.api_key_env.c_str()); key && *key)
      http.api_key = key;
  }
  Result<std::unique_ptr<ChatBackend>> live = NewHttpBackend(http);
  if (!live.ok()) return live.status().WithContext(where + "llm");
  return std::make_unique<RecordingBackend>(
      std::move(recorded), std::move(*live), std::move(*log), replay_file);
}

}  // namespace adse::llm
