#include "analysis/pictures/pictures.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <filesystem>
#include <functional>
#include <map>
#include <new>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "stack/base/files.h"

namespace adse::analysis {
namespace {

constexpr int kMinTrajectoryWidthPx = 200;
constexpr int kMinPlotSidePx = 300;
constexpr int kMaxSidePx = 4000;       // 4000 x 8000 x 3 bytes is the largest
constexpr double kMaxMapAspect = 2.0;  // height / width
constexpr double kMinMapAspect = 0.25;
constexpr double kMinExtentM = 1.0;
// A vehicle that moves further than this between two samples was removed
// and re-inserted (or teleported): its path is not drawn across the gap.
constexpr double kVehicleJumpM = 50.0;
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
// Text, lines and markers scale with the picture, but text stays legible
// on small ones.
constexpr double kMinUi = 0.6;
constexpr double kMaxUi = 3.5;
// Sub-pixel drawing: coordinates are passed to OpenCV times 2^kShift.
constexpr int kShift = 4;
constexpr double kShiftScale = 1 << kShift;

cv::Scalar Bgr(Rgb c) { return cv::Scalar(c.b, c.g, c.r); }
const cv::Scalar kBlack(0, 0, 0);
const cv::Scalar kWhite(255, 255, 255);
const cv::Scalar kDarkGrey(90, 90, 90);

// Hershey fonts only have ASCII: one '?' per non-ASCII character, spaces
// for control characters.
std::string Ascii(const std::string& text) {
  std::string out;
  for (unsigned char c : text) {
    if (c >= 0x80) {
      if (c >= 0xC0) out += '?';  // lead byte; continuation bytes dropped
    } else if (c < 0x20 || c == 0x7F) {
      out += ' ';
    } else {
      out += static_cast<char>(c);
    }
  }
  return out;
}

// Scale of text, line widths and markers relative to the default size.
struct Style {
  double ui = 1.0;
  double font_scale() const { return 0.5 * ui; }
  int text_thickness() const { return std::max(1, static_cast<int>(ui + 0.5)); }
  int Px(double px) const {
    return std::max(1, static_cast<int>(std::lround(px * ui)));
  }
};

cv::Size TextSize(const std::string& text, const Style& s, int* baseline) {
  return cv::getTextSize(text, kFont, s.font_scale(), s.text_thickness(),
                         baseline);
}

// Cuts `text` (ASCII) until it fits in `max_width_px`, marking the cut.
std::string FitText(std::string text, const Style& s, int max_width_px) {
  int baseline = 0;
  if (TextSize(text, s, &baseline).width <= max_width_px) return text;
  while (!text.empty() &&
         TextSize(text + "...", s, &baseline).width > max_width_px) {
    text.pop_back();
  }
  return text + "...";
}

enum class Align { kLeft, kRight, kCentre };

// Draws one line of text with its baseline at `y`, optionally on a white
// box so it stays legible over drawing; returns its width.
int DrawText(cv::Mat* img, const std::string& raw, int x, int y, Align align,
             const Style& s, const cv::Scalar& colour, bool boxed) {
  const std::string text = FitText(Ascii(raw), s, img->cols - s.Px(16));
  int baseline = 0;
  const cv::Size size = TextSize(text, s, &baseline);
  if (align == Align::kRight) x -= size.width;
  if (align == Align::kCentre) x -= size.width / 2;
  x = std::clamp(x, 0, std::max(0, img->cols - size.width));
  if (boxed) {
    const int pad = s.Px(2);
    cv::rectangle(*img,
                  cv::Rect(x - pad, y - size.height - pad, size.width + 2 * pad,
                           size.height + baseline + pad),
                  kWhite, cv::FILLED);
  }
  cv::putText(*img, text, cv::Point(x, y), kFont, s.font_scale(), colour,
              s.text_thickness(), cv::LINE_AA);
  return size.width;
}

// Liang-Barsky: clips segment a-b to `box`; false if nothing is inside.
bool ClipSegment(const cv::Rect2d& box, cv::Point2d* a, cv::Point2d* b) {
  const double dx = b->x - a->x, dy = b->y - a->y;
  double t0 = 0.0, t1 = 1.0;
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {a->x - box.x, box.x + box.width - a->x, a->y - box.y,
                       box.y + box.height - a->y};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0.0) {
      if (q[i] < 0.0) return false;
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
  const cv::Point2d start = *a;
  *a = start + t0 * cv::Point2d(dx, dy);
  *b = start + t1 * cv::Point2d(dx, dy);
  return true;
}

cv::Point Fixed(const cv::Point2d& p) {
  return cv::Point(static_cast<int>(std::lround(p.x * kShiftScale)),
                   static_cast<int>(std::lround(p.y * kShiftScale)));
}

bool Finite(const cv::Point2d& p) {
  return std::isfinite(p.x) && std::isfinite(p.y);
}

// A line in pixel coordinates of any size (far off-image ends, non-finite
// ends are skipped) with sub-pixel precision.
void DrawSegment(cv::Mat* img, cv::Point2d a, cv::Point2d b,
                 const cv::Scalar& colour, int thickness,
                 cv::LineTypes type = cv::LINE_AA) {
  if (!Finite(a) || !Finite(b)) return;
  const double pad = thickness + 2.0;
  const cv::Rect2d box(-pad, -pad, img->cols + 2 * pad, img->rows + 2 * pad);
  if (!ClipSegment(box, &a, &b)) return;
  cv::line(*img, Fixed(a), Fixed(b), colour, thickness, type, kShift);
}

// A polyline in pixel coordinates; non-finite points break it.
void DrawPolyline(cv::Mat* img, const std::vector<cv::Point2d>& points,
                  const cv::Scalar& colour, int thickness,
                  cv::LineTypes type = cv::LINE_AA) {
  if (points.size() == 1) {
    DrawSegment(img, points[0], points[0], colour, thickness, type);
  }
  for (size_t i = 1; i < points.size(); ++i) {
    DrawSegment(img, points[i - 1], points[i], colour, thickness, type);
  }
}

void DrawDashed(cv::Mat* img, cv::Point2d a, cv::Point2d b,
                const cv::Scalar& colour, int thickness, double dash_px) {
  const double length = cv::norm(b - a);
  if (!(length > 0.0)) return;
  const cv::Point2d step = (b - a) * (1.0 / length);
  for (double t = 0.0; t < length; t += 2.0 * dash_px) {
    DrawSegment(img, a + step * t, a + step * std::min(length, t + dash_px),
                colour, thickness);
  }
}

// 1, 2 or 5 times a power of ten, at most `limit` (> 0).
double NiceBelow(double limit) {
  const double power = std::pow(10.0, std::floor(std::log10(limit)));
  for (double m : {5.0, 2.0, 1.0}) {
    if (m * power <= limit) return m * power;
  }
  return power;
}

// 1, 2 or 5 times a power of ten, nearest above `rough` (> 0).
double NiceAbove(double rough) {
  const double power = std::pow(10.0, std::floor(std::log10(rough)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * power >= rough * (1.0 - 1e-9)) return m * power;
  }
  return 10.0 * power;
}

std::string FormatNumber(double value) { return fmt::format("{:g}", value); }

Status EncodeOk(const cv::Mat& img, std::string* png) {
  std::vector<uchar> bytes;
  if (!cv::imencode(".png", img, bytes) || bytes.empty()) {
    return Status::Internal("PNG encoding failed");
  }
  png->assign(bytes.begin(), bytes.end());
  return Status::Ok();
}

Status WritePng(Result<std::string> png, const std::string& path) {
  if (path.empty()) return Status::InvalidArgument("empty PNG path");
  if (!png.ok()) return png.status().WithContext(path);
  return WriteFileAtomic(path, *png);
}

// ---------------------------------------------------------------------------
// Trajectory image.

void AddFinite(std::vector<cv::Point2d>* out, double x, double y) {
  if (std::isfinite(x) && std::isfinite(y)) out->emplace_back(x, y);
}

Result<WorldToImage> MappingImpl(const runfile::RunData& run,
                                 const TrajectoryImageOptions& o) {
  if (o.width_px < kMinTrajectoryWidthPx || o.width_px > kMaxSidePx) {
    return Status::InvalidArgument(
        fmt::format("trajectory image width {} px is outside {}..{}",
                    o.width_px, kMinTrajectoryWidthPx, kMaxSidePx));
  }
  if (!std::isfinite(o.margin_m) || o.margin_m < 0.0) {
    return Status::InvalidArgument(
        fmt::format("trajectory image margin {} m is not >= 0", o.margin_m));
  }
  std::vector<cv::Point2d> points;
  for (const auto& p : run.ideal_path) AddFinite(&points, p.x_m, p.y_m);
  for (const auto& e : run.ego) AddFinite(&points, e.x_m, e.y_m);
  if (points.empty()) {
    for (const auto& l : run.lanes) AddFinite(&points, l.x_m, l.y_m);
  }
  if (points.empty()) {
    return Status::InvalidArgument(
        "nothing to draw: the run has no finite ideal path, trajectory or "
        "lane points");
  }
  double min_x = points[0].x, max_x = min_x, min_y = points[0].y, max_y = min_y;
  for (const auto& p : points) {
    min_x = std::min(min_x, p.x);
    max_x = std::max(max_x, p.x);
    min_y = std::min(min_y, p.y);
    max_y = std::max(max_y, p.y);
  }
  const double centre_x = 0.5 * (min_x + max_x);
  const double centre_y = 0.5 * (min_y + max_y);
  double extent_x = std::max(kMinExtentM, max_x - min_x + 2.0 * o.margin_m);
  double extent_y = std::max(kMinExtentM, max_y - min_y + 2.0 * o.margin_m);
  if (!std::isfinite(extent_x) || !std::isfinite(extent_y)) {
    return Status::InvalidArgument("coordinates too large to draw");
  }
  extent_x = std::max(extent_x, extent_y / kMaxMapAspect);
  extent_y = std::max(extent_y, extent_x * kMinMapAspect);

  const Style style{std::clamp(o.width_px / 1200.0, kMinUi, kMaxUi)};
  int baseline = 0;
  const cv::Size text = TextSize("Ag", style, &baseline);
  const int line_px = text.height + baseline + style.Px(8);

  WorldToImage map;
  map.width_px = o.width_px;
  map.px_per_m = o.width_px / extent_x;
  map.map_top_px = 2 * line_px + style.Px(8);
  const int map_height_px =
      std::max(1, static_cast<int>(std::lround(extent_y * map.px_per_m)));
  map.height_px = map.map_top_px + map_height_px;
  map.min_x_m = centre_x - 0.5 * extent_x;
  map.max_y_m = centre_y + 0.5 * map_height_px / map.px_per_m;
  return map;
}

std::string Title(const runfile::RunData& run) {
  std::string point;
  for (const auto& [name, value] : run.design_point) {
    point += (point.empty() ? "" : ", ") + name + "=" + FormatNumber(value);
  }
  std::string reason = run.termination_reason;
  reason = reason.substr(0, reason.find('\n'));
  std::string outcome = run.status == "complete" ? reason : "FAILED: " + reason;
  if (auto it = run.metrics.find("nav_time_s"); it != run.metrics.end()) {
    outcome += fmt::format(", nav {:.1f} s", it->second);
  }
  return fmt::format(
      "{} | {} | {}",
      run.scenario_name.empty() ? "(no scenario)" : run.scenario_name,
      point.empty() ? "(no design point)" : point,
      outcome.empty() ? "(no outcome)" : outcome);
}

void DrawStartMarker(cv::Mat* img, cv::Point2d at, const Style& s) {
  if (!Finite(at)) return;
  const int radius = s.Px(8) * static_cast<int>(kShiftScale);
  cv::circle(*img, Fixed(at), radius, Bgr(kStartRgb), cv::FILLED, cv::LINE_AA,
             kShift);
  cv::circle(*img, Fixed(at), radius, kBlack, 1, cv::LINE_AA, kShift);
}

void DrawGoalMarker(cv::Mat* img, cv::Point2d at, const Style& s) {
  if (!Finite(at)) return;
  const double arm = s.Px(9);
  for (const cv::Point2d d : {cv::Point2d(arm, arm), cv::Point2d(arm, -arm)}) {
    DrawSegment(img, at - d, at + d, Bgr(kGoalRgb), s.Px(3));
  }
}

void DrawMarkerLabel(cv::Mat* img, cv::Point2d at, const std::string& text,
                     const Style& s, const cv::Scalar& colour) {
  if (!Finite(at) || at.x < -1e6 || at.x > 1e6 || at.y < -1e6 || at.y > 1e6) {
    return;
  }
  DrawText(img, text, static_cast<int>(at.x) + s.Px(12),
           static_cast<int>(at.y) - s.Px(10), Align::kLeft, s, colour,
           /*boxed=*/true);
}

// One legend entry of the header: a short sample of the drawing, then its
// name. Returns the x after it.
int LegendEntry(cv::Mat* img, int x, int y, const std::string& name,
                const Style& s,
                const std::function<void(cv::Point2d, cv::Point2d)>& draw) {
  int baseline = 0;
  const int mid = y - TextSize("A", s, &baseline).height / 2;
  draw(cv::Point2d(x, mid), cv::Point2d(x + s.Px(26), mid));
  x += s.Px(32);
  x += DrawText(img, name, x, y, Align::kLeft, s, kBlack, false);
  return x + s.Px(18);
}

Result<std::string> TrajectoryPngImpl(const runfile::RunData& run,
                                      const TrajectoryImageOptions& o) {
  Result<WorldToImage> mapping = MappingImpl(run, o);
  if (!mapping.ok()) return mapping.status();
  const WorldToImage& map = *mapping;
  const Style s{std::clamp(o.width_px / 1200.0, kMinUi, kMaxUi)};
  cv::Mat img(map.height_px, map.width_px, CV_8UC3, Bgr(kBackgroundRgb));
  auto px = [&map](double x_m, double y_m) {
    return cv::Point2d(map.Column(x_m), map.Row(y_m));
  };

  // Lanes: surfaces first, so that no band hides another lane's centre.
  std::vector<std::vector<cv::Point2d>> lanes;
  for (size_t i = 0; i < run.lanes.size(); ++i) {
    if (i == 0 || run.lanes[i].lane != run.lanes[i - 1].lane) {
      lanes.emplace_back();
    }
    lanes.back().push_back(px(run.lanes[i].x_m, run.lanes[i].y_m));
  }
  const double lane_px = run.lane_width_m * map.px_per_m;
  if (std::isfinite(lane_px) && lane_px >= 2.0) {
    const int thickness = static_cast<int>(std::min(lane_px, 500.0));
    for (const auto& lane : lanes) {
      DrawPolyline(&img, lane, Bgr(kLaneRgb), thickness);
    }
  }
  for (const auto& lane : lanes) {
    // Crisp: an anti-aliased 1-px line would fade into the band.
    DrawPolyline(&img, lane, Bgr(kLaneCentreRgb), 1, cv::LINE_8);
  }

  // Other vehicles, faintly, one path per id in time order.
  bool any_vehicle = false;
  if (o.draw_vehicles) {
    std::map<std::string, std::vector<std::pair<double, cv::Point2d>>> paths;
    for (const auto& v : run.vehicles) {
      paths[v.id].emplace_back(v.t_s, cv::Point2d(v.x_m, v.y_m));
    }
    for (auto& [id, samples] : paths) {
      std::stable_sort(
          samples.begin(), samples.end(),
          [](const auto& a, const auto& b) { return a.first < b.first; });
      std::vector<cv::Point2d> line;
      for (size_t i = 0; i < samples.size(); ++i) {
        const cv::Point2d& w = samples[i].second;
        if (i > 0 && cv::norm(w - samples[i - 1].second) > kVehicleJumpM) {
          line.emplace_back(NAN, NAN);  // break
        }
        line.push_back(px(w.x, w.y));
      }
      DrawPolyline(&img, line, Bgr(kVehiclePathRgb), s.Px(1.5));
      any_vehicle = any_vehicle || !line.empty();
    }
  }

  // The trajectory thick underneath, the ideal path thin on top: both stay
  // visible where they coincide.
  std::vector<cv::Point2d> ego, ideal;
  for (const auto& e : run.ego) ego.push_back(px(e.x_m, e.y_m));
  for (const auto& p : run.ideal_path) ideal.push_back(px(p.x_m, p.y_m));
  DrawPolyline(&img, ego, Bgr(kTrajectoryRgb), s.Px(5));
  DrawPolyline(&img, ideal, Bgr(kIdealPathRgb), s.Px(2));

  cv::Point2d start(NAN, NAN), goal(NAN, NAN);
  for (const auto& p : ego) {
    if (Finite(p)) {
      start = p;
      break;
    }
  }
  if (!Finite(start)) {
    for (const auto& p : ideal) {
      if (Finite(p)) {
        start = p;
        break;
      }
    }
  }
  for (auto it = ideal.rbegin(); it != ideal.rend(); ++it) {
    if (Finite(*it)) {
      goal = *it;
      break;
    }
  }
  DrawGoalMarker(&img, goal, s);
  DrawStartMarker(&img, start, s);
  DrawMarkerLabel(&img, goal, "goal", s, Bgr(kGoalRgb));
  DrawMarkerLabel(&img, start, "start", s, Bgr(kStartRgb));

  // Scale bar, bottom centre.
  const double map_width_m = map.width_px / map.px_per_m;
  const double bar_m = NiceBelow(map_width_m / 5.0);
  const double bar_px = bar_m * map.px_per_m;
  const int bar_y = map.height_px - s.Px(14);
  const cv::Point2d bar_a(0.5 * (map.width_px - bar_px), bar_y);
  const cv::Point2d bar_b = bar_a + cv::Point2d(bar_px, 0);
  const double tick = s.Px(5);
  DrawSegment(&img, bar_a, bar_b, kBlack, s.Px(2));
  DrawSegment(&img, bar_a - cv::Point2d(0, tick), bar_a + cv::Point2d(0, tick),
              kBlack, s.Px(2));
  DrawSegment(&img, bar_b - cv::Point2d(0, tick), bar_b + cv::Point2d(0, tick),
              kBlack, s.Px(2));
  DrawText(&img, FormatNumber(bar_m) + " m", map.width_px / 2,
           bar_y - static_cast<int>(tick) - s.Px(4), Align::kCentre, s, kBlack,
           /*boxed=*/true);

  // World coordinates of the map's corners, inside them.
  auto corner = [](double x, double y) {
    return fmt::format("({:.1f}, {:.1f}) m", x, y);
  };
  int baseline = 0;
  const int text_h = TextSize("Ag", s, &baseline).height;
  const int inset = s.Px(6);
  const int top_y = map.map_top_px + inset + text_h;
  const int bottom_y = map.height_px - inset - baseline;
  DrawText(&img, corner(map.min_x_m, map.max_y_m), inset, top_y, Align::kLeft,
           s, kDarkGrey, true);
  DrawText(&img, corner(map.MaxXM(), map.max_y_m), map.width_px - inset, top_y,
           Align::kRight, s, kDarkGrey, true);
  DrawText(&img, corner(map.min_x_m, map.MinYM()), inset, bottom_y,
           Align::kLeft, s, kDarkGrey, true);
  DrawText(&img, corner(map.MaxXM(), map.MinYM()), map.width_px - inset,
           bottom_y, Align::kRight, s, kDarkGrey, true);

  // Header: title, then the legend; a rule above the map.
  cv::rectangle(img, cv::Rect(0, 0, map.width_px, map.map_top_px),
                Bgr(kBackgroundRgb), cv::FILLED);
  const int line_px = (map.map_top_px - s.Px(8)) / 2;
  DrawText(&img, Title(run), s.Px(8), line_px - baseline, Align::kLeft, s,
           kBlack, false);
  const int legend_y = 2 * line_px - baseline;
  int x = s.Px(8);
  auto line_sample = [&](Rgb c, int thickness) {
    return [&img, c, thickness](cv::Point2d a, cv::Point2d b) {
      DrawSegment(&img, a, b, Bgr(c), thickness);
    };
  };
  if (!lanes.empty())
    x = LegendEntry(&img, x, legend_y, "lane", s,
                    line_sample(kLaneCentreRgb, s.Px(2)));
  x = LegendEntry(&img, x, legend_y, "ideal path", s,
                  line_sample(kIdealPathRgb, s.Px(2)));
  x = LegendEntry(&img, x, legend_y, "trajectory", s,
                  line_sample(kTrajectoryRgb, s.Px(5)));
  if (any_vehicle) {
    x = LegendEntry(&img, x, legend_y, "other vehicles", s,
                    line_sample(kVehiclePathRgb, s.Px(2)));
  }
  x = LegendEntry(&img, x, legend_y, "start", s,
                  [&](cv::Point2d a, cv::Point2d b) {
                    DrawStartMarker(&img, 0.5 * (a + b), s);
                  });
  LegendEntry(&img, x, legend_y, "goal", s, [&](cv::Point2d a, cv::Point2d b) {
    DrawGoalMarker(&img, 0.5 * (a + b), s);
  });
  cv::line(img, cv::Point(0, map.map_top_px - 1),
           cv::Point(map.width_px - 1, map.map_top_px - 1), Bgr(kLaneCentreRgb),
           1);

  std::string png;
  ADSE_RETURN_IF_ERROR(EncodeOk(img, &png));
  return png;
}

// ---------------------------------------------------------------------------
// Pareto plot.

struct Axis {
  double min = 0.0, max = 1.0, step = 1.0;
  int decimals = 0;
};

// Range of `values` padded by 5 %, with 1-2-5 ticks about every 1/6.
Axis MakeAxis(const std::vector<double>& values) {
  double lo = values[0], hi = values[0];
  for (double v : values) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  if (!(hi > lo)) {
    const double half = std::max(std::abs(lo) * 0.1, 1.0);
    lo -= half;
    hi += half;
  }
  const double pad = 0.05 * (hi - lo);
  Axis axis;
  axis.min = lo - pad;
  axis.max = hi + pad;
  axis.step = NiceAbove((axis.max - axis.min) / 6.0);
  axis.decimals =
      std::max(0, -static_cast<int>(std::floor(std::log10(axis.step) + 1e-9)));
  return axis;
}

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

