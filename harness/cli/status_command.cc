// `adse status`: runs done / failed / running / pending of a campaign and
// the Slurm jobs submitted for it (harness/slurm/status.h), then the answer
// so far. Exit 0, or 2 when the folder is not a campaign.
#include <cstdio>
#include <filesystem>
#include <optional>

#include <nlohmann/json.hpp>

#include "harness/campaign/headline.h"
#include "harness/campaign/replay.h"
#include "harness/cli/cli_support.h"
#include "harness/cli/commands.h"
#include "harness/slurm/status.h"

namespace adse::cli {

int RunStatus(const StatusArgs& args) {
  std::error_code ec;
  if (!std::filesystem::exists(args.campaign, ec)) {
    std::fprintf(stderr, "error: %s: no such folder\n", args.campaign.c_str());
    return 2;
  }
  const std::string folder = CampaignOfRunsFolder(args.campaign);
  Result<slurm::CampaignStatus> status = slurm::ReadCampaignStatus(folder);
  if (!status.ok()) {
    std::fprintf(stderr, "error: %s\n", status.status().message().c_str());
    return ExitCodeFor(status.status());
  }
  // The answer so far, when the campaign has an index: the same headline
  // as adse run's, from the scenario stored in it.
  std::optional<campaign::Recording> recorded;
  // A campaign on its first runs has an index without rows yet.
  const bool no_result_yet = status->done + status->failed == 0 &&
                             status->views == slurm::ViewsState::kInProgress;
  if (!no_result_yet && std::filesystem::exists(folder + "/campaign.h5", ec)) {
    Result<campaign::Recording> r = campaign::LoadRecording(folder);
    if (r.ok()) {
      recorded = std::move(*r);
    } else {
      // The views are not complete when their index does not read.
      status->views = slurm::ViewsState::kUnreadable;
      status->unreadable_because = r.status().message();
      std::fprintf(stderr, "warning: no answer: %s\n",
                   r.status().message().c_str());
    }
  }
  if (args.json) {
    nlohmann::json j = nlohmann::json::parse(slurm::StatusJson(*status));
    if (recorded) {
      j["answer"] = campaign::AnswerJson(
          recorded->spec, recorded->rows,
          campaign::ComputeHeadline(recorded->spec, recorded->rows));
    }
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  std::fputs(slurm::FormatStatus(*status).c_str(), stdout);
  if (no_result_yet) std::printf("answer so far: no run has a result yet\n");
  if (recorded) {
    std::printf("%s (campaign.h5):\n%s",
                status->views == slurm::ViewsState::kComplete ? "answer"
                                                              : "answer so far",
                campaign::HeadlineText(
                    recorded->spec, recorded->rows,
                    campaign::ComputeHeadline(recorded->spec, recorded->rows))
                    .c_str());
  }
  return 0;
}

}  // namespace adse::cli
