#include "stack/algorithms/tracker.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <optional>
#include <tuple>

#include "stack/geometry/geometry.h"

namespace adse::algorithms {
namespace {

// A box's length and width as extents along the unit vector u and across
// it: a box nearer across u than along it is seen sideways. (Projecting
// the box would widen it by the heading's noise.)
Eigen::Vector2d ExtentsAlong(const Detection& box, const Eigen::Vector2d& u) {
  const Eigen::Vector2d axis(std::cos(box.yaw_rad), std::sin(box.yaw_rad));
  const bool sideways =
      std::abs(axis.dot(u)) < std::abs(axis.x() * u.y() - axis.y() * u.x());
  return sideways ? Eigen::Vector2d(box.width_m, box.length_m)
                  : Eigen::Vector2d(box.length_m, box.width_m);
}

// A box shorter than this share of its track's length along the track's
// heading is a view of part of the object.
constexpr double kPartOfExtent = 0.6;

}  // namespace

void Tracker::Reset() {
  tracks_.clear();
  next_id_ = 1;
  has_time_ = false;
  last_t_s_ = 0.0;
  last_work_units_ = 0;
}

void Tracker::Predict(Track* track, double dt_s) const {
  if (dt_s <= 0.0) return;
  Eigen::Matrix4d f = Eigen::Matrix4d::Identity();
  f(0, 2) = f(1, 3) = dt_s;
  // White acceleration noise integrated over dt (per axis).
  const double q = params_.accel_noise_mps2 * params_.accel_noise_mps2;
  const double dt2 = dt_s * dt_s, dt3 = dt2 * dt_s, dt4 = dt3 * dt_s;
  Eigen::Matrix4d qm = Eigen::Matrix4d::Zero();
  for (int a = 0; a < 2; ++a) {
    qm(a, a) = q * dt4 / 4;
    qm(a, a + 2) = qm(a + 2, a) = q * dt3 / 2;
    qm(a + 2, a + 2) = q * dt2;
  }
  track->position += dt_s * track->velocity;
  track->covariance = f * track->covariance * f.transpose() + qm;
}

std::optional<Eigen::Vector2d> Tracker::MovingHeading(
    const Track& track) const {
  const double speed = track.velocity.norm();
  if (params_.partial_view_min_speed_mps <= 0.0 ||
      speed < params_.partial_view_min_speed_mps) {
    return std::nullopt;
  }
  return Eigen::Vector2d(track.velocity / speed);
}

Eigen::Vector2d Tracker::MeasuredCenter(const Track& track,
                                        const Detection& detection) const {
  const std::optional<Eigen::Vector2d> heading = MovingHeading(track);
  if (!heading) return detection.center;
  const Eigen::Vector2d& u = *heading;
  const Eigen::Vector2d n(-u.y(), u.x());
  const Eigen::Vector2d seen = ExtentsAlong(detection, u);
  const double slack_along = std::max(0.0, track.extent_along_m - seen.x()) / 2;
  const double slack_across =
      std::max(0.0, track.extent_across_m - seen.y()) / 2;
  const Eigen::Vector2d off = track.position - detection.center;
  return detection.center +
         std::clamp(off.dot(u), -slack_along, slack_along) * u +
         std::clamp(off.dot(n), -slack_across, slack_across) * n;
}

void Tracker::GrowExtents(const Eigen::Vector2d& seen, Track* track) const {
  track->extent_along_m = std::min(std::max(track->extent_along_m, seen.x()),
                                   params_.max_extent_along_m);
  track->extent_across_m = std::min(std::max(track->extent_across_m, seen.y()),
                                    params_.max_extent_across_m);
}

void Tracker::Correct(Track* track, const Detection& detection) const {
  Eigen::Matrix<double, 2, 4> h = Eigen::Matrix<double, 2, 4>::Zero();
  h(0, 0) = h(1, 1) = 1.0;
  const Eigen::Matrix2d r = Eigen::Matrix2d::Identity() *
                            params_.position_noise_m * params_.position_noise_m;
  const Eigen::Matrix4d& p = track->covariance;
  const Eigen::Matrix2d s = h * p * h.transpose() + r;
  const Eigen::Matrix<double, 4, 2> k = p * h.transpose() * s.inverse();
  Eigen::Vector4d x;
  x << track->position, track->velocity;
  x += k * (MeasuredCenter(*track, detection) - track->position);
  track->position = x.head<2>();
  track->velocity = x.tail<2>();
  // Joseph form: stays symmetric positive definite under rounding.
  const Eigen::Matrix4d i_kh = Eigen::Matrix4d::Identity() - k * h;
  track->covariance = i_kh * p * i_kh.transpose() + k * r * k.transpose();
  const double w = std::clamp(params_.size_smoothing, 0.0, 1.0);
  track->length_m = (1 - w) * track->length_m + w * detection.length_m;
  track->width_m = (1 - w) * track->width_m + w * detection.width_m;
  track->yaw_rad = detection.yaw_rad;
  const std::optional<Eigen::Vector2d> heading = MovingHeading(*track);
  GrowExtents(heading ? ExtentsAlong(detection, *heading)
                      : Eigen::Vector2d(detection.length_m, detection.width_m),
              track);
  // A moving track's box is its object's, along its heading: a view of
  // part of it would put the box's near edge beyond the object's.
  if (heading) {
    track->yaw_rad = std::atan2(track->velocity.y(), track->velocity.x());
    track->length_m = std::max(track->length_m, track->extent_along_m);
    track->width_m = std::max(track->width_m, track->extent_across_m);
  }
}

std::vector<Detection> Tracker::JoinViewsOfOneObject(
    const std::vector<Detection>& detections) const {
  if (params_.join_margin_m < 0.0 || detections.size() < 2) return detections;
  std::vector<char> joined(detections.size(), 0);
  std::vector<Detection> out;
  for (const Track& track : tracks_) {  // by id: deterministic
    if (!track.confirmed) continue;
    const Eigen::Vector2d u = MovingHeading(track).value_or(
        Eigen::Vector2d(std::cos(track.yaw_rad), std::sin(track.yaw_rad)));
    const Eigen::Vector2d n(-u.y(), u.x());
    // Along its heading, as far as the gate: its prediction may run ahead
    // of an object braking.
    const double half_along =
        0.5 * std::max(track.extent_along_m, track.length_m) +
        std::max(params_.join_margin_m, params_.gate_m);
    const double half_across =
        0.5 * std::max(track.extent_across_m, track.width_m) +
        params_.join_margin_m;
    // Parts only: a box as long as the object is a whole one (two cars
    // passing each other are two objects).
    const double part_below_m =
        kPartOfExtent * std::max(track.extent_along_m, track.length_m);
    std::vector<size_t> inside;
    for (size_t d = 0; d < detections.size(); ++d) {
      const Eigen::Vector2d off = detections[d].center - track.position;
      if (!joined[d] && std::abs(off.dot(u)) <= half_along &&
          std::abs(off.dot(n)) <= half_across &&
          ExtentsAlong(detections[d], u).x() < part_below_m) {
        inside.push_back(d);
      }
    }
    if (inside.size() < 2) continue;
    // Their corners' bounds along and across the track's heading.
    double lo_u = INFINITY, hi_u = -INFINITY, lo_n = INFINITY, hi_n = -INFINITY;
    Detection box;
    box.z_min_m = INFINITY;
    box.z_max_m = -INFINITY;
    for (const size_t d : inside) {
      const Detection& part = detections[d];
      joined[d] = 1;
      geometry::OrientedBox part_box;
      part_box.center = part.center;
      part_box.yaw_rad = part.yaw_rad;
      part_box.length_m = part.length_m;
      part_box.width_m = part.width_m;
      for (const Eigen::Vector2d& c : geometry::BoxCorners(part_box)) {
        lo_u = std::min(lo_u, c.dot(u));
        hi_u = std::max(hi_u, c.dot(u));
        lo_n = std::min(lo_n, c.dot(n));
        hi_n = std::max(hi_n, c.dot(n));
      }
      box.z_min_m = std::min(box.z_min_m, part.z_min_m);
      box.z_max_m = std::max(box.z_max_m, part.z_max_m);
      box.point_count += part.point_count;
    }
    box.center = 0.5 * (lo_u + hi_u) * u + 0.5 * (lo_n + hi_n) * n;
    // Length along the yaw, at least the width; yaw in (-pi/2, pi/2].
    double yaw = std::atan2(u.y(), u.x());
    box.length_m = hi_u - lo_u;
    box.width_m = hi_n - lo_n;
    if (box.length_m < box.width_m) {
      std::swap(box.length_m, box.width_m);
      yaw += M_PI / 2;
    }
    yaw = std::remainder(yaw, M_PI);
    box.yaw_rad = yaw <= -M_PI / 2 ? yaw + M_PI : yaw;
    out.push_back(box);
  }
  if (out.empty()) return detections;
  for (size_t d = 0; d < detections.size(); ++d) {
    if (!joined[d]) out.push_back(detections[d]);
  }
  return out;
}

const Track* Tracker::NearestConfirmed(const Eigen::Vector2d& at,
                                       size_t count) const {
  const Track* nearest = nullptr;
  if (params_.split_radius_m <= 0.0) return nearest;
  double best2 = params_.split_radius_m * params_.split_radius_m;
  for (size_t t = 0; t < count; ++t) {
    const double d2 = (tracks_[t].position - at).squaredNorm();
    if (tracks_[t].confirmed && d2 <= best2) {
      best2 = d2;
      nearest = &tracks_[t];
    }
  }
  return nearest;
}

void Tracker::Update(double t_s, const std::vector<Detection>& seen) {
  double dt = has_time_ ? t_s - last_t_s_ : 0.0;
  dt = std::min(dt, params_.max_dt_s);
  if (!has_time_ || t_s > last_t_s_) {
    last_t_s_ = t_s;
    has_time_ = true;
  }
  for (Track& track : tracks_) Predict(&track, dt);
  const std::vector<Detection> detections = JoinViewsOfOneObject(seen);

  // Greedy global nearest neighbour: all gated pairs, closest first. Ties
  // break by track then detection index, so results are deterministic.
  std::vector<std::tuple<double, size_t, size_t>> pairs;
  const double gate2 = params_.gate_m * params_.gate_m;
  for (size_t t = 0; t < tracks_.size(); ++t) {
    for (size_t d = 0; d < detections.size(); ++d) {
      const double d2 =
          (MeasuredCenter(tracks_[t], detections[d]) - tracks_[t].position)
              .squaredNorm();
      if (d2 <= gate2) pairs.emplace_back(d2, t, d);
    }
  }
  last_work_units_ = static_cast<int64_t>(tracks_.size()) *
                     static_cast<int64_t>(detections.size());
  std::sort(pairs.begin(), pairs.end());
  std::vector<char> track_used(tracks_.size(), 0);
  std::vector<char> det_used(detections.size(), 0);
  for (const auto& [d2, t, d] : pairs) {
    if (track_used[t] || det_used[d]) continue;
    track_used[t] = det_used[d] = 1;
    Track& track = tracks_[t];
    Correct(&track, detections[d]);
    ++track.hits;
    track.misses = 0;
    track.last_seen_s = t_s;
    if (track.hits >= params_.confirm_hits) track.confirmed = true;
  }
  for (size_t t = 0; t < tracks_.size(); ++t) {
    ++tracks_[t].age;
    if (!track_used[t]) ++tracks_[t].misses;
  }
  std::erase_if(tracks_, [&](const Track& track) {
    return track.misses >= (track.confirmed ? params_.max_misses
                                            : params_.tentative_max_misses);
  });
  const size_t existing = tracks_.size();
  for (size_t d = 0; d < detections.size(); ++d) {
    if (det_used[d]) continue;
    Track track;
    track.id = next_id_++;
    track.position = detections[d].center;
    track.covariance.setZero();
    const double pn = params_.position_noise_m * params_.position_noise_m;
    const double vn =
        params_.initial_velocity_std_mps * params_.initial_velocity_std_mps;
    track.covariance.diagonal() << pn, pn, vn, vn;
    // A piece of a confirmed track's object moves as that track does. Born
    // standing, such pieces of a car accelerating out of a turn outlived
    // their parent with a third of its speed, and the crossing yield let
    // the ego turn in front of the car (3 runs of the reference study).
    if (const Track* parent =
            NearestConfirmed(detections[d].center, existing)) {
      track.velocity = parent->velocity;
      track.covariance.bottomRightCorner<2, 2>() =
          parent->covariance.bottomRightCorner<2, 2>();
      track.extent_along_m = parent->extent_along_m;
      track.extent_across_m = parent->extent_across_m;
    }
    track.length_m = detections[d].length_m;
    track.width_m = detections[d].width_m;
    track.yaw_rad = detections[d].yaw_rad;
    GrowExtents({track.length_m, track.width_m}, &track);
    track.age = 1;
    track.hits = 1;
    track.last_seen_s = t_s;
    track.confirmed = params_.confirm_hits <= 1;
    tracks_.push_back(track);
  }
}

std::vector<Track> Tracker::ConfirmedTracks() const {
  std::vector<Track> out;
  for (const Track& track : tracks_) {
    if (track.confirmed) out.push_back(track);
  }
  return out;  // tracks_ is ordered by id: births are appended
}

std::vector<Track> Tracker::ConfirmedTracksAt(double t_s) const {
  std::vector<Track> out = ConfirmedTracks();
  const double dt =
      has_time_ ? std::min(t_s - last_t_s_, params_.max_dt_s) : 0.0;
  for (Track& track : out) Predict(&track, dt);
  return out;
}

}  // namespace adse::algorithms
