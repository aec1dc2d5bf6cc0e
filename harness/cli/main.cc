// adse: design-space exploration of autonomous-driving systems.
#include <CLI/CLI.hpp>

#include <cstdio>

#include "harness/cli/commands.h"

int main(int argc, char** argv) {
  CLI::App app{
      "adse: find the cheapest computer on which a self-driving stack still "
      "drives well.\nA scenario YAML file describes the study; see "
      "scenarios/README.md."};
  app.set_version_flag("--version", std::string("adse ") + ADSE_VERSION);
  app.require_subcommand(1);

  adse::cli::ValidateArgs validate;
  CLI::App* validate_cmd = app.add_subcommand(
      "validate", "Check a scenario file; print it normalised and the size of "
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
      "world", "Check the simulated world alone: load the map, plan the ideal "
               "path and, with --follow-ideal, drive it with a perfect "
               "controller while the LiDAR scans");
  world_cmd->add_option("scenario", world.scenario, "Scenario YAML file")
      ->required();
  world_cmd->add_flag("--follow-ideal", world.follow_ideal,
                      "Drive the ideal path with a ground-truth controller");
  world_cmd->add_option("-o,--out", world.out,
                        "Output folder (default: <output>/world-check)");
  CLI::Option* seed_opt = world_cmd->add_option(
      "--seed", seed, "Traffic seed (overrides world.traffic.seed)");
  world_cmd->add_flag("!--no-scan", world.scan, "Do not simulate the LiDAR");
  world_cmd->add_option("--save-scans", world.save_every_nth_scan,
                        "Keep every Nth scan as a PCD file (0: none)")
      ->check(CLI::NonNegativeNumber);
  world_cmd->add_flag("--json", world.json, "Print the summary as JSON");

  adse::cli::SimulateArgs simulate;
  uint64_t simulate_seed = 0;
  CLI::App* simulate_cmd = app.add_subcommand(
      "simulate", "Drive one design point in closed loop (world + stack on the "
                  "virtual platform) and print its metrics");
  simulate_cmd->add_option("scenario", simulate.scenario, "Scenario YAML file")->required();
  simulate_cmd->add_option("-p,--point", simulate.point,
                           "Design point, e.g. cores=4,freq_ghz=1.2,lidar_hz=14 "
                           "(default: exploration.start_from)");
  CLI::Option* simulate_seed_opt = simulate_cmd->add_option(
      "--seed", simulate_seed, "Traffic and sensor seed (overrides world.traffic.seed)");
  simulate_cmd->add_option("-o,--out", simulate.out,
                           "Run file (default: <output>/simulate/<point>.h5)");
  simulate_cmd->add_flag("--json", simulate.json, "Print metrics and timings as JSON");
  simulate_cmd->add_flag("-q,--quiet", simulate.quiet, "No progress line");

  adse::cli::CalibrateArgs calibrate;
  CLI::App* calibrate_cmd = app.add_subcommand(
      "calibrate", "Fit the `counted` cost model's per-callback costs on this host "
                   "from measured runs");
  calibrate_cmd->add_option("scenario", calibrate.scenario, "Scenario YAML file")->required();
  calibrate_cmd->add_option("-p,--point", calibrate.point,
                            "Design point to run (default: exploration.start_from)");
  calibrate_cmd->add_option("--runs", calibrate.runs, "Measured runs to fit")
      ->check(CLI::Range(1, 100));
  calibrate_cmd->add_option("-o,--out", calibrate.out, "Calibration file to write");

  adse::cli::SchemaCheckArgs schema_check;
  CLI::App* schema_cmd = app.add_subcommand("schema", "Run-file schema tools");
  schema_cmd->require_subcommand(1);
  CLI::App* schema_check_cmd = schema_cmd->add_subcommand(
      "check", "Check run files against results-schema/run.schema.json");
  schema_check_cmd->add_option("files", schema_check.files, "Run files (.h5)")->required();

  adse::cli::AnalyzeArgs analyze;
  CLI::App* analyze_cmd = app.add_subcommand(
      "analyze", "Recompute metrics, deviation, diagnosis, pictures and the Pareto front from "
                 "run files, into a new analysis version next to them (raw data is never "
                 "rewritten); exit 2 if any file could not be read");
  analyze_cmd->add_option("targets", analyze.targets, "Run files (.h5) or folders of them");
  analyze_cmd->add_option("--threshold", analyze.thresholds,
                          "Diagnosis option NAME=VALUE (repeatable), e.g. "
                          "frequency_bound_fraction=0.2");
  analyze_cmd->add_option("--diff", analyze.diff, "Compare two analysis version folders: --diff A B")
      ->expected(2);
  analyze_cmd->add_flag("--json", analyze.json, "Print the report(s) as JSON");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    // CLI11 uses its own codes; usage errors are bad input (2).
    return code == 0 ? 0 : 2;
  }
  if (seed_opt->count() > 0) world.seed = seed;
  if (simulate_seed_opt->count() > 0) simulate.seed = simulate_seed;
  if (*simulate_cmd) return adse::cli::RunSimulate(simulate);
  if (*calibrate_cmd) return adse::cli::RunCalibrate(calibrate);
  if (*schema_check_cmd) return adse::cli::RunSchemaCheck(schema_check);
  if (*analyze_cmd) {
    if (analyze.targets.empty() && analyze.diff.empty()) {
      std::fprintf(stderr, "error: analyze needs run files or folders, or --diff A B\n");
      return 2;
    }
    return adse::cli::RunAnalyze(analyze);
  }
  if (*validate_cmd) return adse::cli::RunValidate(validate);
  if (*world_cmd) return adse::cli::RunWorld(world);
  return 2;
}
