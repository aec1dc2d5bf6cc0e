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
  std::string task_case;  // --case: one of task.cases (required with them)
  bool follow_ideal = false;
  std::string out;               // default: <output>/world-check
  std::optional<uint64_t> seed;  // overrides world.traffic.seed
  bool scan = true;              // simulate the LiDAR while driving
  int save_every_nth_scan = 10;  // PCD files kept; 0: none
  bool json = false;
};
int RunWorld(const WorldArgs& args);

struct SimulateArgs {
  std::string scenario;
  std::string task_case;  // --case: one of task.cases (required with them)
  std::string point;      // "cores=4,freq_ghz=1.2"; empty: start_from
  std::optional<uint64_t> seed;  // overrides world.traffic.seed
  std::string out;               // default: <output>/simulate/<point>.h5
  bool json = false;
  bool quiet = false;
};
int RunSimulate(const SimulateArgs& args);

struct CalibrateArgs {
  std::string scenario;
  std::string task_case;  // --case: one of task.cases (required with them)
  std::string point;      // empty: start_from
  int runs = 2;  // measured runs fitted together (seeds seed, seed+1, ...)
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
  // A reference campaign (folder or campaign.h5, e.g. an exhaustive
  // recording): each campaign's pareto.png is drawn in the study's form
  // over it.
  std::string reference;
  bool json = false;
};
int RunAnalyze(const AnalyzeArgs& args);

struct WorkerArgs {
  std::string scenario;
  std::string task_case;  // --case: one of task.cases (required with them)
  std::string point;      // required
  std::optional<uint64_t> seed;  // overrides world.traffic.seed
  std::string out;               // run file to write (atomically)
  std::string expect_key;        // refuse to run when the key differs
  std::string report;            // also write the RunReport JSON here
  std::string image_dir;         // draw the trajectory picture here
};
int RunWorker(const WorkerArgs& args);

struct RunArgs {
  std::string scenario;
  std::string out;        // campaign folder; default: the scenario's output
  std::string strategy;   // overrides exploration.strategy
  int budget = -1;        // overrides exploration.budget
  int confirm_runs = -1;  // overrides exploration.confirm_runs
  int workers = -1;       // overrides harness.workers (0: auto)
  std::string isolation;  // overrides harness.isolation
  bool no_cache = false;
  std::string cache_dir;  // overrides harness.cache_dir
  bool retry_failed = false;
  bool quiet = false;
  bool json = false;
  std::string executor;  // overrides harness.executor: local | slurm
};
int RunRun(const RunArgs& args);

struct ExploreArgs {
  std::string replay;                   // recorded campaign folder
  std::vector<std::string> strategies;  // default: the recorded strategy set
  int budget = 0;                       // 0: the recording's scenario budget
  int confirm_runs = -1;  // -1: the recording's exploration.confirm_runs
  // -1: the recording's exploration.initial_points (the agent's).
  int initial_points = -1;
  // Replay as if the scenario had only these of its objectives (metric
  // names); empty: all of them.
  std::vector<std::string> objectives;
  int seeds = 20;
  uint64_t first_seed = 1;
  bool rationale = false;  // print every seed's proposals with their reasons
  bool json = false;
};
int RunExplore(const ExploreArgs& args);

struct InterpretArgs {
  std::string request;             // in plain words
  std::string out;                 // scenario file; empty: stdout
  std::string backend = "ollama";  // ollama|openai|replay
  std::string endpoint;            // empty: the backend's default
  std::string model = "llama3.1";
  std::string prompts;  // prompt folder; empty: bundled
  double timeout_s = 120.0;
  int retries = 2;
  int max_corrections = 3;
  std::string record;  // exchanges JSONL; default <out stem>.interpret.jsonl
  std::string replay_from;  // answer from this record first (replay: only)
  bool check_world = true;  // validate the map, start and goal in SUMO
};
int RunInterpret(const InterpretArgs& args);

struct SubmitArgs {
  std::string scenario;
  std::string out;                       // campaign folder
  std::string strategy;                  // overrides exploration.strategy
  int budget = -1;                       // overrides exploration.budget
  int confirm_runs = -1;                 // overrides exploration.confirm_runs
  bool dry_run = false;                  // print the scripts only
  std::vector<std::string> sbatch_args;  // more #SBATCH options
  bool no_cache = false;
  std::string cache_dir;
  bool json = false;
};
int RunSubmit(const SubmitArgs& args);

struct StatusArgs {
  std::string campaign;  // campaign folder
  bool json = false;
};
int RunStatus(const StatusArgs& args);

struct ShardArgs {
  std::string campaign;  // campaign folder with slurm/plan.json
  int task = -1;         // -1: SLURM_ARRAY_TASK_ID
  bool local = false;    // local worker processes instead of job steps
  bool quiet = false;
};
int RunShard(const ShardArgs& args);

struct IndexArgs {
  std::string campaign;  // campaign folder with slurm/plan.json
  bool json = false;
};
int RunIndex(const IndexArgs& args);

struct ProfileImportArgs {
  std::string caret;    // CARET report folder (analyze_node/*/stats_node.yaml)
  std::string mapping;  // adse callback -> CARET callbacks (YAML)
  std::string out;      // profile file to write (atomically)
};
int RunProfileImport(const ProfileImportArgs& args);

struct ProfileShowArgs {
  std::string profile;  // profile file
};
int RunProfileShow(const ProfileShowArgs& args);

struct ProfileCheckArgs {
  std::string scenario;   // names platform.profile
  std::string task_case;  // which of task.cases; required when it has any
  int cores = 16;         // the reference machine's cores (i9-12900KF: 16)
  double lidar_hz = 10;   // the source's LiDAR rate (CARET: 9.6 Hz observed)
  std::string out;        // folder; default <output>/profile-check
};
int RunProfileCheck(const ProfileCheckArgs& args);

struct FidelityArgs {
  std::string scenario;             // names platform.profile
  std::string task_case;            // which of task.cases (when it has any)
  std::vector<std::string> points;  // "cores=1,freq_ghz=2.1,..."
  int runs = 3;                     // real-time runs per point
  int perturbed_runs = 4;           // virtual runs with costs x (1 ± 1e-4 k)
  std::string clock_by;             // "padding"/"quota"; empty: the file's
  // The virtual platform's dispatches, each held against the same
  // real-time runs; empty: the file's platform.dispatch.
  std::vector<std::string> dispatch;
  std::string out;  // folder; default <output>/fidelity (or `compare`)
  // An earlier call's folder: its runs/ compared again, no run made.
  std::string compare;
};
int RunFidelity(const FidelityArgs& args);

}  // namespace adse::cli

#endif  // ADSE_HARNESS_CLI_COMMANDS_H_
