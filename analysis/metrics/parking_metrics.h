// The valet task's metrics, from a run's /parking record and the ego's
// trajectory: did it park within the tolerances, how far it strayed from
// its planned manoeuvre, how close it came to the lot's obstacles, whether
// it touched one, and how often it changed gear.
#ifndef ADSE_ANALYSIS_METRICS_PARKING_METRICS_H_
#define ADSE_ANALYSIS_METRICS_PARKING_METRICS_H_

#include <map>
#include <string>
#include <vector>

#include "analysis/runfile/run_data.h"

namespace adse::analysis {

// Speeds below this count as standing when counting gear changes (m/s).
inline constexpr double kStandstillMps = 1e-3;

// Adds, for a run with a /parking record (nothing otherwise):
//   parked (0/1): the run ended standing with the body's centre within
//     the goal's tolerance_m of the slot's target and the heading within
//     yaw_tolerance;
//   parking_position_error_m, parking_yaw_error_deg: at the run's end;
//   parking_time_s: from the stack's plan to the end of the run (NaN when
//     it never planned);
//   parking_path_deviation_m, parking_path_deviation_max_m: mean and
//     largest distance of the rear axle from the planned manoeuvre while
//     driving it (NaN without a plan);
//   min_clearance_m: smallest gap between the ego's body and any obstacle
//     of the lot (wall, pole, parked car) over the run (0 when touching);
//   obstacle_collisions: contacts of the body with those obstacles;
//   gear_changes: reversals of the direction of motion.
void AddParkingMetrics(const runfile::RunData& run,
                       std::map<std::string, double>* metrics);

// One contact of the body with an obstacle of the lot: the first ego sample
// touching it and a point where the outlines meet (m).
struct ParkingContact {
  runfile::EgoSample ego;
  double x_m = 0.0;
  double y_m = 0.0;
};

// The run's contacts in time order (obstacle_collisions counts them); empty
// without a /parking record.
std::vector<ParkingContact> ParkingContacts(const runfile::RunData& run);

}  // namespace adse::analysis

#endif  // ADSE_ANALYSIS_METRICS_PARKING_METRICS_H_
