// Trajectory deviation: how far, and how, a driven trajectory strays from
// the ideal path (the route's lane centreline or a reference run).
//
// Method (FitDeviation):
//  1. Path model. The ideal polyline (vertices closer than 5 cm to the
//     previous one dropped) is parametrised by its arc length s in [0, L].
//     A C1 cubic Hermite curve c(s) follows it: exactly (straight, unit
//     speed) along each segment, and through a fillet at each vertex that
//     starts up to 1 m before it and ends up to 1 m after it (at most half
//     of either segment). A 90-degree corner is cut by 0.35 m; a dense
//     polyline (a reference run) is smoothed like a quadratic B-spline.
//     Rounded corners give every sample up to ~1 m inside them a unique
//     nearest point, which keeps the fit to a few iterations.
//  2. Initial guess. Each sample is projected onto the polyline, searching
//     forward from the previous projection only (a window of 10 m plus 3x
//     the distance driven since the last sample; each metre further ahead
//     costs 0.1 m of distance), so a path that passes the same place twice
//     is followed in order. The first sample takes the earliest of the
//     nearest projections (within 0.5 m). Only when the best candidate is
//     over 5 m away is the whole rest of the path searched (a skipped
//     detour).
//  3. Ceres fit. Unknowns: one s_i per sample, bounded to [0, L].
//     Residuals: (a) the 2D gap p_i - c(s_i), under a Huber loss of scale
//     robust_loss_scale_m; (b) smoothness: sqrt(smoothness_weight) times the
//     second difference of s(t) generalised to irregular sampling,
//     dt_c * ((s_{i+1}-s_i)/dt_i - (s_i-s_{i-1})/dt_{i-1}) with dt_c the mean
//     of both steps (metres; zero at any constant speed, whatever the
//     sampling); (c) monotonicity: 10 * max(0, s_i - s_{i+1}). Solved with
//     Levenberg-Marquardt and sparse normal Cholesky (SuiteSparse; the
//     normal matrix is pentadiagonal), stopping at a relative cost change of
//     1e-6 (3-7 iterations from the initial guess). A monotone parametrisation
//     (s_{i+1} = s_i + exp(u_i)) is not used on purpose: every residual would
//     depend on all earlier unknowns and the normal matrix would be dense
//     (24,000^2). Instead the solution is projected onto the monotone sequences
//     afterwards (isotonic regression, pool-adjacent-violators), so s is
//     non-decreasing exactly.
//  4. Lateral error e_i = (p_i - c(s_i)) . n(s_i), n the left unit normal
//     (left of the direction of travel is positive).
//  5. Offset vs oscillation. e(t) is split by a Whittaker smoother over time:
//     z = argmin  sum_i w_i (z_i - e_i)^2 + tau^4 sum_j w_j (z''_j)^2
//     (w: trapezoidal time weights, z'': second divided differences), with
//     tau = smoothing_window_s. Its response is 1 / (1 + (omega tau)^4):
//     lateral changes slower than a period of 2 pi tau (12.6 s by default)
//     stay in the smooth part z, faster ones (a weave) go to e - z.
//
// Definitions. Means are weighted by the progress along the path around
// each sample, w_i = (s_{i+1} - s_{i-1}) / 2, i.e. they are integrals over
// s divided by the length driven (mean_abs_lateral_m is the area between
// the two trajectories per metre of route). So standing still neither
// dilutes nor inflates them, the sampling rate does not matter and lateral
// spikes weigh no more than other samples. A run that never moves along
// the path (under 1 cm) uses time weights instead.
//   normalizer        = normalize_by_m, or lane_width_m / 2 when that is 0.
//   mean_abs_lateral_m = mean |e_i|;   max_deviation_m = max |e_i|.
//   deviation_score   = clamp(mean_abs_lateral_m / normalizer, 0, 1).
//   offset_m          = mean z_i (signed, left positive).
//   oscillation_rms_m = sqrt(mean (e_i - z_i)^2).
//   zigzag_index      = lateral direction reversals per second, clamped to
//                       [0, 1]. A reversal is counted when de/dt (of e
//                       smoothed as above with tau = 0.25 s, against noise)
//                       swings from >= +zigzag_threshold_mps to
//                       <= -zigzag_threshold_mps or back (hysteresis), and
//                       the count is divided by the run's duration. A
//                       steady weave of period P scores 2/P (0.5 at 4 s);
//                       1 means a reversal every second or faster.
//   complete          = L - s_last <= 2 m; driven_fraction = s_last / L.
// An incomplete run is scored on what it drove: only its samples count.
#ifndef ADSE_ANALYSIS_DEVIATION_DEVIATION_H_
#define ADSE_ANALYSIS_DEVIATION_DEVIATION_H_

