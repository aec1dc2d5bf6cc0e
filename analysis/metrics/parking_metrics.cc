#include "analysis/metrics/parking_metrics.h"

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "stack/geometry/geometry.h"

namespace adse::analysis {
namespace {

using Vec2 = Eigen::Vector2d;
constexpr double kInf = std::numeric_limits<double>::infinity();

double Cross(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}

bool SegmentsCross(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double d1 = Cross(b - a, c - a), d2 = Cross(b - a, d - a);
  const double d3 = Cross(d - c, a - c), d4 = Cross(d - c, b - c);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0));
}

double SegmentSegment(const Vec2& a, const Vec2& b, const Vec2& c,
                      const Vec2& d) {
  if (SegmentsCross(a, b, c, d)) return 0.0;
  return std::min({geometry::DistanceToSegment(a, c, d),
                   geometry::DistanceToSegment(b, c, d),
                   geometry::DistanceToSegment(c, a, b),
                   geometry::DistanceToSegment(d, a, b)});
}

size_t Edges(const std::vector<Vec2>& outline) {
  return outline.size() == 2 ? 1 : outline.size();
}

// Only an outline of three or more points can hold the other.
bool Holds(const std::vector<Vec2>& outline, const Vec2& p) {
  return outline.size() >= 3 && geometry::InsidePolygon(outline, p);
}

// Distance between two closed outlines (a 2-point outline is a segment);
// 0 when they touch or one holds the other.
double OutlineDistance(const std::vector<Vec2>& a, const std::vector<Vec2>& b) {
  double best = kInf;
  for (size_t i = 0; i < Edges(a); ++i) {
    for (size_t j = 0; j < Edges(b); ++j) {
      best = std::min(best, SegmentSegment(a[i], a[(i + 1) % a.size()], b[j],
                                           b[(j + 1) % b.size()]));
    }
  }
  if (best > 0 && (Holds(a, b.front()) || Holds(b, a.front()))) best = 0.0;
  return best;
}

// A point where two touching outlines meet: the mean of their edges'
// crossings, or of the vertices of one inside the other.
Vec2 MeetingPoint(const std::vector<Vec2>& a, const std::vector<Vec2>& b) {
  Vec2 sum = Vec2::Zero();
  int n = 0;
  for (size_t i = 0; i < Edges(a); ++i) {
    const Vec2 &p = a[i], &r = a[(i + 1) % a.size()];
    for (size_t j = 0; j < Edges(b); ++j) {
      const Vec2 &q = b[j], &t = b[(j + 1) % b.size()];
      if (!SegmentsCross(p, r, q, t)) continue;
      const double u = Cross(q - p, t - q) / Cross(r - p, t - q);
      sum += p + u * (r - p);
      ++n;
    }
  }
  auto add_inside = [&](const std::vector<Vec2>& points,
                        const std::vector<Vec2>& outline) {
    for (const Vec2& v : points) {
      if (!Holds(outline, v)) continue;
      sum += v;
      ++n;
    }
  };
  add_inside(a, b);
  add_inside(b, a);
  if (n > 0) return sum / n;
  // Touching without crossing (within rounding): the nearest vertex of b.
  const Vec2 centre = 0.25 * (a[0] + a[1] + a[2] + a[3]);
  Vec2 best = b.front();
  for (const Vec2& v : b) {
    if ((v - centre).norm() < (best - centre).norm()) best = v;
  }
  return best;
}

// The body's corners for a rear-axle sample.
std::vector<Vec2> Body(const runfile::EgoSample& e,
                       const runfile::ParkingRecord& p) {
  const Vec2 dir(std::cos(e.yaw_rad), std::sin(e.yaw_rad));
  const Vec2 left(-dir.y(), dir.x());
  const Vec2 centre = Vec2(e.x_m, e.y_m) + 0.5 * p.wheelbase_m * dir;
  const Vec2 hl = 0.5 * p.length_m * dir, hw = 0.5 * p.width_m * left;
  return {centre + hl + hw, centre - hl + hw, centre - hl - hw,
          centre + hl - hw};
}

struct Clearance {
  double min_m = kInf;
  std::vector<ParkingContact> contacts;
};

