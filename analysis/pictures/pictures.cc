#include "analysis/pictures/pictures.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "analysis/metrics/standing.h"
#include "analysis/pictures/internal/drawing_impl.h"
#include "analysis/pictures/internal/parking_layer_impl.h"
#include "analysis/pictures/internal/trajectory_text.h"

namespace adse::analysis::internal {

constexpr int kMinTrajectoryWidthPx = 200;
constexpr double kMaxMapAspect = 2.0;  // height / width
constexpr double kMinMapAspect = 0.25;
constexpr double kMinExtentM = 1.0;
// valet_parking's detail panel: height / width.
constexpr double kDetailAspect = 0.45;
// A vehicle that moves further than this between two samples was removed
// and re-inserted (or teleported): its path is not drawn across the gap.
constexpr double kVehicleJumpM = 50.0;
// A vehicle whose samples all lie this close to its first stood throughout.
constexpr double kStoodM = 0.5;
// Stands shorter than this are not marked (the wait for the first
// trajectory, stop-and-go); only the longest few are labelled.
constexpr double kMarkStandS = 3.0;
constexpr size_t kLabelledStands = 6;

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
  // The title, then the legend: a parking run's has a second line for the
  // lot's entries.
  map.map_top_px = (run.parking.present ? 3 : 2) * line_px + style.Px(8);
  const int map_height_px =
      std::max(1, static_cast<int>(std::lround(extent_y * map.px_per_m)));
  map.height_px = map.map_top_px + map_height_px;
  if (run.parking.present && !run.parking.slots.empty()) {
    map.detail_px = static_cast<int>(std::lround(kDetailAspect * o.width_px));
    map.height_px += map.detail_px;
  }
  map.min_x_m = centre_x - 0.5 * extent_x;
  map.max_y_m = centre_y + 0.5 * map_height_px / map.px_per_m;
  return map;
}

void DrawStartMarker(cv::Mat* img, cv::Point2d at, const Style& s) {
  DrawRingedDot(img, at, s.Px(8), Bgr(kStartRgb), kBlack);
}

void DrawGoalMarker(cv::Mat* img, cv::Point2d at, const Style& s) {
  if (!Finite(at)) return;
  const double arm = s.Px(9);
  for (const cv::Point2d d : {cv::Point2d(arm, arm), cv::Point2d(arm, -arm)}) {
    DrawSegment(img, at - d, at + d, Bgr(kGoalRgb), s.Px(3));
  }
}

Rgb StandRgb(const analysis::Stand& stand) {
  if (!stand.known) return kStandOtherRgb;
  switch (stand.cause.reason) {
    case StopReason::kRedLight:
      return kStandRedLightRgb;
    case StopReason::kObstacle:
    case StopReason::kLaneChange:
      return kStandObstacleRgb;
    case StopReason::kLocalizationLost:
      return kStandLocalizationRgb;
    default:
      return kStandOtherRgb;
  }
}

// Where a collision with traffic happened: between the ego's and the
// other's recorded positions nearest its time (the ego's alone when the
// other was not recorded).
struct CollisionPlace {
  double x_m = 0.0, y_m = 0.0, t_s = 0.0;
  bool ego_caused = false;
};

// The sample of `samples` nearest `t_s` among those `keep` accepts; null
// when there is none.
template <typename Sample, typename Keep>
const Sample* NearestInTime(const std::vector<Sample>& samples, double t_s,
                            Keep keep) {
  const Sample* best = nullptr;
  for (const Sample& s : samples) {
    if (keep(s) && (best == nullptr ||
                    std::abs(s.t_s - t_s) < std::abs(best->t_s - t_s))) {
      best = &s;
    }
  }
  return best;
}

std::vector<CollisionPlace> CollisionPlaces(const runfile::RunData& run) {
  std::vector<CollisionPlace> out;
  for (const runfile::CollisionEvent& c : run.collisions) {
    const runfile::EgoSample* ego =
        NearestInTime(run.ego, c.t_s, [](const auto&) { return true; });
    if (ego == nullptr) return out;
    CollisionPlace place{ego->x_m, ego->y_m, c.t_s, c.ego_caused == 1};
    const runfile::VehicleSample* other = NearestInTime(
        run.vehicles, c.t_s, [&](const auto& v) { return v.id == c.other_id; });
    if (other != nullptr) {
      place.x_m = 0.5 * (place.x_m + other->x_m);
      place.y_m = 0.5 * (place.y_m + other->y_m);
    }
    out.push_back(place);
  }
  return out;
}

