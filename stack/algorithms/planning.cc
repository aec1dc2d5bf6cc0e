#include "stack/algorithms/planning.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace adse::algorithms {
namespace {

// Passes of the path within this much of the nearest count as ties.
constexpr double kPassTieM = 1.0;

// Segment i of the path holds arc length s ([s_m[i], s_m[i+1]]).
size_t SegmentIndex(const geometry::Path2& path, double s) {
  const auto it = std::upper_bound(path.s_m.begin(), path.s_m.end(), s);
  size_t i = static_cast<size_t>(it - path.s_m.begin());
  i = i == 0 ? 0 : i - 1;
  return std::min(i, path.s_m.size() - 2);
}

}  // namespace

double ProjectOnPath(const geometry::Path2& path, const Eigen::Vector2d& p,
                     double s_lo, double s_hi, double s_ref, double* lateral_m,
                     double* distance_m) {
  s_lo = std::clamp(s_lo, 0.0, path.length_m());
  s_hi = std::clamp(s_hi, s_lo, path.length_m());
  const size_t i_lo = SegmentIndex(path, s_lo);
  const size_t i_hi = SegmentIndex(path, s_hi);
  struct Candidate {
    double distance, s, lateral;
  };
  std::vector<Candidate> per_segment;
  per_segment.reserve(i_hi - i_lo + 1);
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = i_lo; i <= i_hi; ++i) {
    const Eigen::Vector2d a = path.points[i];
    const Eigen::Vector2d ab = path.points[i + 1] - a;
    const double len = path.s_m[i + 1] - path.s_m[i];
    // Only the part of the segment inside [s_lo, s_hi].
    double t_lo = 0.0, t_hi = 1.0;
    if (len > 0.0) {
      t_lo = std::clamp((s_lo - path.s_m[i]) / len, 0.0, 1.0);
      t_hi = std::clamp((s_hi - path.s_m[i]) / len, 0.0, 1.0);
    }
    const double ab2 = ab.squaredNorm();
    double t = ab2 > 0.0 ? (p - a).dot(ab) / ab2 : 0.0;
    t = std::clamp(t, t_lo, t_hi);
    const Eigen::Vector2d r = p - (a + t * ab);
    Candidate c{r.norm(), path.s_m[i] + t * len, 0.0};
    const Eigen::Vector2d dir =
        ab2 > 0.0 ? Eigen::Vector2d(ab / std::sqrt(ab2))
                  : Eigen::Vector2d(std::cos(path.HeadingAt(c.s)),
                                    std::sin(path.HeadingAt(c.s)));
    c.lateral =
        dir.x() * r.y() - dir.y() * r.x() >= 0 ? c.distance : -c.distance;
    best = std::min(best, c.distance);
    per_segment.push_back(c);
  }
  // Where the path passes the point several times about as closely (laps,
  // overlapping lanes), each pass is a run of consecutive near segments;
  // take the nearest point of each run and, of those, the pass nearest to
  // s_ref, so near-ties do not flip between passes.
  const double near = best + kPassTieM;
  Candidate chosen{best, s_lo, 0.0};
  double chosen_gap = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < per_segment.size();) {
    if (per_segment[i].distance > near) {
      ++i;
      continue;
    }
    Candidate run_best = per_segment[i];
    for (; i < per_segment.size() && per_segment[i].distance <= near; ++i) {
      if (per_segment[i].distance < run_best.distance)
        run_best = per_segment[i];
    }
    const double gap = std::abs(run_best.s - s_ref);
    if (gap < chosen_gap) {
      chosen_gap = gap;
      chosen = run_best;
    }
  }
  *lateral_m = chosen.lateral;
  *distance_m = chosen.distance;
  return chosen.s;
}

void PathPlanner::SetRoute(const geometry::Path2& route,
                           std::optional<Eigen::Vector2d> goal) {
  route_ = route;
  if (route_.s_m.size() != route_.points.size()) route_.UpdateArcLength();
  has_progress_ = false;
  last_s_m_ = 0.0;
  goal_s_m_ = route_.length_m();
  if (goal && has_route()) {
    double lateral = 0.0, distance = 0.0;
    goal_s_m_ = ProjectOnPath(route_, *goal, 0.0, route_.length_m(),
                              route_.length_m(), &lateral, &distance);
  }
  route_goal_s_m_ = goal_s_m_;
  held_at_end_ = false;
}

