// The adse subcommands. Each returns the process exit code: 0 ok, 2 bad
// input, 1 any other failure.
#ifndef ADSE_HARNESS_CLI_COMMANDS_H_
#define ADSE_HARNESS_CLI_COMMANDS_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace adse::cli {

struct ValidateArgs {
  std::string scenario;
  bool check_world = true;  // load the map in SUMO, check start and goal
  bool quiet = false;       // no normalised spec on stdout
};
int RunValidate(const ValidateArgs& args);

struct WorldArgs {
  std::string scenario;
  bool follow_ideal = false;
  std::string out;                 // default: <output>/world-check
  std::optional<uint64_t> seed;    // overrides world.traffic.seed
  bool scan = true;                // simulate the LiDAR while driving
  int save_every_nth_scan = 10;    // PCD files kept; 0: none
  bool json = false;
};
int RunWorld(const WorldArgs& args);

struct SimulateArgs {
  std::string scenario;
  std::string point;              // "cores=4,freq_ghz=1.2"; empty: start_from
  std::optional<uint64_t> seed;   // overrides world.traffic.seed
  std::string out;                // default: <output>/simulate/<point>.h5
  bool json = false;
  bool quiet = false;
};
int RunSimulate(const SimulateArgs& args);

struct CalibrateArgs {
  std::string scenario;
  std::string point;     // empty: start_from
  int runs = 2;          // measured runs fitted together (seeds seed, seed+1, ...)
  std::string out = "calibration.json";
};
int RunCalibrate(const CalibrateArgs& args);

struct SchemaCheckArgs {
  std::vector<std::string> files;
};
int RunSchemaCheck(const SchemaCheckArgs& args);

struct AnalyzeArgs {
  std::vector<std::string> targets;     // run files or folders of them
  std::vector<std::string> thresholds;  // NAME=VALUE (diagnosis options)
  std::vector<std::string> diff;        // two analysis version folders
  bool json = false;
};
int RunAnalyze(const AnalyzeArgs& args);

}  // namespace adse::cli

#endif  // ADSE_HARNESS_CLI_COMMANDS_H_
