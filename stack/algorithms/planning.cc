#include "stack/algorithms/planning.h"

#include <algorithm>
#include <cmath>
#include <limits>

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

void BehaviorVelocityPlanner::SetPath(const geometry::Path2& path,
                                      std::optional<Eigen::Vector2d> goal) {
  path_ = path;
  if (path_.s_m.size() != path_.points.size()) path_.UpdateArcLength();
  has_progress_ = false;
  last_s_m_ = 0.0;
  goal_s_m_ = path_.length_m();
  if (goal && has_path()) {
    double lateral = 0.0, distance = 0.0;
    goal_s_m_ = Project(*goal, 0.0, path_.length_m(), path_.length_m(),
                        &lateral, &distance);
  }
}

double BehaviorVelocityPlanner::Project(const Eigen::Vector2d& p, double s_lo,
                                        double s_hi, double s_ref,
                                        double* lateral_m,
                                        double* distance_m) const {
  s_lo = std::clamp(s_lo, 0.0, path_.length_m());
  s_hi = std::clamp(s_hi, s_lo, path_.length_m());
  const size_t i_lo = SegmentIndex(path_, s_lo);
  const size_t i_hi = SegmentIndex(path_, s_hi);
  struct Candidate {
    double distance, s, lateral;
  };
  std::vector<Candidate> per_segment;
  per_segment.reserve(i_hi - i_lo + 1);
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = i_lo; i <= i_hi; ++i) {
    const Eigen::Vector2d a = path_.points[i];
    const Eigen::Vector2d ab = path_.points[i + 1] - a;
    const double len = path_.s_m[i + 1] - path_.s_m[i];
    // Only the part of the segment inside [s_lo, s_hi].
    double t_lo = 0.0, t_hi = 1.0;
    if (len > 0.0) {
      t_lo = std::clamp((s_lo - path_.s_m[i]) / len, 0.0, 1.0);
      t_hi = std::clamp((s_hi - path_.s_m[i]) / len, 0.0, 1.0);
    }
    const double ab2 = ab.squaredNorm();
    double t = ab2 > 0.0 ? (p - a).dot(ab) / ab2 : 0.0;
    t = std::clamp(t, t_lo, t_hi);
    const Eigen::Vector2d r = p - (a + t * ab);
    Candidate c{r.norm(), path_.s_m[i] + t * len, 0.0};
    const Eigen::Vector2d dir =
        ab2 > 0.0 ? Eigen::Vector2d(ab / std::sqrt(ab2))
                  : Eigen::Vector2d(std::cos(path_.HeadingAt(c.s)),
                                    std::sin(path_.HeadingAt(c.s)));
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

double BehaviorVelocityPlanner::CurvatureAt(double s) const {
  // Curvature of the circle through three path points spaced over the
  // window (Menger curvature): smooth across polyline vertices, where the
  // tangent heading jumps, and right for a circle sampled by chords.
  const double half = 0.5 * std::max(params_.curvature_window_m, 1e-3);
  const double lo = std::max(0.0, s - half);
  const double hi = std::min(path_.length_m(), s + half);
  if (hi - lo < 1e-6) return 0.0;
  const Eigen::Vector2d a = path_.PointAt(lo);
  const Eigen::Vector2d b = path_.PointAt(0.5 * (lo + hi));
  const Eigen::Vector2d c = path_.PointAt(hi);
  const Eigen::Vector2d ab = b - a, ac = c - a;
  const double denom = ab.norm() * (c - b).norm() * ac.norm();
  if (denom < 1e-12) return 0.0;
  return 2.0 * (ab.x() * ac.y() - ab.y() * ac.x()) / denom;
}

PlannedTrajectory BehaviorVelocityPlanner::Plan(
    const geometry::Pose2& pose,
    const std::vector<PlannerObstacle>& obstacles) {
  PlannedTrajectory out;
  if (!has_path()) return out;
  const Eigen::Vector2d ego(pose.x_m, pose.y_m);
  const double length = path_.length_m();

  // Ego projection: near the last one while it fits, else the whole path.
  double lateral = 0.0, distance = 0.0;
  double s = 0.0;
  bool searched_globally = !has_progress_;
  if (has_progress_) {
    s = Project(ego, last_s_m_ - params_.projection_back_m,
                last_s_m_ + params_.projection_ahead_m, last_s_m_, &lateral,
                &distance);
    if (distance > params_.reacquire_distance_m) searched_globally = true;
  }
  if (searched_globally) {
    s = Project(ego, 0.0, length, has_progress_ ? last_s_m_ : 0.0, &lateral,
                &distance);
  }
  // Monotone progress: small backward jitter of the pose does not move the
  // trajectory start back (a re-acquisition may).
  if (has_progress_ && !searched_globally) s = std::max(s, last_s_m_);
  last_s_m_ = s;
  has_progress_ = true;
  out.ego_s_m = s;
  out.lateral_offset_m = lateral;
  int64_t work = 0;

  const double end_s = std::min({s + params_.horizon_m, goal_s_m_, length});
  if (goal_s_m_ <= s + params_.horizon_m) {
    out.stop_for_goal = true;
    out.stop_s_m = goal_s_m_;
  }

  // The nearest obstacle blocking the corridor between the ego and the
  // trajectory end sets a stop point before it.
  double obstacle_stop_s = std::numeric_limits<double>::infinity();
  for (const PlannerObstacle& ob : obstacles) {
    if (!ob.position.allFinite()) continue;
    double ob_lateral = 0.0, ob_distance = 0.0;
    const double ob_s = Project(ob.position, s - params_.ego_front_m,
                                end_s + 10.0, s, &ob_lateral, &ob_distance);
    work += 1 + static_cast<int64_t>((end_s - s) /
                                     std::max(0.1, params_.spacing_m));
    // The box's half extents across and along the path at that point.
    const double rel = ob.yaw_rad - path_.HeadingAt(ob_s);
    const double cr = std::abs(std::cos(rel)), sr = std::abs(std::sin(rel));
    const double half_across = 0.5 * (ob.length_m * sr + ob.width_m * cr);
    const double half_along = 0.5 * (ob.length_m * cr + ob.width_m * sr);
    if (ob_distance - half_across > params_.corridor_half_width_m) continue;
    if (ob_s + half_along < s) continue;  // behind the rear axle
    const double stop =
        ob_s - half_along - params_.stop_margin_m - params_.ego_front_m;
    if (stop < obstacle_stop_s) {
      obstacle_stop_s = stop;
      out.obstacle_id = ob.id;
    }
  }
  if (obstacle_stop_s <= end_s) {
    out.stop_for_obstacle = true;
    out.stop_s_m = out.stop_for_goal ? std::min(out.stop_s_m, obstacle_stop_s)
                                     : obstacle_stop_s;
  } else {
    out.obstacle_id = -1;
  }

  // Sample arc lengths: regular spacing, the end, and the obstacle stop
  // point exactly (so v reaches 0 there, not up to one spacing later).
  std::vector<double> samples;
  const double step = std::max(params_.spacing_m, 0.05);
  for (double si = s; si < end_s - 1e-6; si += step) samples.push_back(si);
  samples.push_back(std::max(end_s, s));
  if (out.stop_for_obstacle && obstacle_stop_s > s && obstacle_stop_s < end_s) {
    samples.push_back(obstacle_stop_s);
    std::sort(samples.begin(), samples.end());
    samples.erase(std::unique(samples.begin(), samples.end(),
                              [](double a, double b) { return b - a < 1e-3; }),
                  samples.end());
  }
  out.points.reserve(samples.size());
  for (double si : samples) {
    PlannedPoint pt;
    const Eigen::Vector2d p = path_.PointAt(si);
    pt.x_m = p.x();
    pt.y_m = p.y();
    pt.yaw_rad = path_.HeadingAt(si);
    pt.s_m = si;
    pt.curvature_1pm = CurvatureAt(si);
    double v = params_.speed_limit_mps;
    const double k = std::abs(pt.curvature_1pm);
    if (k > 1e-9) {
      const double v_curve = std::sqrt(params_.max_lateral_accel_mps2 / k);
      v = std::min(v, std::max(v_curve, params_.min_curve_speed_mps));
    }
    if (out.stop_for_goal && si >= goal_s_m_ - 1e-6) v = 0.0;
    if (out.stop_for_obstacle && si >= obstacle_stop_s - 1e-6) v = 0.0;
    pt.v_mps = std::max(0.0, v);
    out.points.push_back(pt);
  }
  out.work_units = work + static_cast<int64_t>(out.points.size());
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