  std::vector<double> xs, ys;
  for (const auto* p : shown) {
    xs.push_back(p->cost);
    ys.push_back(p->nav_time_s);
  }
  for (double v : o.vertical_lines) {
    if (std::isfinite(v)) xs.push_back(v);
  }
  for (double v : o.horizontal_lines) {
    if (std::isfinite(v)) ys.push_back(v);
  }
  const Axis ax = MakeAxis(xs), ay = MakeAxis(ys);

  const Style s{std::clamp(std::min(o.width_px / 1000.0, o.height_px / 700.0),
                           kMinUi, kMaxUi)};
  int baseline = 0;
  const int text_h = TextSize("Ag", s, &baseline).height;
  const int line_px = text_h + baseline + s.Px(8);
  // Room on the left for the turned y label and tick labels, on top for
  // the title and a note, below for tick labels and the x label.
  const int left = s.Px(58) + line_px;
  const int top = 2 * line_px + s.Px(6);
  const int right = o.width_px - s.Px(24);
  const int bottom = o.height_px - 2 * line_px - s.Px(8);
  const cv::Rect area(left, top, right - left, bottom - top);
  auto px = [&](double x, double y) {
    return cv::Point2d(
        area.x + (x - ax.min) / (ax.max - ax.min) * area.width,
        area.y + area.height - (y - ay.min) / (ay.max - ay.min) * area.height);
  };

