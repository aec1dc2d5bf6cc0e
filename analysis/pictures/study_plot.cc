// The reference study's figure: a campaign's points over an exhaustive
// reference campaign, navigation time across, cost up.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <tuple>

#include "analysis/pictures/internal/drawing_impl.h"
#include "analysis/pictures/pictures.h"

namespace adse::analysis::internal {
namespace {

constexpr int kMinSidePx = 300;
constexpr double kInf = std::numeric_limits<double>::infinity();
const cv::Scalar kReferenceDot = Bgr(kReferenceRgb);
const cv::Scalar kReferenceLine = Bgr(kReferenceFrontRgb);
const cv::Scalar kTriangle = Bgr(kStudyPointRgb);

bool Placed(const ParetoPlotPoint& p) {
  return std::isfinite(p.cost) && std::isfinite(p.nav_time_s);
}

Result<std::string> StudyPngImpl(const std::vector<ParetoPlotPoint>& points,
                                 const std::vector<ParetoPlotPoint>& reference,
                                 const StudyPlotOptions& o) {
  for (int side : {o.width_px, o.height_px}) {
    if (side < kMinSidePx || side > kMaxSidePx) {
      return Status::InvalidArgument(
          fmt::format("study plot size {}x{} px is outside {}..{}", o.width_px,
                      o.height_px, kMinSidePx, kMaxSidePx));
    }
  }
  // Runs that went on far past everything that matters (a 600 s timeout
  // beside a 90 s bound) would squash the figure against its left axis: as
  // in the front's picture, the time axis then ends a little past what
  // matters, and the slower points sit on its right edge as wedges.
  double x_matters = -kInf, x_all = -kInf;
  for (const auto* set : {&points, &reference}) {
    for (const ParetoPlotPoint& p : *set) {
      if (!Placed(p)) continue;
      x_all = std::max(x_all, p.nav_time_s);
      if (p.feasible || p.on_front)
        x_matters = std::max(x_matters, p.nav_time_s);
    }
  }
  for (double v : o.time_bounds_s) {
    if (std::isfinite(v)) x_matters = std::max(x_matters, v);
  }
  const bool clip_x = std::isfinite(x_matters) && x_matters > 0.0 &&
                      x_all > kClipRatio * x_matters;
  std::vector<double> xs, ys;
  for (const auto* set : {&points, &reference}) {
    for (const ParetoPlotPoint& p : *set) {
      if (!Placed(p)) continue;
      if (!clip_x || p.nav_time_s <= x_matters) xs.push_back(p.nav_time_s);
      ys.push_back(p.cost);
    }
  }
  if (ys.empty()) return Status::InvalidArgument("no point to plot");
  if (clip_x) xs.push_back(x_matters * 1.15);  // room for the wedges
  for (double v : o.time_bounds_s) {
    if (std::isfinite(v)) xs.push_back(v);
  }
  for (double v : o.cost_bounds) {
    if (std::isfinite(v)) ys.push_back(v);
  }
  // One line on top: the title.
  const PlotFrame frame =
      MakePlotFrame(o.width_px, o.height_px, MakeAxis(xs), MakeAxis(ys), 1, 10);
  const Style& s = frame.style;
  const Axis &ax = frame.ax, &ay = frame.ay;
  int baseline = frame.baseline;
  const int text_h = frame.text_h, line_px = frame.line_px;
  const int right = frame.right();
  const cv::Rect& area = frame.area;
  auto px = [&](double time, double cost) { return frame.ToPx(time, cost); };
  auto beyond = [&](const ParetoPlotPoint& p) { return p.nav_time_s > ax.max; };
  // Where a point is drawn: a point beyond the axis on its right edge.
  auto at = [&](const ParetoPlotPoint& p) {
    return px(std::min(p.nav_time_s, ax.max), p.cost);
  };

  cv::Mat img(o.height_px, o.width_px, CV_8UC3, Bgr(kBackgroundRgb));
  DrawAxes(&img, area, ax, ay, s);
  for (double v : o.time_bounds_s) {
    if (std::isfinite(v)) {
      DrawDashed(&img, px(v, ay.min), px(v, ay.max), kBlack, s.Px(1.5),
                 s.Px(8));
    }
  }
  for (double v : o.cost_bounds) {
    if (std::isfinite(v)) {
      DrawDashed(&img, px(ax.min, v), px(ax.max, v), kBlack, s.Px(1.5),
                 s.Px(8));
    }
  }

  // The reference: every point, then its front as a staircase in cost
  // order (a min-min front promises nothing between its points).
  const int dot = s.Px(2.5);
  auto draw_dot = [&](cv::Point2d c, const cv::Scalar& colour, int r) {
    cv::circle(img, Fixed(c), r * static_cast<int>(kShiftScale), colour,
               cv::FILLED, cv::LINE_AA, kShift);
  };
  // A point beyond the axis: a wedge pointing right from its edge.
  auto draw_wedge = [&](cv::Point2d tip, const cv::Scalar& colour) {
    const double side = s.Px(4);
    const std::vector<cv::Point> corners = {
        Fixed(tip), Fixed(tip + cv::Point2d(-2.2 * side, -1.4 * side)),
        Fixed(tip + cv::Point2d(-2.2 * side, 1.4 * side))};
    cv::fillConvexPoly(img, corners, colour, cv::LINE_AA, kShift);
  };
  bool reference_beyond = false, points_beyond = false;
  std::vector<const ParetoPlotPoint*> front;
  for (const ParetoPlotPoint& p : reference) {
    if (!Placed(p)) continue;
    if (beyond(p)) {
      reference_beyond = true;
      draw_wedge(at(p), kReferenceDot);
    } else {
      draw_dot(px(p.nav_time_s, p.cost), kReferenceDot, dot);
    }
    if (p.on_front && p.feasible) front.push_back(&p);
  }
  std::sort(front.begin(), front.end(), [](const auto* a, const auto* b) {
    return a->cost < b->cost ||
           (a->cost == b->cost && a->nav_time_s < b->nav_time_s);
  });
  std::vector<cv::Point2d> line;
  for (const auto* p : front) {
    const cv::Point2d c = px(p->nav_time_s, p->cost);
    // Cost rises as time falls: step across in cost first, then in time.
    if (!line.empty()) line.push_back({line.back().x, c.y});
    line.push_back(c);
  }
  DrawPolyline(&img, line, kReferenceLine, s.Px(2));
  for (const auto* p : front) {
    draw_dot(px(p->nav_time_s, p->cost), kReferenceLine, dot + s.Px(1));
  }

  // The campaign's points on top.
  auto draw_triangle = [&](cv::Point2d c, bool filled) {
    // A hollow one a little larger, so that its inside shows.
    const double side = filled ? s.Px(7) : s.Px(9);
    const std::vector<cv::Point> corners = {
        Fixed(c + cv::Point2d(0, -side * 0.6)),
        Fixed(c + cv::Point2d(-side * 0.55, side * 0.4)),
        Fixed(c + cv::Point2d(side * 0.55, side * 0.4))};
    if (filled) {
      cv::fillConvexPoly(img, corners, kTriangle, cv::LINE_AA, kShift);
    } else {
      // White inside, so that stacked hollow triangles still read hollow.
      cv::fillConvexPoly(img, corners, kWhite, cv::LINE_AA, kShift);
      cv::polylines(img, corners, true, kTriangle, s.Px(1.2), cv::LINE_AA,
                    kShift);
    }
  };
  for (const ParetoPlotPoint& p : points) {
    if (!Placed(p)) continue;
    if (beyond(p)) {
      points_beyond = true;
      draw_wedge(at(p), kTriangle);
    } else {
      draw_triangle(px(p.nav_time_s, p.cost), p.feasible);
    }
  }
  // The answer: the campaign's cheapest feasible design, ringed.
  auto draw_ring = [&](cv::Point2d c) {
    cv::circle(img, Fixed(c), s.Px(9) * static_cast<int>(kShiftScale), kBlack,
               s.Px(1.5), cv::LINE_AA, kShift);
  };
  bool any_highlight = false;
  for (const ParetoPlotPoint& p : points) {
    if (!Placed(p) || !p.highlight) continue;
    draw_ring(at(p));
    any_highlight = true;
  }
  cv::rectangle(img, area, kBlack, 1);

  // Legend: at the top (right, middle or left) where it covers the fewest
  // points and no bound (slow and expensive, top right, is usually empty,
  // but a time bound near the right edge runs through it).
  struct Entry {
    std::string name;
    std::function<void(cv::Point2d)> sample;
  };
  // The marks drawn, no others.
  bool any_feasible = false, any_infeasible = false;
  for (const ParetoPlotPoint& p : points) {
    if (!Placed(p) || beyond(p)) continue;
    (p.feasible ? any_feasible : any_infeasible) = true;
  }
  std::vector<Entry> entries;
  if (any_feasible) {
    entries.push_back({o.points_name + ", feasible",
                       [&](cv::Point2d c) { draw_triangle(c, true); }});
  }
  if (any_infeasible) {
    entries.push_back({o.points_name + ", infeasible",
                       [&](cv::Point2d c) { draw_triangle(c, false); }});
  }
  if (any_highlight) {
    entries.push_back(
        {o.points_name + ", cheapest feasible", [&](cv::Point2d c) {
           draw_triangle(c, true);
           draw_ring(c);
         }});
  }
  if (std::any_of(reference.begin(), reference.end(), Placed)) {
    entries.push_back({o.reference_name, [&](cv::Point2d c) {
                         draw_dot(c, kReferenceDot, dot);
                       }});
  }
  if (!front.empty()) {
    entries.push_back({"its true front", [&](cv::Point2d c) {
                         DrawSegment(&img, c - cv::Point2d(s.Px(12), 0),
                                     c + cv::Point2d(s.Px(12), 0),
                                     kReferenceLine, s.Px(2));
                       }});
  }
  // Short, so that the legend still fits beside the bound.
  for (const auto& [drawn, name, colour] :
       {std::tuple(points_beyond, o.points_name + ", ", kTriangle),
        std::tuple(reference_beyond, std::string(), kReferenceDot)}) {
    if (!drawn) continue;
    entries.push_back({fmt::format("{}slower than {:.0f} s", name, ax.max),
                       [&, colour = colour](cv::Point2d c) {
                         draw_wedge(c + cv::Point2d(s.Px(8), 0), colour);
                       }});
  }
  if (!o.time_bounds_s.empty() || !o.cost_bounds.empty()) {
    entries.push_back({"constraint bound", [&](cv::Point2d c) {
                         DrawDashed(&img, c - cv::Point2d(s.Px(12), 0),
                                    c + cv::Point2d(s.Px(12), 0), kBlack,
                                    s.Px(1.5), s.Px(5));
                       }});
  }
  int text_w = 0;
  for (const Entry& e : entries) {
    text_w = std::max(text_w, TextSize(Ascii(e.name), s, &baseline).width);
  }
  const int row = line_px;
  const int box_w = s.Px(50) + text_w;
  const int box_h = row * static_cast<int>(entries.size()) + s.Px(6);
  cv::Rect box;
  double least = kInf;
  for (const int x : {right - s.Px(10) - box_w,
                      area.x + (area.width - box_w) / 2, area.x + s.Px(10)}) {
    const cv::Rect candidate(x, area.y + s.Px(10), box_w, box_h);
    double covered = 0.0;
    for (const auto* set : {&points, &reference}) {
      for (const ParetoPlotPoint& p : *set) {
        if (!Placed(p)) continue;
        const cv::Point2d c = at(p);
        covered += candidate.contains(
            cv::Point(static_cast<int>(c.x), static_cast<int>(c.y)));
      }
    }
    for (double v : o.time_bounds_s) {
      const double x_px = px(v, ay.min).x;
      if (x_px >= candidate.x && x_px <= candidate.x + candidate.width) {
        covered += 10.0;  // worse than a few hidden points
      }
    }
    if (covered < least) {
      least = covered;
      box = candidate;
    }
  }
  cv::rectangle(img, box, kWhite, cv::FILLED);
  cv::rectangle(img, box, kDarkGrey, 1);
  for (size_t i = 0; i < entries.size(); ++i) {
    const int y = box.y + s.Px(3) + row * static_cast<int>(i) + row / 2;
    entries[i].sample(cv::Point2d(box.x + s.Px(20), y));
    DrawText(&img, entries[i].name, box.x + s.Px(40), y + text_h / 2,
             Align::kLeft, s, kBlack, false);
  }

  DrawText(&img, o.title, o.width_px / 2, line_px - baseline, Align::kCentre, s,
           kBlack, false);
  DrawText(&img, "navigation time (s)", area.x + area.width / 2,
           o.height_px - s.Px(8) - baseline, Align::kCentre, s, kBlack, false);
  DrawTurnedLabel(&img, o.cost_label, area, s);

  std::string png;
  ADSE_RETURN_IF_ERROR(EncodeOk(img, &png));
  return png;
}

}  // namespace
}  // namespace adse::analysis::internal

namespace adse::analysis {

Result<std::string> StudyPlotPng(const std::vector<ParetoPlotPoint>& points,
                                 const std::vector<ParetoPlotPoint>& reference,
                                 const StudyPlotOptions& o) {
  return internal::Guarded("study plot", [&] {
    return internal::StudyPngImpl(points, reference, o);
  });
}

}  // namespace adse::analysis
