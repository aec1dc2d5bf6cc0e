// The side-by-side bar chart of `adse profile check`: adse's latencies
// beside what the real stack measured.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "analysis/pictures/internal/drawing_impl.h"
#include "analysis/pictures/pictures.h"

namespace adse::analysis {
namespace {

using internal::Align;
using internal::Bgr;
using internal::DrawText;
using internal::Style;

Status Check(const std::vector<ComparisonRow>& rows,
             const ComparisonChartOptions& o) {
  if (rows.empty()) return Status::InvalidArgument("comparison chart: no rows");
  if (o.width_px < 400 || o.width_px > internal::kMaxSidePx) {
    return Status::InvalidArgument(
        fmt::format("comparison chart: width_px must be in [400, {}], got {}",
                    internal::kMaxSidePx, o.width_px));
  }
  if (o.row_height_px < 12 || o.row_height_px > 200) {
    return Status::InvalidArgument(fmt::format(
        "comparison chart: row_height_px must be in [12, 200], got {}",
        o.row_height_px));
  }
  if (static_cast<long long>(rows.size()) * o.row_height_px >
      internal::kMaxSidePx) {
    return Status::InvalidArgument(
        fmt::format("comparison chart: {} rows do not fit in {} px",
                    rows.size(), internal::kMaxSidePx));
  }
  for (const ComparisonRow& r : rows) {
    auto bad = [](double v) { return !std::isfinite(v) || v < 0.0; };
    if (bad(r.adse) || (r.reference && bad(*r.reference))) {
      return Status::InvalidArgument("comparison chart: row '" + r.label +
                                     "': values must be finite and >= 0");
    }
  }
  return Status::Ok();
}

Result<std::string> ComparisonChartPng(const std::vector<ComparisonRow>& rows,
                                       const ComparisonChartOptions& o) {
  ADSE_RETURN_IF_ERROR(Check(rows, o));
  return internal::Guarded("comparison chart", [&]() -> Result<std::string> {
    const Style s{
        std::clamp(o.row_height_px / 34.0, internal::kMinUi, internal::kMaxUi)};
    const int header = s.Px(64), footer = s.Px(40), margin = s.Px(12);
    const int height =
        header + static_cast<int>(rows.size()) * o.row_height_px + footer;
    cv::Mat img(height, o.width_px, CV_8UC3, internal::kWhite);

    // Labels take the left third at most; the bars the rest.
    int label_px = 0;
    for (const ComparisonRow& r : rows) {
      int baseline = 0;
      label_px =
          std::max(label_px, internal::TextSize(r.label, s, &baseline).width);
    }
    label_px = std::min(label_px, o.width_px / 3);
    const int x0 = margin + label_px + s.Px(8);
    const int value_px = s.Px(130);  // room for the values after a pair
    const int x1 = o.width_px - margin - value_px;
    double top = 0.0;
    for (const ComparisonRow& r : rows) {
      top = std::max({top, r.adse, r.reference.value_or(0.0)});
    }
    // Four to six ticks of a round step, whichever ends nearest past the
    // longest bar (five alone put a bar of 370 on an axis to 500; a round
    // top alone, 500 for a bar of 217, left half the chart empty).
    const double longest = top > 0 ? top : 1.0;
    int ticks = 5;
    top = 5.0 * internal::NiceAbove(longest / 5.0);
    for (int n : {4, 6}) {
      const double candidate = n * internal::NiceAbove(longest / n);
      if (candidate < top) {
        top = candidate;
        ticks = n;
      }
    }
    auto x_of = [&](double v) {
      return x0 + static_cast<int>(std::lround((x1 - x0) * v / top));
    };

    DrawText(&img, o.title, margin, s.Px(22), Align::kLeft, s, internal::kBlack,
             false);
    // Legend.
    int lx = margin;
    for (const auto& [name, colour] :
         {std::pair{o.adse_name, kAdseBarRgb},
          std::pair{o.reference_name, kReferenceBarRgb}}) {
      cv::rectangle(img, cv::Rect(lx, s.Px(34), s.Px(18), s.Px(10)),
                    Bgr(colour), cv::FILLED);
      lx += s.Px(24) +
            DrawText(&img, name, lx + s.Px(24), s.Px(44), Align::kLeft, s,
                     internal::kBlack, false) +
            s.Px(16);
    }
    // Grid and axis ticks.
    const int y_bottom =
        header + static_cast<int>(rows.size()) * o.row_height_px;
    for (int i = 0; i <= ticks; ++i) {
      const double v = top * i / ticks;
      const int x = x_of(v);
      cv::line(img, {x, header - s.Px(4)}, {x, y_bottom},
               cv::Scalar(225, 225, 225), 1);
      DrawText(&img, internal::FormatNumber(v), x, y_bottom + s.Px(16),
               Align::kCentre, s, internal::kDarkGrey, false);
    }
    DrawText(&img, o.unit, x1, y_bottom + s.Px(32), Align::kRight, s,
             internal::kDarkGrey, false);
    // Rows.
    const int bar = std::max(2, (o.row_height_px - s.Px(8)) / 2);
    for (size_t i = 0; i < rows.size(); ++i) {
      const ComparisonRow& r = rows[i];
      const int y = header + static_cast<int>(i) * o.row_height_px;
      DrawText(&img, internal::FitText(internal::Ascii(r.label), s, label_px),
               x0 - s.Px(8), y + bar + s.Px(4), Align::kRight, s,
               internal::kBlack, false);
      auto draw_bar = [&](double v, int top_y, Rgb colour) {
        cv::rectangle(img, cv::Rect(x0, top_y, std::max(1, x_of(v) - x0), bar),
                      Bgr(colour), cv::FILLED);
      };
      draw_bar(r.adse, y, kAdseBarRgb);
      if (r.reference) draw_bar(*r.reference, y + bar, kReferenceBarRgb);
      // Both values on one line past the longer bar, in the legend's
      // order: two bars are thinner than a line of text each.
      const std::string values =
          r.reference ? fmt::format("{:.1f} / {:.1f}", r.adse, *r.reference)
                      : fmt::format("{:.1f}", r.adse);
      int baseline = 0;
      const int text_h = internal::TextSize(values, s, &baseline).height;
      DrawText(&img, values,
               x_of(std::max(r.adse, r.reference.value_or(0.0))) + s.Px(4),
               y + bar + text_h / 2, Align::kLeft, s, internal::kBlack, false);
    }
    std::string png;
    ADSE_RETURN_IF_ERROR(internal::EncodeOk(img, &png));
    return png;
  });
}

}  // namespace

Status RenderComparisonChart(const std::vector<ComparisonRow>& rows,
                             const ComparisonChartOptions& options,
                             const std::string& path) {
  return internal::WritePng(ComparisonChartPng(rows, options), path);
}

}  // namespace adse::analysis
