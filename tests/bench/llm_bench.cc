// adse's own cost of one `llm` iteration — prompt building, memory
// curation, strict parsing, recording — with models that answer at once,
// and one chat round trip over HTTP (libcurl to a local server). The
// models' own latency comes on top; see the README.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "harness/llm/exchange_log.h"
#include "harness/llm/llm_strategy.h"
#include "harness/spec/spec_parser.h"
#include "tests/harness/llm/testing/fake_llm_server.h"

namespace adse::llm {
namespace {

// Answers the DSE agent with the grid's points in order and the command
// agent with an empty (refused, then fallen back on) answer.
class InstantBackend : public ChatBackend {
 public:
  explicit InstantBackend(const spec::DesignSpace* space) : space_(space) {}
  Result<ChatReply> Chat(const ChatRequest& request) override {
    ChatReply reply;
    if (request.agent != "dse") {
      reply.text = "{}";
      return reply;
    }
    spec::DesignPoint p;
    uint64_t i = next_++;
    for (auto it = space_->parameters.rbegin(); it != space_->parameters.rend();
         ++it) {
      p[it->name] = it->values[i % it->values.size()];
      i /= it->values.size();
    }
    reply.text =
        nlohmann::json({{"point", p}, {"rationale", "next in order"}}).dump();
    return reply;
  }
  std::string name() const override { return "instant"; }

 private:
  const spec::DesignSpace* space_;
  uint64_t next_ = 0;
};

void BM_LlmIteration(benchmark::State& state) {
  Result<spec::Spec> spec = spec::LoadSpec(
      std::string(ADSE_SOURCE_DIR) + "/scenarios/robotaxi_parking_lot.yaml");
  if (!spec.ok()) {
    state.SkipWithError(spec.status().ToString().c_str());
    return;
  }
  spec->exploration.budget = 280;
  LlmStrategyOptions options;
  options.report_path = [](const std::string&) {
    return std::string("/nonexistent");
  };
  options.image_path = options.report_path;
  options.backend = std::make_unique<RecordingBackend>(
      std::vector<ExchangeRecord>{},
      std::make_unique<InstantBackend>(&spec->design_space), JsonlLog(), "");
  Result<std::unique_ptr<explore::Strategy>> strategy =
      NewLlmStrategy(*spec, std::move(options));
  if (!strategy.ok()) {
    state.SkipWithError(strategy.status().ToString().c_str());
    return;
  }
  int n = 0;
  for (auto _ : state) {
    const std::vector<spec::DesignPoint> points = (*strategy)->Ask(1);
    if (points.empty()) {
      state.SkipWithError("budget spent");
      break;
    }
    explore::Observation o;
    o.point = points[0];
    o.feasible = ++n % 3 != 0;
    o.metrics = {{"completed", 1.0},
                 {"nav_time_s", 30.0 + n % 17},
                 {"hardware_cost", n % 23},
                 {"ctrl_rate_hz", 20.0},
                 {"deviation_score", 0.1}};
    (*strategy)->Tell(o);
  }
}
// 250 iterations: memory grows to 250 records, as in a long campaign.
BENCHMARK(BM_LlmIteration)->Iterations(250)->Unit(benchmark::kMillisecond);

void BM_ChatRoundTripOverHttp(benchmark::State& state) {
  Result<std::unique_ptr<testing::FakeLlmServer>> server =
      testing::FakeLlmServer::Start(testing::FakeLlmServer::Sequence(
          {{200, R"({"bottlenecks": [], "summary": "ok"})"}}));
  if (!server.ok()) {
    state.SkipWithError(server.status().ToString().c_str());
    return;
  }
  HttpBackendOptions http;
  http.endpoint = (*server)->url();
  Result<std::unique_ptr<ChatBackend>> backend = NewHttpBackend(http);
  ChatRequest request{
      "text", "m", {{"user", std::string(3000, 'x'), {}}}, true};
  for (auto _ : state) {
    Result<ChatReply> reply = (*backend)->Chat(request);
    if (!reply.ok()) state.SkipWithError(reply.status().ToString().c_str());
  }
}
BENCHMARK(BM_ChatRoundTripOverHttp)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace adse::llm

BENCHMARK_MAIN();
