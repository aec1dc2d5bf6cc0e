// adse: design-space exploration of autonomous-driving systems.
#include <CLI/CLI.hpp>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "harness/cli/commands.h"
#include "harness/pool/worker_pool.h"
#include "harness/spec/spec.h"
#include "harness/spec/text_util.h"
#include "harness/spec/types.h"
#include "stack/base/platform_limits.h"

namespace {

// CLI11's PositiveNumber and NonNegativeNumber name the largest double as
// their range's end in their message; these say what is expected.
// A whole number in [least, most], written as the scenario may write one
// ("1000", "1e3"), handed on as plain digits.
CLI::Validator WholeNumber(int64_t least, int64_t most) {
  return CLI::Validator(
      [least, most](std::string& text) -> std::string {
        double value = 0.0;
        if (adse::spec::ParseNumber(text, &value) &&
            value == std::floor(value) && value >= static_cast<double>(least) &&
            value <= static_cast<double>(most)) {
          text = std::to_string(static_cast<int64_t>(value));
          return {};
        }
        return fmt::format("expected a whole number from {} to {}, found '{}'",
                           least, most, text);
      },
      fmt::format("INT in [{}, {}]", least, most));
}

CLI::Validator AboveZero() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double value = 0.0;
        if (CLI::detail::lexical_cast(text, value) && std::isfinite(value) &&
            value > 0.0) {
          return {};
        }
        return fmt::format("expected a finite number above 0, found '{}'",
                           text);
      },
      "NUMBER>0");
}

// A seed as the scenario reads one: 0 to 2^64 - 1 (CLI11 wraps "-1").
CLI::Validator Seed() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        uint64_t value = 0;
        const auto [end, ec] =
            std::from_chars(text.data(), text.data() + text.size(), value);
        if (!text.empty() && ec == std::errc() &&
            end == text.data() + text.size()) {
          return {};
        }
        return fmt::format("expected a whole number from 0 to {}, found '{}'",
                           std::numeric_limits<uint64_t>::max(), text);
      },
      "SEED");
}

// A budget on the command line has the bounds of exploration.budget.
const CLI::Validator kBudget =
    WholeNumber(adse::spec::kMinBudget, adse::spec::kMaxBudget);

// --confirm-runs, as exploration.confirm_runs.
void AddConfirmRunsOption(CLI::App* command, int* confirm_runs,
                          const std::string& default_text) {
  command
      ->add_option("--confirm-runs", *confirm_runs,
                   "Runs after the budget, at most, that settle the designs "
                   "cheaper than the cheapest feasible one (0: none; " +
                       default_text + ")")
      ->transform(WholeNumber(0, adse::spec::kMaxBudget));
}