void PathPlanner::EndAt(double s_m) {
  goal_s_m_ = std::clamp(s_m, 0.0, route_.length_m());
  held_at_end_ = true;
}

void PathPlanner::ResumeAt(double s_m) {
  last_s_m_ = std::clamp(s_m, 0.0, route_.length_m());
  has_progress_ = true;
  goal_s_m_ = route_goal_s_m_;
  held_at_end_ = false;
}

double PathPlanner::CurvatureAt(double s) const {
  // Curvature of the circle through three path points spaced over the
  // window (Menger curvature): smooth across polyline vertices, where the
  // tangent heading jumps, and right for a circle sampled by chords.
  const double half = 0.5 * std::max(params_.curvature_window_m, 1e-3);
  const double lo = std::max(0.0, s - half);
  const double hi = std::min(route_.length_m(), s + half);
  if (hi - lo < 1e-6) return 0.0;
  const Eigen::Vector2d a = route_.PointAt(lo);
  const Eigen::Vector2d b = route_.PointAt(0.5 * (lo + hi));
  const Eigen::Vector2d c = route_.PointAt(hi);
  const Eigen::Vector2d ab = b - a, ac = c - a;
  const double denom = ab.norm() * (c - b).norm() * ac.norm();
  if (denom < 1e-12) return 0.0;
  return 2.0 * (ab.x() * ac.y() - ab.y() * ac.x()) / denom;
}

PlannedPath PathPlanner::Plan(const geometry::Pose2& pose) {
  PlannedPath out;
  if (!has_route()) return out;
  const Eigen::Vector2d ego(pose.x_m, pose.y_m);
  const double length = route_.length_m();

  // Ego projection: near the last one while it fits, else the whole route.
  double lateral = 0.0, distance = 0.0;
  double s = 0.0;
  bool searched_globally = !has_progress_;
  if (has_progress_) {
    s = ProjectOnPath(route_, ego, last_s_m_ - params_.projection_back_m,
                      last_s_m_ + params_.projection_ahead_m, last_s_m_,
                      &lateral, &distance);
    if (distance > params_.reacquire_distance_m) searched_globally = true;
  }
  if (searched_globally) {
    s = ProjectOnPath(route_, ego, 0.0, length, has_progress_ ? last_s_m_ : 0.0,
                      &lateral, &distance);
  }
  // Monotone progress: small backward jitter of the pose does not move the
  // path start back (a re-acquisition may).
  if (has_progress_ && !searched_globally) s = std::max(s, last_s_m_);
  if (held_at_end_) s = std::min(s, goal_s_m_);
  last_s_m_ = s;
  has_progress_ = true;
  out.ego_s_m = s;
  out.lateral_offset_m = lateral;
  out.ends_at_goal = goal_s_m_ <= s + params_.horizon_m;

  const double end_s =
      std::max(s, std::min({s + params_.horizon_m, goal_s_m_, length}));
  const double step = std::max(params_.spacing_m, 0.05);
  std::vector<double> samples;
  for (double si = s; si < end_s - 1e-6; si += step) samples.push_back(si);
  samples.push_back(end_s);
  out.points.reserve(samples.size());
  for (double si : samples) {
    PlannedPoint pt;
    const Eigen::Vector2d p = route_.PointAt(si);
    pt.x_m = p.x();
    pt.y_m = p.y();
    pt.yaw_rad = route_.HeadingAt(si);
    pt.s_m = si;
    pt.curvature_1pm = CurvatureAt(si);
    pt.v_mps = params_.speed_limit_mps;
    out.points.push_back(pt);
  }
  out.work_units = static_cast<int64_t>(out.points.size());
  return out;
}

int64_t LimitVelocity(std::vector<PlannedPoint>* points, bool ends_at_goal,
                      const VelocityLimitParams& params) {
  if (points == nullptr || points->empty()) return 0;
  for (PlannedPoint& pt : *points) {
    const double k = std::abs(pt.curvature_1pm);
    if (k > 1e-9) {
      const double v_curve = std::sqrt(params.max_lateral_accel_mps2 / k);
      pt.v_mps =
          std::min(pt.v_mps, std::max(v_curve, params.min_curve_speed_mps));
    }
    pt.v_mps = std::max(0.0, pt.v_mps);
  }
  if (ends_at_goal) points->back().v_mps = 0.0;
  return static_cast<int64_t>(points->size());
}

