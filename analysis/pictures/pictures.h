// Pictures of runs and campaigns (OpenCV inside, PNG out): the top-down
// trajectory image a vision model or a person looks at to judge a drive,
// and the cost/time Pareto plot of a campaign. No OpenCV types here; every
// function returns a Status and never throws.
#ifndef ADSE_ANALYSIS_PICTURES_PICTURES_H_
#define ADSE_ANALYSIS_PICTURES_PICTURES_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "analysis/runfile/run_data.h"
#include "stack/base/status.h"

namespace adse::analysis {

// Colours of the pictures, so tests and documents can refer to them.
struct Rgb {
  uint8_t r, g, b;
  bool operator==(const Rgb&) const = default;
};
inline constexpr Rgb kBackgroundRgb{255, 255, 255};
inline constexpr Rgb kLaneRgb{215, 215, 215};         // lane surface
inline constexpr Rgb kLaneCentreRgb{160, 160, 160};   // lane centreline
inline constexpr Rgb kIdealPathRgb{0, 110, 40};       // dark green
inline constexpr Rgb kTrajectoryRgb{80, 170, 255};    // light blue
inline constexpr Rgb kVehiclePathRgb{245, 195, 160};  // faint orange
inline constexpr Rgb kStartRgb{0, 170, 0};
inline constexpr Rgb kGoalRgb{220, 0, 0};
inline constexpr Rgb kFeasibleRgb{40, 90, 200};
inline constexpr Rgb kInfeasibleRgb{150, 150, 150};
inline constexpr Rgb kFrontRgb{230, 90, 0};  // front points + line
inline constexpr Rgb kConstraintRgb{190, 30, 60};
inline constexpr Rgb kUnstableRgb{140, 60, 200};  // violet ring: runs disagree
// The study's form: the campaign's points, the reference's, its front.
inline constexpr Rgb kStudyPointRgb{215, 30, 30};  // red triangles
inline constexpr Rgb kReferenceRgb{175, 175, 175};
inline constexpr Rgb kReferenceFrontRgb{90, 105, 140};  // slate
// valet_parking: the lot and the manoeuvre.
inline constexpr Rgb kSlotRgb{175, 185, 200};      // cool grey
inline constexpr Rgb kObstacleRgb{112, 104, 96};   // warm grey: walls, cars
inline constexpr Rgb kTargetSlotRgb{230, 140, 0};  // orange
inline constexpr Rgb kPlannedForwardRgb{150, 60, 190};  // purple
inline constexpr Rgb kPlannedReverseRgb{215, 40, 140};  // magenta
inline constexpr Rgb kEarlierPlanRgb{205, 180, 230};    // pale violet
inline constexpr Rgb kEgoBodyRgb{20, 60, 160};          // dark blue
inline constexpr Rgb kContactRgb{230, 20, 20};          // red: touching
// Where the car stood, by what held it.
inline constexpr Rgb kStandRedLightRgb{200, 0, 60};        // crimson
inline constexpr Rgb kStandObstacleRgb{240, 150, 0};       // amber
inline constexpr Rgb kStandLocalizationRgb{130, 50, 190};  // violet
inline constexpr Rgb kStandOtherRgb{90, 90, 90};           // dark grey

struct TrajectoryImageOptions {
  int width_px = 1200;     // 200..4000
  double margin_m = 10.0;  // world margin around the route and trajectory
  bool draw_vehicles = true;
};

// Where the world lands in a trajectory image: a header band of
// `map_top_px` rows (title, legend) above the map, whose pixel rows and
// columns map linearly to world metres with y up.
struct WorldToImage {
  double min_x_m = 0.0;  // world x at the map's left edge
  double max_y_m = 0.0;  // world y at the map's top edge
  double px_per_m = 1.0;
  int map_top_px = 0;
  int width_px = 0;
  int height_px = 0;  // whole image, header and detail panel included
  // valet_parking: rows of the detail panel below the map, which shows the
  // manoeuvre enlarged (0: no panel).
  int detail_px = 0;

