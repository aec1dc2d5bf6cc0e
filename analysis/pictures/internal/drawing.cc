#include "analysis/pictures/internal/drawing_impl.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "stack/base/files.h"
#include "stack/geometry/geometry.h"

namespace adse::analysis::internal {

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
  Eigen::Vector2d from(a->x, a->y), to(b->x, b->y);
  if (!geometry::ClipSegmentToRect({box.x, box.y},
                                   {box.x + box.width, box.y + box.height},
                                   &from, &to)) {
    return false;
  }
  *a = {from.x(), from.y()};
  *b = {to.x(), to.y()};
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
                 const cv::Scalar& colour, int thickness, cv::LineTypes type) {
  if (!Finite(a) || !Finite(b)) return;
  const double pad = thickness + 2.0;
  const cv::Rect2d box(-pad, -pad, img->cols + 2 * pad, img->rows + 2 * pad);
  if (!ClipSegment(box, &a, &b)) return;
  cv::line(*img, Fixed(a), Fixed(b), colour, thickness, type, kShift);
}

// A polyline in pixel coordinates; non-finite points break it.
void DrawPolyline(cv::Mat* img, const std::vector<cv::Point2d>& points,
                  const cv::Scalar& colour, int thickness, cv::LineTypes type) {
  if (points.size() == 1) {
    DrawSegment(img, points[0], points[0], colour, thickness, type);
  }
  for (size_t i = 1; i < points.size(); ++i) {
    DrawSegment(img, points[i - 1], points[i], colour, thickness, type);
  }
}

void DrawRingedDot(cv::Mat* img, cv::Point2d at, int radius_px,
                   const cv::Scalar& fill, const cv::Scalar& ring) {
  if (!Finite(at)) return;
  const int radius = radius_px * static_cast<int>(kShiftScale);
  cv::circle(*img, Fixed(at), radius, fill, cv::FILLED, cv::LINE_AA, kShift);
  cv::circle(*img, Fixed(at), radius, ring, 1, cv::LINE_AA, kShift);
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

Style PlotStyle(int width_px, int height_px) {
  return Style{std::clamp(std::min(width_px / 1000.0, height_px / 700.0),
                          kMinUi, kMaxUi)};
}

PlotFrame MakePlotFrame(int width_px, int height_px, const Axis& ax,
                        const Axis& ay, int top_lines, double top_pad) {
  PlotFrame f;
  f.style = PlotStyle(width_px, height_px);
  const Style& s = f.style;
  f.text_h = TextSize("Ag", s, &f.baseline).height;
  f.line_px = f.text_h + f.baseline + s.Px(8);
  const int left = s.Px(58) + f.line_px;
  const int top = top_lines * f.line_px + s.Px(top_pad);
  const int right = width_px - s.Px(24);
  const int bottom = height_px - 2 * f.line_px - s.Px(8);
  f.area = cv::Rect(left, top, right - left, bottom - top);
  f.ax = ax;
  f.ay = ay;
  return f;
}

void DrawAxes(cv::Mat* img, const cv::Rect& area, const Axis& ax,
              const Axis& ay, const Style& s) {
  const cv::Scalar grid(235, 235, 235);
  int baseline = 0;
  const int text_h = TextSize("Ag", s, &baseline).height;
  const int tick = s.Px(5);
  const int bottom = area.y + area.height;
  const int right = area.x + area.width;
  auto text = [](double v, const Axis& a) {
    if (std::abs(v) < 1e-9 * a.step) v = 0.0;  // no "-0"
    return fmt::format("{:.{}f}", v, a.decimals);
  };
  for (double k = std::ceil(ax.min / ax.step); k * ax.step <= ax.max; ++k) {
    const double v = k * ax.step;
    const double x = area.x + (v - ax.min) / (ax.max - ax.min) * area.width;
    DrawSegment(img, {x, double(area.y)}, {x, double(bottom)}, grid, 1);
    DrawSegment(img, {x, double(bottom)}, {x, double(bottom + tick)}, kBlack,
                1);
    DrawText(img, text(v, ax), static_cast<int>(x),
             bottom + tick + text_h + s.Px(4), Align::kCentre, s, kBlack,
             false);
  }
  for (double k = std::ceil(ay.min / ay.step); k * ay.step <= ay.max; ++k) {
    const double v = k * ay.step;
    const double y = bottom - (v - ay.min) / (ay.max - ay.min) * area.height;
    DrawSegment(img, {double(area.x), y}, {double(right), y}, grid, 1);
    DrawSegment(img, {double(area.x - tick), y}, {double(area.x), y}, kBlack,
                1);
    DrawText(img, text(v, ay), area.x - tick - s.Px(4),
             static_cast<int>(y) + text_h / 2, Align::kRight, s, kBlack, false);
  }
}

void DrawTurnedLabel(cv::Mat* img, const std::string& label,
                     const cv::Rect& area, const Style& s) {
  // OpenCV draws text horizontally only: draw it on its own strip and
  // turn the strip.
  const std::string text = FitText(Ascii(label), s, area.height);
  int baseline = 0;
  const cv::Size size = TextSize(text, s, &baseline);
  cv::Mat strip(size.height + baseline + 2, size.width + 2, CV_8UC3,
                Bgr(kBackgroundRgb));
  cv::putText(strip, text, cv::Point(1, size.height + 1), kFont, s.font_scale(),
              kBlack, s.text_thickness(), cv::LINE_AA);
  cv::Mat turned;
  cv::rotate(strip, turned, cv::ROTATE_90_COUNTERCLOCKWISE);
  const int x = s.Px(6);
  const int y = std::clamp(area.y + area.height / 2 - turned.rows / 2, 0,
                           std::max(0, img->rows - turned.rows));
  if (x + turned.cols <= img->cols && y + turned.rows <= img->rows) {
    turned.copyTo((*img)(cv::Rect(x, y, turned.cols, turned.rows)));
  }
}

}  // namespace adse::analysis::internal