  cv::Mat img(o.height_px, o.width_px, CV_8UC3, Bgr(kBackgroundRgb));
  const cv::Scalar grid(235, 235, 235);

  // Grid, ticks and tick labels.
  const int tick = s.Px(5);
  auto tick_text = [](double v, const Axis& a) {
    if (std::abs(v) < 1e-9 * a.step) v = 0.0;  // no "-0"
    return fmt::format("{:.{}f}", v, a.decimals);
  };
  for (double k = std::ceil(ax.min / ax.step); k * ax.step <= ax.max; ++k) {
    const double v = k * ax.step;
    const double x = px(v, ay.min).x;
    DrawSegment(&img, {x, double(area.y)}, {x, double(bottom)}, grid, 1);
    DrawSegment(&img, {x, double(bottom)}, {x, double(bottom + tick)}, kBlack,
                1);
    DrawText(&img, tick_text(v, ax), static_cast<int>(x),
             bottom + tick + text_h + s.Px(4), Align::kCentre, s, kBlack,
             false);
  }
  for (double k = std::ceil(ay.min / ay.step); k * ay.step <= ay.max; ++k) {
    const double v = k * ay.step;
    const double y = px(ax.min, v).y;
    DrawSegment(&img, {double(area.x), y}, {double(right), y}, grid, 1);
    DrawSegment(&img, {double(area.x - tick), y}, {double(area.x), y}, kBlack,
                1);
    DrawText(&img, tick_text(v, ay), area.x - tick - s.Px(4),
             static_cast<int>(y) + text_h / 2, Align::kRight, s, kBlack, false);
  }

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
  for (const auto* p : shown) {
    if (!p->feasible && !p->on_front) {
      draw_cross(px(p->cost, p->nav_time_s), Bgr(kInfeasibleRgb));
    }
  }
  for (const auto* p : shown) {
    if (p->feasible && !p->on_front) {
      draw_dot(px(p->cost, p->nav_time_s), Bgr(kFeasibleRgb), radius);
    }
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
  std::vector<cv::Point2d> front_line;
  for (const auto* p : front) front_line.push_back(px(p->cost, p->nav_time_s));
  DrawPolyline(&img, front_line, Bgr(kFrontRgb), s.Px(2));
  for (const auto* p : front) {
    const cv::Point2d c = px(p->cost, p->nav_time_s);
    if (p->feasible) {
      draw_dot(c, Bgr(kFrontRgb), radius + s.Px(1));
    } else {
      draw_cross(c, Bgr(kFrontRgb));
    }
  }
  for (const auto* p : front) {
    if (p->label.empty()) continue;
    const cv::Point2d c = px(p->cost, p->nav_time_s);
    const std::string label = Ascii(p->label);
    const int w = TextSize(label, s, &baseline).width;
    const bool left = c.x + s.Px(8) + w > right;
    DrawText(&img, label,
             static_cast<int>(left ? c.x - s.Px(8) : c.x + s.Px(8)),
             static_cast<int>(c.y) - s.Px(6),
             left ? Align::kRight : Align::kLeft, s, kDarkGrey, false);
  }
  cv::rectangle(img, area, kBlack, 1);

  // Legend, bottom left: below a min-min front that corner is empty.
  {
    struct Entry {
      std::string name;
      std::function<void(cv::Point2d)> sample;
    };
    std::vector<Entry> entries = {
        {"feasible",
         [&](cv::Point2d c) { draw_dot(c, Bgr(kFeasibleRgb), radius); }},
        {"infeasible",
         [&](cv::Point2d c) { draw_cross(c, Bgr(kInfeasibleRgb)); }},
        {"Pareto front", [&](cv::Point2d c) {
           DrawSegment(&img, c - cv::Point2d(s.Px(12), 0),
                       c + cv::Point2d(s.Px(12), 0), Bgr(kFrontRgb), s.Px(2));
           draw_dot(c, Bgr(kFrontRgb), radius + s.Px(1));
         }}};
    if (!o.vertical_lines.empty() || !o.horizontal_lines.empty()) {
      entries.push_back({"constraint", [&](cv::Point2d c) {
                           DrawDashed(&img, c - cv::Point2d(s.Px(12), 0),
                                      c + cv::Point2d(s.Px(12), 0),
                                      Bgr(kConstraintRgb), s.Px(2), s.Px(5));
                         }});
    }
    int text_w = 0;
    for (const auto& e : entries) {
      text_w = std::max(text_w, TextSize(e.name, s, &baseline).width);
    }
    const int row = line_px;
    const cv::Rect box(
        area.x + s.Px(10),
        bottom - s.Px(10) - row * static_cast<int>(entries.size()) - s.Px(6),
        s.Px(40) + text_w + s.Px(10),
        row * static_cast<int>(entries.size()) + s.Px(6));
    cv::rectangle(img, box, kWhite, cv::FILLED);
    cv::rectangle(img, box, kDarkGrey, 1);
    for (size_t i = 0; i < entries.size(); ++i) {
      const int y = box.y + s.Px(3) + row * static_cast<int>(i) + row / 2;
      entries[i].sample(cv::Point2d(box.x + s.Px(20), y));
      DrawText(&img, entries[i].name, box.x + s.Px(40), y + text_h / 2,
               Align::kLeft, s, kBlack, false);
    }
  }

  // Title, note and axis labels.
  DrawText(&img, o.title, o.width_px / 2, line_px - baseline, Align::kCentre, s,
           kBlack, false);
  if (hidden > 0) {
    DrawText(&img,
             fmt::format("{} point(s) with a non-finite cost or time not shown",
                         hidden),
             o.width_px / 2, 2 * line_px - baseline, Align::kCentre, s,
             Bgr(kConstraintRgb), false);
  }
  DrawText(&img, o.x_label, area.x + area.width / 2,
           o.height_px - s.Px(8) - baseline, Align::kCentre, s, kBlack, false);
  if (!o.y_label.empty()) {
    // OpenCV draws text horizontally only: draw it on its own strip and
    // turn the strip.
    const std::string label = FitText(Ascii(o.y_label), s, area.height);
    const cv::Size size = TextSize(label, s, &baseline);
    cv::Mat strip(size.height + baseline + 2, size.width + 2, CV_8UC3,
                  Bgr(kBackgroundRgb));
    cv::putText(strip, label, cv::Point(1, size.height + 1), kFont,
                s.font_scale(), kBlack, s.text_thickness(), cv::LINE_AA);
    cv::Mat turned;
    cv::rotate(strip, turned, cv::ROTATE_90_COUNTERCLOCKWISE);
    const int x = s.Px(6);
    const int y = std::clamp(area.y + area.height / 2 - turned.rows / 2, 0,
                             std::max(0, o.height_px - turned.rows));
    if (x + turned.cols <= o.width_px && y + turned.rows <= o.height_px) {
      turned.copyTo(img(cv::Rect(x, y, turned.cols, turned.rows)));
    }
  }

  std::string png;
  ADSE_RETURN_IF_ERROR(EncodeOk(img, &png));
  return png;
}

// OpenCV reports errors (and allocation failures) by throwing.
template <typename F>
auto Guarded(const char* what, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const cv::Exception& e) {
    return Status::Internal(std::string(what) + ": OpenCV: " + e.what());
  } catch (const std::bad_alloc&) {
    return Status::Internal(std::string(what) + ": out of memory");
  } catch (const std::exception& e) {
    return Status::Internal(std::string(what) + ": " + e.what());
  }
}

}  // namespace

