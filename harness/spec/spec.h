// Scenario spec v1: one YAML file describes a whole study. These are the
// typed options every part of adse reads. Field documentation for users is
// in scenarios/README.md; parsing and validation in spec_parser.h.
#ifndef ADSE_HARNESS_SPEC_SPEC_H_
#define ADSE_HARNESS_SPEC_SPEC_H_

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "stack/config/stack_config.h"
#include "stack/world/world_options.h"

namespace adse::spec {

// A design point: parameter name -> value, ordered by name.
using DesignPoint = std::map<std::string, double>;

// What a design parameter stands for, for strategies that reason about
// capacity (the built-in agent's priors and the diagnosis' remedies):
// none, cores, frequency, sensor_rate (more of it is more load),
// downsample (more of it is less load and less precision: a voxel or
// azimuth step).
enum class KnobRole { kNone, kCores, kFrequency, kSensorRate, kDownsample };

struct DesignParameter {
  std::string name;  // key under design_space:
  std::string bind;  // "platform.cores", "stack.lidar.rate_hz", ...
  // `role:`; by default cores for platform.cores, frequency for
  // platform.freq_ghz, sensor_rate for a sensor's rate knob, downsample for
  // a stack knob that thins the data (KnobInfo::Load), else none.
  KnobRole role = KnobRole::kNone;
  // The allowed values, ascending and distinct. A `range: [lo, hi]` with an
  // optional `step` (default 1) is expanded here.
  std::vector<double> values;
  bool integer = false;  // all values are whole numbers

  // Index of the allowed value equal to `value` (within a relative 1e-9, so
  // "1.2" typed on a command line matches), or -1.
  int IndexOf(double value) const;
  // "7, 14" or, for long regular lists, "1, 2, ..., 28 (28 values)".
  std::string DescribeValues() const;
};

struct DesignSpace {
  std::vector<DesignParameter> parameters;  // in file order

