#include "analysis/pictures/internal/parking_layer_impl.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace adse::analysis::internal {
namespace {

void Fill(cv::Mat* img, const std::vector<cv::Point2d>& corners,
          const cv::Scalar& colour) {
  std::vector<cv::Point> pts;
  for (const cv::Point2d& p : corners) {
    if (!Finite(p) || std::abs(p.x) > 1e6 || std::abs(p.y) > 1e6) return;
    pts.push_back(Fixed(p));
  }
  cv::fillPoly(*img, std::vector<std::vector<cv::Point>>{pts}, colour,
               cv::LINE_AA, kShift);
}

}  // namespace

std::vector<cv::Point2d> BoxPx(double cx, double cy, double yaw, double length,
                               double width, const ToPixel& px) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  std::vector<cv::Point2d> out;
  for (const auto& [u, v] : {std::pair{0.5, 0.5}, std::pair{-0.5, 0.5},
                             std::pair{-0.5, -0.5}, std::pair{0.5, -0.5}}) {
    const double lx = u * length, ly = v * width;
    out.push_back(px(cx + c * lx - s * ly, cy + s * lx + c * ly));
  }
  return out;
}

void Outline(cv::Mat* img, std::vector<cv::Point2d> corners,
             const cv::Scalar& colour, int thickness, cv::LineTypes type) {
  corners.push_back(corners.front());
  DrawPolyline(img, corners, colour, thickness, type);
}

void DrawParkingLot(cv::Mat* img, const runfile::ParkingRecord& parking,
                    const ToPixel& px, const Style& s) {
  if (!parking.present) return;
  for (const runfile::ParkingSlotRow& slot : parking.slots) {
    Outline(img,
            BoxPx(slot.x_m, slot.y_m, slot.yaw_rad, slot.length_m, slot.width_m,
                  px),
            Bgr(kSlotRgb), s.Px(1), cv::LINE_8);  // crisp, as lane centres
  }
  // Obstacles: consecutive rows of one number are one outline.
  std::vector<cv::Point2d> outline;
  auto flush = [&] {
    if (outline.size() >= 3) {
      Fill(img, outline, Bgr(kObstacleRgb));
    } else if (outline.size() == 2) {
      DrawSegment(img, outline[0], outline[1], Bgr(kObstacleRgb), s.Px(3));
    }
    outline.clear();
  };
  for (size_t i = 0; i < parking.obstacles.size(); ++i) {
    if (i > 0 &&
        parking.obstacles[i].obstacle != parking.obstacles[i - 1].obstacle) {
      flush();
    }
    outline.push_back(px(parking.obstacles[i].x_m, parking.obstacles[i].y_m));
  }
  flush();
  for (const runfile::ParkingSlotRow& slot : parking.slots) {
    if (!slot.target) continue;
    Outline(img,
            BoxPx(slot.x_m, slot.y_m, slot.yaw_rad, slot.length_m, slot.width_m,
                  px),
            Bgr(kTargetSlotRgb), s.Px(3));
  }
}

void DrawParkingManoeuvre(cv::Mat* img, const runfile::RunData& run,
                          const std::vector<ParkingContact>& contacts,
                          const ToPixel& px, const Style& s) {
  const runfile::ParkingRecord& parking = run.parking;
  if (!parking.present) return;
  // Plans a later one replaced, pale, under the last.
  const std::vector<runfile::EarlierPlanRow>& earlier = parking.earlier_plans;
  for (size_t i = 1; i < earlier.size(); ++i) {
    if (earlier[i].plan != earlier[i - 1].plan) continue;
    DrawSegment(img, px(earlier[i - 1].x_m, earlier[i - 1].y_m),
                px(earlier[i].x_m, earlier[i].y_m), Bgr(kEarlierPlanRgb),
                s.Px(2));
  }
  // Each leg of the plan in its gear's colour (a pose's gear is the gear
  // driving to it).
  for (size_t i = 1; i < parking.planned_path.size(); ++i) {
    const runfile::ParkingPathRow& a = parking.planned_path[i - 1];
    const runfile::ParkingPathRow& b = parking.planned_path[i];
    DrawSegment(img, px(a.x_m, a.y_m), px(b.x_m, b.y_m),
                Bgr(b.reverse ? kPlannedReverseRgb : kPlannedForwardRgb),
                s.Px(2));
  }
  // The car's body, centre half a wheelbase ahead of the rear axle, with a
  // tick on its nose.
  auto body = [&](const runfile::EgoSample& e, Rgb colour) {
    const double ahead = 0.5 * parking.wheelbase_m;
    const double cx = e.x_m + ahead * std::cos(e.yaw_rad);
    const double cy = e.y_m + ahead * std::sin(e.yaw_rad);
    Outline(img,
            BoxPx(cx, cy, e.yaw_rad, parking.length_m, parking.width_m, px),
            Bgr(colour), s.Px(2));
    const double nose = 0.5 * parking.length_m;
    DrawSegment(
        img, px(cx, cy),
        px(cx + nose * std::cos(e.yaw_rad), cy + nose * std::sin(e.yaw_rad)),
        Bgr(colour), s.Px(2));
  };
  for (const ParkingContact& c : contacts) body(c.ego, kContactRgb);
  if (!run.ego.empty()) body(run.ego.back(), kEgoBodyRgb);
  // The meeting points last, on top of everything.
  for (const ParkingContact& c : contacts)
    DrawContactMarker(img, px(c.x_m, c.y_m), s);
}

