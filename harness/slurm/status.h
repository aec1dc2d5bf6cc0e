// `adse status <campaign>`: how far a campaign is — runs done, failed,
// running and pending — and the Slurm jobs submitted for it with their
// states, read from the campaign folder and from squeue (sacct where the
// cluster keeps accounting). Works for local campaigns too (no jobs).
#ifndef ADSE_HARNESS_SLURM_STATUS_H_
#define ADSE_HARNESS_SLURM_STATUS_H_

#include <string>
#include <vector>

#include "harness/slurm/client.h"
#include "harness/slurm/records.h"
#include "stack/base/status.h"

namespace adse::slurm {

struct RunningStep {
  std::string step_id;  // "123.4", "123_2.0"
  std::string key;      // content key prefix from the step's name
  std::string point;    // when the plan names it
  std::string elapsed;
  std::string nodes;
};

struct JobStatus {
  SubmittedJob job;
  // One line: "RUNNING", "3 COMPLETED, 1 RUNNING", or "not known to
  // Slurm any more (finished)".
  std::string summary;
  bool active = false;
  std::vector<JobState> tasks;
};

// How a campaign runs, as `adse status` tells it.
enum class CampaignKind {
  kLocal,        // `adse run` on this machine
  kCoordinator,  // an adaptive campaign whose coordinator runs on Slurm
  kSweep,        // a static sweep as a Slurm job array
};
// The token of a kind ("sweep"), as `adse status --json` writes it.
const char* CampaignKindToString(CampaignKind kind);

// What the campaign's views (summary.json, report.md, campaign.h5) are.
enum class ViewsState {
  kNone,        // none written yet
  kInProgress,  // written on the way by a campaign that is running
  kAbandoned,   // written on the way by a campaign whose process is gone
  kStopped,     // final, but the campaign stopped before its end
  kComplete,    // final: the answer
  kUnreadable,  // a summary.json that is no JSON object
};
// The token of a state ("in_progress"), as `adse status --json` writes it.
const char* ViewsStateToString(ViewsState state);

struct CampaignStatus {
  std::string folder;
  std::string scenario;
  std::string strategy;
  CampaignKind kind = CampaignKind::kLocal;
  int total = 0;  // planned points, or the budget; 0 when unknown
  // Runs at most after the budget (exploration.confirm_runs, as
  // summary.json holds it), not in `total`.
  int confirm_runs = 0;
  int done = 0, failed = 0, running = 0, pending = 0;
  std::vector<RunningStep> running_steps;
  // The points a local campaign (or a coordinator) is running, as its views
  // name them.
  std::vector<std::string> running_points;
  std::vector<JobStatus> jobs;
  std::string lock_holder;  // who holds (or last held) the campaign lock
  ViewsState views = ViewsState::kNone;
  std::string stopped_because;  // why a stopped campaign stopped
  // kUnreadable: which view could not be read and why, e.g.
  // "summary.json is no JSON object".
  std::string unreadable_because;
  std::vector<std::string> notes;
};

// NotFound when the folder is not a campaign folder.
Result<CampaignStatus> ReadCampaignStatus(const std::string& folder);

std::string FormatStatus(const CampaignStatus& status);
std::string StatusJson(const CampaignStatus& status);

}  // namespace adse::slurm

#endif  // ADSE_HARNESS_SLURM_STATUS_H_
