// `adse index`: builds a submitted sweep's campaign.h5, report.md,
// summary.json and pareto.png from its run files (harness/slurm/sweep.h);
// the job adse submit queues after the array. Exit 0 when every planned
// point has a result, 1 when some have none yet (the views say which),
// 2 bad input.
#include <cstdio>

#include "harness/campaign/headline.h"
#include "harness/cli/commands.h"
#include "harness/slurm/sweep.h"
#include "harness/spec/text_util.h"
#include "stack/base/files.h"

namespace adse::cli {

int RunIndex(const IndexArgs& args) {
  spec::Spec spec;
  Result<campaign::CampaignSummary> summary =
      slurm::BuildSweepIndex(args.campaign, &spec);
  if (!summary.ok()) {
    std::fprintf(stderr, "error: %s\n", summary.status().message().c_str());
    return ExitCodeFor(summary.status());
  }
  const campaign::CampaignSummary& s = *summary;
  if (args.json) {
    Result<std::string> text = ReadFile(s.output_dir + "/summary.json");
    std::printf("%s", text.ok() ? text->c_str() : "{}\n");
  } else {
    const auto& rows = s.exploration.evaluations;
    std::printf("%s: %s (%d simulated, %d reused, %d failed)\n",
                s.output_dir.c_str(),
                spec::Counted(rows.size(), "evaluation").c_str(), s.simulated,
                s.reused, s.failed);
    std::printf("%s", campaign::HeadlineText(
                          spec, rows, campaign::ComputeHeadline(spec, rows))
                          .c_str());
    std::printf("report: %s/report.md\n", s.output_dir.c_str());
  }
  if (s.unfinished > 0) {
    std::fprintf(stderr,
                 "incomplete: %d planned point(s) have no result yet; adse "
                 "submit the scenario again to run them\n",
                 s.unfinished);
    return 1;
  }
  return 0;
}

}  // namespace adse::cli