void InsertStopAt(std::vector<PlannedPoint>* points, double stop_s) {
  std::vector<PlannedPoint>& pts = *points;
  if (pts.empty()) return;
  const double s0 = pts.front().s_m;
  // A point exactly at the stop line, so v reaches 0 there and not up to
  // one spacing later.
  if (stop_s > s0) {
    auto it = std::lower_bound(
        pts.begin(), pts.end(), stop_s,
        [](const PlannedPoint& p, double s) { return p.s_m < s; });
    if (it != pts.end() && it->s_m - stop_s > 1e-3 &&
        stop_s - std::prev(it)->s_m > 1e-3) {
      const PlannedPoint& a = *std::prev(it);
      const PlannedPoint& b = *it;
      const double t = (stop_s - a.s_m) / (b.s_m - a.s_m);
      PlannedPoint q = a;
      q.x_m = a.x_m + t * (b.x_m - a.x_m);
      q.y_m = a.y_m + t * (b.y_m - a.y_m);
      q.yaw_rad = t < 0.5 ? a.yaw_rad : b.yaw_rad;
      q.curvature_1pm =
          a.curvature_1pm + t * (b.curvature_1pm - a.curvature_1pm);
      q.s_m = stop_s;
      q.v_mps = std::min(a.v_mps, b.v_mps);
      pts.insert(it, q);
    }
  }
  for (PlannedPoint& p : pts) {
    if (p.s_m >= stop_s - 1e-6) p.v_mps = 0.0;
  }
}