// One pass over the trajectory: the smallest gap between the body and the
// lot's obstacles, and each contact as it begins.
Clearance MeasureClearance(const runfile::RunData& run) {
  const runfile::ParkingRecord& p = run.parking;
  std::vector<std::vector<Vec2>> outlines;
  for (const runfile::OutlinePoint& v : p.obstacles) {
    if (static_cast<size_t>(v.obstacle) >= outlines.size())
      outlines.resize(v.obstacle + 1);
    outlines[v.obstacle].emplace_back(v.x_m, v.y_m);
  }
  Clearance out;
  bool touching = false;
  for (const runfile::EgoSample& e : run.ego) {
    const std::vector<Vec2> body = Body(e, p);
    const Vec2 centre = 0.25 * (body[0] + body[1] + body[2] + body[3]);
    double nearest = kInf;
    const std::vector<Vec2>* touched = nullptr;
    for (const std::vector<Vec2>& o : outlines) {
      if (o.size() < 2) continue;
      // Skip what is far away (the body's half-diagonal is under 3 m).
      double far = kInf;
      for (const Vec2& v : o) far = std::min(far, (v - centre).norm());
      if (o.size() > 2 && far > 30.0) continue;
      const double d = OutlineDistance(body, o);
      if (d < nearest) nearest = d;
      if (d <= 0.0 && touched == nullptr) touched = &o;
    }
    out.min_m = std::min(out.min_m, nearest);
    if (touched != nullptr && !touching) {
      const Vec2 at = MeetingPoint(body, *touched);
      out.contacts.push_back({e, at.x(), at.y()});
    }
    touching = touched != nullptr;
  }
  return out;
}

}  // namespace

std::vector<ParkingContact> ParkingContacts(const runfile::RunData& run) {
  if (!run.parking.present) return {};
  return MeasureClearance(run).contacts;
}

void AddParkingMetrics(const runfile::RunData& run,
                       std::map<std::string, double>* m) {
  const runfile::ParkingRecord& p = run.parking;
  if (!p.present) return;
  const double nan = std::nan("");

  // Where it ended up.
  if (run.ego.empty()) {
    (*m)["parked"] = 0.0;
    (*m)["parking_position_error_m"] = nan;
    (*m)["parking_yaw_error_deg"] = nan;
  } else {
    const runfile::EgoSample& end = run.ego.back();
    const double pos = std::hypot(end.x_m - p.goal_x_m, end.y_m - p.goal_y_m);
    const double yaw =
        std::abs(std::remainder(end.yaw_rad - p.goal_yaw_rad, 2 * M_PI));
    (*m)["parking_position_error_m"] = pos;
    (*m)["parking_yaw_error_deg"] = yaw * 180.0 / M_PI;
    (*m)["parked"] = std::abs(end.v_mps) < 0.05 &&
                             geometry::WithinTolerance(
                                 {end.x_m, end.y_m, end.yaw_rad},
                                 {p.goal_x_m, p.goal_y_m, p.goal_yaw_rad},
                                 p.tolerance_m, p.yaw_tolerance_rad)
                         ? 1.0
                         : 0.0;
  }
  const double end_s = run.ego.empty() ? 0.0 : run.ego.back().t_s;
  // From the first plan (a record without one has only its last).
  const double first_s =
      p.first_planned_at_s >= 0 ? p.first_planned_at_s : p.planned_at_s;
  (*m)["parking_time_s"] = first_s >= 0 ? end_s - first_s : nan;
  (*m)["parking_replans"] = p.replans;

  // Deviation from the plan while driving it.
  if (p.planned_path.size() >= 2) {
    double sum = 0.0, worst = 0.0;
    int n = 0;
    for (const runfile::EgoSample& e : run.ego) {
      if (e.t_s < p.planned_at_s) continue;
      double d = kInf;
      for (size_t i = 0; i + 1 < p.planned_path.size(); ++i) {
        const auto& a = p.planned_path[i];
        const auto& b = p.planned_path[i + 1];
        d = std::min(
            d, geometry::DistanceToSegment(
                   Vec2(e.x_m, e.y_m), Vec2(a.x_m, a.y_m), Vec2(b.x_m, b.y_m)));
      }
      sum += d;
      worst = std::max(worst, d);
      ++n;
    }
    (*m)["parking_path_deviation_m"] = n > 0 ? sum / n : nan;
    (*m)["parking_path_deviation_max_m"] = n > 0 ? worst : nan;
  } else {
    (*m)["parking_path_deviation_m"] = nan;
    (*m)["parking_path_deviation_max_m"] = nan;
  }

  // Clearance and contacts with the lot's obstacles.
  const Clearance c = MeasureClearance(run);
  (*m)["min_clearance_m"] = std::isfinite(c.min_m) ? c.min_m : nan;
  (*m)["obstacle_collisions"] = static_cast<double>(c.contacts.size());

  // Gear changes: the direction of motion reversing.
  int changes = 0, last = 0;
  for (const runfile::EgoSample& e : run.ego) {
    const int sign = e.v_mps > kStandstillMps    ? 1
                     : e.v_mps < -kStandstillMps ? -1
                                                 : 0;
    if (sign != 0 && last != 0 && sign != last) ++changes;
    if (sign != 0) last = sign;
  }
  (*m)["gear_changes"] = changes;
}

}  // namespace adse::analysis
