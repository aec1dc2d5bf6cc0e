#include "harness/campaign/strategy_factory.h"

#include <fmt/format.h>

#include "harness/campaign/run_store.h"
#include "harness/llm/llm_strategy.h"
#include "harness/spec/types.h"

namespace adse::campaign {

Status CheckStrategyName(const std::string& name) {
  if (spec::IsStrategyName(name)) return Status::Ok();
  return Status::InvalidArgument(
      fmt::format("unknown exploration strategy '{}'; valid: {}", name,
                  fmt::join(spec::StrategyNames(), ", ")));
}

Result<bool> StrategyIsAdaptive(const spec::Spec& spec) {
  const std::string& name = spec.exploration.strategy;
  ADSE_RETURN_IF_ERROR(CheckStrategyName(name));
  if (name == spec::kLlmStrategy) return true;
  Result<std::unique_ptr<explore::Strategy>> strategy =
      explore::CreateStrategy(name, {&spec});
  if (!strategy.ok()) return strategy.status();
  return (*strategy)->adaptive();
}

Result<std::unique_ptr<explore::Strategy>> CreateCampaignStrategy(
    const spec::Spec& spec, const std::string& folder, bool record, Env* env) {
  const std::string& name = spec.exploration.strategy;
  ADSE_RETURN_IF_ERROR(CheckStrategyName(name));
  if (name != spec::kLlmStrategy) return explore::CreateStrategy(name, {&spec});

  spec::Spec llm_spec = spec;
  if (!record) {
    // A replay answers every request from the recording's own exchanges.
    llm_spec.llm.backend = "replay";
    llm_spec.llm.replay_from = folder;
  }
  Result<std::unique_ptr<llm::RecordingBackend>> backend =
      llm::OpenBackend(llm_spec, record ? folder : "", env);
  if (!backend.ok()) return backend.status();
  const CampaignFolder layout(folder);
  llm::LlmStrategyOptions options;
  options.report_path = [layout](const std::string& key) {
    return layout.ReportPath(key);
  };
  options.image_path = [layout](const std::string& key) {
    return layout.TrajectoryImagePath(key);
  };
  options.record_dir = record ? folder : "";
  options.backend = std::move(*backend);
  options.env = env;
  return llm::NewLlmStrategy(spec, std::move(options));
}

}  // namespace adse::campaign