namespace {

// The trajectory as a polyline for obstacle search: extended straight back
// from its first point to the rear of the ego's front bumper window and on
// past its end, with the route arc length of the polyline's start.
struct SearchPath {
  geometry::Path2 path;
  double offset_s_m = 0.0;  // route s of path's s = 0
  double back_m = 0.0;      // path s of the trajectory's first point
};

SearchPath MakeSearchPath(const std::vector<PlannedPoint>& pts,
                          const ObstacleStopParams& params) {
  const auto heading = [](double yaw) {
    return Eigen::Vector2d(std::cos(yaw), std::sin(yaw));
  };
  SearchPath out;
  out.back_m = params.ego_front_m;
  out.path.points.push_back(Eigen::Vector2d(pts.front().x_m, pts.front().y_m) -
                            out.back_m * heading(pts.front().yaw_rad));
  for (const PlannedPoint& p : pts) out.path.points.emplace_back(p.x_m, p.y_m);
  out.path.points.push_back(Eigen::Vector2d(pts.back().x_m, pts.back().y_m) +
                            params.beyond_end_m * heading(pts.back().yaw_rad));
  out.path.UpdateArcLength();
  out.offset_s_m = pts.front().s_m - out.back_m;
  return out;
}

// Where a box centred at `center` with its length along `yaw_rad` meets the
// path: its route s, its half extents across and along the path there, and
// whether it enters the corridor.
struct BoxOnPath {
  double s_m = 0.0;
  double half_across_m = 0.0;
  double half_along_m = 0.0;
  double relative_yaw_rad = 0.0;  // box heading minus the path's
  bool in_corridor = false;
};

BoxOnPath PlaceBox(const SearchPath& search, const Eigen::Vector2d& center,
                   double length_m, double width_m, double yaw_rad,
                   double corridor_half_width_m) {
  BoxOnPath out;
  double lateral = 0.0, distance = 0.0;
  const double local_s =
      ProjectOnPath(search.path, center, 0.0, search.path.length_m(),
                    search.back_m, &lateral, &distance);
  out.s_m = local_s + search.offset_s_m;
  out.relative_yaw_rad = yaw_rad - search.path.HeadingAt(local_s);
  const double cr = std::abs(std::cos(out.relative_yaw_rad));
  const double sr = std::abs(std::sin(out.relative_yaw_rad));
  out.half_across_m = 0.5 * (length_m * sr + width_m * cr);
  out.half_along_m = 0.5 * (length_m * cr + width_m * sr);
  out.in_corridor = distance - out.half_across_m <= corridor_half_width_m;
  return out;
}

geometry::OrientedBox BoxOf(const PlannerObstacle& ob) {
  geometry::OrientedBox box;
  box.center = ob.position;
  box.yaw_rad = ob.yaw_rad;
  box.length_m = ob.length_m;
  box.width_m = ob.width_m;
  return box;
}

// Whether the car's footprint from its rear axle at `rear` to the front
// bumper, half_width_m either side, overlaps `box`.
bool FootprintTouches(const geometry::Pose2& rear, double half_width_m,
                      const geometry::OrientedBox& box, double ego_front_m) {
  const Eigen::Vector2d at(rear.x_m, rear.y_m);
  // Nothing within reach of the footprint's far corner is skipped.
  const double reach_m = std::hypot(ego_front_m, half_width_m) +
                         0.5 * std::hypot(box.length_m, box.width_m);
  if ((at - box.center).norm() > reach_m) return false;
  geometry::OrientedBox footprint;
  footprint.length_m = ego_front_m;
  footprint.width_m = 2 * half_width_m;
  footprint.yaw_rad = rear.yaw_rad;
  footprint.center =
      at + 0.5 * ego_front_m *
               Eigen::Vector2d(std::cos(rear.yaw_rad), std::sin(rear.yaw_rad));
  return geometry::BoxesOverlap(footprint, box);
}

// The rear axle's first arc length along `pts`, from from_s_m on, at which
// the footprint (FootprintTouches) would touch `box`; none when it never
// does. (Behind the rear axle the car cannot stop for anything.)
std::optional<double> FootprintTouchS(const std::vector<PlannedPoint>& pts,
                                      const geometry::OrientedBox& box,
                                      double half_width_m, double from_s_m,
                                      const ObstacleStopParams& params) {
  const double step = std::max(params.footprint_step_m, 0.01);
  for (size_t i = 0; i < pts.size(); ++i) {
    const PlannedPoint& b = pts[i];
    const PlannedPoint& a = i == 0 ? b : pts[i - 1];
    if (b.s_m < from_s_m) continue;
    const double seg = b.s_m - a.s_m;
    const int n = seg > step ? static_cast<int>(std::ceil(seg / step)) : 1;
    for (int k = i == 0 ? n : 1; k <= n; ++k) {
      const double w = static_cast<double>(k) / n;
      if (a.s_m + w * seg < from_s_m) continue;
      const geometry::Pose2 rear = geometry::InterpolatePose(
          {a.x_m, a.y_m, a.yaw_rad}, {b.x_m, b.y_m, b.yaw_rad}, w);
      if (FootprintTouches(rear, half_width_m, box, params.ego_front_m)) {
        return a.s_m + w * seg;
      }
    }
  }
  return std::nullopt;
}

// Where the footprint, body wide plus the drive-off clearance, would touch
// `box` as the car drives off along `drive_off` (s0 when it would) and
// then along `pts` from as far as it drove.
std::optional<double> DriveOffTouchS(
    const std::vector<PlannedPoint>& pts,
    const std::vector<geometry::Pose2>& drive_off,
    const geometry::OrientedBox& box, const ObstacleStopParams& params) {
  const double half_width_m =
      params.ego_half_width_m + params.drive_off_clearance_m;
  double driven_m = 0.0;
  for (size_t i = 0; i < drive_off.size(); ++i) {
    if (FootprintTouches(drive_off[i], half_width_m, box, params.ego_front_m)) {
      return pts.front().s_m;
    }
    if (i > 0) {
      driven_m += std::hypot(drive_off[i].x_m - drive_off[i - 1].x_m,
                             drive_off[i].y_m - drive_off[i - 1].y_m);
    }
  }
  return FootprintTouchS(pts, box, half_width_m, pts.front().s_m + driven_m,
                         params);
}

// Time to cover distance_m from speed v0_mps, speeding up at accel_mps2 up
// to cap_mps (>= v0_mps).
double EarliestArrival(double distance_m, double v0_mps, double accel_mps2,
                       double cap_mps) {
  if (distance_m <= 0.0) return 0.0;
  if (accel_mps2 <= 0.0 || cap_mps <= v0_mps) {
    return v0_mps > 0.0 ? distance_m / v0_mps
                        : std::numeric_limits<double>::infinity();
  }
  const double t_cap = (cap_mps - v0_mps) / accel_mps2;
  const double d_cap = v0_mps * t_cap + 0.5 * accel_mps2 * t_cap * t_cap;
  if (distance_m <= d_cap) {
    return (std::sqrt(v0_mps * v0_mps + 2 * accel_mps2 * distance_m) - v0_mps) /
           accel_mps2;
  }
  return t_cap + (distance_m - d_cap) / cap_mps;
}

// Makes `stop` (rear axle) for `ob`, whose near edge is at near_edge, the
// stop found so far when it is nearer than *stop_s.
void KeepNearer(double stop, double near_edge, const PlannerObstacle& ob,
                double* stop_s, double* near_edge_s, ObstacleStop* out) {
  if (!(stop < *stop_s)) return;
  *stop_s = stop;
  *near_edge_s = near_edge;
  out->obstacle_id = ob.id;
  out->static_structure = ob.static_structure;
}

// Stops the trajectory at `stop_s` for `out`'s obstacle (already set) and
// fills in the stop; or, past the trajectory's end, clears it.
void FinishStop(std::vector<PlannedPoint>* points, double stop_s,
                double near_edge_s, double ego_front_m, ObstacleStop* out) {
  if (stop_s > points->back().s_m) {
    out->obstacle_id = -1;
    out->static_structure = false;
    return;
  }
  out->stop = true;
  out->stop_s_m = stop_s;
  out->gap_m = near_edge_s - (points->front().s_m + ego_front_m);
  InsertStopAt(points, stop_s);
}

}  // namespace

