#include "stack/geometry/geometry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace adse::geometry {
namespace {

// Index i of the segment [points[i], points[i+1]] holding arc length s, with
// s already clamped to [0, length]. Callers ensure points.size() >= 2.
size_t SegmentAt(const std::vector<double>& s_m, double s) {
  // First vertex strictly beyond s; the segment starts one before it.
  const auto it = std::upper_bound(s_m.begin(), s_m.end(), s);
  size_t i = static_cast<size_t>(it - s_m.begin());
  i = i == 0 ? 0 : i - 1;
  return std::min(i, s_m.size() - 2);
}

// Keeps the part of convex `polygon` where n·p <= c (Sutherland-Hodgman).
std::vector<Eigen::Vector2d> ClipHalfPlane(
    const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& n,
    double c) {
  std::vector<Eigen::Vector2d> out;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % polygon.size()];
    const double da = n.dot(a) - c;
    const double db = n.dot(b) - c;
    if (da <= 0) out.push_back(a);
    if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
      out.push_back(a + da / (da - db) * (b - a));
    }
  }
  return out;
}

}  // namespace

void Path2::UpdateArcLength() {
  s_m.assign(points.size(), 0.0);
  for (size_t i = 1; i < points.size(); ++i) {
    s_m[i] = s_m[i - 1] + (points[i] - points[i - 1]).norm();
  }
}

Eigen::Vector2d Path2::PointAt(double s) const {
  if (points.empty()) return Eigen::Vector2d::Zero();
  if (points.size() == 1 || s_m.size() != points.size()) return points.front();
  s = std::clamp(s, 0.0, length_m());
  const size_t i = SegmentAt(s_m, s);
  const double ds = s_m[i + 1] - s_m[i];
  if (ds <= 0.0) return points[i];
  const double t = std::clamp((s - s_m[i]) / ds, 0.0, 1.0);
  return points[i] + t * (points[i + 1] - points[i]);
}

double Path2::HeadingAt(double s) const {
  if (points.size() < 2 || s_m.size() != points.size()) return 0.0;
  s = std::clamp(s, 0.0, length_m());
  const size_t seg = SegmentAt(s_m, s);
  // Repeated points give zero-length segments with no direction: use the
  // nearest real segment ahead, else behind.
  for (size_t i = seg; i + 1 < points.size(); ++i) {
    const Eigen::Vector2d d = points[i + 1] - points[i];
    if (d.squaredNorm() > 0.0) return std::atan2(d.y(), d.x());
  }
  for (size_t i = seg; i-- > 0;) {
    const Eigen::Vector2d d = points[i + 1] - points[i];
    if (d.squaredNorm() > 0.0) return std::atan2(d.y(), d.x());
  }
  return 0.0;
}

double Path2::MaxGap() const {
  double gap = 0.0;
  for (size_t i = 1; i < points.size(); ++i) {
    gap = std::max(gap, (points[i] - points[i - 1]).norm());
  }
  return gap;
}

double Path2::DistanceTo(const Eigen::Vector2d& p, double s_lo, double s_hi,
                         double* s_out) const {
  if (points.size() == 1 || s_m.size() != points.size()) {
    if (s_out) *s_out = 0.0;
    return points.empty() ? INFINITY : (points.front() - p).norm();
  }
  // The first segment that ends at or after s_lo.
  size_t i = std::lower_bound(s_m.begin(), s_m.end(), s_lo) - s_m.begin();
  i = i > 0 ? i - 1 : 0;
  double best = INFINITY;
  double best_s = 0.0;
  for (; i + 1 < points.size() && s_m[i] <= s_hi; ++i) {
    const Eigen::Vector2d a = points[i];
    const Eigen::Vector2d ab = points[i + 1] - a;
    const double len2 = ab.squaredNorm();
    const double u =
        len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    const double d = (a + u * ab - p).norm();
    if (d < best) {
      best = d;
      best_s = s_m[i] + u * (s_m[i + 1] - s_m[i]);
    }
  }
  if (s_out) *s_out = best_s;
  return best;
}

std::vector<Eigen::Vector2d> BoxCorners(const OrientedBox& box) {
  const Eigen::Vector2d ax(std::cos(box.yaw_rad), std::sin(box.yaw_rad));
  const Eigen::Vector2d ay(-ax.y(), ax.x());
  const Eigen::Vector2d hx = 0.5 * box.length_m * ax;
  const Eigen::Vector2d hy = 0.5 * box.width_m * ay;
  // Front-right, front-left, rear-left, rear-right: counter-clockwise.
  return {box.center + hx - hy, box.center + hx + hy, box.center - hx + hy,
          box.center - hx - hy};
}

