#include "stack/geometry/geometry.h"

#include <gtest/gtest.h>

#include <cmath>

namespace adse::geometry {
namespace {

OrientedBox Box(double x, double y, double yaw, double length, double width) {
  OrientedBox b;
  b.center = Eigen::Vector2d(x, y);
  b.yaw_rad = yaw;
  b.length_m = length;
  b.width_m = width;
  return b;
}

TEST(BoxCornersTest, CounterClockwiseAroundCentre) {
  const auto c = BoxCorners(Box(1.0, 2.0, M_PI / 2, 4.0, 2.0));
  ASSERT_EQ(c.size(), 4u);
  // Rotated 90 degrees: length along +y.
  EXPECT_NEAR(c[0].x(), 2.0, 1e-12);
  EXPECT_NEAR(c[0].y(), 4.0, 1e-12);
  EXPECT_NEAR(c[2].x(), 0.0, 1e-12);
  EXPECT_NEAR(c[2].y(), 0.0, 1e-12);
  double area2 = 0.0;  // shoelace: positive when counter-clockwise
  for (int i = 0; i < 4; ++i) {
    const auto& a = c[i];
    const auto& b = c[(i + 1) % 4];
    area2 += a.x() * b.y() - b.x() * a.y();
  }
  EXPECT_NEAR(area2 / 2, 8.0, 1e-12);
}

TEST(BoxesOverlapTest, SeparatedOverlappingAndTouching) {
  const OrientedBox a = Box(0, 0, 0, 4, 2);
  EXPECT_TRUE(BoxesOverlap(a, Box(3.0, 0.5, 0, 4, 2)));
  EXPECT_FALSE(BoxesOverlap(a, Box(4.01, 0, 0, 4, 2)));
  EXPECT_FALSE(BoxesOverlap(a, Box(0, 2.01, 0, 4, 2)));
  // Touching edges count as overlap (closed boxes).
  EXPECT_TRUE(BoxesOverlap(a, Box(4.0, 0, 0, 4, 2)));
  EXPECT_TRUE(BoxesOverlap(a, Box(0, 2.0, 0, 4, 2)));
  // Containment.
  EXPECT_TRUE(BoxesOverlap(a, Box(0.1, 0, 0.3, 1, 0.5)));
  // Symmetric.
  EXPECT_TRUE(BoxesOverlap(Box(3.0, 0.5, 0, 4, 2), a));
}

TEST(BoxesOverlapTest, RotatedCasesNeedAllAxes) {
  const OrientedBox a = Box(0, 0, 0, 2, 2);
  // A diamond (square rotated 45 deg, half-diagonal sqrt 2) whose corner
  // points at a's corner (1, 1): the gap along the diagonal is what
  // separates them, which only the diamond's own axes detect.
  const double s = std::sqrt(2.0);
  EXPECT_FALSE(BoxesOverlap(a, Box(2.0 + 0.02, 2.0 + 0.02, M_PI / 4, 2, 2)));
  EXPECT_FALSE(BoxesOverlap(Box(2.02, 2.02, M_PI / 4, 2, 2), a));
  EXPECT_TRUE(BoxesOverlap(
      a, Box(1.0 + s / 2 - 0.01, 1.0 + s / 2 - 0.01, M_PI / 4, 2, 2)));
  // Diamond's corner poking into a's side.
  EXPECT_TRUE(BoxesOverlap(a, Box(1.0 + s - 0.05, 0, M_PI / 4, 2, 2)));
  EXPECT_FALSE(BoxesOverlap(a, Box(1.0 + s + 0.05, 0, M_PI / 4, 2, 2)));
  // Long thin boxes crossing in an X: the centres are far from each
  // other's extents along their own short axes.
  EXPECT_TRUE(BoxesOverlap(Box(0, 0, 0.5, 10, 0.2), Box(0, 0, -0.5, 10, 0.2)));
}

TEST(ContactOfBoxesTest, TheFaceOfLeastOverlapAndTheCornersIn) {
  // b overlaps a's front face by 0.2 m and its side by 1.5 m: it came
  // through the front. One corner of each lies in the other.
  const OrientedBox a = Box(0, 0, 0, 4, 2);
  const OrientedBox b = Box(3.8, 0.5, 0, 4, 2);
  BoxContact contact = ContactOfBoxes(a, b);
  EXPECT_NEAR(contact.normal.x(), 1.0, 1e-12);
  EXPECT_NEAR(contact.normal.y(), 0.0, 1e-12);
  EXPECT_NEAR(contact.depth_m, 0.2, 1e-12);
  // a's corner (2, 1) and b's corner (1.8, -0.5).
  EXPECT_NEAR(contact.point.x(), 1.9, 1e-12);
  EXPECT_NEAR(contact.point.y(), 0.25, 1e-12);
  // Seen from b, the normal points back at a.
  contact = ContactOfBoxes(b, a);
  EXPECT_NEAR(contact.normal.x(), -1.0, 1e-12);
  EXPECT_NEAR(contact.depth_m, 0.2, 1e-12);

  // Rotated 90 degrees and beside a's left side, 0.1 m in: the normal is
  // a's left, whichever box's axis gives it.
  contact = ContactOfBoxes(a, Box(0.5, 1.9, M_PI / 2, 2, 4));
  EXPECT_NEAR(contact.normal.x(), 0.0, 1e-12);
  EXPECT_NEAR(contact.normal.y(), 1.0, 1e-12);
  EXPECT_NEAR(contact.depth_m, 0.1, 1e-12);

  // Apart: the depth is the gap, negative; no corner is in, so the point
  // is halfway between the centres.
  contact = ContactOfBoxes(a, Box(5.0, 0, 0, 4, 2));
  EXPECT_NEAR(contact.depth_m, -1.0, 1e-12);
  EXPECT_NEAR(contact.point.x(), 2.5, 1e-12);
}

Path2 LShape() {
  Path2 p;
  p.points = {{0, 0}, {10, 0}, {10, 5}};
  p.UpdateArcLength();
  return p;
}

TEST(BoxTouchesOutlineTest, PolygonsSegmentsAndPoints) {
  // A car-sized box at the origin, turned 90 degrees: 4.6 m along y.
  const OrientedBox box{{0.0, 0.0}, M_PI / 2, 4.6, 1.9};
  using V = Eigen::Vector2d;
  auto square = [](double x, double y, double half) {
    return std::vector<V>{{x - half, y - half},
                          {x + half, y - half},
                          {x + half, y + half},
                          {x - half, y + half}};
  };
  // A pole by its side, one just clear of its nose, one touching it.
  EXPECT_TRUE(BoxTouchesOutline(box, square(1.0, 1.0, 0.15)));
  EXPECT_FALSE(BoxTouchesOutline(box, square(0.0, 2.5, 0.15)));
  EXPECT_TRUE(BoxTouchesOutline(box, square(0.0, 2.4, 0.15)));
  // A building round the whole car: no edge meets it, yet it is inside.
  EXPECT_TRUE(BoxTouchesOutline(box, square(0.0, 0.0, 10.0)));
  // A wall as a segment crossing it, passing it, and a point.
  EXPECT_TRUE(BoxTouchesOutline(box, {V(-5.0, 0.5), V(5.0, 0.5)}));
  EXPECT_FALSE(BoxTouchesOutline(box, {V(-5.0, 3.0), V(5.0, 3.0)}));
  EXPECT_TRUE(BoxTouchesOutline(box, {V(0.5, -2.0)}));
  EXPECT_FALSE(BoxTouchesOutline(box, {V(1.5, -2.0)}));
  EXPECT_FALSE(BoxTouchesOutline(box, {}));
}

TEST(Path2Test, ArcLengthAndPointAtOnLShape) {
  const Path2 p = LShape();
  ASSERT_EQ(p.s_m.size(), 3u);
  EXPECT_DOUBLE_EQ(p.s_m[1], 10.0);
  EXPECT_DOUBLE_EQ(p.length_m(), 15.0);
  EXPECT_TRUE(p.PointAt(4.0).isApprox(Eigen::Vector2d(4, 0)));
  EXPECT_TRUE(p.PointAt(10.0).isApprox(Eigen::Vector2d(10, 0)));
  EXPECT_TRUE(p.PointAt(12.5).isApprox(Eigen::Vector2d(10, 2.5)));
  // Clamped beyond the ends.
  EXPECT_TRUE(p.PointAt(-3.0).isApprox(Eigen::Vector2d(0, 0)));
  EXPECT_TRUE(p.PointAt(99.0).isApprox(Eigen::Vector2d(10, 5)));
  EXPECT_DOUBLE_EQ(p.MaxGap(), 10.0);
}

TEST(Path2Test, HeadingAtOnLShape) {
  const Path2 p = LShape();
  EXPECT_NEAR(p.HeadingAt(0.0), 0.0, 1e-12);
  EXPECT_NEAR(p.HeadingAt(9.9), 0.0, 1e-12);
  EXPECT_NEAR(p.HeadingAt(10.1), M_PI / 2, 1e-12);
  EXPECT_NEAR(p.HeadingAt(15.0), M_PI / 2, 1e-12);
  EXPECT_NEAR(p.HeadingAt(100.0), M_PI / 2, 1e-12);
  EXPECT_NEAR(p.HeadingAt(-1.0), 0.0, 1e-12);
}

TEST(Path2Test, RepeatedPointsAndDegenerateInputs) {
  Path2 p;
  p.points = {{0, 0}, {0, 0}, {0, 3}, {0, 3}};
  p.UpdateArcLength();
  EXPECT_NEAR(p.HeadingAt(0.0), M_PI / 2, 1e-12);
  EXPECT_NEAR(p.HeadingAt(3.0), M_PI / 2, 1e-12);
  EXPECT_TRUE(p.PointAt(1.5).isApprox(Eigen::Vector2d(0, 1.5)));

  Path2 empty;
  empty.UpdateArcLength();
  EXPECT_EQ(empty.length_m(), 0.0);
  EXPECT_TRUE(empty.PointAt(1.0).isZero());
  Path2 one;
  one.points = {{2, 3}};
  one.UpdateArcLength();
  EXPECT_TRUE(one.PointAt(5.0).isApprox(Eigen::Vector2d(2, 3)));
  EXPECT_EQ(one.MaxGap(), 0.0);
}

TEST(Path2Test, DistanceToTheWholePathOrToAWindowOfIt) {
  // Out 10 m along x and back 2 m to the left: a point between the legs
  // is nearest the way back, unless the window holds only the way out.
  Path2 p;
  p.points = {{0, 0}, {10, 0}, {10, 2}, {0, 2}};
  p.UpdateArcLength();
  const Eigen::Vector2d q(4, 1.5);
  double s = -1.0;
  EXPECT_NEAR(p.DistanceTo(q, 0.0, INFINITY, &s), 0.5, 1e-12);
  EXPECT_NEAR(s, 18.0, 1e-12);
  EXPECT_NEAR(p.DistanceTo(q, 0.0, 9.0, &s), 1.5, 1e-12);
  EXPECT_NEAR(s, 4.0, 1e-12);
  EXPECT_NEAR(p.DistanceTo(q), 0.5, 1e-12);

  Path2 empty;
  EXPECT_TRUE(std::isinf(empty.DistanceTo(q)));
  Path2 one;
  one.points = {{4, 5.5}};
  one.UpdateArcLength();
  EXPECT_NEAR(one.DistanceTo(q), 4.0, 1e-12);
}

TEST(MotionAfter, StraightLineAndQuarterCircle) {
  const Pose2 straight = MotionAfter({10.0, 0.0}, 0.1);
  EXPECT_NEAR(straight.x_m, 1.0, 1e-12);
  EXPECT_EQ(straight.y_m, 0.0);
  EXPECT_EQ(straight.yaw_rad, 0.0);
  // Radius 5 m, a quarter turn: from (0, 0) heading +x to (5, 5) heading +y.
  const double w = 0.5 * M_PI;
  const Pose2 quarter = MotionAfter({5.0 * w, w}, 1.0);
  EXPECT_NEAR(quarter.x_m, 5.0, 1e-9);
  EXPECT_NEAR(quarter.y_m, 5.0, 1e-9);
  EXPECT_NEAR(quarter.yaw_rad, w, 1e-12);
  // Turning right mirrors it.
  const Pose2 right = MotionAfter({5.0 * w, -w}, 1.0);
  EXPECT_NEAR(right.y_m, -5.0, 1e-9);
}

TEST(DistanceAlongPathToBoxTest, StraightCorridorAheadAndBeside) {
  const std::vector<Eigen::Vector2d> path = {{0, 0}, {30, 0}};
  // In the lane ahead: its rear at 8 m.
  EXPECT_NEAR(DistanceAlongPathToBox(path, 1.2, Box(10, 0, 0, 4, 2)), 8.0,
              1e-9);
  // In the next lane (3.2 m over): its near side 2.2 m from the path.
  EXPECT_LT(DistanceAlongPathToBox(path, 1.2, Box(10, 3.2, 0, 4, 2)), 0);
  // Standing across the lane, reaching 0.25 m past the path.
  EXPECT_NEAR(DistanceAlongPathToBox(path, 1.2, Box(10, 2.0, M_PI / 2, 4.5, 2)),
              9.0, 1e-9);
  // Only a corner inside the strip: the nearest point of that part counts.
  EXPECT_NEAR(DistanceAlongPathToBox(path, 1.2, Box(10, 2.3, M_PI / 4, 2, 2)),
              10.0 - (1.2 - (2.3 - std::sqrt(2.0))), 1e-9);
  // Beyond the path's end, behind its start, or covering the start.
  EXPECT_LT(DistanceAlongPathToBox(path, 1.2, Box(33, 0, 0, 4, 2)), 0);
  EXPECT_LT(DistanceAlongPathToBox(path, 1.2, Box(-3, 0, 0, 4, 2)), 0);
  EXPECT_NEAR(DistanceAlongPathToBox(path, 1.2, Box(0.5, 0, 0, 4, 2)), 0.0,
              1e-9);
}

TEST(DistanceAlongPathToBoxTest, FollowsABendAndSkipsDegenerateSegments) {
  const std::vector<Eigen::Vector2d> path = {
      {0, 0}, {10, 0}, {10, 0}, {10, 20}};
  // Round the corner: 10 m to it, then the box's rear 12 - 2.25 m up.
  EXPECT_NEAR(
      DistanceAlongPathToBox(path, 1.0, Box(10, 12, M_PI / 2, 4.5, 1.8)), 19.75,
      1e-9);
  // Straight on past the corner is not on the path.
  EXPECT_LT(DistanceAlongPathToBox(path, 1.0, Box(16, 0, 0, 4.5, 1.8)), 0);
  EXPECT_LT(DistanceAlongPathToBox({}, 1.0, Box(0, 0, 0, 4.5, 1.8)), 0);
  EXPECT_LT(DistanceAlongPathToBox({{1, 1}}, 1.0, Box(1, 1, 0, 4.5, 1.8)), 0);
}

TEST(InsidePolygon, ConvexConcaveAndDegenerate) {
  const std::vector<Eigen::Vector2d> square = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  EXPECT_TRUE(InsidePolygon(square, {1, 1}));
  EXPECT_FALSE(InsidePolygon(square, {3, 1}));
  EXPECT_FALSE(InsidePolygon(square, {1, -0.5}));
  // An L shape: the notch at the top right is outside.
  const std::vector<Eigen::Vector2d> ell = {{0, 0}, {4, 0}, {4, 2},
                                            {2, 2}, {2, 4}, {0, 4}};
  EXPECT_TRUE(InsidePolygon(ell, {1, 3}));
  EXPECT_TRUE(InsidePolygon(ell, {3, 1}));
  EXPECT_FALSE(InsidePolygon(ell, {3, 3}));
  // Fewer than three points enclose nothing.
  EXPECT_FALSE(InsidePolygon({}, {0, 0}));
  EXPECT_FALSE(InsidePolygon({{0, 0}, {1, 1}}, {0.5, 0.5}));
}

TEST(InterpolatePoseTest, MovesAlongTheLineAndTurnsTheShortWay) {
  const Pose2 p = InterpolatePose({0, 0, 0.1}, {2, 4, 0.3}, 0.25);
  EXPECT_NEAR(p.x_m, 0.5, 1e-12);
  EXPECT_NEAR(p.y_m, 1.0, 1e-12);
  EXPECT_NEAR(p.yaw_rad, 0.15, 1e-12);
  // Across the +-pi seam: half way from 170 deg to -170 deg is 180 deg.
  const Pose2 q = InterpolatePose({0, 0, M_PI - 0.2}, {0, 0, -M_PI + 0.2}, 0.5);
  EXPECT_NEAR(std::abs(q.yaw_rad), M_PI, 1e-9);
  EXPECT_NEAR(InterpolatePose({1, 2, 3}, {5, 6, -3}, 1.0).x_m, 5.0, 1e-12);
}

TEST(WithinToleranceTest, BothPositionAndHeadingWithinTheirTolerances) {
  const Pose2 goal{10, 5, -M_PI / 2};
  EXPECT_TRUE(WithinTolerance({10.3, 5.39, -M_PI / 2}, goal, 0.5, 0.1));
  EXPECT_FALSE(WithinTolerance({10.3, 5.41, -M_PI / 2}, goal, 0.5, 0.1));
  EXPECT_TRUE(WithinTolerance({10, 5, -M_PI / 2 + 0.099}, goal, 0.5, 0.1));
  EXPECT_FALSE(WithinTolerance({10, 5, -M_PI / 2 - 0.11}, goal, 0.5, 0.1));
  // Headings compare across the +-pi seam.
  EXPECT_TRUE(
      WithinTolerance({0, 0, M_PI - 0.05}, {0, 0, -M_PI + 0.04}, 0.1, 0.1));
}

TEST(WithinToleranceOrAheadTest, AlongTheGoalsLineUpToAheadPastIt) {
  // The goal heads along -y: "ahead" is smaller y, "lateral" is x.
  const Pose2 goal{10, 5, -M_PI / 2};
  const double heading = -M_PI / 2;
  EXPECT_TRUE(WithinToleranceOrAhead({10.9, 1.0, heading}, goal, 1, 5, 0.3));
  EXPECT_TRUE(WithinToleranceOrAhead({9.1, 5.9, heading}, goal, 1, 5, 0.3));
  // Too far past, behind, or to the side; or heading elsewhere.
  EXPECT_FALSE(WithinToleranceOrAhead({10, -0.1, heading}, goal, 1, 5, 0.3));
  EXPECT_FALSE(WithinToleranceOrAhead({10, 6.1, heading}, goal, 1, 5, 0.3));
  EXPECT_FALSE(WithinToleranceOrAhead({11.1, 3, heading}, goal, 1, 5, 0.3));
  EXPECT_FALSE(
      WithinToleranceOrAhead({10, 3, heading + 0.31}, goal, 1, 5, 0.3));
  // Within the plain tolerance it is within this one.
  EXPECT_TRUE(
      WithinToleranceOrAhead({10.3, 5.39, heading + 0.29}, goal, 0.5, 0, 0.3));
}

}  // namespace
}  // namespace adse::geometry