#include <Eigen/Core>
#include <vector>

#include "stack/base/status.h"

namespace adse::analysis {

// One sample of the actual trajectory (world frame, metres, seconds).
struct TimedXy {
  double t_s = 0.0;
  double x_m = 0.0;
  double y_m = 0.0;
};

struct DeviationOptions {
  // Distance that maps to a score of 1; 0: half the lane width.
  double normalize_by_m = 0.0;
  // Weight of the s(t) second-difference residuals against the 2D gap
  // residuals (both in metres); larger = smoother s, less noise-chasing.
  double smoothness_weight = 1.0;
  // Huber scale of the 2D gap residuals: samples farther than this from
  // the path pull on s only linearly (spikes, off-route excursions). 0: no
  // robust loss.
  double robust_loss_scale_m = 0.5;
  // Time scale tau of the offset / oscillation split: lateral changes with
  // a period above 2 pi tau count as offset, faster ones as oscillation.
  double smoothing_window_s = 2.0;
  // Lateral speed the error must reach on both sides of a reversal for it
  // to count in zigzag_index (ignores slow drift and noise).
  double zigzag_threshold_mps = 0.1;
  // Cap on Ceres trust-region iterations (the initial guess is close, so a
  // handful usually suffice).
  int max_iterations = 100;
};

struct DeviationResult {
  double deviation_score = 0.0;     // mean |lateral| / normalizer, in [0, 1]
  double mean_abs_lateral_m = 0.0;  // mean |e| per metre of path driven
  double max_deviation_m = 0.0;     // max |e| over the samples
  double offset_m = 0.0;            // signed steady part (left positive)
  double zigzag_index = 0.0;        // reversals per second, clamped to [0, 1]
  double oscillation_rms_m = 0.0;   // RMS of e minus its smooth part
  bool complete = false;            // L - s of the last sample <= 2 m
  double driven_fraction = 0.0;     // s of the last sample / path length
  double path_length_m = 0.0;       // L, the ideal path's length
  double normalizer_m = 0.0;        // the distance a score of 1 stands for
  // Per actual sample: fitted arc length (non-decreasing), signed lateral
  // error and its smooth (offset) part.
  std::vector<double> s_m;
  std::vector<double> lateral_m;
  std::vector<double> smooth_lateral_m;
  int iterations = 0;      // Ceres iterations of the arc-length fit
  bool converged = false;  // Ceres reported convergence (not an iteration cap)
};

// Fits `actual` onto `ideal_path` (method above). Errors (InvalidArgument):
// fewer than 2 path points or a zero-length path, an empty trajectory,
// non-increasing times, non-finite values, a non-positive normalizer
// (lane_width_m <= 0 with normalize_by_m == 0), out-of-range options.
Result<DeviationResult> FitDeviation(
    const std::vector<Eigen::Vector2d>& ideal_path,
    const std::vector<TimedXy>& actual, double lane_width_m,
    const DeviationOptions& options = {});

}  // namespace adse::analysis

#endif  // ADSE_ANALYSIS_DEVIATION_DEVIATION_H_
