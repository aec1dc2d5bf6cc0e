// Drawing primitives shared by the pictures (OpenCV); included only by
// analysis/pictures .cc files, never by users of pictures.h.
#ifndef ADSE_ANALYSIS_PICTURES_INTERNAL_DRAWING_IMPL_H_
#define ADSE_ANALYSIS_PICTURES_INTERNAL_DRAWING_IMPL_H_

#include <exception>
#include <new>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "analysis/pictures/pictures.h"
#include "stack/base/status.h"

namespace adse::analysis::internal {

inline constexpr int kMaxSidePx = 4000;  // 4000 x 8000 x 3 bytes is the largest
inline constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
// Text, lines and markers scale with the picture, but text stays legible
// on small ones.
inline constexpr double kMinUi = 0.6;
inline constexpr double kMaxUi = 3.5;
// Sub-pixel drawing: coordinates are passed to OpenCV times 2^kShift.
inline constexpr int kShift = 4;
inline constexpr double kShiftScale = 1 << kShift;
// Points more than this many times slower than the slowest that matters
// (feasible designs, the front, the bounds) are drawn on the time axis'
// edge instead of stretching it.
inline constexpr double kClipRatio = 2.0;

inline cv::Scalar Bgr(Rgb c) { return cv::Scalar(c.b, c.g, c.r); }
inline const cv::Scalar kBlack(0, 0, 0);
inline const cv::Scalar kWhite(255, 255, 255);
inline const cv::Scalar kDarkGrey(90, 90, 90);

// Scale of text, line widths and markers relative to the default size.
struct Style {
  double ui = 1.0;
  double font_scale() const { return 0.5 * ui; }
  int text_thickness() const { return std::max(1, static_cast<int>(ui + 0.5)); }
  int Px(double px) const {
    return std::max(1, static_cast<int>(std::lround(px * ui)));
  }
};

enum class Align { kLeft, kRight, kCentre };

// Hershey fonts only have ASCII: one '?' per non-ASCII character, spaces
// for control characters.
std::string Ascii(const std::string& text);

cv::Size TextSize(const std::string& text, const Style& s, int* baseline);

// Cuts `text` (ASCII) until it fits in `max_width_px`, marking the cut.
std::string FitText(std::string text, const Style& s, int max_width_px);

// Draws one line of text with its baseline at `y`, optionally on a white
// box so it stays legible over drawing; returns its width.
int DrawText(cv::Mat* img, const std::string& raw, int x, int y, Align align,
             const Style& s, const cv::Scalar& colour, bool boxed);

// Liang-Barsky: clips segment a-b to `box`; false if nothing is inside.
bool ClipSegment(const cv::Rect2d& box, cv::Point2d* a, cv::Point2d* b);

cv::Point Fixed(const cv::Point2d& p);

bool Finite(const cv::Point2d& p);

// A line in pixel coordinates of any size (far off-image ends, non-finite
// ends are skipped) with sub-pixel precision.
void DrawSegment(cv::Mat* img, cv::Point2d a, cv::Point2d b,
                 const cv::Scalar& colour, int thickness,
                 cv::LineTypes type = cv::LINE_AA);

// A polyline in pixel coordinates; non-finite points break it.
void DrawPolyline(cv::Mat* img, const std::vector<cv::Point2d>& points,
                  const cv::Scalar& colour, int thickness,
                  cv::LineTypes type = cv::LINE_AA);

void DrawDashed(cv::Mat* img, cv::Point2d a, cv::Point2d b,
                const cv::Scalar& colour, int thickness, double dash_px);

// A filled dot of `radius_px` with a 1-px ring (a marker); nothing at a
// non-finite point.
void DrawRingedDot(cv::Mat* img, cv::Point2d at, int radius_px,
                   const cv::Scalar& fill, const cv::Scalar& ring);

// 1, 2 or 5 times a power of ten, at most `limit` (> 0).
double NiceBelow(double limit);

// A linear plot axis: its range and tick step, ticks written with
// `decimals` decimals.
struct Axis {
  double min = 0.0, max = 1.0, step = 1.0;
  int decimals = 0;
};
// Range of `values` (not empty) padded by 5 %, with 1-2-5 ticks about
// every 1/6.
Axis MakeAxis(const std::vector<double>& values);
// The style of a plot drawn at width x height px (1000 x 700 is scale 1).
Style PlotStyle(int width_px, int height_px);
// Grid lines, ticks and tick labels of a plot `area` over the axes.
void DrawAxes(cv::Mat* img, const cv::Rect& area, const Axis& ax,
              const Axis& ay, const Style& s);
// A y-axis label, turned upright, left of `area` and centred on it.
void DrawTurnedLabel(cv::Mat* img, const std::string& label,
                     const cv::Rect& area, const Style& s);

// The layout of a plot of width x height px: its style, the height of a
// line of text, and the data area, with room on the left for the turned y
// label and tick labels, `top_lines` lines of text and `top_pad` (unscaled)
// px on top, tick labels and the x label below.
struct PlotFrame {
  Style style;
  int text_h = 0;    // height of a line's letters, px
  int baseline = 0;  // depth below the baseline, px
  int line_px = 0;   // one line of text with its spacing, px
  cv::Rect area;
  Axis ax, ay;
  int right() const { return area.x + area.width; }
  int bottom() const { return area.y + area.height; }
  // Pixel position of data point (x, y).
  cv::Point2d ToPx(double x, double y) const {
    return cv::Point2d(
        area.x + (x - ax.min) / (ax.max - ax.min) * area.width,
        area.y + area.height - (y - ay.min) / (ay.max - ay.min) * area.height);
  }
};
PlotFrame MakePlotFrame(int width_px, int height_px, const Axis& ax,
                        const Axis& ay, int top_lines, double top_pad);

// 1, 2 or 5 times a power of ten, nearest above `rough` (> 0).
double NiceAbove(double rough);

std::string FormatNumber(double value);

Status EncodeOk(const cv::Mat& img, std::string* png);

Status WritePng(Result<std::string> png, const std::string& path);

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

}  // namespace adse::analysis::internal

#endif  // ADSE_ANALYSIS_PICTURES_INTERNAL_DRAWING_IMPL_H_
