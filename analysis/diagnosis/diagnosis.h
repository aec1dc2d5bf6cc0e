// Trace statistics (topic rates, callback latencies, core utilisation,
// end-to-end latency) and deterministic bottleneck diagnosis of one run,
// computed from its stored RunData alone (never from the simulator).
//
// Everything is measured over a window [start_s, end_s) of simulated time;
// rates are counts in the window divided by its length. Nothing here knows
// the stack's node names: the graph is read from the run's callback_info.
#ifndef ADSE_ANALYSIS_DIAGNOSIS_DIAGNOSIS_H_
#define ADSE_ANALYSIS_DIAGNOSIS_DIAGNOSIS_H_

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "analysis/diagnosis/remedy.h"
#include "analysis/runfile/run_data.h"
#include "stack/base/status.h"

namespace adse::analysis {

struct DiagnosisOptions {
  // CPU-bound: a subscription falls behind its topic when its relative
  // deficit 1 - take_hz / publish_hz exceeds
  //   allowed(r) = base_fraction / (1 + r / tighten_hz) + floor_fraction
  // with r = publish_hz. With the defaults: 1 Hz -> 32.3 %, 7 Hz -> 22.6 %,
  // 10 Hz -> 20 %, 14 Hz -> 17.5 %, 100 Hz -> 7.7 %, never below 5 %:
  // strict at high rates, lenient where a few late messages are a big share.
  double cpu_bound_base_fraction = 0.3;    // extra allowance at low rates
  double cpu_bound_tighten_hz = 10.0;      // rate at which it has halved
  double cpu_bound_floor_fraction = 0.05;  // allowance at any rate (edges)
  // 1: a state input (a subscription whose callback publishes nothing, in a
  // node whose other callbacks do) needs one fresh message per output of
  // its node, not every message, so its deficit is measured against the
  // smaller of the publish rate and the node's output rate (the run rate of
  // its busiest publishing callback): a 50 Hz pose kept last-1 by a 10 Hz
  // LiDAR node is not flagged for the poses that went stale unread. 0:
  // against the publish rate, as the rule is stated.
  double cpu_bound_state_inputs_per_output = 1;
  // Frequency-bound: a node's slowest input is more than this fraction below
  // the median rate of its other inputs.
  double frequency_bound_fraction = 0.10;
  // 1: compare only inputs whose callback published in the window (they
  // trigger the node's outputs); 0: every subscribed input, as the rule is
  // stated. State inputs such as a 50 Hz pose cached by a 14 Hz LiDAR node
  // make the latter flag most pipeline nodes of a healthy stack.
  double frequency_bound_driving_inputs_only = 0;
  // Topics with fewer publishes in the window are ignored (latched/one-shot).
  double min_messages = 5;
  // Window in simulated seconds; end_s < 0 means the run's end. Clamped to
  // [0, run end].
  double start_s = 0.0;
  double end_s = -1.0;
  // Remedy of a cpu_bound finding (higher frequency vs more cores), see
  // Finding::remedies: the node's execution load at which faster cores are
  // needed, and the core-wait / execution ratio at which more cores are.
  double remedy_exec_load = 1.0;
  double remedy_wait_ratio = 1.0;
  // Starved input: a subscription that took nothing for at least this long
  // while its messages were dropped unread and its own node ran its other
  // callbacks at least `starved_input_busy_share` of the time (see
  // Finding). A starved computer leaves its nodes waiting for a core, not
  // running, so this names a stack that starves itself.
  double starved_input_min_s = 5.0;
  double starved_input_busy_share = 0.9;
};

// Sets one option by its field name (for `--threshold NAME=VALUE`).
// Unknown names and out-of-range values -> InvalidArgument (the message of
// an unknown name lists the valid ones).
Status SetOption(DiagnosisOptions* options, const std::string& name,
                 double value);
// The names SetOption accepts, in declaration order.
std::vector<std::string> DiagnosisOptionNames();
// allowed(r) above: the largest relative deficit tolerated at `rate_hz`.
double AllowedDeficit(const DiagnosisOptions& options, double rate_hz);

struct SubscriberStats {
  std::string callback;  // "<node>/<callback>"
  double take_rate_hz = 0.0;
  int64_t takes = 0;
  int64_t drops = 0;
  // The window's longest stretch without a take (from its start, between
  // takes, to its end): a node that starves one of its own subscriptions
  // shows it here, not in the take rate.
  double longest_gap_s = 0.0;
};

struct TopicStats {
  std::string name;
  // Node(s) publishing it over the whole run, sorted and ", "-joined;
  // "external" for messages from outside the graph (sensors); "" if none.
  std::string publisher;
  double publish_rate_hz = 0.0;
  int64_t publishes = 0;
  std::vector<SubscriberStats> subscribers;  // by callback index
};

// Per callback, over runs whose ready_s lies in the window. Statistics of
// a callback without runs are NaN.
struct CallbackStats {
  std::string name;  // "<node>/<callback>"
  std::string node;
  int64_t runs = 0;
  double latency_p50_s = 0.0;  // end - ready
  double latency_p99_s = 0.0;
  double latency_max_s = 0.0;
  double exec_p50_s = 0.0;  // cost
  // Busy core-seconds (cost x cores, clipped to the window) / window; above
  // 1 for callbacks holding several cores.
  double utilization = 0.0;
  int64_t timer_overruns = 0;  // whole run (the trace keeps only totals)
};

// Where a frequency_bound finding's slow input gets its rate: its main
// publisher followed upstream to the first sensor topic (published from
// outside the graph), timer or cpu_bound node.
enum class RateOriginKind {
  kNone,      // not a frequency_bound finding
  kSensor,    // `where` is the sensor topic
  kTimer,     // `where` is the timer callback, "<node>/<callback>"
  kCpuBound,  // `where` is the cpu_bound node
  kUnknown,   // the chain ends without one (no publisher seen, a cycle)
};

struct RateOrigin {
  RateOriginKind kind = RateOriginKind::kNone;
  std::string where;  // empty for kNone and kUnknown
  // The sensor's publish rate or the timer's rate; 0 when it has none.
  double rate_hz = 0.0;
};

struct Finding {
  FindingKind kind = FindingKind::kCpuBound;
  // The node that cannot keep up (cpu_bound) / that is input-limited
  // (frequency_bound) / whose callbacks starve one of its subscriptions
  // (starved_input).
  std::string node;
  std::vector<std::string> topics;  // the topic fallen behind / slow input
  // Node(s) publishing topics[0] ("external" for a sensor).
  std::string upstream;
  // frequency_bound: where the slow input's rate comes from (its kind
  // chooses the second remedy). kNone for the other kinds.
  RateOrigin origin;
  // Evidence by name. cpu_bound: publish_hz, take_hz, deficit,
  // allowed_deficit, exec_load, core_wait_ratio. frequency_bound:
  // slowest_hz, others_median_hz, deficit, allowed_fraction,
  // "input_hz:<topic>" for every input considered, and origin_hz (the
  // sensor's or timer's rate) when the origin has one. starved_input (not
  // rates, despite the name): starved_s, from_s, node_busy_share, dropped,
  // holder_timer_overruns (of the callback that held the node most).
  std::map<std::string, double> rates_hz;
  // What would relieve it, most important first. cpu_bound: higher_frequency
  // when exec_load >= remedy_exec_load, more_cores when core_wait_ratio >=
  // remedy_wait_ratio (if neither, the one nearer its threshold), both about
  // `node`; plus lower_sensor_rate of topics[0] when it comes from outside
  // the graph. frequency_bound: raise_publisher_rate of topics[0] (publisher
  // `upstream`, "unknown" if none), then by origin raise_sensor_rate of the
  // sensor topic | shorten_timer_period of the timer | relieve_node of the
  // cpu_bound node. starved_input: own_callback_group of the subscription.
  std::vector<Remedy> remedies;
  // RemediesText(remedies), e.g. "higher frequency; lower sensor rate".
  std::string remedy;
  std::string message;    // one readable sentence with the numbers
  double severity = 0.0;  // the relative deficit; findings sort by it
};

struct Diagnosis {
  double window_start_s = 0.0;
  double window_s = 0.0;
  std::vector<TopicStats> topics;        // by topic index
  std::vector<CallbackStats> callbacks;  // by callback index
  // Busy fraction of each virtual core over the window.
  std::vector<double> core_utilization;
  // LiDAR -> control: control publish time minus the stamp of the sensor
  // message it derives from, over controls published in the window; NaN
  // when there are none.
  double e2e_latency_p50_s = 0.0;
  double e2e_latency_p99_s = 0.0;
  // Severity descending; ties by kind, node, topic (deterministic).
  std::vector<Finding> findings;
};

// Never throws; a malformed run (indices out of range) is read defensively
// and its bad entries ignored.
Diagnosis Diagnose(const runfile::RunData& run,
                   const DiagnosisOptions& options = {});

}  // namespace adse::analysis

#endif  // ADSE_ANALYSIS_DIAGNOSIS_DIAGNOSIS_H_
