#include "stack/algorithms/lane_change.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace adse::algorithms {
namespace {

// Objects are looked for this far along the route before a section's
// start and past its end.
constexpr double kSearchMarginM = 120.0;

// The ego speeding up from v0 to v_top at `accel`: where (from its start)
// and how fast it is after t seconds. A plan slower than the ego now keeps
// its speed (the guard does not count on it slowing down).
std::pair<double, double> EgoAfter(double v0, double v_top, double accel,
                                   double t) {
  if (v_top <= v0 || accel <= 0.0) return {v0 * t, v0};
  const double t_top = (v_top - v0) / accel;
  if (t <= t_top) return {v0 * t + 0.5 * accel * t * t, v0 + accel * t};
  return {v0 * t_top + 0.5 * accel * t_top * t_top + v_top * (t - t_top),
          v_top};
}

}  // namespace

double LaneChangeSection::Weight(double s_m) const {
  if (end_s_m <= start_s_m) return s_m >= end_s_m ? 1.0 : 0.0;
  const double a =
      std::clamp((s_m - start_s_m) / (end_s_m - start_s_m), 0.0, 1.0);
  return a * a * (3.0 - 2.0 * a);
}

LaneChangeGap RssGap(double ego_s_m, double ego_v_mps, double object_s_m,
                     double object_v_mps, double object_length_m,
                     const LaneChangeParams& params) {
  const auto rss = [&params](double front_v, double rear_v) {
    front_v = std::max(0.0, front_v);
    rear_v = std::max(0.0, rear_v);
    const double d = rear_v * params.rear_reaction_time_s +
                     rear_v * rear_v / (2.0 * params.rear_decel_mps2) -
                     front_v * front_v / (2.0 * params.front_decel_mps2) +
                     rear_v * params.rear_safety_margin_s;
    return std::max(params.min_gap_m, d);
  };
  const double ego_centre_s =
      ego_s_m + 0.5 * (params.ego_front_m - params.ego_rear_m);
  LaneChangeGap out;
  if (object_s_m >= ego_centre_s) {
    out.gap_m =
        object_s_m - 0.5 * object_length_m - (ego_s_m + params.ego_front_m);
    out.required_m = rss(object_v_mps, ego_v_mps);
  } else {
    out.gap_m =
        ego_s_m - params.ego_rear_m - (object_s_m + 0.5 * object_length_m);
    out.required_m = rss(ego_v_mps, object_v_mps);
  }
  return out;
}

LaneChangeGuard::LaneChangeGuard(const geometry::Path2& route,
                                 std::vector<LaneChangeSection> sections,
                                 const LaneChangeParams& params)
    : route_(route), sections_(std::move(sections)), params_(params) {
  std::sort(sections_.begin(), sections_.end(),
            [](const LaneChangeSection& a, const LaneChangeSection& b) {
              return a.start_s_m < b.start_s_m;
            });
}

int LaneChangeGuard::Next(double ego_s_m) const {
  for (size_t i = 0; i < sections_.size(); ++i) {
    if (sections_[i].end_s_m > ego_s_m) return static_cast<int>(i);
  }
  return -1;
}

ObstacleStop LaneChangeGuard::Plan(
    std::vector<PlannedPoint>* points,
    const std::vector<PlannerObstacle>& obstacles, double ego_v_mps,
    double now_s) {
  ObstacleStop out;
  out.reason = StopReason::kLaneChange;
  if (points == nullptr || points->empty() || route_.points.size() < 2) {
    return out;
  }
  const std::vector<PlannedPoint>& pts = *points;
  const double s0 = pts.front().s_m;
  const int index = Next(s0);
  if (index < 0 || sections_[index].start_s_m > pts.back().s_m) {
    held_ = -1;
    return out;
  }
  if (held_ != index) held_ = -1;
  const LaneChangeSection* next = &sections_[index];
  const double v0 = std::max(0.0, ego_v_mps);
  const double to_start = next->start_s_m - s0;
  const bool committed =
      held_ < 0 &&
      (to_start < 0.0 || v0 * v0 / (2.0 * params_.max_decel_mps2) > to_start);
  if (committed) return out;

  double v_top = 0.0;
  for (const PlannedPoint& p : pts) v_top = std::max(v_top, p.v_mps);
  const double sign = next->shift_m >= 0.0 ? 1.0 : -1.0;
  const double half_lane = 0.5 * next->lane_width_m;
  const Eigen::Vector2d start_dir(std::cos(route_.HeadingAt(0.0)),
                                  std::sin(route_.HeadingAt(0.0)));
  int unsafe_id = -1;
  double unsafe_gap_m = 0.0;
  int64_t work = 0;
  for (const PlannerObstacle& ob : obstacles) {
    if (ob.static_structure) continue;
    double lateral = 0.0, distance = 0.0;
    double s_o =
        ProjectOnPath(route_, ob.position, next->start_s_m - kSearchMarginM,
                      next->end_s_m + kSearchMarginM, s0, &lateral, &distance);
    if (s_o <= 1e-9) {
      // Behind the route's start: along its first heading.
      const Eigen::Vector2d r = ob.position - route_.points.front();
      s_o = r.dot(start_dir);
      lateral = start_dir.x() * r.y() - start_dir.y() * r.x();
    }
    // Across from the lane the route leaves: in a lane it enters?
    const double across = sign * (lateral + next->shift_m * next->Weight(s_o));
    if (across < half_lane || across > std::abs(next->shift_m) + half_lane) {
      continue;
    }
    const double heading = route_.HeadingAt(std::max(0.0, s_o));
    const double v_along = ob.velocity.x() * std::cos(heading) +
                           ob.velocity.y() * std::sin(heading);
    const LaneChangeGap now =
        RssGap(s0, v0, s_o, v_along, ob.length_m, params_);
    const bool ahead = now.gap_m > 0.0 && s_o > s0;
    if (ahead && ob.velocity.norm() < params_.min_front_object_speed_mps) {
      continue;
    }
    // The ego's manoeuvre: from its front entering the section until its
    // rear axle is through.
    for (double t = 0.0; t <= params_.horizon_s + 1e-9; t += params_.step_s) {
      ++work;
      const auto [ds, v] = EgoAfter(v0, v_top, params_.max_accel_mps2, t);
      const double s_e = s0 + ds;
      if (s_e > next->end_s_m) break;
      if (s_e + params_.ego_front_m < next->start_s_m) continue;
      const LaneChangeGap g =
          RssGap(s_e, v, s_o + v_along * t, v_along, ob.length_m, params_);
      if (g.gap_m < g.required_m) {
        unsafe_id = ob.id;
        unsafe_gap_m = now.gap_m;
        break;
      }
      // A plan that stands still is judged as it stands.
      if (v <= 0.0) break;
    }
    if (unsafe_id >= 0) break;
  }
  out.work_units = work;
  const bool unsafe = unsafe_id >= 0;
  if (unsafe) last_unsafe_s_ = now_s;
  const bool hold = unsafe || (held_ >= 0 && now_s - last_unsafe_s_ <
                                                 params_.transit_margin_s);
  if (!hold) {
    held_ = -1;
    return out;
  }
  if (unsafe) {
    last_id_ = unsafe_id;
    last_gap_m_ = unsafe_gap_m;
  }
  held_ = index;
  out.stop = true;
  out.obstacle_id = last_id_;
  out.gap_m = last_gap_m_;
  out.stop_s_m = std::max(next->start_s_m, s0);
  InsertStopAt(points, out.stop_s_m);
  return out;
}

}  // namespace adse::algorithms
