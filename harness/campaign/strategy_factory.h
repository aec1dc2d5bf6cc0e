// Strategies for a campaign folder: the explore factory's, plus `llm`,
// whose agents read the folder's run reports and pictures and record their
// exchanges in it. Used by harness/campaign and harness/slurm.
#ifndef ADSE_HARNESS_CAMPAIGN_STRATEGY_FACTORY_H_
#define ADSE_HARNESS_CAMPAIGN_STRATEGY_FACTORY_H_

#include <memory>
#include <string>

#include "harness/explore/strategy.h"
#include "harness/spec/spec.h"
#include "stack/base/env.h"
#include "stack/base/status.h"

namespace adse::campaign {

// Checks the name before anything is created (InvalidArgument listing the
// valid names, `llm` included).
Status CheckStrategyName(const std::string& name);

// Whether the scenario's strategy proposes from results (agent, llm, ga,
// nsga2) or not (exhaustive, random); errors as CheckStrategyName.
Result<bool> StrategyIsAdaptive(const spec::Spec& spec);

// `folder`: the campaign folder runs are read from. `record`: the llm
// agents record into it (live campaigns) or only read it (replay, where
// their answers come from the folder's own record).
// The llm agents' records are appended through `env`.
Result<std::unique_ptr<explore::Strategy>> CreateCampaignStrategy(
    const spec::Spec& spec, const std::string& folder, bool record,
    Env* env = Env::Default());

}  // namespace adse::campaign

#endif  // ADSE_HARNESS_CAMPAIGN_STRATEGY_FACTORY_H_