double DistanceAlongPathToBox(const std::vector<Eigen::Vector2d>& path,
                              double half_width_m, const OrientedBox& box) {
  const std::vector<Eigen::Vector2d> corners = BoxCorners(box);
  double s0 = 0.0;
  for (size_t i = 0; i + 1 < path.size(); ++i) {
    const Eigen::Vector2d d = path[i + 1] - path[i];
    const double length = d.norm();
    if (length < 1e-9) continue;
    const Eigen::Vector2d u = d / length;
    const Eigen::Vector2d n(-u.y(), u.x());
    // The box in the segment's frame: x along it from its start, y across.
    std::vector<Eigen::Vector2d> local;
    local.reserve(corners.size());
    for (const Eigen::Vector2d& c : corners) {
      const Eigen::Vector2d r = c - path[i];
      local.emplace_back(u.dot(r), n.dot(r));
    }
    local = ClipHalfPlane(local, {-1, 0}, 0.0);
    local = ClipHalfPlane(local, {1, 0}, length);
    local = ClipHalfPlane(local, {0, -1}, half_width_m);
    local = ClipHalfPlane(local, {0, 1}, half_width_m);
    if (!local.empty()) {
      double x = length;
      for (const Eigen::Vector2d& p : local) x = std::min(x, p.x());
      return s0 + x;
    }
    s0 += length;
  }
  return -1.0;
}

namespace {

// A box as its centre, its two face normals (along its heading and to its
// left) and its half extents along them, worked out once per box.
struct BoxFrame {
  Eigen::Vector2d center;
  std::array<Eigen::Vector2d, 2> axes;
  std::array<double, 2> half;
};

BoxFrame FrameOf(const OrientedBox& box) {
  const double c = std::cos(box.yaw_rad), s = std::sin(box.yaw_rad);
  return {box.center,
          {Eigen::Vector2d(c, s), Eigen::Vector2d(-s, c)},
          {0.5 * box.length_m, 0.5 * box.width_m}};
}

// How far the projections of two boxes onto `axis` (a unit vector)
// overlap; negative when a gap separates them.
double OverlapAlong(const BoxFrame& a, const BoxFrame& b,
                    const Eigen::Vector2d& axis) {
  auto reach = [&](const BoxFrame& box) {
    return box.half[0] * std::abs(box.axes[0].dot(axis)) +
           box.half[1] * std::abs(box.axes[1].dot(axis));
  };
  return reach(a) + reach(b) - std::abs((b.center - a.center).dot(axis));
}

bool Contains(const BoxFrame& box, const Eigen::Vector2d& p) {
  const Eigen::Vector2d d = p - box.center;
  return std::abs(d.dot(box.axes[0])) <= box.half[0] &&
         std::abs(d.dot(box.axes[1])) <= box.half[1];
}

}  // namespace

bool BoxesOverlap(const OrientedBox& a, const OrientedBox& b) {
  // Two convex shapes are disjoint iff some edge normal separates them; a
  // box has two distinct normals. Boxes are closed sets, so touching boxes
  // overlap (a collision check should err towards "hit").
  const BoxFrame fa = FrameOf(a), fb = FrameOf(b);
  for (const BoxFrame* box : {&fa, &fb}) {
    for (const Eigen::Vector2d& axis : box->axes) {
      if (OverlapAlong(fa, fb, axis) < 0.0) return false;
    }
  }
  return true;
}

BoxContact ContactOfBoxes(const OrientedBox& a, const OrientedBox& b) {
  BoxContact contact;
  contact.depth_m = std::numeric_limits<double>::infinity();
  const BoxFrame fa = FrameOf(a), fb = FrameOf(b);
  const Eigen::Vector2d d = b.center - a.center;
  for (const BoxFrame* box : {&fa, &fb}) {
    for (const Eigen::Vector2d& axis : box->axes) {
      const double overlap = OverlapAlong(fa, fb, axis);
      if (overlap < contact.depth_m) {
        contact.depth_m = overlap;
        contact.normal = d.dot(axis) < 0.0 ? Eigen::Vector2d(-axis) : axis;
      }
    }
  }
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  int inside = 0;
  for (const auto& [from, into] : {std::pair{&a, &fb}, std::pair{&b, &fa}}) {
    for (const Eigen::Vector2d& corner : BoxCorners(*from)) {
      if (!Contains(*into, corner)) continue;
      sum += corner;
      ++inside;
    }
  }
  contact.point = inside > 0 ? Eigen::Vector2d(sum / inside)
                             : Eigen::Vector2d(0.5 * (a.center + b.center));
  return contact;
}

