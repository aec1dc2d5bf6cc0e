// Multi-object tracker in the map frame: a constant-velocity Kalman filter
// per track, detections within one track's box joined, greedy
// nearest-neighbour association inside a gate, birth
// after N hits (at the velocity of a confirmed track it splits from) and
// deletion after M misses. A box smaller than its track's object (a car
// partly hidden) measures only where the object's box may stand. Eigen and
// std types only.
#ifndef ADSE_STACK_ALGORITHMS_TRACKER_H_
#define ADSE_STACK_ALGORITHMS_TRACKER_H_

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "stack/algorithms/clustering.h"

namespace adse::algorithms {

struct TrackerParams {
  double gate_m = 2.0;   // a detection further from a prediction is not it
  int confirm_hits = 3;  // hits before a track is reported (births)
  int max_misses = 3;    // consecutive misses that delete a confirmed track
  // Consecutive misses that delete a tentative track: clutter dies fast.
  int tentative_max_misses = 1;
  double accel_noise_mps2 = 2.0;  // process noise (white accel, 1 sigma)
  double position_noise_m = 0.3;  // detection centre noise (1 sigma)
  double initial_velocity_std_mps = 8.0;  // a new track's speed is unknown
  double size_smoothing = 0.3;  // weight of a new box size (0..1, EMA)
  double max_dt_s = 2.0;        // longer gaps predict at most this far
  // A detection born this near a confirmed track is a piece of that object
  // (a turning car seen as two clusters, or a box whose centre jumped past
  // the gate) and starts at its velocity, not standing. 0 never.
  double split_radius_m = 4.0;
  // A moving track's box is measured as a view of part of its object: its
  // centre may lie anywhere the object's largest box seen so far would
  // still cover the detection, and the measurement is the point there
  // nearest the prediction. The centre of a car seen in part lagged
  // 2-3.5 m behind the car's and its track took half its speed (2
  // collisions of the reference study at run key v16). 0 never.
  double partial_view_min_speed_mps = 2.0;
  // Detections whose centres lie within a confirmed track's box (its
  // largest extents about its prediction) grown by this are one view of
  // its object and are joined into one box first, as Autoware's
  // detection_by_tracker does: near, a LiDAR's rings cross a car's roof
  // in thin arcs metres apart. Negative: never.
  double join_margin_m = 0.3;
  // Extents beyond these are not kept as the object's: boxes that long or
  // wide are merged clusters or trucks, taken as seen.
  double max_extent_along_m = 6.0;
  double max_extent_across_m = 2.6;
};

struct Track {
  int id = 0;  // unique, increasing from 1, never reused
  Eigen::Vector2d position = Eigen::Vector2d::Zero();        // map frame
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();        // m/s
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Identity();  // px py vx vy
  // The boxes' size, smoothed; when faster than partial_view_min_speed_mps
  // at least its extents.
  double length_m = 0.0;
  double width_m = 0.0;
  // Of the last box (boxes have no front), or its velocity's when faster
  // than partial_view_min_speed_mps.
  double yaw_rad = 0.0;
  // The largest extents seen along and across its heading (its velocity's
  // when faster than partial_view_min_speed_mps, else its box's), at most
  // max_extent_along_m and max_extent_across_m.
  double extent_along_m = 0.0;
  double extent_across_m = 0.0;
  int age = 0;     // updates since birth
  int hits = 0;    // updates with an associated detection
  int misses = 0;  // consecutive updates without one
  bool confirmed = false;
  double last_seen_s = 0.0;  // time of the last associated detection
};

class Tracker {
 public:
  explicit Tracker(const TrackerParams& params = {}) : params_(params) {}

  // One frame of detections (map frame) taken at time t_s. Out-of-order
  // frames (t_s earlier than the last) are applied without prediction.
  void Update(double t_s, const std::vector<Detection>& detections);

  // Confirmed tracks, ordered by id.
  std::vector<Track> ConfirmedTracks() const;
  // Confirmed tracks predicted by their motion to t_s (at most max_dt_s
  // ahead of the last update), the filter's state untouched: what a tracker
  // that publishes on its own timer reports (Autoware's delay
  // compensation). At or before the last update, ConfirmedTracks().
  std::vector<Track> ConfirmedTracksAt(double t_s) const;
  // Whether a frame has been applied, and the time of the newest.
  bool has_time() const { return has_time_; }
  double last_update_s() const { return last_t_s_; }
  // All tracks including tentative ones, ordered by id.
  const std::vector<Track>& tracks() const { return tracks_; }
  void Reset();

  // Association work of the last update: tracks x detections.
  int64_t last_work_units() const { return last_work_units_; }
  const TrackerParams& params() const { return params_; }

 private:
  void Predict(Track* track, double dt_s) const;
  void Correct(Track* track, const Detection& detection) const;
  // Its velocity's direction when faster than partial_view_min_speed_mps.
  std::optional<Eigen::Vector2d> MovingHeading(const Track& track) const;
  // Widens the track's extents to `seen` (along, across), within the caps.
  void GrowExtents(const Eigen::Vector2d& seen, Track* track) const;
  // Where `detection` puts the track's centre: its box's centre, or for a
  // moving track seen in part the point nearest the prediction within the
  // track's extents around what was seen.
  Eigen::Vector2d MeasuredCenter(const Track& track,
                                 const Detection& detection) const;
  // `detections` with those within one confirmed track's box joined into
  // one box each (join_margin_m).
  std::vector<Detection> JoinViewsOfOneObject(
      const std::vector<Detection>& detections) const;
  // The confirmed track among the first `count` nearest to `at`, within
  // split_radius_m, if any.
  const Track* NearestConfirmed(const Eigen::Vector2d& at, size_t count) const;

  TrackerParams params_;
  std::vector<Track> tracks_;
  int next_id_ = 1;
  bool has_time_ = false;
  double last_t_s_ = 0.0;
  int64_t last_work_units_ = 0;
};

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_TRACKER_H_
