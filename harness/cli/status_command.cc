// `adse status`: runs done / failed / running / pending of a campaign and
// the Slurm jobs submitted for it (harness/slurm/status.h). Exit 0, or 2
// when the folder is not a campaign.
#include <cstdio>

#include "harness/cli/commands.h"
#include "harness/slurm/status.h"

namespace adse::cli {

int RunStatus(const StatusArgs& args) {
  Result<slurm::CampaignStatus> status =
      slurm::ReadCampaignStatus(args.campaign);
  if (!status.ok()) {
    std::fprintf(stderr, "error: %s\n", status.status().message().c_str());
    return ExitCodeFor(status.status());
  }
  const std::string text =
      args.json ? slurm::StatusJson(*status) : slurm::FormatStatus(*status);
  std::fputs(text.c_str(), stdout);
  return 0;
}

}  // namespace adse::cli