void DrawStandMarker(cv::Mat* img, cv::Point2d at, Rgb colour, const Style& s) {
  DrawRingedDot(img, at, s.Px(6), Bgr(colour), Bgr(kBackgroundRgb));
}

// A stand where the car started (waiting for the stack) would hide under
// the start marker: it rings it instead, in the stand's colour.
void DrawStandRing(cv::Mat* img, cv::Point2d at, Rgb colour, const Style& s) {
  if (!Finite(at)) return;
  cv::circle(*img, Fixed(at), s.Px(12) * static_cast<int>(kShiftScale),
             Bgr(colour), s.Px(3), cv::LINE_AA, kShift);
}

// Where a run that did not reach its goal ended: a black square.
void DrawEndMarker(cv::Mat* img, cv::Point2d at, const Style& s) {
  if (!Finite(at)) return;
  const double half = s.Px(6);
  const cv::Point2d d(half, half);
  cv::rectangle(*img, Fixed(at - d - cv::Point2d(s.Px(2), s.Px(2))),
                Fixed(at + d + cv::Point2d(s.Px(2), s.Px(2))), kWhite,
                cv::FILLED, cv::LINE_AA, kShift);
  cv::rectangle(*img, Fixed(at - d), Fixed(at + d), kBlack, cv::FILLED,
                cv::LINE_AA, kShift);
}

// What held the car, in words: the planner's reason, or "plan said go"
// when the plan did not stop (a cause outside the planner held it).
std::string StandText(const analysis::Stand& stand) {
  if (!stand.known) return "stood";
  if (stand.cause.reason == StopReason::kNone) return "plan said go";
  return StopReasonToString(stand.cause.reason);
}

// Labels a marker: above and right of it, else (header above, image edge
// right, another label there) below it or on its left; a label that fits
// nowhere free is left out. `taken` holds the labels placed so far.
void DrawMarkerLabel(cv::Mat* img, cv::Point2d at, const std::string& text,
                     const Style& s, const cv::Scalar& colour, int map_top_px,
                     std::vector<cv::Rect>* taken) {
  if (!Finite(at) || at.x < -1e6 || at.x > 1e6 || at.y < -1e6 || at.y > 1e6) {
    return;
  }
  int baseline = 0;
  const cv::Size size = TextSize(text, s, &baseline);
  const int pad = s.Px(3);
  const int x = static_cast<int>(at.x), y = static_cast<int>(at.y);
  const int right = x + s.Px(12), left = x - s.Px(12) - size.width;
  const int above = y - s.Px(10), below = y + s.Px(12) + size.height;
  for (const auto& [lx, ly] :
       {std::pair{right, above}, std::pair{right, below},
        std::pair{left, above}, std::pair{left, below}}) {
    const cv::Rect box(lx - pad, ly - size.height - pad, size.width + 2 * pad,
                       size.height + baseline + 2 * pad);
    if (box.y < map_top_px || box.x < 0 || box.br().x > img->cols ||
        box.br().y > img->rows) {
      continue;
    }
    bool free = true;
    for (const cv::Rect& other : *taken) free = free && (box & other).empty();
    if (!free) continue;
    DrawText(img, text, lx, ly, Align::kLeft, s, colour, /*boxed=*/true);
    taken->push_back(box);
    return;
  }
}