bool ClipSegmentToRect(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
                       Eigen::Vector2d* a, Eigen::Vector2d* b) {
  const Eigen::Vector2d d = *b - *a;
  double t0 = 0.0, t1 = 1.0;
  const double p[4] = {-d.x(), d.x(), -d.y(), d.y()};
  const double q[4] = {a->x() - lo.x(), hi.x() - a->x(), a->y() - lo.y(),
                       hi.y() - a->y()};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0.0) {
      if (q[i] < 0.0) return false;  // parallel and outside
      continue;
    }
    const double t = q[i] / p[i];
    if (p[i] < 0.0) {
      t0 = std::max(t0, t);
    } else {
      t1 = std::min(t1, t);
    }
    if (t0 > t1) return false;
  }
  const Eigen::Vector2d start = *a;
  *a = start + t0 * d;
  *b = start + t1 * d;
  return true;
}

bool BoxTouchesOutline(const OrientedBox& box,
                       const std::vector<Eigen::Vector2d>& outline) {
  if (outline.empty()) return false;
  // In the box's frame the box is [-hx, hx] x [-hy, hy]; a segment meets
  // it unless clipping it to that rectangle leaves nothing.
  const double c = std::cos(box.yaw_rad), s = std::sin(box.yaw_rad);
  auto local = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2d d = p - box.center;
    return Eigen::Vector2d(c * d.x() + s * d.y(), -s * d.x() + c * d.y());
  };
  const Eigen::Vector2d half(0.5 * box.length_m, 0.5 * box.width_m);
  auto segment_meets = [&](Eigen::Vector2d a, Eigen::Vector2d b) {
    return ClipSegmentToRect(-half, half, &a, &b);
  };
  std::vector<Eigen::Vector2d> points;
  points.reserve(outline.size());
  for (const Eigen::Vector2d& p : outline) points.push_back(local(p));
  const size_t n = points.size();
  const size_t edges = n <= 2 ? n - 1 : n;
  if (n == 1) return segment_meets(points[0], points[0]);
  for (size_t i = 0; i < edges; ++i) {
    if (segment_meets(points[i], points[(i + 1) % n])) return true;
  }
  // No edge meets the box: it overlaps only if it lies wholly inside.
  return n >= 3 && InsidePolygon(outline, box.center);
}

Pose2 InterpolatePose(const Pose2& a, const Pose2& b, double w) {
  const double dyaw = std::remainder(b.yaw_rad - a.yaw_rad, 2 * M_PI);
  return {a.x_m + w * (b.x_m - a.x_m), a.y_m + w * (b.y_m - a.y_m),
          std::remainder(a.yaw_rad + w * dyaw, 2 * M_PI)};
}

bool WithinTolerance(const Pose2& pose, const Pose2& goal, double tolerance_m,
                     double yaw_tolerance_rad) {
  const double yaw_error =
      std::abs(std::remainder(pose.yaw_rad - goal.yaw_rad, 2 * M_PI));
  return std::hypot(pose.x_m - goal.x_m, pose.y_m - goal.y_m) <= tolerance_m &&
         yaw_error <= yaw_tolerance_rad;
}

bool WithinToleranceOrAhead(const Pose2& pose, const Pose2& goal,
                            double tolerance_m, double ahead_m,
                            double yaw_tolerance_rad) {
  const double dx = pose.x_m - goal.x_m;
  const double dy = pose.y_m - goal.y_m;
  const double c = std::cos(goal.yaw_rad);
  const double s = std::sin(goal.yaw_rad);
  const double along_m = dx * c + dy * s;
  const double lateral_m = -dx * s + dy * c;
  return along_m >= -tolerance_m && along_m <= ahead_m &&
         std::abs(lateral_m) <= tolerance_m &&
         std::abs(std::remainder(pose.yaw_rad - goal.yaw_rad, 2 * M_PI)) <=
             yaw_tolerance_rad;
}

Pose2 MotionAfter(const Twist2& twist, double dt_s) {
  const double yaw = twist.yaw_rate_rps * dt_s;
  const double d = twist.v_mps * dt_s;
  Pose2 out;
  out.yaw_rad = yaw;
  if (std::abs(yaw) < 1e-9) {
    out.x_m = d;
    return out;
  }
  // Chord of the arc of radius v / w.
  const double r = twist.v_mps / twist.yaw_rate_rps;
  out.x_m = r * std::sin(yaw);
  out.y_m = r * (1.0 - std::cos(yaw));
  return out;
}

bool InsidePolygon(const std::vector<Eigen::Vector2d>& polygon,
                   const Eigen::Vector2d& p) {
  bool inside = false;
  for (size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

double DistanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                         const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t =
      len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

}  // namespace adse::geometry