  // Number of points (product of value counts); saturates at UINT64_MAX.
  uint64_t Size() const;
  const DesignParameter* Find(const std::string& name) const;
  // The parameter bound to `target` ("platform.cores"), or nullptr.
  const DesignParameter* FindByBind(const std::string& target) const;
  std::vector<std::string> Names() const;
  // Ok when `point` names exactly the space's parameters with allowed values;
  // otherwise InvalidArgument naming the parameter and the allowed values.
  Status Check(const DesignPoint& point) const;
};

enum class PlatformKind { kVirtual, kCgroup };
// kind cgroup: what stands for the point's clock on the host.
// kPadding: each callback busy-works to its cost at the point's clock.
// kQuota: threads get a CPU quota of f / host_ghz of each core (cpu.max),
// and callbacks pad to their cost at f scaled by that share.
// kCpufreq: the stack's CPUs are held at f by cpufreq, and callbacks pad
// as with kPadding.
enum class ClockBy { kPadding, kQuota, kCpufreq };
// kind virtual: how its cores run the callbacks in progress
// (stack::DispatchKind). kRunToCompletion: a callback holds its cores to its
// end. kProcessorSharing: one executor thread per core, data-parallel
// parts on a full team, the cores shared among all threads with work.
enum class Dispatch { kRunToCompletion, kProcessorSharing };
enum class CostModel { kMeasured, kCounted };

struct PlatformOptions {
  PlatformKind kind = PlatformKind::kVirtual;
  // Frequency at which measured callback costs are taken as-is.
  double reference_ghz = 2.1;
  CostModel cost_model = CostModel::kMeasured;
  // Calibration file for cost_model: counted (absolute path; may be empty).
  std::string calibration;
  // Cost profile for cost_model: counted (absolute path; may be empty):
  // measured per-callback costs of a production stack, used instead of a
  // calibration (harness/profile).
  std::string profile;
  // Defaults when the design space does not bind them.
  int cores = 4;
  double freq_ghz = 2.1;
  // Multiplies every callback cost: a sensitivity knob (1 = as measured or
  // as profiled).
  double cost_scale = 1.0;
  // kind cgroup: wall seconds per simulated second (>= 1); slows the sim
  // clock and stretches every callback cost alike, so a small host can
  // hold a heavy stack.
  double time_dilation = 1.0;
  // kind virtual: how its cores run the callbacks (see Dispatch).
  Dispatch dispatch = Dispatch::kRunToCompletion;
  // kind cgroup: what stands for the point's clock (see ClockBy).
  ClockBy clock_by = ClockBy::kPadding;
  // clock_by quota: the host's clock in GHz; 0 reads it from /proc/cpuinfo.
  double host_ghz = 0.0;
};

struct Objective {
  std::string metric;  // a metric name, e.g. "nav_time_s"
  bool minimize = true;
};

// A metric named in objectives and constraint/cost expressions.
struct MetricInfo {
  std::string name;
  std::string doc;
  bool boolean = false;  // 0 or 1
  bool count = false;    // a whole number of events, 0 or more
  // How far the car strays from where it should be (lower is better): a
  // knob that thins the stack's data (role downsample) makes it worse
  // while it relieves the computer.
  bool precision = false;
  // Reported by valet_parking runs only (NaN or absent otherwise): an
  // objective or constraint on it in another task is an error.
  bool valet_parking_only = false;
  // Rounded to kDecimalDigits where a run makes it (a sum of 0.05 s steps,
  // a product of short decimals), so that it ties where it should; read
  // rounded from files written before it was (2026-12-07).
  bool decimal = false;
};
// Metrics a run reports (documented in scenarios/README.md).
const std::vector<MetricInfo>& KnownMetrics();

// Bounds of exploration.budget, which the command line's --budget
// overrides within the same bounds.
inline constexpr int kMinBudget = 1;
inline constexpr int kMaxBudget = 1000000000;
// harness.workers (and --workers) at most.
inline constexpr int kMaxWorkers = 1000000;

struct ExplorationOptions {
  std::string strategy = "agent";  // exhaustive|random|ga|nsga2|agent|llm
  int budget = 15;                 // evaluations, replicas not counted
  // Runs after the budget, at most, that settle the designs cheaper than
  // the cheapest feasible one (campaign/cheaper.h, SettlePicks); the phase
  // ends early when none is left untried. 0: no confirm phase.
  int confirm_runs = 0;
  int batch = 1;  // points proposed per round
  uint64_t seed = 1;
  DesignPoint start_from;  // empty: the strategy chooses
  // The built-in agent's proposals after its first point that are seeded
  // space-filling draws rather than its model's picks (an initial design,
  // as Optuna's n_startup_trials); 0: the model picks from the second
  // point on. Other strategies do not read it.
  int initial_points = 0;
  // GA / NSGA-II settings.
  int population = 8;
  double crossover_rate = 0.9;
  double mutation_rate = 0.2;
};

struct LlmOptions {
  std::string backend = "ollama";  // ollama|openai|replay
  std::string endpoint = "http://127.0.0.1:11434";
  // Model per role: dse, vision, text, command, interpretation.
  std::map<std::string, std::string> models;
  std::string prompts;      // folder of prompt templates; empty: built-in
  std::string replay_from;  // campaign folder, for backend: replay
  double timeout_s = 120.0;
  int retries = 2;
  std::string api_key_env = "OPENAI_API_KEY";
};

struct SlurmOptions {
  std::string partition;
  std::string account;
  int nodes = 1;
  int cpus = 0;  // 0: workers * cores_per_worker
  std::string time_limit = "02:00:00";
  int max_parallel = 0;  // array throttle; 0: no limit
  int shard_size = 0;    // points per array task; 0: automatic
  std::vector<std::string> extra_args;
  // Seconds before the time limit at which Slurm warns adse
  // (--signal=B:USR1@<s>); running steps get this minus 30 s to finish.
  int signal_lead_s = 300;
  // Expected seconds per run, for the automatic shard size.
  double run_estimate_s = 60.0;
};

struct HarnessOptions {
  int workers = 0;  // 0 means auto: host cores / cores_per_worker
  int cores_per_worker = 1;
  int memory_mb = 4096;
  double run_timeout_s = 900.0;
  int retries = 1;
  int replicas = 1;
  // End a run as soon as a constraint is certainly violated (see
  // harness/sim/early_stop.h); false runs every point to the goal or the
  // timeout.
  bool early_stop = true;
  std::string isolation = "auto";  // auto|cgroup|affinity
  std::string executor = "local";  // local|slurm
  std::string cache_dir;           // empty: the user's cache dir
  SlurmOptions slurm;
};

// A variant of the task (task.cases): every design point runs once per
// case, and is feasible only when it is feasible in each. A case changes
// the task's start, waypoints or goal (a parking goal's heading, another
// slot); everything else is the scenario's.
struct TaskCase {
  std::string name;         // unique in the scenario; names its runs
  world::TaskOptions task;  // the scenario's task with the case's places
};

// Where in the file a field was written, for messages after parsing.
struct SourceMark {
  int line = 0;    // 1-based; 0 when the field took its default
  int column = 0;  // 1-based
};

struct Spec {
  int version = 1;
  std::string name;
  std::string source_path;  // the file as given
  std::string source_text;  // its exact text
  std::string base_dir;     // folder relative paths in the file resolve from

  world::WorldOptions world;
  world::TaskOptions task;
  // task.cases, in file order; empty when the task has no variants. A spec
  // made for one case (ForCase) has none and names it in `task_case`.
  std::vector<TaskCase> cases;
  std::string task_case;
  StackConfig stack;
  PlatformOptions platform;
  DesignSpace design_space;
  std::string cost = "cores * freq_ghz";
  std::vector<Objective> objectives;
  std::vector<std::string> constraints;  // expressions, as written
  ExplorationOptions exploration;
  LlmOptions llm;
  HarnessOptions harness;
  std::string output;  // as written; see ResolvedOutput()

  // Field path ("task.goal.x") -> where it was written.
  std::map<std::string, SourceMark> marks;

  // "file:line:col: " for a field path, or "file: " when not written.
  // A field that took its default cites its closest written parent
  // ("task.goal.tolerance_m" -> where `goal:` was written).
  std::string Where(const std::string& field_path) const;

  // `output` made absolute: relative paths resolve from the current
  // working directory (the parser refused any that escape it).
  std::string ResolvedOutput() const;
};

// The runs a point takes per seed: one per case, one without cases.
int CaseCount(const Spec& spec);

// "backing_in, nose_in": the names of the cases.
std::string CaseNames(const Spec& spec);

// The name of case `index` ("case <index>" for one the spec lacks, as a
// campaign file of another scenario may name).
std::string CaseName(const Spec& spec, int64_t index);

// The index of the case named `name`, or -1.
int FindCase(const Spec& spec, const std::string& name);

// The spec of case `index` (0 <= index < cases.size()): the case's task,
// no cases, `task_case` its name, and the case's fields' marks under
// task.* too, so an error about the case's goal cites its line.
Spec ForCase(const Spec& spec, int index);

}  // namespace adse::spec

#endif  // ADSE_HARNESS_SPEC_SPEC_H_
