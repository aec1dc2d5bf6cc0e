// The adse subcommands. Each returns the process exit code: 0 ok, 2 bad
// input, 1 any other failure.
#ifndef ADSE_HARNESS_CLI_COMMANDS_H_
#define ADSE_HARNESS_CLI_COMMANDS_H_

#include <cstdint>
#include <optional>
#include <string>

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

}  // namespace adse::cli

#endif  // ADSE_HARNESS_CLI_COMMANDS_H_
