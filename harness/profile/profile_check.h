// `adse profile check`: a run simulated on a profile's reference machine,
// held against what the profile's source measured: per-callback latency and
// the chain latencies (sensing, localization, sensing to control).
#ifndef ADSE_HARNESS_PROFILE_PROFILE_CHECK_H_
#define ADSE_HARNESS_PROFILE_PROFILE_CHECK_H_

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "analysis/runfile/run_data.h"
#include "harness/profile/profile.h"

namespace adse::profile {

// One line of the comparison, in ms. The source's figures are optional:
// a callback or chain the source did not measure has none.
struct CheckRow {
  std::string name;
  int samples = 0;  // adse's invocations or chain instances
  double adse_avg_ms = 0.0;
  double adse_p95_ms = 0.0;
  std::optional<double> source_avg_ms;  // measured mean
  std::optional<double> source_p95_ms;  // chains: measured; callbacks: the
                                        // profile's single-thread p95
  // Allowed |adse_avg / source_avg - 1| (issue 13's targets), if any.
  std::optional<double> tolerance;
};

// A callback whose cost scales with its work: the units it reported on
// average beside the profile's reference_units, which by definition are
// what a typical invocation reports on the scenario they were measured on
// (robotaxi_small.yaml for the bundled profile). There, when the stack
// changes how much work a scan takes (NDT's iterations fall with a better
// initial guess), the two part and the profile charges that callback more
// or less than its source measured; on another map the scans differ.
struct UnitsRow {
  std::string name;
  int samples = 0;
  double adse_mean_units = 0.0;
  double reference_units = 0.0;

  // Whether |adse_mean_units / reference_units - 1| is beyond kUnitsTolerance.
  bool beyond_tolerance() const;
};

// How far a callback's mean units may lie from its reference_units.
inline constexpr double kUnitsTolerance = 0.05;

struct ProfileCheck {
  std::vector<CheckRow> chains;     // in ChainNames() order
  std::vector<CheckRow> callbacks;  // by name
  std::vector<UnitsRow> units;      // by name, reference_units > 0 only
};

// Topics that delimit the chains in adse's stack (stack/nodes/ad_stack.cc).
struct ChainTopics {
  std::string raw_scan = "/sensing/lidar/points_raw";  // LiDAR in
  std::string scan = "/sensing/lidar/points";  // after the sensing stages
  std::string ndt_pose = "/localization/ndt_pose";
  std::string pose = "/localization/pose";  // the EKF's fused pose
};

// Every instance of each chain of ChainNames() in `run`, in seconds, as
// CompareWithProfile measures them (below).
std::map<std::string, std::vector<double>> ChainLatencies(
    const runfile::RunData& run, const ChainTopics& topics = {});

// Compares `run` (simulated with `profile`) with the profile's source.
// Chains: sensing = a raw scan's arrival to the publication of its
// processed cloud (same stamp); localization = that publication to the
// first fused pose after the EKF took the scan's NDT pose; sensing to
// control = a command's time minus the stamp of the scan it was built on.
ProfileCheck CompareWithProfile(const runfile::RunData& run,
                                const Profile& profile,
                                const ChainTopics& topics = {});

// The table `adse profile check` prints.
std::string FormatProfileCheck(const ProfileCheck& check);

}  // namespace adse::profile

#endif  // ADSE_HARNESS_PROFILE_PROFILE_CHECK_H_
