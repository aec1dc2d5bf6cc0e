// The formulas follow Reeds and Shepp's paper (sections 8.1-8.11): each
// word is solved for a goal (x, y, phi) in the start's frame with unit
// radius; the paper's symmetries (time flip, reflection, backwards) give
// the other words of a family from one solver.
#include "stack/algorithms/reeds_shepp.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace adse::algorithms {
namespace {

constexpr double kPi = M_PI;
// Slack on the sign tests of segment lengths (round-off of the solvers).
constexpr double kZero = 1e-10;

using geometry::Pose2;

// Angle in [-pi, pi]: every arc of an optimal word is at most half a turn.
double Mod2Pi(double a) {
  double v = std::fmod(a, 2.0 * kPi);
  if (v < -kPi) {
    v += 2.0 * kPi;
  } else if (v > kPi) {
    v -= 2.0 * kPi;
  }
  return v;
}

void Polar(double x, double y, double* r, double* theta) {
  *r = std::hypot(x, y);
  *theta = std::atan2(y, x);
}

// The paper's tau/omega helper for the CCCC words.
void TauOmega(double u, double v, double xi, double eta, double phi,
              double* tau, double* omega) {
  const double delta = Mod2Pi(u - v);
  const double a = std::sin(u) - std::sin(delta);
  const double b = std::cos(u) - std::cos(delta) - 1.0;
  const double t1 = std::atan2(eta * a - xi * b, xi * a + eta * b);
  const double t2 = 2.0 * (std::cos(delta) - std::cos(v) - std::cos(u)) + 3.0;
  *tau = t2 < 0 ? Mod2Pi(t1 + kPi) : Mod2Pi(t1);
  *omega = Mod2Pi(*tau - u + v - phi);
}

// 8.1: L+ S+ L+.
bool LpSpLp(double x, double y, double phi, double* t, double* u, double* v) {
  Polar(x - std::sin(phi), y - 1.0 + std::cos(phi), u, t);
  if (*t < -kZero) return false;
  *v = Mod2Pi(phi - *t);
  return *v >= -kZero;
}

// 8.2: L+ S+ R+.
bool LpSpRp(double x, double y, double phi, double* t, double* u, double* v) {
  double u1, t1;
  Polar(x + std::sin(phi), y - 1.0 - std::cos(phi), &u1, &t1);
  u1 *= u1;
  if (u1 < 4.0) return false;
  *u = std::sqrt(u1 - 4.0);
  *t = Mod2Pi(t1 + std::atan2(2.0, *u));
  *v = Mod2Pi(*t - phi);
  return *t >= -kZero && *v >= -kZero;
}

// 8.3: L+ R- L.
bool LpRmL(double x, double y, double phi, double* t, double* u, double* v) {
  const double xi = x - std::sin(phi);
  const double eta = y - 1.0 + std::cos(phi);
  double u1, theta;
  Polar(xi, eta, &u1, &theta);
  if (u1 > 4.0) return false;
  *u = -2.0 * std::asin(0.25 * u1);
  *t = Mod2Pi(theta + 0.5 * *u + kPi);
  *v = Mod2Pi(phi - *t + *u);
  return *t >= -kZero && *u <= kZero;
}

// 8.7: L+ R+ L- R-, the middle arcs of equal length.
bool LpRupLumRm(double x, double y, double phi, double* t, double* u,
                double* v) {
  const double xi = x + std::sin(phi);
  const double eta = y - 1.0 - std::cos(phi);
  const double rho = 0.25 * (2.0 + std::sqrt(xi * xi + eta * eta));
  if (rho > 1.0) return false;
  *u = std::acos(rho);
  TauOmega(*u, -*u, xi, eta, phi, t, v);
  return *t >= -kZero && *v <= kZero;
}

// 8.8: L+ R- L- R+, the middle arcs of equal length.
bool LpRumLumRp(double x, double y, double phi, double* t, double* u,
                double* v) {
  const double xi = x + std::sin(phi);
  const double eta = y - 1.0 - std::cos(phi);
  const double rho = (20.0 - xi * xi - eta * eta) / 16.0;
  if (rho < 0.0 || rho > 1.0) return false;
  *u = -std::acos(rho);
  if (*u < -0.5 * kPi) return false;
  TauOmega(*u, *u, xi, eta, phi, t, v);
  return *t >= -kZero && *v >= -kZero;
}

// 8.9: L+ R-(pi/2) S- L-.
bool LpRmSmLm(double x, double y, double phi, double* t, double* u, double* v) {
  const double xi = x - std::sin(phi);
  const double eta = y - 1.0 + std::cos(phi);
  double rho, theta;
  Polar(xi, eta, &rho, &theta);
  if (rho < 2.0) return false;
  const double r = std::sqrt(rho * rho - 4.0);
  *u = 2.0 - r;
  *t = Mod2Pi(theta + std::atan2(r, -2.0));
  *v = Mod2Pi(phi - 0.5 * kPi - *t);
  return *t >= -kZero && *u <= kZero && *v <= kZero;
}

// 8.10: L+ R-(pi/2) S- R-.
bool LpRmSmRm(double x, double y, double phi, double* t, double* u, double* v) {
  const double xi = x + std::sin(phi);
  const double eta = y - 1.0 - std::cos(phi);
  double rho, theta;
  Polar(-eta, xi, &rho, &theta);
  if (rho < 2.0) return false;
  *t = theta;
  *u = 2.0 - rho;
  *v = Mod2Pi(*t + 0.5 * kPi - phi);
  return *t >= -kZero && *u <= kZero && *v <= kZero;
}

// 8.11: L+ R-(pi/2) S- L-(pi/2) R+.
bool LpRmSLmRp(double x, double y, double phi, double* t, double* u,
               double* v) {
  const double xi = x + std::sin(phi);
  const double eta = y - 1.0 - std::cos(phi);
  double rho, theta;
  Polar(xi, eta, &rho, &theta);
  if (rho < 2.0) return false;
  *u = 4.0 - std::sqrt(rho * rho - 4.0);
  if (*u > kZero) return false;
  *t = Mod2Pi(
      std::atan2((4.0 - *u) * xi - 2.0 * eta, -2.0 * xi + (*u - 4.0) * eta));
  *v = Mod2Pi(*t - phi);
  return *t >= -kZero && *v >= -kZero;
}

using Solver = bool (*)(double, double, double, double*, double*, double*);
constexpr SteerKind L = SteerKind::kLeft;
constexpr SteerKind R = SteerKind::kRight;
constexpr SteerKind S = SteerKind::kStraight;

SteerKind Mirror(SteerKind k) { return k == L ? R : (k == R ? L : S); }

// Collects the words of one solver under the paper's symmetries. A word is
// given for the plain solution as steer kinds and lengths (unit radius).
class Collector {
 public:
  explicit Collector(std::vector<ReedsSheppPath>* out, double radius)
      : out_(out), radius_(radius) {}