void DrawContactMarker(cv::Mat* img, cv::Point2d at, const Style& s) {
  DrawRingedDot(img, at, s.Px(5), Bgr(kContactRgb), kBlack);
}

void DrawParkingDetail(cv::Mat* panel, const runfile::RunData& run,
                       const std::vector<ParkingContact>& contacts,
                       const std::vector<std::vector<cv::Point2d>>& lanes,
                       const Style& s) {
  const runfile::ParkingRecord& parking = run.parking;
  // What to show: the target slot and the plan (or, without one, the
  // slot's surroundings), with a margin.
  std::vector<cv::Point2d> focus;
  for (const runfile::ParkingSlotRow& slot : parking.slots) {
    if (slot.target) focus.emplace_back(slot.x_m, slot.y_m);
  }
  for (const runfile::ParkingPathRow& p : parking.planned_path) {
    focus.emplace_back(p.x_m, p.y_m);
  }
  if (focus.empty()) focus.emplace_back(parking.goal_x_m, parking.goal_y_m);
  cv::Point2d lo = focus[0], hi = focus[0];
  for (const cv::Point2d& p : focus) {
    lo.x = std::min(lo.x, p.x);
    lo.y = std::min(lo.y, p.y);
    hi.x = std::max(hi.x, p.x);
    hi.y = std::max(hi.y, p.y);
  }
  constexpr double kMarginM = 5.0;
  const double width_m = hi.x - lo.x + 2 * kMarginM;
  const double height_m = hi.y - lo.y + 2 * kMarginM;
  const double px_per_m =
      std::min(panel->cols / width_m, panel->rows / height_m);
  const cv::Point2d centre = 0.5 * (lo + hi);
  const ToPixel px = [&](double x, double y) {
    return cv::Point2d(0.5 * panel->cols + (x - centre.x) * px_per_m,
                       0.5 * panel->rows - (y - centre.y) * px_per_m);
  };

  const double lane_px = run.lane_width_m * px_per_m;
  for (const auto& lane : lanes) {
    std::vector<cv::Point2d> line;
    for (const cv::Point2d& p : lane) line.push_back(px(p.x, p.y));
    if (std::isfinite(lane_px) && lane_px >= 2.0) {
      DrawPolyline(panel, line, Bgr(kLaneRgb),
                   static_cast<int>(std::min(lane_px, 500.0)));
    }
  }
  DrawParkingLot(panel, parking, px, s);
  std::vector<cv::Point2d> ego, ideal;
  for (const auto& e : run.ego) ego.push_back(px(e.x_m, e.y_m));
  for (const auto& p : run.ideal_path) ideal.push_back(px(p.x_m, p.y_m));
  DrawPolyline(panel, ego, Bgr(kTrajectoryRgb), s.Px(5));
  DrawPolyline(panel, ideal, Bgr(kIdealPathRgb), s.Px(2));
  DrawParkingManoeuvre(panel, run, contacts, px, s);

  // Scale bar and caption, bottom left.
  const double bar_m = NiceBelow(0.2 * panel->cols / px_per_m);
  const int y = panel->rows - s.Px(12);
  const cv::Point2d a(s.Px(10), y), b(s.Px(10) + bar_m * px_per_m, y);
  DrawSegment(panel, a, b, kBlack, s.Px(2));
  int baseline = 0;
  const int text_h = TextSize("Ag", s, &baseline).height;
  DrawText(panel, FormatNumber(bar_m) + " m", s.Px(10), y - s.Px(6),
           Align::kLeft, s, kBlack, true);
  DrawText(panel,
           "detail: slot " + (parking.slot.empty() ? "?" : parking.slot) +
               " and the manoeuvre",
           s.Px(10), s.Px(6) + text_h, Align::kLeft, s, kDarkGrey, true);
}

}  // namespace adse::analysis::internal