// Every command that drives one run of a scenario takes the case it drives.
void AddCaseOption(CLI::App* command, std::string* task_case) {
  command->add_option(
      "--case", *task_case,
      "Which of the scenario's task.cases to run (required when it has cases)");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "adse: find the cheapest computer on which a self-driving stack still "
      "drives well.\nA scenario YAML file describes the study; see "
      "scenarios/README.md."};
  app.set_version_flag("--version", std::string("adse ") + ADSE_VERSION);
  app.require_subcommand(1);

  adse::cli::ValidateArgs validate;
  CLI::App* validate_cmd = app.add_subcommand(
      "validate",
      "Check a scenario file; print it normalised and the size of "
      "its design space");
  validate_cmd->add_option("scenario", validate.scenario, "Scenario YAML file")
      ->required();
  validate_cmd->add_flag("!--no-world", validate.check_world,
                         "Skip loading the map in SUMO (start/goal checks)");
  validate_cmd->add_flag("-q,--quiet", validate.quiet,
                         "Print only the summary, not the normalised spec");

  adse::cli::WorldArgs world;
  uint64_t seed = 0;
  CLI::App* world_cmd = app.add_subcommand(
      "world",
      "Check the simulated world alone: load the map, plan the ideal "
      "path and, with --follow-ideal, drive it with a perfect "
      "controller while the LiDAR scans");
  world_cmd->add_option("scenario", world.scenario, "Scenario YAML file")
      ->required();
  AddCaseOption(world_cmd, &world.task_case);
  world_cmd->add_flag("--follow-ideal", world.follow_ideal,
                      "Drive the ideal path with a ground-truth controller");
  world_cmd->add_option("-o,--out", world.out,
                        "Output folder (default: <output>/world-check)");
  CLI::Option* seed_opt = world_cmd->add_option(
      "--seed", seed, "Traffic seed (overrides world.traffic.seed)");
  seed_opt->check(Seed());
  world_cmd->add_flag("!--no-scan", world.scan, "Do not simulate the LiDAR");
  world_cmd
      ->add_option("--save-scans", world.save_every_nth_scan,
                   "Keep every Nth scan as a PCD file (0: none)")
      ->transform(WholeNumber(0, std::numeric_limits<int>::max()));
  world_cmd->add_flag("--json", world.json, "Print the summary as JSON");

  adse::cli::SimulateArgs simulate;
  uint64_t simulate_seed = 0;
  CLI::App* simulate_cmd = app.add_subcommand(
      "simulate",
      "Drive one design point in closed loop (world + stack on the "
      "virtual platform) and print its metrics");
  simulate_cmd->add_option("scenario", simulate.scenario, "Scenario YAML file")
      ->required();
  AddCaseOption(simulate_cmd, &simulate.task_case);
  simulate_cmd->add_option(
      "-p,--point", simulate.point,
      "Design point, e.g. cores=4,freq_ghz=1.2,lidar_hz=14 "
      "(default: exploration.start_from)");
  CLI::Option* simulate_seed_opt = simulate_cmd->add_option(
      "--seed", simulate_seed,
      "Traffic and sensor seed (overrides world.traffic.seed)");
  simulate_seed_opt->check(Seed());
  simulate_cmd->add_option("-o,--out", simulate.out,
                           "Run file (default: <output>/simulate/<point>.h5)");
  simulate_cmd->add_flag("--json", simulate.json,
                         "Print metrics and timings as JSON");
  simulate_cmd->add_flag("-q,--quiet", simulate.quiet, "No progress line");

  adse::cli::CalibrateArgs calibrate;
  CLI::App* calibrate_cmd = app.add_subcommand(
      "calibrate",
      "Fit the `counted` cost model's per-callback costs on this host "
      "from measured runs");
  calibrate_cmd
      ->add_option("scenario", calibrate.scenario, "Scenario YAML file")
      ->required();
  AddCaseOption(calibrate_cmd, &calibrate.task_case);
  calibrate_cmd->add_option(
      "-p,--point", calibrate.point,
      "Design point to run (default: exploration.start_from)");
  calibrate_cmd->add_option("--runs", calibrate.runs, "Measured runs to fit")
      ->transform(WholeNumber(1, 100));
  calibrate_cmd->add_option("-o,--out", calibrate.out,
                            "Calibration file to write");

  adse::cli::SchemaCheckArgs schema_check;
  CLI::App* schema_cmd = app.add_subcommand("schema", "Run-file schema tools");
  schema_cmd->require_subcommand(1);
  CLI::App* schema_check_cmd = schema_cmd->add_subcommand(
      "check", "Check run files against results-schema/run.schema.json");
  schema_check_cmd->add_option("files", schema_check.files, "Run files (.h5)")
      ->required();

  adse::cli::AnalyzeArgs analyze;
  CLI::App* analyze_cmd = app.add_subcommand(
      "analyze",
      "Recompute metrics, deviation, diagnosis, pictures and the Pareto front "
      "from "
      "run files, into a new analysis version next to them (raw data is never "
      "rewritten); exit 2 if any file could not be read");
  analyze_cmd->add_option("targets", analyze.targets,
                          "Run files (.h5) or folders of them");
  analyze_cmd->add_option("--threshold", analyze.thresholds,
                          "Diagnosis option NAME=VALUE (repeatable), e.g. "
                          "frequency_bound_fraction=0.2");
  analyze_cmd
      ->add_option("--diff", analyze.diff,
                   "Compare two campaigns or analysis versions (a "
                   "campaign root, its runs/ folder, or analysis/vN): "
                   "--diff A B")
      ->expected(2);
  analyze_cmd->add_option(
      "--reference", analyze.reference,
      "A reference campaign (e.g. an exhaustive recording): draw each "
      "campaign's pareto.png in the reference study's form over it "
      "(navigation time across, cost up, its points in grey, its front as a "
      "line, this campaign's as red triangles)");
  analyze_cmd->add_flag("--json", analyze.json, "Print the report(s) as JSON");

  adse::cli::RunArgs run;
  CLI::App* run_cmd =
      app.add_subcommand("run",
                         "Explore the scenario's design space within its "
                         "budget: runs go to a pool of "
                         "worker processes (cgroup-limited), results to the "
                         "campaign folder (runs/, "
                         "campaign.h5, report.md, pareto.png, summary.json). "
                         "Run it again to resume.");
  run_cmd->add_option("scenario", run.scenario, "Scenario YAML file")
      ->required();
  run_cmd->add_option("-o,--out", run.out,
                      "Campaign folder (default: the scenario's output)");
  run_cmd
      ->add_option(
          "--strategy", run.strategy,
          "Override exploration.strategy: " +
              fmt::format("{}", fmt::join(adse::spec::StrategyNames(), ", ")))
      ->check(CLI::IsMember(adse::spec::StrategyNames()));
  run_cmd
      ->add_option("--budget", run.budget,
                   "Override exploration.budget (evaluations)")
      ->transform(kBudget);
  AddConfirmRunsOption(run_cmd, &run.confirm_runs,
                       "default: exploration.confirm_runs");
  run_cmd
      ->add_option("--workers", run.workers,
                   "Override harness.workers (0: auto)")
      ->transform(WholeNumber(0, adse::spec::kMaxWorkers));
  run_cmd
      ->add_option(
          "--isolation", run.isolation,
          "Override harness.isolation: " +
              fmt::format("{}", fmt::join(adse::pool::IsolationNames(), ", ")))
      ->check(CLI::IsMember(adse::pool::IsolationNames()));
  run_cmd->add_flag("--no-cache", run.no_cache,
                    "Neither read nor fill the shared evaluation cache");
  run_cmd->add_option("--cache-dir", run.cache_dir,
                      "Override harness.cache_dir");
  run_cmd->add_flag(
      "--retry-failed", run.retry_failed,
      "Run again points whose runs failed for good in an earlier session");
  run_cmd->add_flag("-q,--quiet", run.quiet,
                    "No progress on stderr, only failures and errors; the "
                    "answer is still printed");
  run_cmd->add_flag("--json", run.json,
                    "Print summary.json on stdout at the end");
  run_cmd
      ->add_option(
          "--executor", run.executor,
          "Override harness.executor: local (worker processes here) or slurm "
          "(each run a job step, srun, inside the current Slurm allocation)")
      ->check(CLI::IsMember(adse::spec::ExecutorNames()));

  adse::cli::WorkerArgs worker;
  uint64_t worker_seed = 0;
  CLI::App* worker_cmd = app.add_subcommand(
      "worker",
      "Run one design point in this process and write its run file (what the "
      "campaign's pool starts; rarely used by hand)");
  worker_cmd->add_option("scenario", worker.scenario, "Scenario YAML file")
      ->required();
  AddCaseOption(worker_cmd, &worker.task_case);
  worker_cmd->add_option("-p,--point", worker.point, "Design point")
      ->required();
  CLI::Option* worker_seed_opt =
      worker_cmd->add_option("--seed", worker_seed, "Traffic seed");
  worker_seed_opt->check(Seed());
  worker_cmd->add_option("-o,--out", worker.out, "Run file to write")
      ->required();
  worker_cmd->add_option("--expect-key", worker.expect_key,
                         "Refuse to run unless the run's content key is this");
  worker_cmd->add_option("--report", worker.report,
                         "Also write the run's analysis (RunReport JSON) here, "
                         "after the run file");
  worker_cmd->add_option(
      "--image-dir", worker.image_dir,
      "Draw the trajectory picture (trajectory.png) into this folder");

  adse::cli::ExploreArgs explore;
  CLI::App* explore_cmd = app.add_subcommand(
      "explore",
      "Compare strategies without simulating: replay them against a recorded "
      "campaign over many seeds");
  explore_cmd
      ->add_option("--replay", explore.replay,
                   "Recorded campaign folder (campaign.h5)")
      ->required();
  explore_cmd
      ->add_option(
          "--strategy", explore.strategies,
          "Strategies, comma-separated, among " +
              fmt::format("{}", fmt::join(adse::spec::StrategyNames(), ", ")) +
              " (default: all but llm, which replays a recorded LLM "
              "campaign's exchanges)")
      ->delimiter(',')
      ->check(CLI::IsMember(adse::spec::StrategyNames()));
  explore_cmd
      ->add_option("--budget", explore.budget,
                   "Evaluations per replay (default: the "
                   "recorded scenario's budget)")
      ->transform(kBudget);
  AddConfirmRunsOption(explore_cmd, &explore.confirm_runs,
                       "default: the recorded scenario's");
  explore_cmd
      ->add_option("--initial-points", explore.initial_points,
                   "The built-in agent's seeded space-filling points after "
                   "its first, before its model picks (as "
                   "exploration.initial_points; default: the recorded "
                   "scenario's)")
      ->transform(WholeNumber(0, adse::spec::kMaxBudget));
  explore_cmd
      ->add_option("--objectives", explore.objectives,
                   "Replay with only these of the recorded scenario's "
                   "objectives (metric names, comma-separated), e.g. "
                   "hardware_cost,nav_time_s; the true front is then "
                   "theirs too (default: all)")
      ->delimiter(',');
  explore_cmd->add_option("--seeds", explore.seeds, "Seeds per strategy")
      ->transform(WholeNumber(1, 100000));
  explore_cmd
      ->add_option("--first-seed", explore.first_seed, "First exploration seed")
      ->check(Seed());
  explore_cmd->add_flag("--rationale", explore.rationale,
                        "Also print, per seed, each iteration's proposals "
                        "and the strategy's rationale for them");
  explore_cmd->add_flag("--json", explore.json, "Print the results as JSON");

  adse::cli::InterpretArgs interpret;
  CLI::App* interpret_cmd = app.add_subcommand(
      "interpret",
      "Turn a request in plain words into a validated scenario file with the "
      "interpretation agent (an LLM: Ollama, an OpenAI-compatible server, or a "
      "recorded exchange)");
  interpret_cmd
      ->add_option("request", interpret.request,
                   "What to study, e.g. \"robotaxi in a parking lot; cheapest "
                   "computer that reaches the goal within 60 s\"")
      ->required();
  interpret_cmd->add_option("-o,--out", interpret.out,
                            "Scenario file to write (default: print it)");
  interpret_cmd
      ->add_option("--backend", interpret.backend,
                   "ollama, openai (sends $OPENAI_API_KEY when set) or replay")
      ->check(CLI::IsMember(adse::spec::LlmBackendNames()));
  interpret_cmd->add_option("--endpoint", interpret.endpoint,
                            "Server URL (default: http://127.0.0.1:11434)");
  interpret_cmd->add_option("--model", interpret.model, "Model name")
      ->capture_default_str();
  interpret_cmd->add_option(
      "--prompts", interpret.prompts,
      "Folder of prompt templates (default: the bundled prompts/)");
  interpret_cmd
      ->add_option("--timeout", interpret.timeout_s, "Seconds per request")
      ->check(AboveZero())
      ->capture_default_str();
  interpret_cmd
      ->add_option("--retries", interpret.retries, "HTTP retries per request")
      ->transform(WholeNumber(0, 100))
      ->capture_default_str();
  interpret_cmd
      ->add_option("--max-corrections", interpret.max_corrections,
                   "Validation errors sent back to the model at most")
      ->transform(WholeNumber(0, 20))
      ->capture_default_str();
  interpret_cmd->add_option(
      "--record", interpret.record,
      "Where exchanges are recorded (default: <out stem>.interpret.jsonl "
      "beside the output)");
  interpret_cmd
      ->add_option(
          "--replay-from", interpret.replay_from,
          "Recorded exchanges (.jsonl) answered first; with --backend replay "
          "the only answers")
      ->check(CLI::ExistingFile);
  interpret_cmd->add_flag("!--no-world", interpret.check_world,
                          "Do not load the map in SUMO when validating");

  adse::cli::SubmitArgs submit;
  CLI::App* submit_cmd =
      app.add_subcommand("submit",
                         "Hand the campaign to Slurm (from a login node): "
                         "adaptive strategies as one "
                         "batch job running the coordinator, whose runs are "
                         "job steps; static sweeps "
                         "(exhaustive, random) as a job array of shards plus "
                         "an index job after it. "
                         "The scripts go to <campaign>/slurm/. Submit again to "
                         "continue after a cancel "
                         "or time limit: finished runs are not repeated.");
  submit_cmd->add_option("scenario", submit.scenario, "Scenario YAML file")
      ->required();
  submit_cmd->add_option(
      "-o,--out", submit.out,
      "Campaign folder on a shared filesystem (default: the scenario's "
      "output)");
  submit_cmd
      ->add_option(
          "--strategy", submit.strategy,
          "Override exploration.strategy: " +
              fmt::format("{}", fmt::join(adse::spec::StrategyNames(), ", ")))
      ->check(CLI::IsMember(adse::spec::StrategyNames()));
  submit_cmd
      ->add_option("--budget", submit.budget, "Override exploration.budget")
      ->transform(kBudget);
  AddConfirmRunsOption(submit_cmd, &submit.confirm_runs,
                       "default: exploration.confirm_runs");
  submit_cmd->add_flag("--dry-run", submit.dry_run,
                       "Print the sbatch scripts; write and submit nothing");
  submit_cmd
      ->add_option("--sbatch-arg", submit.sbatch_args,
                   "Another sbatch option for every script, e.g. "
                   "--sbatch-arg=--qos=long "
                   "(repeatable; after adse's own #SBATCH lines, so it wins)")
      ->allow_extra_args(false);
  submit_cmd->add_flag(
      "--no-cache", submit.no_cache,
      "The jobs neither read nor fill the shared evaluation cache");
  submit_cmd->add_option("--cache-dir", submit.cache_dir,
                         "Override harness.cache_dir");
  submit_cmd->add_flag("--json", submit.json,
                       "Print what was submitted as JSON");

  adse::cli::StatusArgs status;
  CLI::App* status_cmd =
      app.add_subcommand("status",
                         "Show a campaign's runs (done, failed, running, "
                         "pending) and the Slurm jobs "
                         "submitted for it with their states");
  status_cmd->add_option("campaign", status.campaign, "Campaign folder")
      ->required();
  status_cmd->add_flag("--json", status.json, "Print the status as JSON");

  adse::cli::ShardArgs shard;
  CLI::App* shard_cmd = app.add_subcommand(
      "shard",
      "Run one shard of a submitted sweep (what each job-array task runs): its "
      "points without a result, as job steps in this allocation");
  shard_cmd
      ->add_option("campaign", shard.campaign,
                   "Campaign folder (with slurm/plan.json)")
      ->required();
  shard_cmd
      ->add_option("--task", shard.task,
                   "Shard number (default: $SLURM_ARRAY_TASK_ID)")
      ->transform(WholeNumber(0, std::numeric_limits<int>::max()));
  shard_cmd->add_flag(
      "--local", shard.local,
      "Run the points in local worker processes instead of job steps");
  shard_cmd->add_flag("-q,--quiet", shard.quiet,
                      "Only failures and errors on stderr");

  adse::cli::IndexArgs index;
  CLI::App* index_cmd = app.add_subcommand(
      "index",
      "Build a submitted sweep's campaign.h5, report.md, summary.json and "
      "pareto.png from its run files (the job adse submit queues after the "
      "array); "
      "exit 1 while points lack a result");
  index_cmd
      ->add_option("campaign", index.campaign,
                   "Campaign folder (with slurm/plan.json)")
      ->required();
  index_cmd->add_flag("--json", index.json, "Print summary.json on stdout");

  adse::cli::ProfileImportArgs profile_import;
  adse::cli::ProfileShowArgs profile_show;
  CLI::App* profile_cmd = app.add_subcommand(
      "profile",
      "Callback cost profiles (what each callback costs on a reference "
      "machine, for the counted cost model): import one from a CARET report, "
      "show one");
  profile_cmd->require_subcommand(1);
  CLI::App* profile_import_cmd = profile_cmd->add_subcommand(
      "import",
      "Build a cost profile from a CARET report's "
      "analyze_node/*/stats_node.yaml and a mapping file that names the "
      "report's callbacks each adse callback stands for; nothing is written "
      "on error");
  profile_import_cmd
      ->add_option("--caret", profile_import.caret,
                   "CARET report folder (with analyze_node/<area>/"
                   "stats_node.yaml)")
      ->required();
  profile_import_cmd
      ->add_option("--map", profile_import.mapping,
                   "Mapping file (adse_profile_mapping: 1), e.g. "
                   "scenarios/profiles/autoware-2022.12-mapping.yaml")
      ->required();
  profile_import_cmd
      ->add_option("-o,--out", profile_import.out,
                   "Profile file to write (adse_profile: 1)")
      ->required();
  CLI::App* profile_show_cmd = profile_cmd->add_subcommand(
      "show",
      "Print a profile's callbacks: p50 and p95 cost, observed rate and load "
      "(cores busy) at the reference clock, and the total load");
  profile_show_cmd
      ->add_option("profile", profile_show.profile, "Profile file (YAML)")
      ->required();

  adse::cli::ProfileCheckArgs profile_check;
  CLI::App* profile_check_cmd = profile_cmd->add_subcommand(
      "check",
      "Simulate the scenario on its profile's reference machine (all cores "
      "at the profile's clock) and compare the chain latencies (sensing, "
      "localization, sensing to control) and per-callback latencies with "
      "what the profile's source measured");
  profile_check_cmd
      ->add_option("scenario", profile_check.scenario,
                   "Scenario YAML file naming platform.profile")
      ->required();
  AddCaseOption(profile_check_cmd, &profile_check.task_case);
  profile_check_cmd
      ->add_option("--cores", profile_check.cores,
                   "Cores of the reference machine (default 16, the "
                   "i9-12900KF's)")
      ->transform(WholeNumber(1, adse::kMaxPlatformCores));
  profile_check_cmd
      ->add_option("--lidar-hz", profile_check.lidar_hz,
                   "LiDAR rate of the reference run (default 10, as the "
                   "source's recording)")
      ->check(AboveZero());
  profile_check_cmd->add_option(
      "-o,--out", profile_check.out,
      "Folder for run.h5, check.txt and check.png (default: "
      "<output>/profile-check)");

  adse::cli::FidelityArgs fidelity;
  CLI::App* fidelity_cmd = app.add_subcommand(
      "fidelity",
      "Hold the virtual platform against real execution: run each point on "
      "the virtual platform (and --perturbed-runs more times with costs "
      "moved by parts in ten thousand) and --runs times on the real-time one "
      "(the "
      "stack in a process of its own on as many host CPUs as the point has "
      "cores), and "
      "compare nav time, control rate, drops, the time without a pose, the "
      "sensing-to-control chain and each callback's p50/p99 latency; writes "
      "fidelity.txt, "
      "fidelity.json and a picture per point");
  fidelity_cmd->add_option(
      "scenario", fidelity.scenario,
      "Scenario YAML file (cost_model: counted with a profile); required "
      "unless --compare");
  AddCaseOption(fidelity_cmd, &fidelity.task_case);
  fidelity_cmd->add_option(
      "--points", fidelity.points,
      "Design points, e.g. cores=1,freq_ghz=2.1,lidar_hz=7; at most as many "
      "cores as this host gives the process; required unless --compare");
  fidelity_cmd
      ->add_option("--runs", fidelity.runs,
                   "Real-time runs per point (default 3; their median is "
                   "compared)")
      ->transform(WholeNumber(1, 100));
  fidelity_cmd
      ->add_option(
          "--perturbed-runs", fidelity.perturbed_runs,
          "Virtual runs per point besides the scenario's own, with every "
          "cost scaled by 1 + 1e-4, 1 - 1e-4, 1 + 2e-4, ... (default 4; a "
          "starved closed loop answers so small a change with another "
          "callback order, so one virtual run is one draw, as one real-time "
          "run is; the run metrics' median over them is compared)")
      ->transform(WholeNumber(0, 100));
  fidelity_cmd
      ->add_option(
          "--clock-by", fidelity.clock_by,
          fmt::format("What stands for the clock in the real-time runs: {} "
                      "(default: the scenario's platform.clock_by)",
                      fmt::join(adse::spec::ClockByNames(), ", ")))
      ->check(CLI::IsMember(adse::spec::ClockByNames()));
  fidelity_cmd
      ->add_option(
          "--dispatch", fidelity.dispatch,
          fmt::format("The virtual platform's dispatch, one or more of {} "
                      "(comma-separated), each held against the same "
                      "real-time runs (default: the scenario's "
                      "platform.dispatch)",
                      fmt::join(adse::spec::DispatchNames(), ", ")))
      ->delimiter(',')
      ->check(CLI::IsMember(adse::spec::DispatchNames()));
  fidelity_cmd->add_option(
      "-o,--out", fidelity.out,
      "Folder for fidelity.txt, fidelity.json and fidelity-N.png (default: "
      "<output>/fidelity, or the --compare folder)");
  CLI::Option* fidelity_compare = fidelity_cmd->add_option(
      "--compare", fidelity.compare,
      "Compare again the runs an earlier adse fidelity wrote to this folder "
      "(its runs/), simulating nothing; writes fidelity.txt, fidelity.json "
      "and the pictures there, or to -o");
  for (const char* name : {"scenario", "--case", "--points", "--runs",
                           "--perturbed-runs", "--clock-by", "--dispatch"}) {
    fidelity_compare->excludes(name);
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    // CLI11 uses its own codes; usage errors are bad input (2).
    return code == 0 ? 0 : 2;
  }
  // An exception that escapes a command is a defect of adse; it is said
  // plainly rather than ending the process with an abort.
  auto dispatch = [&]() -> int {
    if (seed_opt->count() > 0) world.seed = seed;
    if (simulate_seed_opt->count() > 0) simulate.seed = simulate_seed;
    if (worker_seed_opt->count() > 0) worker.seed = worker_seed;
    if (*profile_import_cmd) return adse::cli::RunProfileImport(profile_import);
    if (*profile_show_cmd) return adse::cli::RunProfileShow(profile_show);
    if (*profile_check_cmd) return adse::cli::RunProfileCheck(profile_check);
    if (*fidelity_cmd) return adse::cli::RunFidelity(fidelity);
    if (*run_cmd) return adse::cli::RunRun(run);
    if (*submit_cmd) return adse::cli::RunSubmit(submit);
    if (*status_cmd) return adse::cli::RunStatus(status);
    if (*shard_cmd) return adse::cli::RunShard(shard);
    if (*index_cmd) return adse::cli::RunIndex(index);
    if (*worker_cmd) return adse::cli::RunWorker(worker);
    if (*explore_cmd) return adse::cli::RunExplore(explore);
    if (*interpret_cmd) return adse::cli::RunInterpret(interpret);
    if (*simulate_cmd) return adse::cli::RunSimulate(simulate);
    if (*calibrate_cmd) return adse::cli::RunCalibrate(calibrate);
    if (*schema_check_cmd) return adse::cli::RunSchemaCheck(schema_check);
    if (*analyze_cmd) {
      if (analyze.targets.empty() && analyze.diff.empty()) {
        std::fprintf(
            stderr,
            "error: analyze needs run files or folders, or --diff A B\n");
        return 2;
      }
      return adse::cli::RunAnalyze(analyze);
    }
    if (*validate_cmd) return adse::cli::RunValidate(validate);
    if (*world_cmd) return adse::cli::RunWorld(world);
    return 2;
  };
  try {
    return dispatch();
  } catch (const std::exception& e) {
    std::fprintf(stderr,
                 "error: internal error (a defect of adse; please report it "
                 "with the command): %s\n",
                 e.what());
    return 1;
  }
}