  // `word(t, u, v)` returns the segments for a plain solution; the four
  // symmetric goals (time flip: -x, -phi; reflection: -y, -phi; both) reuse
  // it with negated lengths and/or mirrored turns.
  template <typename Word>
  void AllSymmetries(Solver solve, double x, double y, double phi, Word word) {
    double t, u, v;
    if (solve(x, y, phi, &t, &u, &v)) Add(word(t, u, v), false, false);
    if (solve(-x, y, -phi, &t, &u, &v)) Add(word(t, u, v), true, false);
    if (solve(x, -y, -phi, &t, &u, &v)) Add(word(t, u, v), false, true);
    if (solve(-x, -y, phi, &t, &u, &v)) Add(word(t, u, v), true, true);
  }

 private:
  void Add(std::vector<RsSegment> segments, bool flip, bool reflect) {
    ReedsSheppPath path;
    for (RsSegment s : segments) {
      if (flip) s.length_m = -s.length_m;
      if (reflect) s.steer = Mirror(s.steer);
      s.length_m *= radius_;
      if (std::abs(s.length_m) > 1e-9) path.segments.push_back(s);
    }
    out_->push_back(std::move(path));
  }
  std::vector<ReedsSheppPath>* out_;
  double radius_;
};

}  // namespace

double ReedsSheppPath::length_m() const {
  double sum = 0.0;
  for (const RsSegment& s : segments) sum += std::abs(s.length_m);
  return sum;
}

int ReedsSheppPath::gear_changes() const {
  int changes = 0;
  for (size_t i = 1; i < segments.size(); ++i) {
    if ((segments[i].length_m < 0) != (segments[i - 1].length_m < 0)) {
      ++changes;
    }
  }
  return changes;
}

