// Plain geometric types shared by the world and the stack (Eigen only).
#ifndef ADSE_STACK_GEOMETRY_GEOMETRY_H_
#define ADSE_STACK_GEOMETRY_GEOMETRY_H_

#include <Eigen/Core>
#include <cmath>
#include <vector>

namespace adse::geometry {

// Planar pose; yaw counter-clockwise from +x, radians.
struct Pose2 {
  double x_m = 0.0;
  double y_m = 0.0;
  double yaw_rad = 0.0;
};

// An oriented box standing on the ground (vehicles, parked cars).
struct OrientedBox {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  double yaw_rad = 0.0;
  double length_m = 4.5;
  double width_m = 1.8;
  double height_m = 1.5;
};

// A polyline with cumulative arc length, e.g. the ideal path.
struct Path2 {
  std::vector<Eigen::Vector2d> points;
  std::vector<double> s_m;  // s_m[i] = arc length at points[i]; s_m[0] = 0

  double length_m() const { return s_m.empty() ? 0.0 : s_m.back(); }
  // Recomputes s_m from points.
  void UpdateArcLength();
  // Point at arc length s (clamped to the ends).
  Eigen::Vector2d PointAt(double s) const;
  // Tangent heading at arc length s.
  double HeadingAt(double s) const;
  // Largest distance between consecutive points.
  double MaxGap() const;
  // Distance from p to the nearest point of the segments that reach into
  // arc lengths [s_lo, s_hi] (the whole path by default; a window keeps a
  // point on its own pass of a path that comes back near itself), and in
  // *s_out that point's arc length. Infinity for an empty path.
  double DistanceTo(const Eigen::Vector2d& p, double s_lo = 0.0,
                    double s_hi = INFINITY, double* s_out = nullptr) const;
};

// Planar motion at constant speed and yaw rate (a sweeping LiDAR's carrier
// during one revolution, Autoware's distortion-corrector model).
struct Twist2 {
  double v_mps = 0.0;         // forward speed
  double yaw_rate_rps = 0.0;  // counter-clockwise
};

// Where a frame that starts at the origin with `twist` is after `dt_s`:
// the exact constant-twist arc, a straight line when the yaw rate is ~0.
Pose2 MotionAfter(const Twist2& twist, double dt_s);

// The pose a fraction `w` (0: a, 1: b) of the way from `a` to `b`: the
// position along the straight line, the heading turned the shorter way
// round (in (-pi, pi]).
Pose2 InterpolatePose(const Pose2& a, const Pose2& b, double w);

// Whether `pose` lies within `tolerance_m` of `goal` and within
// `yaw_tolerance_rad` of its heading: the one test of "at the goal pose"
// that the world (true pose), the stack (its estimate) and the metrics
// (the run file) apply alike.
bool WithinTolerance(const Pose2& pose, const Pose2& goal, double tolerance_m,
                     double yaw_tolerance_rad);

// Whether `pose` lies on the way on from `goal`: within `tolerance_m` of
// the line through it along its heading, from `tolerance_m` before it to
// `ahead_m` past it, and within `yaw_tolerance_rad` of its heading. A car
// that has turned onto a lane a little past the pose it aimed for has
// turned all the same.
bool WithinToleranceOrAhead(const Pose2& pose, const Pose2& goal,
                            double tolerance_m, double ahead_m,
                            double yaw_tolerance_rad);

// The four corners of a box, counter-clockwise.
std::vector<Eigen::Vector2d> BoxCorners(const OrientedBox& box);

// True when two oriented boxes overlap (separating axis test).
bool BoxesOverlap(const OrientedBox& a, const OrientedBox& b);

// Where two oriented boxes meet.
struct BoxContact {
  // Of the boxes' four face normals, the one along which they overlap
  // least (the face one came through), pointing from a towards b.
  Eigen::Vector2d normal = Eigen::Vector2d::UnitX();
  double depth_m = 0.0;  // their overlap along it (negative: that far apart)
  // The corners of either box inside the other, averaged; halfway between
  // the centres when none is (edges crossing with no corner in).
  Eigen::Vector2d point = Eigen::Vector2d::Zero();
};
BoxContact ContactOfBoxes(const OrientedBox& a, const OrientedBox& b);

// Clips segment a-b to the axis-aligned rectangle [lo, hi] (Liang-Barsky):
// false when no part of it lies inside; else a and b become the ends of
// the part inside.
bool ClipSegmentToRect(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
                       Eigen::Vector2d* a, Eigen::Vector2d* b);

// True when an oriented box and an outline overlap or touch: a polygon
// closed back to its first point (3 or more points, inside counts), a
// segment (2), a point (1).
bool BoxTouchesOutline(const OrientedBox& box,
                       const std::vector<Eigen::Vector2d>& outline);

// How far along `path` the strip reaching `half_width_m` either side of it
// first meets `box`: the smallest arc length of a point of the box inside
// the strip (0 when the box covers the path's start), or -1 when the box
// stays outside the strip. A car's corridor ahead, with the path starting
// at its front bumper. Each segment's strip ends square, so a bend leaves
// a sliver outside on its outer side and counts one twice on the inner.
double DistanceAlongPathToBox(const std::vector<Eigen::Vector2d>& path,
                              double half_width_m, const OrientedBox& box);

// Even-odd rule: whether `p` lies inside the polygon closed back to its
// first point. Points on the boundary may go either way.
bool InsidePolygon(const std::vector<Eigen::Vector2d>& polygon,
                   const Eigen::Vector2d& p);

// Distance from `p` to the segment a-b (to `a` when they coincide).
double DistanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                         const Eigen::Vector2d& b);

}  // namespace adse::geometry

#endif  // ADSE_STACK_GEOMETRY_GEOMETRY_H_
