// `adse submit`: hands a campaign to Slurm from a login node — a
// coordinator batch job for adaptive strategies, a job array of shards plus
// an index job for static sweeps (harness/slurm/submit.h). --dry-run
// prints the scripts and touches nothing. Exit 0 submitted, 2 bad input
// (scenario, flags, sbatch missing), 1 when Slurm refused or jobs of an
// earlier submission still run.
#include <cstdio>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "harness/cli/cli_support.h"
#include "harness/cli/commands.h"
#include "harness/slurm/submit.h"

namespace adse::cli {

int RunSubmit(const SubmitArgs& args) {
  std::optional<spec::Spec> spec = LoadScenarioOrReport(args.scenario);
  if (!spec) return 2;
  if (Status usable =
          CheckCampaignFolders(*spec, args.out, !args.no_cache, args.cache_dir);
      !usable.ok()) {
    std::fprintf(stderr, "error: %s\n", usable.message().c_str());
    return 2;
  }
  slurm::SubmitOptions options;
  options.output_dir = args.out;
  options.strategy = args.strategy;
  options.budget = args.budget;
  options.confirm_runs = args.confirm_runs;
  options.use_cache = !args.no_cache;
  options.cache_dir = args.cache_dir;
  options.dry_run = args.dry_run;
  options.sbatch_args = args.sbatch_args;
  Result<slurm::SubmitResult> result = slurm::Submit(*spec, options);
  if (!result.ok()) {
    std::fprintf(stderr, "error: %s\n", result.status().message().c_str());
    return ExitCodeFor(result.status());
  }
  const slurm::SubmitResult& r = *result;
  if (args.json) {
    nlohmann::json scripts = nlohmann::json::array();
    for (const slurm::SubmittedScript& s : r.scripts) {
      scripts.push_back({{"kind", slurm::JobKindToString(s.kind)},
                         {"path", s.path},
                         {"job_id", s.job_id},
                         {"text", s.text}});
    }
    nlohmann::json j = {{"campaign", r.output_dir},
                        {"adaptive", r.adaptive},
                        {"dry_run", args.dry_run},
                        {"scripts", scripts},
                        {"notes", r.notes}};
    if (!r.adaptive) {
      j["points"] = r.points;
      j["finished_points"] = r.finished_points;
      j["shards"] = r.shards;
      j["shard_size"] = r.shard_size;
      j["submitted_shards"] = r.submitted_shards;
      j["sharding"] = r.sharding;
    } else {
      j["steps_at_once"] = r.steps_at_once;
    }
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  for (const std::string& note : r.notes) {
    std::fprintf(stderr, "note: %s\n", note.c_str());
  }
  if (args.dry_run) {
    for (const slurm::SubmittedScript& s : r.scripts) {
      std::printf(
          "# ---- %s script (dry run: not written, not submitted) "
          "----\n%s\n",
          slurm::JobKindToString(s.kind), s.text.c_str());
    }
  }
  if (r.adaptive) {
    std::fprintf(stderr, "%s coordinator: %d step(s) at once\n",
                 args.dry_run ? "would submit a" : "submitted the",
                 r.steps_at_once);
  } else {
    std::fprintf(stderr,
                 "sweep: %d points in %d shard(s) of %d (%s); %d already "
                 "have a result; %s %zu array task(s)\n",
                 r.points, r.shards, r.shard_size, r.sharding.c_str(),
                 r.finished_points, args.dry_run ? "would submit" : "submitted",
                 r.submitted_shards.size());
  }
  if (!args.dry_run) {
    for (const slurm::SubmittedScript& s : r.scripts) {
      std::printf("%s job %s (%s)\n", slurm::JobKindToString(s.kind),
                  s.job_id.c_str(), s.path.c_str());
    }
    std::printf("follow it with: adse status %s\n", r.output_dir.c_str());
  }
  return 0;
}

}  // namespace adse::cli