ObstacleStop InsertObstacleStop(std::vector<PlannedPoint>* points,
                                const std::vector<PlannerObstacle>& obstacles,
                                const DriveOff& drive_off,
                                const ObstacleStopParams& params) {
  ObstacleStop out;
  if (points == nullptr || points->empty()) return out;
  const std::vector<PlannedPoint>& pts = *points;
  const double s0 = pts.front().s_m;
  const SearchPath search = MakeSearchPath(pts, params);
  double stop_s = std::numeric_limits<double>::infinity();
  double near_edge_s = 0.0;
  std::optional<std::vector<geometry::Pose2>> driving_off;
  for (const PlannerObstacle& ob : obstacles) {
    if (!ob.position.allFinite()) continue;
    out.work_units += 1 + static_cast<int64_t>(pts.size());
    const BoxOnPath box = PlaceBox(search, ob.position, ob.length_m, ob.width_m,
                                   ob.yaw_rad, params.corridor_half_width_m);
    double stop = std::numeric_limits<double>::infinity();
    double near_edge = 0.0;
    // A road user that moves may be cutting in: the corridor from the
    // rear axle on. One that stands, only ahead of the front bumper:
    // alongside the car only what its body would touch driving off counts
    // (below). On a curved path a car waiting beside the car projects into
    // the corridor, though the car turns away from it, and the two stood
    // for each other.
    const bool standing = ob.velocity.allFinite() &&
                          ob.velocity.norm() < params.standing_object_mps;
    const double corridor_from_s =
        standing ? s0 + params.ego_front_m + box.half_along_m
                 : s0 - box.half_along_m;
    if (box.in_corridor && box.s_m >= corridor_from_s) {
      near_edge = box.s_m - box.half_along_m;
      stop = near_edge - params.stop_margin_m - params.ego_front_m;
    }
    // Where the swept footprint touches it first, if earlier: the outside
    // of a tight turn. A standing one within the corridor where the car
    // stands holds it only if the body would come nearer than the
    // clearance as the car drives off (away from it, the car may).
    const geometry::OrientedBox ob_box = BoxOf(ob);
    std::optional<double> touch =
        FootprintTouchS(pts, ob_box, params.corridor_half_width_m, s0, params);
    if (touch && *touch <= s0 && standing) {
      if (!driving_off) {
        driving_off = drive_off ? drive_off() : std::vector<geometry::Pose2>();
        out.work_units += static_cast<int64_t>(driving_off->size());
      }
      touch = DriveOffTouchS(pts, *driving_off, ob_box, params);
    }
    if (touch && *touch - params.stop_margin_m < stop) {
      stop = *touch - params.stop_margin_m;
      near_edge = *touch + params.ego_front_m;
    }
    KeepNearer(stop, near_edge, ob, &stop_s, &near_edge_s, &out);
  }
  FinishStop(points, stop_s, near_edge_s, params.ego_front_m, &out);
  return out;
}