Result<RgbImage> ReadImage(const std::string& path) {
  return Guarded("reading an image", [&]() -> Result<RgbImage> {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
      return Status::NotFound(path + ": no such image file");
    }
    const cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
    if (bgr.empty()) return Status::Corruption(path + ": does not decode");
    cv::Mat rgb;
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    RgbImage image;
    image.width_px = rgb.cols;
    image.height_px = rgb.rows;
    image.rgb.resize(static_cast<size_t>(rgb.cols) * rgb.rows * 3);
    for (int r = 0; r < rgb.rows; ++r) {
      std::memcpy(image.rgb.data() + static_cast<size_t>(r) * rgb.cols * 3,
                  rgb.ptr(r), static_cast<size_t>(rgb.cols) * 3);
    }
    return image;
  });
}

Result<WorldToImage> TrajectoryImageMapping(const runfile::RunData& run,
                                            const TrajectoryImageOptions& o) {
  return Guarded("trajectory image mapping",
                 [&] { return MappingImpl(run, o); });
}

Result<std::string> TrajectoryImagePng(const runfile::RunData& run,
                                       const TrajectoryImageOptions& o) {
  return Guarded("trajectory image", [&] { return TrajectoryPngImpl(run, o); });
}

Status RenderTrajectoryImage(const runfile::RunData& run,
                             const std::string& png_path,
                             const TrajectoryImageOptions& o) {
  if (png_path.empty()) return Status::InvalidArgument("empty PNG path");
  return WritePng(TrajectoryImagePng(run, o), png_path);
}

Result<std::string> ParetoPlotPng(const std::vector<ParetoPlotPoint>& points,
                                  const ParetoPlotOptions& o) {
  return Guarded("Pareto plot", [&] { return ParetoPngImpl(points, o); });
}

Status RenderParetoPlot(const std::vector<ParetoPlotPoint>& points,
                        const std::string& png_path,
                        const ParetoPlotOptions& o) {
  if (png_path.empty()) return Status::InvalidArgument("empty PNG path");
  return WritePng(ParetoPlotPng(points, o), png_path);
}

}  // namespace adse::analysis