  // Pixel coordinates (column, row; fractional) of a world point.
  double Column(double x_m) const { return (x_m - min_x_m) * px_per_m; }
  double Row(double y_m) const {
    return map_top_px + (max_y_m - y_m) * px_per_m;
  }
  double MaxXM() const { return min_x_m + width_px / px_per_m; }
  int MapBottomPx() const { return height_px - detail_px; }
  double MinYM() const {
    return max_y_m - (MapBottomPx() - map_top_px) / px_per_m;
  }
};

// The mapping RenderTrajectoryImage uses for `run`. The map covers the
// ideal path and the ego trajectory (or, when both are empty, the lanes)
// plus margin_m, so the drive fills the picture even on a large network;
// lanes and other vehicles outside are clipped. The map's aspect ratio is
// kept between 1:4 and 2:1 (height:width) by widening the shorter side.
// InvalidArgument for bad options or nothing finite to draw.
Result<WorldToImage> TrajectoryImageMapping(
    const runfile::RunData& run, const TrajectoryImageOptions& o = {});

// Top-down render of a run: lanes (light grey bands lane_width_m wide with
// a grey centreline, from run.lanes), the ideal path (dark green), the ego
// trajectory (light blue, thicker), other vehicles' paths (faint), a start
// marker (green circle at the first ego sample, else the path start) and a
// goal marker (red cross at the path end) with labels, a scale bar with its
// length, the world coordinates of the map corners written in the corners,
// a title line (scenario, design point, outcome) and a legend. A
// valet_parking run also shows the lot's slots, walls, poles and parked
// cars, the target slot, the stack's planned manoeuvre (forward and
// reverse legs) and the car's body where it ended, and below the map a
// detail panel with the manoeuvre enlarged. Every place the car stood for
// 3 s or more is a dot coloured by what held it (red light, obstacle,
// localization lost, anything else), the longest six labelled with the
// stop reason and the seconds. White
// background, y up. Encoded as PNG in memory, then written atomically
// (adse::WriteFileAtomic): no partial file on any error.
Status RenderTrajectoryImage(const runfile::RunData& run,
                             const std::string& png_path,
                             const TrajectoryImageOptions& o = {});
// The same picture as PNG bytes (e.g. for a vision model).
Result<std::string> TrajectoryImagePng(const runfile::RunData& run,
                                       const TrajectoryImageOptions& o = {});

struct ParetoPlotPoint {
  double cost = 0.0;
  double nav_time_s = 0.0;
  bool feasible = true;
  bool on_front = false;
  std::string label;       // written next to front points, e.g. "6c 1.5GHz 7Hz"
  bool highlight = false;  // ringed, e.g. the cheapest feasible design
  // nav_time_s is only a lower bound (early stop ended the run): drawn as
  // an arrow pointing up from it.
  bool censored = false;
  // A feasible design whose runs (replicas) disagree on feasibility:
  // ringed in violet, so the picture says how sure it is, as the headline
  // does.
  bool unstable = false;
};

struct ParetoPlotOptions {
  int width_px = 1000, height_px = 700;  // 300..4000 each
  std::string x_label = "hardware cost", y_label = "navigation time (s)";
  // Constraint lines (e.g. nav_time_s <= 400 as a horizontal line at 400).
  std::vector<double> vertical_lines, horizontal_lines;
  std::string title;
  // Legend names of infeasible points, the front and highlighted points.
  std::string infeasible_name = "infeasible";
  std::string front_name = "Pareto front";
  std::string highlight_name = "cheapest feasible";
};

// Scatter of all points (feasible: filled circles; infeasible: grey
// crosses; front points: in the front colour, a cross if infeasible;
// points far above the rest as grey triangles on the top edge) with
// the front drawn as a staircase in x order (a min-min front promises
// nothing between its points), highlighted points ringed in black and
// unstable feasible ones in violet, constraint lines dashed, linear axes
// with ticks and labels, a legend, and the title. Front designs on one
// marker (equal cost and time) share one label, the first two named and
// the rest counted. Front labels never
// overlap one another, the legend or the front, and hide another design's
// marker only where no place around their point is free of one; a label
// without room is left out and counted in a note, as are points with a
// non-finite coordinate. The legend lists only the marks drawn.
// InvalidArgument for bad options or no finite point; written like
// RenderTrajectoryImage.
Status RenderParetoPlot(const std::vector<ParetoPlotPoint>& points,
                        const std::string& png_path,
                        const ParetoPlotOptions& o = {});
Result<std::string> ParetoPlotPng(const std::vector<ParetoPlotPoint>& points,
                                  const ParetoPlotOptions& o = {});

// The reference study's form of the same picture: navigation time on x,
// hardware cost on y; a reference campaign's points (an exhaustive
// recording) as small grey dots with its front (`on_front`) as a grey
// staircase; the campaign's own points as red triangles, filled when
// feasible, hollow when not (a run stopped early sits at the bound that
// stopped it, `censored`); each bound dashed. InvalidArgument for bad
// options or when neither set has a finite point.
struct StudyPlotOptions {
  int width_px = 1000, height_px = 700;  // 300..4000 each
  std::string title;
  std::vector<double> time_bounds_s;  // vertical dashed lines
  std::vector<double> cost_bounds;    // horizontal dashed lines
  std::string points_name = "this campaign";
  std::string reference_name = "reference (every point)";
  // What the cost is, e.g. "hardware cost (cores * freq_ghz)".
  std::string cost_label = "hardware cost";
};
Result<std::string> StudyPlotPng(const std::vector<ParetoPlotPoint>& points,
                                 const std::vector<ParetoPlotPoint>& reference,
                                 const StudyPlotOptions& o = {});

// One row of a comparison chart: adse's value beside a reference's (e.g.
// a latency measured on the real stack); a row without a reference shows
// adse's bar alone.
struct ComparisonRow {
  std::string label;
  double adse = 0.0;
  std::optional<double> reference;
};
inline constexpr Rgb kAdseBarRgb{40, 90, 200};
inline constexpr Rgb kReferenceBarRgb{230, 90, 0};

struct ComparisonChartOptions {
  std::string title;
  std::string unit = "ms";
  std::string adse_name = "adse";
  std::string reference_name = "reference";
  int width_px = 1000;
  int row_height_px = 34;  // two bars and a gap
};

// Horizontal bars, one pair per row (adse above, reference below, each with
// its value written after it), the labels left of the bars, a linear axis
// from 0 with ticks, a legend and the title. InvalidArgument for bad
// options, no rows, or a negative or non-finite value. Written atomically.
Status RenderComparisonChart(const std::vector<ComparisonRow>& rows,
                             const ComparisonChartOptions& options,
                             const std::string& path);

// A decoded picture, 8-bit RGB rows top to bottom (for checks and tests
// that should not need OpenCV themselves).
struct RgbImage {
  int width_px = 0, height_px = 0;
  std::vector<uint8_t> rgb;  // width_px * height_px * 3
  Rgb At(int column, int row) const {
    const size_t i = (static_cast<size_t>(row) * width_px + column) * 3;
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};
// Reads an image file (PNG or anything cv::imread knows). NotFound if
// missing, Corruption if it does not decode.
Result<RgbImage> ReadImage(const std::string& path);

}  // namespace adse::analysis

#endif  // ADSE_ANALYSIS_PICTURES_PICTURES_H_