// The header's legend: entries left to right, each a short sample of the
// drawing and its name, on the next line where one would leave the picture.
class HeaderLegend {
 public:
  HeaderLegend(cv::Mat* img, int y, int line_px, const Style& s)
      : img_(img), x_(s.Px(8)), y_(y), line_px_(line_px), s_(s) {}
  void Add(const std::string& name,
           const std::function<void(cv::Point2d, cv::Point2d)>& draw) {
    int baseline = 0;
    const int width = s_.Px(32) + TextSize(Ascii(name), s_, &baseline).width;
    if (x_ > s_.Px(8) && x_ + width > img_->cols - s_.Px(8)) {
      x_ = s_.Px(8);
      y_ += line_px_;
    }
    const int mid = y_ - TextSize("A", s_, &baseline).height / 2;
    draw(cv::Point2d(x_, mid), cv::Point2d(x_ + s_.Px(26), mid));
    x_ += s_.Px(32);
    x_ += DrawText(img_, name, x_, y_, Align::kLeft, s_, kBlack, false);
    x_ += s_.Px(18);
  }
  // Starts the next line.
  void Break() {
    x_ = s_.Px(8);
    y_ += line_px_;
  }

 private:
  cv::Mat* img_;
  int x_, y_;
  const int line_px_;
  const Style& s_;
};

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
  std::vector<std::vector<cv::Point2d>> lanes, lanes_world;
  for (size_t i = 0; i < run.lanes.size(); ++i) {
    if (i == 0 || run.lanes[i].lane != run.lanes[i - 1].lane) {
      lanes.emplace_back();
      lanes_world.emplace_back();
    }
    lanes.back().push_back(px(run.lanes[i].x_m, run.lanes[i].y_m));
    lanes_world.back().emplace_back(run.lanes[i].x_m, run.lanes[i].y_m);
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

  // valet_parking: the lot under the drive.
  const ToPixel to_px = px;
  DrawParkingLot(&img, run.parking, to_px, s);
  const std::vector<ParkingContact> contacts = ParkingContacts(run);

  // Other vehicles, faintly, one path per id in time order. One that never
  // moved (world.traffic.stopped_vehicles, a queue that never cleared) has
  // no path: its body is drawn over the paths below, to show what held
  // the car.
  bool any_vehicle = false;
  std::vector<const runfile::VehicleSample*> stood;
  if (o.draw_vehicles) {
    std::map<std::string, std::vector<const runfile::VehicleSample*>> paths;
    for (const auto& v : run.vehicles) paths[v.id].push_back(&v);
    for (auto& [id, samples] : paths) {
      std::stable_sort(
          samples.begin(), samples.end(),
          [](const auto* a, const auto* b) { return a->t_s < b->t_s; });
      const runfile::VehicleSample& first = *samples.front();
      if (std::all_of(samples.begin(), samples.end(), [&](const auto* v) {
            return std::hypot(v->x_m - first.x_m, v->y_m - first.y_m) <=
                   kStoodM;
          })) {
        stood.push_back(&first);
        any_vehicle = true;
        continue;
      }
      std::vector<cv::Point2d> line;
      for (size_t i = 0; i < samples.size(); ++i) {
        const cv::Point2d w(samples[i]->x_m, samples[i]->y_m);
        if (i > 0 && std::hypot(w.x - samples[i - 1]->x_m,
                                w.y - samples[i - 1]->y_m) > kVehicleJumpM) {
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
  for (const runfile::VehicleSample* v : stood) {
    Outline(&img,
            BoxPx(v->x_m, v->y_m, v->yaw_rad, v->length_m, v->width_m, to_px),
            Bgr(kVehiclePathRgb), s.Px(2.5));
  }
  DrawParkingManoeuvre(&img, run, contacts, to_px, s);

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
  // Where the car stood, the longest labelled.
  const std::vector<analysis::Stand> stands =
      analysis::ListStands(run, kMarkStandS);
  std::vector<size_t> by_length(stands.size());
  for (size_t i = 0; i < stands.size(); ++i) by_length[i] = i;
  std::stable_sort(by_length.begin(), by_length.end(), [&](size_t a, size_t b) {
    return stands[a].standing_s > stands[b].standing_s;
  });
  auto at_start = [&](const analysis::Stand& stand) {
    const cv::Point2d d = px(stand.x_m, stand.y_m) - start;
    return std::hypot(d.x, d.y) < s.Px(14);
  };
  for (const analysis::Stand& stand : stands) {
    if (!at_start(stand)) {
      DrawStandMarker(&img, px(stand.x_m, stand.y_m), StandRgb(stand), s);
    }
  }
  const std::vector<CollisionPlace> collisions = CollisionPlaces(run);
  for (const CollisionPlace& c : collisions) {
    DrawContactMarker(&img, px(c.x_m, c.y_m), s);
  }
  // Where a run that did not arrive ended: its last position.
  cv::Point2d end(NAN, NAN);
  double end_t_s = 0.0;
  for (size_t i = ego.size(); i-- > 0;) {
    if (Finite(ego[i])) {
      end = ego[i];
      end_t_s = run.ego[i].t_s;
      break;
    }
  }
  const std::string end_text = EndText(run, end_t_s);
  if (!end_text.empty()) DrawEndMarker(&img, end, s);
  // Start and goal labelled first, so they get the first choice of place.
  std::vector<cv::Rect> labels;
  DrawGoalMarker(&img, goal, s);
  DrawStartMarker(&img, start, s);
  for (const analysis::Stand& stand : stands) {
    if (at_start(stand)) DrawStandRing(&img, start, StandRgb(stand), s);
  }
  DrawMarkerLabel(&img, goal, "goal", s, Bgr(kGoalRgb), map.map_top_px,
                  &labels);
  DrawMarkerLabel(&img, start, "start", s, Bgr(kStartRgb), map.map_top_px,
                  &labels);
  if (!end_text.empty()) {
    DrawMarkerLabel(&img, end, end_text, s, kBlack, map.map_top_px, &labels);
  }
  for (const CollisionPlace& c : collisions) {
    DrawMarkerLabel(&img, px(c.x_m, c.y_m),
                    fmt::format("collision {:.0f} s{}", c.t_s,
                                c.ego_caused ? " (ego's)" : ""),
                    s, Bgr(kContactRgb), map.map_top_px, &labels);
  }
  for (size_t k = 0; k < std::min(kLabelledStands, by_length.size()); ++k) {
    const analysis::Stand& stand = stands[by_length[k]];
    DrawMarkerLabel(
        &img, px(stand.x_m, stand.y_m),
        fmt::format("{} {:.0f} s", StandText(stand), stand.standing_s), s,
        Bgr(StandRgb(stand)), map.map_top_px, &labels);
  }

  // Scale bar, bottom centre.
  const double map_width_m = map.width_px / map.px_per_m;
  const double bar_m = NiceBelow(map_width_m / 5.0);
  const double bar_px = bar_m * map.px_per_m;
  const int bar_y = map.MapBottomPx() - s.Px(14);
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
  const int bottom_y = map.MapBottomPx() - inset - baseline;
  DrawText(&img, corner(map.min_x_m, map.max_y_m), inset, top_y, Align::kLeft,
           s, kDarkGrey, true);
  DrawText(&img, corner(map.MaxXM(), map.max_y_m), map.width_px - inset, top_y,
           Align::kRight, s, kDarkGrey, true);
  DrawText(&img, corner(map.min_x_m, map.MinYM()), inset, bottom_y,
           Align::kLeft, s, kDarkGrey, true);
  DrawText(&img, corner(map.MaxXM(), map.MinYM()), map.width_px - inset,
           bottom_y, Align::kRight, s, kDarkGrey, true);

  if (map.detail_px > 0) {
    cv::Mat panel =
        img(cv::Rect(0, map.MapBottomPx(), map.width_px, map.detail_px));
    DrawParkingDetail(&panel, run, contacts, lanes_world, s);
    cv::line(img, cv::Point(0, map.MapBottomPx()),
             cv::Point(map.width_px - 1, map.MapBottomPx()),
             Bgr(kLaneCentreRgb), 1);
  }

  // Header: title, then the legend; a rule above the map.
  cv::rectangle(img, cv::Rect(0, 0, map.width_px, map.map_top_px),
                Bgr(kBackgroundRgb), cv::FILLED);
  const int header_lines = run.parking.present ? 3 : 2;
  const int line_px = (map.map_top_px - s.Px(8)) / header_lines;
  DrawText(&img, TrajectoryTitle(run), s.Px(8), line_px - baseline,
           Align::kLeft, s, kBlack, false);
  HeaderLegend legend(&img, 2 * line_px - baseline, line_px, s);
  auto line_sample = [&](Rgb c, int thickness) {
    return [&img, c, thickness](cv::Point2d a, cv::Point2d b) {
      DrawSegment(&img, a, b, Bgr(c), thickness);
    };
  };
  if (!lanes.empty()) legend.Add("lane", line_sample(kLaneCentreRgb, s.Px(2)));
  legend.Add("ideal path", line_sample(kIdealPathRgb, s.Px(2)));
  legend.Add("trajectory", line_sample(kTrajectoryRgb, s.Px(5)));
  if (any_vehicle)
    legend.Add("other vehicles", line_sample(kVehiclePathRgb, s.Px(2)));
  legend.Add("start", [&](cv::Point2d a, cv::Point2d b) {
    DrawStartMarker(&img, 0.5 * (a + b), s);
  });
  legend.Add("goal", [&](cv::Point2d a, cv::Point2d b) {
    DrawGoalMarker(&img, 0.5 * (a + b), s);
  });
  if (!end_text.empty() && Finite(end)) {
    legend.Add("where it ended", [&](cv::Point2d a, cv::Point2d b) {
      DrawEndMarker(&img, 0.5 * (a + b), s);
    });
  }
  if (!stands.empty()) {
    legend.Add("stood >= 3 s", [&](cv::Point2d a, cv::Point2d b) {
      DrawStandMarker(&img, 0.5 * (a + b), StandRgb(stands.front()), s);
    });
  }
  if (!collisions.empty()) {
    legend.Add(fmt::format("collision ({})", collisions.size()),
               [&](cv::Point2d a, cv::Point2d b) {
                 DrawContactMarker(&img, 0.5 * (a + b), s);
               });
  }
  if (run.parking.present) {
    legend.Break();
    legend.Add("target slot", line_sample(kTargetSlotRgb, s.Px(3)));
    legend.Add("parked car / wall", line_sample(kObstacleRgb, s.Px(5)));
    legend.Add("plan fwd", line_sample(kPlannedForwardRgb, s.Px(2)));
    legend.Add("plan rev", line_sample(kPlannedReverseRgb, s.Px(2)));
    if (!run.parking.earlier_plans.empty())
      legend.Add("earlier plans", line_sample(kEarlierPlanRgb, s.Px(2)));
    legend.Add("car at end", line_sample(kEgoBodyRgb, s.Px(2)));
    if (!contacts.empty()) {
      legend.Add(fmt::format("car touching ({})", contacts.size()),
                 [&](cv::Point2d a, cv::Point2d b) {
                   DrawSegment(&img, a, b, Bgr(kContactRgb), s.Px(2));
                   DrawContactMarker(&img, 0.5 * (a + b), s);
                 });
    }
  }
  cv::line(img, cv::Point(0, map.map_top_px - 1),
           cv::Point(map.width_px - 1, map.map_top_px - 1), Bgr(kLaneCentreRgb),
           1);

  std::string png;
  ADSE_RETURN_IF_ERROR(EncodeOk(img, &png));
  return png;
}

}  // namespace adse::analysis::internal

namespace adse::analysis {

Result<RgbImage> ReadImage(const std::string& path) {
  return internal::Guarded("reading an image", [&]() -> Result<RgbImage> {
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
  return internal::Guarded("trajectory image mapping",
                           [&] { return internal::MappingImpl(run, o); });
}

Result<std::string> TrajectoryImagePng(const runfile::RunData& run,
                                       const TrajectoryImageOptions& o) {
  return internal::Guarded("trajectory image",
                           [&] { return internal::TrajectoryPngImpl(run, o); });
}

Status RenderTrajectoryImage(const runfile::RunData& run,
                             const std::string& png_path,
                             const TrajectoryImageOptions& o) {
  if (png_path.empty()) return Status::InvalidArgument("empty PNG path");
  return internal::WritePng(TrajectoryImagePng(run, o), png_path);
}

}  // namespace adse::analysis