namespace {

// Every admissible path of the five families, in the order generated.
std::vector<ReedsSheppPath> AllReedsSheppPaths(const Pose2& from,
                                               const Pose2& to,
                                               double turning_radius_m) {
  std::vector<ReedsSheppPath> out;
  if (!(turning_radius_m > 0.0)) return out;
  // The goal in the start's frame, in units of the radius.
  const double dx = to.x_m - from.x_m;
  const double dy = to.y_m - from.y_m;
  const double c = std::cos(from.yaw_rad);
  const double s = std::sin(from.yaw_rad);
  const double x = (c * dx + s * dy) / turning_radius_m;
  const double y = (-s * dx + c * dy) / turning_radius_m;
  const double phi = Mod2Pi(to.yaw_rad - from.yaw_rad);
  // The "backwards" goal: the path driven from the goal to the start.
  const double xb = x * std::cos(phi) + y * std::sin(phi);
  const double yb = x * std::sin(phi) - y * std::cos(phi);
  const double h = 0.5 * kPi;

  Collector add(&out, turning_radius_m);
  using Segs = std::vector<RsSegment>;
  // CSC.
  add.AllSymmetries(LpSpLp, x, y, phi, [](double t, double u, double v) {
    return Segs{{L, t}, {S, u}, {L, v}};
  });
  add.AllSymmetries(LpSpRp, x, y, phi, [](double t, double u, double v) {
    return Segs{{L, t}, {S, u}, {R, v}};
  });
  // CCC, and its backwards words.
  add.AllSymmetries(LpRmL, x, y, phi, [](double t, double u, double v) {
    return Segs{{L, t}, {R, u}, {L, v}};
  });
  add.AllSymmetries(LpRmL, xb, yb, phi, [](double t, double u, double v) {
    return Segs{{L, v}, {R, u}, {L, t}};
  });
  // CCCC.
  add.AllSymmetries(LpRupLumRm, x, y, phi, [](double t, double u, double v) {
    return Segs{{L, t}, {R, u}, {L, -u}, {R, v}};
  });
  add.AllSymmetries(LpRumLumRp, x, y, phi, [](double t, double u, double v) {
    return Segs{{L, t}, {R, u}, {L, u}, {R, v}};
  });
  // CCSC, and its backwards words.
  add.AllSymmetries(LpRmSmLm, x, y, phi, [h](double t, double u, double v) {
    return Segs{{L, t}, {R, -h}, {S, u}, {L, v}};
  });
  add.AllSymmetries(LpRmSmRm, x, y, phi, [h](double t, double u, double v) {
    return Segs{{L, t}, {R, -h}, {S, u}, {R, v}};
  });
  add.AllSymmetries(LpRmSmLm, xb, yb, phi, [h](double t, double u, double v) {
    return Segs{{L, v}, {S, u}, {R, -h}, {L, t}};
  });
  add.AllSymmetries(LpRmSmRm, xb, yb, phi, [h](double t, double u, double v) {
    return Segs{{R, v}, {S, u}, {R, -h}, {L, t}};
  });
  // CCSCC.
  add.AllSymmetries(LpRmSLmRp, x, y, phi, [h](double t, double u, double v) {
    return Segs{{L, t}, {R, -h}, {S, u}, {L, -h}, {R, v}};
  });
  return out;
}

bool Shorter(const ReedsSheppPath& a, const ReedsSheppPath& b) {
  return a.length_m() < b.length_m();
}

}  // namespace

std::vector<ReedsSheppPath> ReedsSheppCandidates(const Pose2& from,
                                                 const Pose2& to,
                                                 double turning_radius_m) {
  std::vector<ReedsSheppPath> out =
      AllReedsSheppPaths(from, to, turning_radius_m);
  std::stable_sort(out.begin(), out.end(), Shorter);
  return out;
}

double ReedsSheppDistance(const Pose2& from, const Pose2& to,
                          double turning_radius_m) {
  // The planner's heuristic, on its hot path: the shortest, unsorted.
  const std::vector<ReedsSheppPath> paths =
      AllReedsSheppPaths(from, to, turning_radius_m);
  if (paths.empty()) return std::hypot(to.x_m - from.x_m, to.y_m - from.y_m);
  return std::min_element(paths.begin(), paths.end(), Shorter)->length_m();
}

Pose2 AdvanceArc(const Pose2& from, double curvature_1pm, double length_m) {
  Pose2 to;
  if (std::abs(curvature_1pm) < 1e-12) {
    to.x_m = from.x_m + length_m * std::cos(from.yaw_rad);
    to.y_m = from.y_m + length_m * std::sin(from.yaw_rad);
    to.yaw_rad = from.yaw_rad;
    return to;
  }
  const double dyaw = curvature_1pm * length_m;
  const double yaw1 = from.yaw_rad + dyaw;
  to.x_m = from.x_m + (std::sin(yaw1) - std::sin(from.yaw_rad)) / curvature_1pm;
  to.y_m = from.y_m - (std::cos(yaw1) - std::cos(from.yaw_rad)) / curvature_1pm;
  to.yaw_rad = std::remainder(yaw1, 2.0 * kPi);
  return to;
}

std::vector<GearedPose> SampleReedsShepp(const Pose2& from,
                                         const ReedsSheppPath& path,
                                         double turning_radius_m,
                                         double step_m) {
  std::vector<GearedPose> out;
  const bool first_reverse =
      !path.segments.empty() && path.segments.front().length_m < 0;
  out.push_back({from, first_reverse});
  Pose2 pose = from;
  for (const RsSegment& seg : path.segments) {
    const double kappa = seg.steer == SteerKind::kLeft ? 1.0 / turning_radius_m
                         : seg.steer == SteerKind::kRight
                             ? -1.0 / turning_radius_m
                             : 0.0;
    const bool reverse = seg.length_m < 0;
    const int n = std::max(
        1, static_cast<int>(std::ceil(std::abs(seg.length_m) / step_m)));
    for (int i = 1; i <= n; ++i) {
      out.push_back({AdvanceArc(pose, kappa, seg.length_m * i / n), reverse});
    }
    pose = out.back().pose;
  }
  return out;
}

}  // namespace adse::algorithms