ObstacleStop InsertCrossingYield(std::vector<PlannedPoint>* points,
                                 const std::vector<PlannerObstacle>& obstacles,
                                 double ego_v_mps,
                                 const ObstacleStopParams& stop_params,
                                 const CrossingYieldParams& params,
                                 bool yielding) {
  ObstacleStop out;
  if (points == nullptr || points->empty() || params.horizon_s <= 0.0 ||
      params.step_s <= 0.0) {
    return out;
  }
  const std::vector<PlannedPoint>& pts = *points;
  const double s0 = pts.front().s_m;
  const double front_s = s0 + stop_params.ego_front_m;
  const SearchPath search = MakeSearchPath(pts, stop_params);
  const double min_sin = std::sin(params.min_crossing_angle_rad);
  const double ego_v = std::max(std::abs(ego_v_mps), params.min_ego_speed_mps);
  const double braking_m = ego_v_mps * ego_v_mps / (2 * params.max_decel_mps2);
  const int steps = static_cast<int>(params.horizon_s / params.step_s + 1e-9);
  double stop_s = std::numeric_limits<double>::infinity();
  double near_edge_s = 0.0;
  for (const PlannerObstacle& ob : obstacles) {
    if (!ob.position.allFinite() || !ob.velocity.allFinite()) continue;
    const double speed = ob.velocity.norm();
    if (speed < params.min_object_speed_mps || ob.age < params.min_track_age)
      continue;
    const double heading = std::atan2(ob.velocity.y(), ob.velocity.x());
    // Its box along its straight-line prediction: when it next enters the
    // corridor and when it has left it again. Where it is in the corridor
    // now is the stop planner's; a path that meets its way twice (a left
    // turn onto a road and another off it) is crossed again nearer the
    // ego once it has left that part (the ego drove on towards the nearer
    // crossing, held only by the stop for the farther one).
    std::optional<BoxOnPath> entry;
    double t_in = 0.0, t_out = params.horizon_s;
    bool in_corridor_now = false;
    for (int k = 0; k <= steps; ++k) {
      const double t = k * params.step_s;
      out.work_units += 1 + static_cast<int64_t>(pts.size());
      const BoxOnPath box =
          PlaceBox(search, ob.position + t * ob.velocity, ob.length_m,
                   ob.width_m, heading, stop_params.corridor_half_width_m);
      if (k == 0) in_corridor_now = box.in_corridor;
      if (in_corridor_now) {
        in_corridor_now = box.in_corridor;
        continue;
      }
      if (!entry && box.in_corridor) {
        entry = box;
        t_in = t;
      } else if (entry && !box.in_corridor) {
        t_out = t;
        break;
      }
    }
    if (!entry) continue;
    // Following and oncoming traffic does not cross the path.
    if (std::abs(std::sin(entry->relative_yaw_rad)) < min_sin) continue;
    const double near_edge = entry->s_m - entry->half_along_m;
    const double gap = near_edge - front_s;
    if (gap <= 0.0) continue;  // the ego is already in the crossing
    // The ego's time in the crossing, from the earliest it could arrive
    // (speeding up at max_accel_mps2 to the fastest it plans before it) to
    // the latest it could leave (at its speed now, at least
    // min_ego_speed_mps): yield only when it overlaps the object's. Judged
    // at its speed now, an ego speeding up out of a turn came too late to
    // stop for a car it then met in the junction.
    double fastest = std::abs(ego_v_mps);
    for (const PlannedPoint& p : pts) {
      if (p.s_m > near_edge) break;
      fastest = std::max(fastest, p.v_mps);
    }
    const double t_ego_in = EarliestArrival(gap, std::abs(ego_v_mps),
                                            params.max_accel_mps2, fastest);
    const double t_ego_out =
        (gap + 2 * entry->half_along_m + stop_params.ego_front_m) / ego_v;
    if (t_ego_in > t_out + params.time_margin_s ||
        t_ego_out + params.time_margin_s < t_in) {
      continue;
    }
    const double stop =
        near_edge - stop_params.stop_margin_m - stop_params.ego_front_m;
    // Past the point where it can still stop comfortably: go through,
    // unless it is braking for crossing traffic already (or the plan would
    // flicker between yielding and going as it slows).
    if (stop - s0 < braking_m && !yielding) continue;
    KeepNearer(stop, near_edge, ob, &stop_s, &near_edge_s, &out);
  }
  FinishStop(points, stop_s, near_edge_s, stop_params.ego_front_m, &out);
  return out;
}

