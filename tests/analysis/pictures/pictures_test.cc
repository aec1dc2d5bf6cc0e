// The trajectory image: rendered from synthetic runs, decoded back, and
// probed at pixels whose colour is known from the mapping; and ReadImage.
#include "analysis/pictures/pictures.h"

#include <gtest/gtest.h>

#include <stdlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "tests/analysis/pictures/picture_testing.h"

namespace adse::analysis {
namespace {

namespace fs = std::filesystem;
using testing::ColourNear;
using testing::CountColour;
using testing::Name;
using testing::PictureTest;

using runfile::RunData;

// A square lane loop of 100 m, an ideal path along its bottom and right
// sides, and a trajectory 1 m to the left of the path; one other vehicle
// crossing the middle.
RunData SquareRun() {
  RunData run;
  run.scenario_name = "square_loop";
  run.termination_reason = "goal_reached";
  run.design_point = {{"cores", 6}, {"freq_ghz", 1.5}, {"lidar_hz", 7}};
  run.metrics = {{"nav_time_s", 42.5}};
  run.lane_width_m = 3.5;
  const double corners[5][2] = {{0, 0}, {100, 0}, {100, 100}, {0, 100}, {0, 0}};
  for (const auto& c : corners) run.lanes.push_back({0, c[0], c[1]});
  double s = 0;
  for (int i = 0; i <= 100; ++i) run.ideal_path.push_back({s++, 1.0 * i, 0});
  for (int i = 1; i <= 100; ++i) run.ideal_path.push_back({s++, 100, 1.0 * i});
  double t = 0;
  for (int i = 0; i <= 99; ++i) {
    run.ego.push_back({t += 0.1, 1.0 * i, 1.0, 0, 5, 0, 0});
  }
  for (int i = 1; i <= 100; ++i) {
    run.ego.push_back({t += 0.1, 99.0, 1.0 * i, M_PI / 2, 5, 0, 0});
  }
  for (int i = 0; i <= 6; ++i) {
    run.vehicles.push_back(
        {0.5 * i, "veh0", 20.0 + 10 * i, 50, 0, 5, 4.5, 1.8});
  }
  return run;
}

TEST_F(PictureTest, TrajectoryImageHasTheDrawingWhereTheMappingSays) {
  const RunData run = SquareRun();
  const std::string path = Path("trajectory.png");
  const TrajectoryImageOptions options;  // 1200 px, 10 m margin
  ASSERT_TRUE(RenderTrajectoryImage(run, path, options).ok());
  Result<RgbImage> img = ReadImage(path);
  ASSERT_TRUE(img.ok()) << img.status().ToString();
  EXPECT_EQ(img->width_px, 1200);
  Result<WorldToImage> map = TrajectoryImageMapping(run, options);
  ASSERT_TRUE(map.ok());
  EXPECT_EQ(map->height_px, img->height_px);
  EXPECT_NEAR(map->px_per_m, 10.0, 1e-9);  // 120 m across 1200 px
  EXPECT_NEAR(map->min_x_m, -10.0, 1e-9);
  EXPECT_NEAR(map->MaxXM(), 110.0, 1e-9);
  EXPECT_NEAR(map->MinYM(), -10.0, 1e-9);

  auto at = [&](double x, double y, Rgb colour, int radius = 0) {
    return ColourNear(*img, map->Column(x), map->Row(y), colour, radius);
  };
  // The trajectory along both sides, 1 m off the path; the path itself.
  for (double x : {30.0, 50.0, 80.0}) {
    EXPECT_TRUE(at(x, 1.0, kTrajectoryRgb)) << "x=" << x;
    EXPECT_TRUE(at(x, 0.0, kIdealPathRgb, 1)) << "x=" << x;
  }
  for (double y : {30.0, 60.0}) {
    EXPECT_TRUE(at(99.0, y, kTrajectoryRgb)) << "y=" << y;
    EXPECT_TRUE(at(100.0, y, kIdealPathRgb, 1)) << "y=" << y;
  }
  // Lanes: the surface band on the far sides, the centreline there too.
  EXPECT_TRUE(at(50.0, 101.0, kLaneRgb));
  EXPECT_TRUE(at(1.0, 50.0, kLaneRgb));
  EXPECT_TRUE(at(50.0, 100.0, kLaneCentreRgb, 1));
  // Markers: start at the first ego sample, goal at the path's end.
  EXPECT_TRUE(at(0.0, 1.0, kStartRgb));
  EXPECT_TRUE(at(100.0, 100.0, kGoalRgb));
  // The other vehicle, faintly.
  EXPECT_TRUE(at(50.0, 50.0, kVehiclePathRgb, 1));
  // White away from content: inside the loop, in the margin, the corners.
  EXPECT_EQ(img->At(map->Column(40), map->Row(70)), kBackgroundRgb);
  EXPECT_EQ(img->At(map->Column(-6), map->Row(40)), kBackgroundRgb);
  EXPECT_EQ(img->At(map->Column(106), map->Row(40)), kBackgroundRgb);
  for (const auto& [c, r] : std::vector<std::pair<int, int>>{
           {1, 1},
           {img->width_px - 2, 1},
           {1, map->map_top_px + 1},
           {img->width_px - 2, map->map_top_px + 1},
           {1, img->height_px - 2},
           {img->width_px - 2, img->height_px - 2}}) {
    EXPECT_EQ(img->At(c, r), kBackgroundRgb)
        << c << "," << r << " is " << Name(img->At(c, r));
  }
  // Corner coordinates, scale bar and header put dark pixels in those
  // places.
  auto dark_in = [&](int c0, int r0, int c1, int r1) {
    for (int r = r0; r < r1; ++r) {
      for (int c = c0; c < c1; ++c) {
        const Rgb p = img->At(c, r);
        if (p.r < 128 && p.g < 128 && p.b < 128) return true;
      }
    }
    return false;
  };
  const int w = img->width_px, h = img->height_px, top = map->map_top_px;
  EXPECT_TRUE(dark_in(0, 0, w / 2, top / 2));                 // title
  EXPECT_TRUE(dark_in(0, top, 150, top + 30));                // top left
  EXPECT_TRUE(dark_in(w - 150, top, w, top + 30));            // top right
  EXPECT_TRUE(dark_in(0, h - 30, 150, h));                    // bottom left
  EXPECT_TRUE(dark_in(w - 150, h - 30, w, h));                // bottom right
  EXPECT_TRUE(dark_in(w / 2 - 100, h - 40, w / 2 + 100, h));  // scale bar
}

TEST_F(PictureTest, WhereTheCarStoodIsMarkedInTheColourOfWhatHeldIt) {
  // The car stands 10 s at (50, 1) for a red light and 2 s at (99, 30),
  // too short to be marked.
  RunData run = SquareRun();
  for (runfile::EgoSample& e : run.ego) {
    if (e.x_m == 50.0 && e.y_m == 1.0) e.v_mps = 0.0;
    if (e.x_m == 99.0 && e.y_m == 30.0) e.v_mps = 0.0;
  }
  RunData stood = run;
  stood.ego.clear();
  for (const runfile::EgoSample& e : run.ego) {
    stood.ego.push_back(e);
    const int repeats = e.v_mps == 0.0 ? (e.x_m == 50.0 ? 100 : 20) : 0;
    for (int k = 0; k < repeats; ++k) stood.ego.push_back(e);
  }
  double t = 0;
  for (runfile::EgoSample& e : stood.ego) e.t_s = (t += 0.1);
  for (double ts = 0; ts <= t; ts += 0.1) {
    stood.stop_reasons.push_back(
        {ts, ts, StopReason::kRedLight, 0.0, -1, -1.0, 0});
  }
  ASSERT_TRUE(RenderTrajectoryImage(stood, Path("stood.png")).ok());
  ASSERT_TRUE(RenderTrajectoryImage(SquareRun(), Path("plain.png")).ok());
  Result<RgbImage> img = ReadImage(Path("stood.png"));
  Result<RgbImage> plain = ReadImage(Path("plain.png"));
  ASSERT_TRUE(img.ok() && plain.ok());
  Result<WorldToImage> map = TrajectoryImageMapping(stood);
  ASSERT_TRUE(map.ok());
  EXPECT_TRUE(
      ColourNear(*img, map->Column(50.0), map->Row(1.0), kStandRedLightRgb, 1));
  EXPECT_FALSE(ColourNear(*img, map->Column(99.0), map->Row(30.0),
                          kStandRedLightRgb, 4));
  // One dot, its label and the legend's sample: a few hundred pixels.
  EXPECT_GT(CountColour(*img, kStandRedLightRgb), 100);
  EXPECT_EQ(CountColour(*plain, kStandRedLightRgb), 0);
}

TEST_F(PictureTest, AStandWhereTheCarStartedRingsTheStartMarker) {
  // The car waits 10 s at its first sample (0, 1), held by a red light: a
  // dot there would hide under the start marker, so a ring in the stand's
  // colour goes round it.
  RunData run = SquareRun();
  std::vector<runfile::EgoSample> ego(100, run.ego.front());
  for (runfile::EgoSample& e : ego) e.v_mps = 0.0;
  ego.insert(ego.end(), run.ego.begin(), run.ego.end());
  double t = 0;
  for (runfile::EgoSample& e : ego) e.t_s = (t += 0.1);
  run.ego = ego;
  for (double ts = 0; ts <= t; ts += 0.1) {
    run.stop_reasons.push_back(
        {ts, ts, StopReason::kRedLight, 0.0, -1, -1.0, 0});
  }
  ASSERT_TRUE(RenderTrajectoryImage(run, Path("waited.png")).ok());
  Result<RgbImage> img = ReadImage(Path("waited.png"));
  ASSERT_TRUE(img.ok());
  Result<WorldToImage> map = TrajectoryImageMapping(run);
  ASSERT_TRUE(map.ok());
  const double column = map->Column(0.0), row = map->Row(1.0);
  EXPECT_TRUE(ColourNear(*img, column, row, kStartRgb, 2));
  // The ring, 12 px out, left and right of the marker.
  EXPECT_TRUE(ColourNear(*img, column - 12, row, kStandRedLightRgb, 2));
  EXPECT_TRUE(ColourNear(*img, column + 12, row, kStandRedLightRgb, 2));
}

TEST_F(PictureTest, ARunThatDidNotArriveIsMarkedWhereItEnded) {
  // The square loop's run, ended halfway (its last sample at (99, 1)):
  // stopped early, timed out or stalled, a black square there; arrived,
  // none.
  RunData arrived = SquareRun();
  arrived.ego.resize(101);
  for (const std::string reason :
       {"constraint_violated: nav_time_s <= 60", "timeout", "stalled: obstacle",
        "goal_reached"}) {
    RunData run = arrived;
    run.termination_reason = reason;
    ASSERT_TRUE(RenderTrajectoryImage(run, Path("ended.png")).ok());
    Result<RgbImage> img = ReadImage(Path("ended.png"));
    ASSERT_TRUE(img.ok());
    Result<WorldToImage> map = TrajectoryImageMapping(run);
    ASSERT_TRUE(map.ok());
    EXPECT_EQ(
        ColourNear(*img, map->Column(99.0), map->Row(1.0), Rgb{0, 0, 0}, 2),
        reason != "goal_reached")
        << reason;
  }
}

TEST_F(PictureTest, ACollisionWithTrafficIsMarkedWhereItHappened) {
  // At 5.0 s the ego is at (49, 1); a flow car recorded at (52, 3) then.
  RunData run = SquareRun();
  run.vehicles.push_back({5.0, "flow0.1", 52.0, 3.0, M_PI, 4, 4.5, 1.8});
  run.collisions.push_back({5.0, "flow0.1", 1});
  ASSERT_TRUE(RenderTrajectoryImage(run, Path("hit.png")).ok());
  ASSERT_TRUE(RenderTrajectoryImage(SquareRun(), Path("plain.png")).ok());
  Result<RgbImage> img = ReadImage(Path("hit.png"));
  Result<RgbImage> plain = ReadImage(Path("plain.png"));
  ASSERT_TRUE(img.ok() && plain.ok());
  Result<WorldToImage> map = TrajectoryImageMapping(run);
  ASSERT_TRUE(map.ok());
  EXPECT_TRUE(
      ColourNear(*img, map->Column(50.5), map->Row(2.0), kContactRgb, 1));
  // The dot and the legend's sample (the label's text is anti-aliased);
  // nothing without a collision.
  EXPECT_GT(CountColour(*img, kContactRgb), 40);
  EXPECT_EQ(CountColour(*plain, kContactRgb), 0);
}

TEST_F(PictureTest, AVehicleThatNeverMovedIsDrawnAsItsBody) {
  // A broken-down car at (50, 30), 4.5 m by 1.8 m along x, every sample
  // where the first was: no path, so its outline shows where it stood.
  RunData run = SquareRun();
  for (int i = 0; i <= 6; ++i) {
    run.vehicles.push_back({0.5 * i, "stopped0", 50, 30, 0, 0, 4.5, 1.8});
  }
  const TrajectoryImageOptions options;
  ASSERT_TRUE(RenderTrajectoryImage(run, Path("t.png"), options).ok());
  Result<RgbImage> img = ReadImage(Path("t.png"));
  ASSERT_TRUE(img.ok());
  Result<WorldToImage> map = TrajectoryImageMapping(run, options);
  ASSERT_TRUE(map.ok());
  auto at = [&](double x, double y) {
    return ColourNear(*img, map->Column(x), map->Row(y), kVehiclePathRgb, 1);
  };
  EXPECT_TRUE(at(47.75, 30.0));  // rear edge
  EXPECT_TRUE(at(52.25, 30.0));  // front edge
  EXPECT_TRUE(at(50.0, 30.9));   // a side
  EXPECT_FALSE(at(50.0, 30.0));  // not filled
  // The moving car (veh0) keeps its path, not a box.
  EXPECT_FALSE(at(50.0, 50.9));
}

TEST_F(PictureTest, VehiclesCanBeLeftOut) {
  TrajectoryImageOptions options;
  options.width_px = 600;
  options.draw_vehicles = false;
  const RunData run = SquareRun();
  ASSERT_TRUE(RenderTrajectoryImage(run, Path("t.png"), options).ok());
  Result<RgbImage> img = ReadImage(Path("t.png"));
  ASSERT_TRUE(img.ok());
  EXPECT_EQ(img->width_px, 600);
  EXPECT_EQ(CountColour(*img, kVehiclePathRgb), 0);
  EXPECT_GT(CountColour(*img, kTrajectoryRgb), 100);
}

TEST_F(PictureTest, ValetRunShowsTheLotTheTargetAndTheManoeuvre) {
  RunData run = SquareRun();
  runfile::ParkingRecord& p = run.parking;
  p.present = true;
  // Three slots north of the path's first leg; the middle one the target,
  // a parked car in the west one.
  for (int i = 0; i < 3; ++i) {
    p.slots.push_back(
        {40.0 + 2.5 * i, 10.0, M_PI / 2, 5.0, 2.5, i == 0, i == 1});
  }
  p.obstacles = {
      {0, 39.1, 7.8}, {0, 40.9, 7.8}, {0, 40.9, 12.2}, {0, 39.1, 12.2}};
  p.planned_path = {{40, 3, 0, 0}, {46, 3, 0, 0}, {42.5, 8.65, -M_PI / 2, 1}};
  // A first plan the last one replaced, further east.
  p.earlier_plans = {{0, 50, 3, 0, 0}, {0, 56, 3, 0, 0}, {0, 60, 8, 0, 0}};
  RunData plain = SquareRun();
  TrajectoryImageOptions options;
  Result<WorldToImage> map = TrajectoryImageMapping(run, options);
  ASSERT_TRUE(map.ok());
  ASSERT_TRUE(RenderTrajectoryImage(run, Path("valet.png"), options).ok());
  ASSERT_TRUE(RenderTrajectoryImage(plain, Path("plain.png"), options).ok());
  Result<RgbImage> img = ReadImage(Path("valet.png"));
  Result<RgbImage> none = ReadImage(Path("plain.png"));
  ASSERT_TRUE(img.ok() && none.ok());
  // The parked car is filled where it stands, the target slot outlined
  // (its west edge at x = 41.25), both legs of the plan drawn; none of it
  // in a lane-driving picture.
  EXPECT_TRUE(
      ColourNear(*img, map->Column(40.0), map->Row(10.0), kObstacleRgb));
  EXPECT_TRUE(
      ColourNear(*img, map->Column(41.25), map->Row(10.0), kTargetSlotRgb, 2));
  // The detail panel below the map shows the target slot enlarged.
  ASSERT_GT(map->detail_px, 0);
  EXPECT_EQ(img->height_px, map->height_px);
  int target_in_panel = 0;
  for (int r = map->MapBottomPx(); r < img->height_px; ++r) {
    for (int c = 0; c < img->width_px; ++c) {
      target_in_panel += img->At(c, r) == kTargetSlotRgb;
    }
  }
  EXPECT_GT(target_in_panel, 200);
  Result<WorldToImage> plain_map = TrajectoryImageMapping(plain, options);
  ASSERT_TRUE(plain_map.ok());
  EXPECT_EQ(plain_map->detail_px, 0);
  EXPECT_TRUE(
      ColourNear(*img, map->Column(58.0), map->Row(5.5), kEarlierPlanRgb, 2));
  for (Rgb c : {kObstacleRgb, kTargetSlotRgb, kPlannedForwardRgb,
                kPlannedReverseRgb, kEgoBodyRgb, kSlotRgb, kEarlierPlanRgb}) {
    EXPECT_GT(CountColour(*img, c), 20) << Name(c);
    EXPECT_EQ(CountColour(*none, c), 0) << Name(c);
  }
}

TEST_F(PictureTest, ValetRunMarksWhereTheCarTouchedAnObstacle) {
  RunData run = SquareRun();
  run.parking.present = true;
  run.parking.planned_path = {{0, 1, 0, 0}, {99, 1, 0, 0}};
  // A pole reaching into the first leg's left half (the body spans y 0.05
  // to 1.95 there).
  run.parking.obstacles = {
      {0, 60.0, 1.5}, {0, 60.4, 1.5}, {0, 60.4, 1.9}, {0, 60.0, 1.9}};
  TrajectoryImageOptions options;
  Result<WorldToImage> map = TrajectoryImageMapping(run, options);
  ASSERT_TRUE(map.ok());
  ASSERT_TRUE(RenderTrajectoryImage(run, Path("touch.png"), options).ok());
  Result<RgbImage> img = ReadImage(Path("touch.png"));
  ASSERT_TRUE(img.ok());
  // The body in red where it met the pole, a dot there, and the legend.
  EXPECT_TRUE(
      ColourNear(*img, map->Column(60.0), map->Row(1.7), kContactRgb, 3));
  EXPECT_GT(CountColour(*img, kContactRgb), 100);

  // Passing 0.2 m clear of it: nothing red.
  for (runfile::OutlinePoint& v : run.parking.obstacles) v.y_m += 0.6;
  ASSERT_TRUE(RenderTrajectoryImage(run, Path("clear.png"), options).ok());
  Result<RgbImage> clear = ReadImage(Path("clear.png"));
  ASSERT_TRUE(clear.ok());
  EXPECT_EQ(CountColour(*clear, kContactRgb), 0);
}

TEST_F(PictureTest, PngBytesAreAPng) {
  Result<std::string> png = TrajectoryImagePng(SquareRun());
  ASSERT_TRUE(png.ok()) << png.status().ToString();
  ASSERT_GT(png->size(), 8u);
  EXPECT_EQ(png->substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
}

TEST_F(PictureTest, LongThinRoutesKeepAReadableAspect) {
  RunData run;
  for (int i = 0; i <= 1000; ++i)
    run.ideal_path.push_back({1.0 * i, 1.0 * i, 0});
  Result<WorldToImage> map = TrajectoryImageMapping(run, {});
  ASSERT_TRUE(map.ok());
  const int map_height = map->height_px - map->map_top_px;
  EXPECT_GE(map_height, 1200 / 4 - 1);
  run.ideal_path.clear();
  for (int i = 0; i <= 1000; ++i)
    run.ideal_path.push_back({1.0 * i, 0, 1.0 * i});
  map = TrajectoryImageMapping(run, {});
  ASSERT_TRUE(map.ok());
  EXPECT_LE(map->height_px - map->map_top_px, 2 * 1200 + 1);
}

TEST_F(PictureTest, OddDataStillRenders) {
  RunData run = SquareRun();
  run.scenario_name = "Kreuzung Süd — ünïcödé";
  run.termination_reason = "stack crashed\n  #0 somewhere\n";
  run.status = "failed";
  run.ego[10].x_m = std::numeric_limits<double>::quiet_NaN();
  run.ego.front().y_m = std::numeric_limits<double>::infinity();
  run.lanes.push_back({1, 1e9, 1e9});  // far off: clipped, not in bounds
  run.lanes.push_back({1, -1e9, 5});
  run.lanes.push_back({2, 1e300, 1e300});
  run.design_point.clear();
  ASSERT_TRUE(RenderTrajectoryImage(run, Path("odd.png")).ok());
  Result<WorldToImage> map = TrajectoryImageMapping(run);
  ASSERT_TRUE(map.ok());
  EXPECT_NEAR(map->px_per_m, 10.0, 1e-9);
  // Lanes alone still make a picture.
  RunData lanes_only;
  lanes_only.lanes = SquareRun().lanes;
  EXPECT_TRUE(RenderTrajectoryImage(lanes_only, Path("lanes.png")).ok());
}

TEST_F(PictureTest, TrajectoryErrorsLeaveNoFile) {
  const RunData empty;
  Status status = RenderTrajectoryImage(empty, Path("empty.png"));
  EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(status.message().find("nothing to draw"), std::string::npos);

  TrajectoryImageOptions narrow;
  narrow.width_px = 10;
  EXPECT_EQ(
      RenderTrajectoryImage(SquareRun(), Path("narrow.png"), narrow).code(),
      Status::Code::kInvalidArgument);
  TrajectoryImageOptions bad_margin;
  bad_margin.margin_m = -1;
  EXPECT_EQ(
      RenderTrajectoryImage(SquareRun(), Path("m.png"), bad_margin).code(),
      Status::Code::kInvalidArgument);
  EXPECT_EQ(RenderTrajectoryImage(SquareRun(), "").code(),
            Status::Code::kInvalidArgument);
  EXPECT_TRUE(Listing().empty());

  // The target is a folder: the rename fails, no temporary is left.
  fs::create_directories(Path("taken.png"));
  status = RenderTrajectoryImage(SquareRun(), Path("taken.png"));
  EXPECT_FALSE(status.ok());
  EXPECT_EQ(Listing(), std::vector<std::string>{"taken.png"});
  // A parent that is a file.
  std::ofstream(Path("file")) << "x";
  EXPECT_FALSE(RenderTrajectoryImage(SquareRun(), Path("file/t.png")).ok());
  EXPECT_EQ(Listing(), (std::vector<std::string>{"file", "taken.png"}));
}

TEST_F(PictureTest, ReadImageErrors) {
  EXPECT_EQ(ReadImage(Path("missing.png")).status().code(),
            Status::Code::kNotFound);
  std::ofstream(Path("junk.png")) << "not a png";
  EXPECT_EQ(ReadImage(Path("junk.png")).status().code(),
            Status::Code::kCorruption);
}

}  // namespace
}  // namespace adse::analysis
