// The Pareto plot: every evaluation by cost and navigation time, the
// cost-time front as a staircase, its labels placed without overlap.
#include "analysis/pictures/pictures.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "analysis/pictures/internal/drawing_impl.h"

namespace adse::analysis::internal {

constexpr int kMinPlotSidePx = 300;

// ---------------------------------------------------------------------------
// Pareto plot.

Result<std::string> ParetoPngImpl(const std::vector<ParetoPlotPoint>& points,
                                  const ParetoPlotOptions& o) {
  for (int side : {o.width_px, o.height_px}) {
    if (side < kMinPlotSidePx || side > kMaxSidePx) {
      return Status::InvalidArgument(
          fmt::format("Pareto plot size {}x{} px is outside {}..{}", o.width_px,
                      o.height_px, kMinPlotSidePx, kMaxSidePx));
    }
  }
  std::vector<const ParetoPlotPoint*> shown;
  for (const auto& p : points) {
    if (std::isfinite(p.cost) && std::isfinite(p.nav_time_s)) {
      shown.push_back(&p);
    }
  }
  if (shown.empty()) {
    return Status::InvalidArgument(
        points.empty() ? "no points to plot"
                       : "no point with finite cost and time to plot");
  }
  const size_t hidden = points.size() - shown.size();

  // Runs that failed badly (a timeout at 600 s) would squash the front
  // against the axis: when the slowest point is far above everything that
  // matters (feasible points, the front, the bounds), the axis ends above
  // those and the rest are drawn as arrows on its top edge.
  double y_matters = -std::numeric_limits<double>::infinity();
  double y_all = y_matters;
  for (const auto* p : shown) {
    y_all = std::max(y_all, p->nav_time_s);
    if (p->feasible || p->on_front)
      y_matters = std::max(y_matters, p->nav_time_s);
  }
  for (double v : o.horizontal_lines) {
    if (std::isfinite(v)) y_matters = std::max(y_matters, v);
  }
  const bool clip_y = std::isfinite(y_matters) && y_matters > 0.0 &&
                      y_all > kClipRatio * y_matters;
  std::vector<double> xs, ys;
  size_t above = 0;
  for (const auto* p : shown) {
    xs.push_back(p->cost);
    if (clip_y && p->nav_time_s > y_matters) {
      ++above;
    } else {
      ys.push_back(p->nav_time_s);
    }
  }
  if (clip_y) ys.push_back(y_matters * 1.15);  // room for the arrows
  for (const auto* p : shown) {
    // Room above a censored point for its arrow.
    if (p->censored && !(clip_y && p->nav_time_s > y_matters))
      ys.push_back(p->nav_time_s * 1.08);
  }
  for (double v : o.vertical_lines) {
    if (std::isfinite(v)) xs.push_back(v);
  }
  for (double v : o.horizontal_lines) {
    if (std::isfinite(v)) ys.push_back(v);
  }
  // Two lines on top: the title and a note.
  const PlotFrame frame =
      MakePlotFrame(o.width_px, o.height_px, MakeAxis(xs), MakeAxis(ys), 2, 6);
  const Style& s = frame.style;
  const Axis &ax = frame.ax, &ay = frame.ay;
  int baseline = frame.baseline;
  const int text_h = frame.text_h, line_px = frame.line_px;
  const int right = frame.right(), bottom = frame.bottom();
  const cv::Rect& area = frame.area;
  auto px = [&](double x, double y) { return frame.ToPx(x, y); };
  auto clipped = [&](const ParetoPlotPoint* p) {
    return p->nav_time_s > ay.max;
  };

  cv::Mat img(o.height_px, o.width_px, CV_8UC3, Bgr(kBackgroundRgb));
  DrawAxes(&img, area, ax, ay, s);

  // Constraint lines.
  for (double v : o.vertical_lines) {
    if (!std::isfinite(v)) continue;
    DrawDashed(&img, px(v, ay.min), px(v, ay.max), Bgr(kConstraintRgb), s.Px(2),
               s.Px(8));
  }
  for (double v : o.horizontal_lines) {
    if (!std::isfinite(v)) continue;
    DrawDashed(&img, px(ax.min, v), px(ax.max, v), Bgr(kConstraintRgb), s.Px(2),
               s.Px(8));
  }

  // Points: infeasible, feasible, then the front on top.
  const int cross = s.Px(5);
  const int radius = s.Px(4);
  auto draw_cross = [&](cv::Point2d c, const cv::Scalar& colour) {
    DrawSegment(&img, c - cv::Point2d(cross, cross),
                c + cv::Point2d(cross, cross), colour, s.Px(1.5));
    DrawSegment(&img, c - cv::Point2d(cross, -cross),
                c + cv::Point2d(cross, -cross), colour, s.Px(1.5));
  };
  auto draw_dot = [&](cv::Point2d c, const cv::Scalar& colour, int r) {
    cv::circle(img, Fixed(c), r * static_cast<int>(kShiftScale), colour,
               cv::FILLED, cv::LINE_AA, kShift);
  };
  // An arrow pointing up from `base`: a time beyond it.
  auto draw_arrow_up = [&](cv::Point2d base, const cv::Scalar& colour) {
    const cv::Point2d tip = base - cv::Point2d(0, 3 * cross);
    DrawPolyline(&img,
                 {tip + cv::Point2d(-cross, cross), tip,
                  tip + cv::Point2d(cross, cross)},
                 colour, s.Px(1.5));
    DrawSegment(&img, base, tip, colour, s.Px(1.5));
  };
  // A point above the plot: a solid wedge on its top edge, unlike a
  // stopped run's arrow (whose time is a lower bound inside the plot).
  auto draw_wedge = [&](cv::Point2d tip) {
    const std::vector<cv::Point> corners = {
        Fixed(tip), Fixed(tip + cv::Point2d(-1.4 * cross, 2.2 * cross)),
        Fixed(tip + cv::Point2d(1.4 * cross, 2.2 * cross))};
    cv::fillConvexPoly(img, corners, Bgr(kInfeasibleRgb), cv::LINE_AA, kShift);
  };
  // The rings of highlighted designs (radius + 5 px, 1.5 px wide).
  const double ring_reach = radius + s.Px(5) + s.Px(3);
  std::vector<cv::Point2d> rings;
  for (const auto* p : shown) {
    if (p->on_front && p->highlight && !clipped(p)) {
      rings.push_back(px(p->cost, p->nav_time_s));
    }
  }
  bool any_censored = false, any_cross = false, any_above = false;
  for (const auto* p : shown) {
    if (p->feasible || p->on_front) continue;
    if (clipped(p)) {
      any_above = true;
      draw_wedge(px(p->cost, ay.max));
    } else if (p->censored) {
      any_censored = true;
      // A run stopped at the bound a ringed design sits on (as dear, but
      // too slow) starts its arrow above the ring, not through it.
      cv::Point2d base = px(p->cost, p->nav_time_s);
      for (const cv::Point2d& ring : rings) {
        if (std::abs(base.x - ring.x) < ring_reach &&
            std::abs(base.y - ring.y) < ring_reach) {
          base.y = std::min(base.y, ring.y - ring_reach);
        }
      }
      draw_arrow_up(base, Bgr(kInfeasibleRgb));
    } else {
      any_cross = true;
      draw_cross(px(p->cost, p->nav_time_s), Bgr(kInfeasibleRgb));
    }
  }
  // A feasible design whose runs disagree: a thin violet ring.
  const int unstable_radius = radius + s.Px(3);
  auto draw_unstable_ring = [&](cv::Point2d c) {
    cv::circle(img, Fixed(c), unstable_radius * static_cast<int>(kShiftScale),
               Bgr(kUnstableRgb), s.Px(1.5), cv::LINE_AA, kShift);
  };
  bool any_unstable = false, any_dot = false;
  for (const auto* p : shown) {
    if (p->feasible && !p->on_front) {
      any_dot = true;
      draw_dot(px(p->cost, p->nav_time_s), Bgr(kFeasibleRgb), radius);
      if (p->unstable) draw_unstable_ring(px(p->cost, p->nav_time_s));
    }
    any_unstable = any_unstable || (p->feasible && p->unstable);
  }
  std::vector<const ParetoPlotPoint*> front;
  for (const auto* p : shown) {
    if (p->on_front) front.push_back(p);
  }
  std::stable_sort(
      front.begin(), front.end(), [](const auto* a, const auto* b) {
        return a->cost < b->cost ||
               (a->cost == b->cost && a->nav_time_s < b->nav_time_s);
      });
  // The front as a staircase: what it promises holds between its points
  // only in the dominated sense, so a straight line between them would
  // claim designs that do not exist.
  std::vector<cv::Point2d> front_line;
  for (size_t i = 0; i < front.size(); ++i) {
    const cv::Point2d c = px(front[i]->cost, front[i]->nav_time_s);
    if (i > 0) front_line.push_back({c.x, front_line.back().y});
    front_line.push_back(c);
  }
  DrawPolyline(&img, front_line, Bgr(kFrontRgb), s.Px(2));
  for (const auto* p : front) {
    const cv::Point2d c = px(p->cost, p->nav_time_s);
    if (p->feasible) {
      draw_dot(c, Bgr(kFrontRgb), radius + s.Px(1));
      if (p->unstable) draw_unstable_ring(c);
    } else {
      draw_cross(c, Bgr(kFrontRgb));
    }
    if (p->highlight) {
      cv::circle(img, Fixed(c),
                 (radius + s.Px(5)) * static_cast<int>(kShiftScale), kBlack,
                 s.Px(1.5), cv::LINE_AA, kShift);
    }
  }
  cv::rectangle(img, area, kBlack, 1);

  // Legend: the marks drawn, no others.
  struct Entry {
    std::string name;
    std::function<void(cv::Point2d)> sample;
  };
  std::vector<Entry> entries;
  if (any_dot) {
    entries.push_back({"feasible", [&](cv::Point2d c) {
                         draw_dot(c, Bgr(kFeasibleRgb), radius);
                       }});
  }
  // A front of infeasible designs only (nothing is feasible) is crosses.
  bool front_cross = !front.empty();
  for (const auto* p : front) front_cross = front_cross && !p->feasible;
  if (any_cross) {
    entries.push_back({o.infeasible_name, [&](cv::Point2d c) {
                         draw_cross(c, Bgr(kInfeasibleRgb));
                       }});
  }
  if (!front.empty()) {
    entries.push_back({o.front_name, [&, front_cross](cv::Point2d c) {
                         DrawSegment(&img, c - cv::Point2d(s.Px(12), 0),
                                     c + cv::Point2d(s.Px(12), 0),
                                     Bgr(kFrontRgb), s.Px(2));
                         if (front_cross) {
                           draw_cross(c, Bgr(kFrontRgb));
                         } else {
                           draw_dot(c, Bgr(kFrontRgb), radius + s.Px(1));
                         }
                       }});
  }
  bool any_highlight = false;
  for (const auto* p : front) any_highlight = any_highlight || p->highlight;
  if (any_highlight) {
    entries.push_back({o.highlight_name, [&](cv::Point2d c) {
                         draw_dot(c, Bgr(kFrontRgb), radius + s.Px(1));
                         cv::circle(
                             img, Fixed(c),
                             (radius + s.Px(5)) * static_cast<int>(kShiftScale),
                             kBlack, s.Px(1.5), cv::LINE_AA, kShift);
                       }});
  }
  if (any_unstable) {
    entries.push_back({"unstable (its runs disagree)", [&](cv::Point2d c) {
                         draw_dot(c, Bgr(kFeasibleRgb), radius);
                         draw_unstable_ring(c);
                       }});
  }
  if (any_censored) {
    entries.push_back({"stopped early (time at least)", [&](cv::Point2d c) {
                         draw_arrow_up(c + cv::Point2d(0, 1.5 * cross),
                                       Bgr(kInfeasibleRgb));
                       }});
  }
  if (any_above) {
    entries.push_back({"above the plot (see the note)", [&](cv::Point2d c) {
                         draw_wedge(c - cv::Point2d(0, 1.1 * cross));
                       }});
  }
  if (!o.vertical_lines.empty() || !o.horizontal_lines.empty()) {
    entries.push_back({"constraint bound", [&](cv::Point2d c) {
                         DrawDashed(&img, c - cv::Point2d(s.Px(12), 0),
                                    c + cv::Point2d(s.Px(12), 0),
                                    Bgr(kConstraintRgb), s.Px(2), s.Px(5));
                       }});
  }
  int legend_text_w = 0;
  for (const auto& e : entries) {
    legend_text_w =
        std::max(legend_text_w, TextSize(Ascii(e.name), s, &baseline).width);
  }
  const int row = line_px;
  const int legend_w = s.Px(40) + legend_text_w + s.Px(10);
  const int legend_h = row * static_cast<int>(entries.size()) + s.Px(6);
  // The corner covering the fewest markers; top right first, where a
  // min-min plot's dominated designs are rarest.
  cv::Rect legend_box;
  size_t least_covered = std::numeric_limits<size_t>::max();
  const int inset = s.Px(10);
  for (const cv::Point& corner :
       {cv::Point(right - inset - legend_w, area.y + inset),
        cv::Point(area.x + inset, bottom - inset - legend_h),
        cv::Point(area.x + inset, area.y + inset),
        cv::Point(right - inset - legend_w, bottom - inset - legend_h)}) {
    const cv::Rect box(corner.x, corner.y, legend_w, legend_h);
    const cv::Rect grown(box.x - radius, box.y - radius, box.width + 2 * radius,
                         box.height + 2 * radius);
    size_t covered = 0;
    for (const auto* p : shown) {
      const cv::Point2d c = px(p->cost, clipped(p) ? ay.max : p->nav_time_s);
      covered += grown.contains(
          cv::Point(static_cast<int>(c.x), static_cast<int>(c.y)));
    }
    // A bound hidden under the legend weighs as much as a few designs.
    constexpr size_t kBoundWeight = 3;
    for (double v : o.vertical_lines) {
      const double x = px(v, ay.min).x;
      if (std::isfinite(v) && x >= grown.x && x <= grown.x + grown.width) {
        covered += kBoundWeight;
      }
    }
    for (double v : o.horizontal_lines) {
      const double y = px(ax.min, v).y;
      if (std::isfinite(v) && y >= grown.y && y <= grown.y + grown.height) {
        covered += kBoundWeight;
      }
    }
    if (covered < least_covered) {
      least_covered = covered;
      legend_box = box;
    }
  }

  // Front labels: each tries the places around its point in turn and takes
  // the first that stays inside the plot and clear of the legend, the other
  // front markers and the labels already placed; a label with no free
  // place is left out and counted, never drawn over another.
  std::vector<cv::Rect> taken = {legend_box};
  const int marker = radius + s.Px(6);
  for (const auto* p : front) {
    const cv::Point2d c = px(p->cost, p->nav_time_s);
    taken.emplace_back(static_cast<int>(c.x) - marker,
                       static_cast<int>(c.y) - marker, 2 * marker, 2 * marker);
  }
  // The staircase's segments, short of the markers at their ends.
  for (size_t i = 1; i < front_line.size(); ++i) {
    const cv::Point2d a = front_line[i - 1], b = front_line[i];
    const int x0 = static_cast<int>(std::min(a.x, b.x));
    const int x1 = static_cast<int>(std::max(a.x, b.x));
    const int y0 = static_cast<int>(std::min(a.y, b.y));
    const int y1 = static_cast<int>(std::max(a.y, b.y));
    const int w = s.Px(2);
    if (x1 - x0 > 2 * marker) {
      taken.emplace_back(x0 + marker, y0 - w, x1 - x0 - 2 * marker, 2 * w);
    } else if (y1 - y0 > 2 * marker) {
      taken.emplace_back(x0 - w, y0 + marker, 2 * w, y1 - y0 - 2 * marker);
    }
  }
  // The other designs' markers: a label goes over one (on white, hiding
  // it) only when no place around its point is clear of them.
  std::vector<cv::Rect> others;
  for (const auto* p : shown) {
    if (p->on_front) continue;
    const cv::Point2d c = px(p->cost, clipped(p) ? ay.max : p->nav_time_s);
    const int half = p->feasible && p->unstable ? unstable_radius + s.Px(1)
                                                : radius + s.Px(2);
    others.emplace_back(static_cast<int>(c.x) - half,
                        static_cast<int>(c.y) - half, 2 * half, 2 * half);
  }
  auto clear_of = [](const cv::Rect& box, const std::vector<cv::Rect>& rects,
                     const cv::Rect& own_point) {
    for (const cv::Rect& r : rects) {
      // A point's own marker box is not in the way of its own label.
      if ((r & own_point).area() > 0) continue;
      if ((box & r).area() > 0) return false;
    }
    return true;
  };
  // Labels already placed: never overlapped, whatever point they cover.
  std::vector<cv::Rect> labels;
  auto clear_of_labels = [&](const cv::Rect& box) {
    for (const cv::Rect& r : labels) {
      if ((box & r).area() > 0) return false;
    }
    return true;
  };
  // Front designs drawn on one marker (equal cost and time, e.g. 4 cores
  // at 3 GHz and 6 at 2 GHz) share one label, so that no design on the
  // front hides under another's: the first two named, the rest counted.
  struct MarkerLabel {
    cv::Point centre;
    std::string text;
    int designs = 1;
    bool ringed = false;  // its label keeps clear of the ring
  };
  std::vector<MarkerLabel> marker_labels;
  for (const auto* p : front) {
    if (p->label.empty()) continue;
    const cv::Point2d c = px(p->cost, p->nav_time_s);
    const cv::Point centre(static_cast<int>(std::lround(c.x)),
                           static_cast<int>(std::lround(c.y)));
    auto same =
        std::find_if(marker_labels.begin(), marker_labels.end(),
                     [&](const MarkerLabel& m) { return m.centre == centre; });
    if (same == marker_labels.end()) {
      marker_labels.push_back({centre, Ascii(p->label), 1, p->highlight});
    } else {
      same->ringed = same->ringed || p->highlight;
      if (++same->designs == 2) same->text += ", " + Ascii(p->label);
    }
  }
  for (MarkerLabel& m : marker_labels) {
    if (m.designs > 2) m.text += fmt::format(" +{} more", m.designs - 2);
  }
  size_t omitted = 0;
  for (const MarkerLabel& m : marker_labels) {
    const cv::Point2d c(m.centre.x, m.centre.y);
    const std::string& label = m.text;
    const cv::Size size = TextSize(label, s, &baseline);
    const int h = size.height + baseline;
    // Past the ring (radius + 5 px, 1.5 px wide) of a ringed design.
    const int gap = m.ringed ? radius + s.Px(9) : s.Px(8);
    // Top-left corners of the candidate boxes: right, upper right, lower
    // right, left, upper left, lower left, above, below.
    const int cx = static_cast<int>(c.x), cy = static_cast<int>(c.y);
    const cv::Point candidates[] = {{cx + gap, cy - h / 2},
                                    {cx + gap, cy - gap - h},
                                    {cx + gap, cy + gap},
                                    {cx - gap - size.width, cy - h / 2},
                                    {cx - gap - size.width, cy - gap - h},
                                    {cx - gap - size.width, cy + gap},
                                    {cx - size.width / 2, cy - gap - h},
                                    {cx - size.width / 2, cy + gap}};
    const cv::Rect own_point(cx, cy, 1, 1);
    bool placed = false;
    for (int pass = 0; pass < 2 && !placed; ++pass) {
      for (const cv::Point& corner : candidates) {
        const cv::Rect box(corner.x - s.Px(2), corner.y - s.Px(1),
                           size.width + s.Px(4), h + s.Px(2));
        if ((box & area) != box) continue;
        if (!clear_of(box, taken, own_point) || !clear_of_labels(box)) {
          continue;
        }
        if (pass == 0 && !clear_of(box, others, own_point)) continue;
        // On white, so the dots of other designs under it do not garble it.
        cv::rectangle(img, box, kWhite, cv::FILLED);
        DrawText(&img, label, corner.x, corner.y + size.height, Align::kLeft, s,
                 kDarkGrey, false);
        labels.push_back(box);
        placed = true;
        break;
      }
    }
    if (!placed) ++omitted;
  }

  cv::rectangle(img, legend_box, kWhite, cv::FILLED);
  cv::rectangle(img, legend_box, kDarkGrey, 1);
  for (size_t i = 0; i < entries.size(); ++i) {
    const int y = legend_box.y + s.Px(3) + row * static_cast<int>(i) + row / 2;
    entries[i].sample(cv::Point2d(legend_box.x + s.Px(20), y));
    DrawText(&img, entries[i].name, legend_box.x + s.Px(40), y + text_h / 2,
             Align::kLeft, s, kBlack, false);
  }

  // Title, note and axis labels.
  DrawText(&img, o.title, o.width_px / 2, line_px - baseline, Align::kCentre, s,
           kBlack, false);
  std::string note;
  if (hidden > 0) {
    note = fmt::format("{} point(s) with a non-finite cost or time not shown",
                       hidden);
  }
  if (above > 0) {
    note += fmt::format("{}{} infeasible point(s) above the plot (up to {:g})",
                        note.empty() ? "" : "; ", above, y_all);
  }
  if (omitted > 0) {
    note += fmt::format("{}{} front label(s) left out for lack of room",
                        note.empty() ? "" : "; ", omitted);
  }
  if (!note.empty()) {
    DrawText(&img, note, o.width_px / 2, 2 * line_px - baseline, Align::kCentre,
             s, kDarkGrey, false);
  }
  DrawText(&img, o.x_label, area.x + area.width / 2,
           o.height_px - s.Px(8) - baseline, Align::kCentre, s, kBlack, false);
  if (!o.y_label.empty()) DrawTurnedLabel(&img, o.y_label, area, s);

  std::string png;
  ADSE_RETURN_IF_ERROR(EncodeOk(img, &png));
  return png;
}

}  // namespace adse::analysis::internal

namespace adse::analysis {

Result<std::string> ParetoPlotPng(const std::vector<ParetoPlotPoint>& points,
                                  const ParetoPlotOptions& o) {
  return internal::Guarded("Pareto plot",
                           [&] { return internal::ParetoPngImpl(points, o); });
}

Status RenderParetoPlot(const std::vector<ParetoPlotPoint>& points,
                        const std::string& png_path,
                        const ParetoPlotOptions& o) {
  if (png_path.empty()) return Status::InvalidArgument("empty PNG path");
  return internal::WritePng(ParetoPlotPng(points, o), png_path);
}

}  // namespace adse::analysis