ObstacleStop CrossingYielder::Plan(
    std::vector<PlannedPoint>* points,
    const std::vector<PlannerObstacle>& obstacles, double ego_v_mps,
    double now_s, const ObstacleStopParams& stop_params) {
  const bool recent =
      held_ && now_s - last_t_s_ <= params_.transit_margin_s + 1e-9;
  ObstacleStop out = InsertCrossingYield(points, obstacles, ego_v_mps,
                                         stop_params, params_, recent);
  if (points == nullptr || points->empty()) return out;
  const bool reason_to_yield = out.stop;
  const bool keep_last = recent && last_.stop_s_m <= points->back().s_m &&
                         (!out.stop || last_.stop_s_m < out.stop_s_m);
  if (keep_last) {
    const int64_t work = out.work_units;
    const double near_edge =
        last_.stop_s_m + stop_params.stop_margin_m + stop_params.ego_front_m;
    out = last_;
    out.work_units = work;
    out.gap_m = near_edge - (points->front().s_m + stop_params.ego_front_m);
    InsertStopAt(points, out.stop_s_m);
  }
  // A held stop lapses transit_margin_s after the last plan that had a
  // reason to yield.
  if (reason_to_yield) last_t_s_ = now_s;
  held_ = out.stop;
  if (out.stop) last_ = out;
  return out;
}

const ObstacleStop& NearerStop(const ObstacleStop& a, const ObstacleStop& b) {
  if (!b.stop) return a;
  if (!a.stop) return b;
  return b.stop_s_m < a.stop_s_m ? b : a;
}

StopDecision DecideStop(std::vector<PlannedPoint>* points, bool ends_at_goal,
                        bool localization_lost, const ObstacleStop& obstacle,
                        std::optional<double> signal_stop_s_m) {
  StopDecision out;
  if (points == nullptr || points->empty()) {
    out.reason = StopReason::kNoTrajectory;
    out.distance_m = 0.0;
    return out;
  }
  if (localization_lost) {
    for (PlannedPoint& p : *points) p.v_mps = 0.0;
    out.reason = StopReason::kLocalizationLost;
    out.distance_m = 0.0;
    return out;
  }
  const double s0 = points->front().s_m;
  if (ends_at_goal) {
    out.reason = StopReason::kGoal;
    out.distance_m = std::max(0.0, points->back().s_m - s0);
  }
  // The obstacle's stop lies on the path (never past its end), so at the
  // goal or before it: it is the one that holds the car.
  if (obstacle.stop) {
    out.reason = obstacle.reason;
    out.distance_m = std::max(0.0, obstacle.stop_s_m - s0);
    out.obstacle_id = obstacle.obstacle_id;
    out.obstacle_gap_m = obstacle.gap_m;
    out.static_structure = obstacle.static_structure;
  }
  // A signal's stop lies on the path too; the nearer stop holds the car
  // (the obstacle on a tie: a queue at the line is what the car waits for).
  if (signal_stop_s_m &&
      (!obstacle.stop || *signal_stop_s_m < obstacle.stop_s_m)) {
    out = StopDecision();
    out.reason = StopReason::kRedLight;
    out.distance_m = std::max(0.0, *signal_stop_s_m - s0);
  }
  return out;
}

void SmoothVelocity(std::vector<PlannedPoint>* points, double current_v_mps,
                    const SmootherParams& params) {
  if (points == nullptr || points->empty()) return;
  std::vector<PlannedPoint>& pts = *points;
  // Forward: from the current speed, at most max_accel over each step.
  const double start =
      std::max(std::max(current_v_mps, 0.0), params.start_speed_mps);
  pts[0].v_mps = std::min(pts[0].v_mps, start);
  for (size_t i = 1; i < pts.size(); ++i) {
    const double ds = std::max(0.0, pts[i].s_m - pts[i - 1].s_m);
    const double reachable = std::sqrt(pts[i - 1].v_mps * pts[i - 1].v_mps +
                                       2.0 * params.max_accel_mps2 * ds);
    pts[i].v_mps = std::min(pts[i].v_mps, reachable);
  }
  // Backward: every point slow enough to brake for what follows.
  for (size_t i = pts.size() - 1; i-- > 0;) {
    const double ds = std::max(0.0, pts[i + 1].s_m - pts[i].s_m);
    const double brakeable = std::sqrt(pts[i + 1].v_mps * pts[i + 1].v_mps +
                                       2.0 * params.max_decel_mps2 * ds);
    pts[i].v_mps = std::min(pts[i].v_mps, brakeable);
  }
}

}  // namespace adse::algorithms
