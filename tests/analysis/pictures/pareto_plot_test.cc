// pareto.png in its two forms (ParetoPlotPng and the reference study's,
// StudyPlotPng): rendered from synthetic fronts, decoded back, and probed
// by the colours of their marks.
#include "analysis/pictures/pictures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/analysis/pictures/picture_testing.h"

namespace adse::analysis {
namespace {

namespace fs = std::filesystem;
using testing::CountColour;
using testing::PictureTest;

// The reference study's shape: cost = cores x GHz, time falling with it.
std::vector<ParetoPlotPoint> StudyPoints() {
  return {
      {4.8, 1248, false, false, "4c 1.2GHz 14Hz"},
      {9.0, 505, false, true, "6c 1.5GHz 7Hz"},
      {12.0, 380, true, true, "8c 1.5GHz"},
      {16.0, 300, true, false, ""},
      {20.0, 240, true, true, "10c 2.0GHz"},
      {32.4, 165, true, true, "18c 1.8GHz 7Hz"},
      {34.5, 171, true, false, "23c 1.5GHz 7Hz"},
      {40.0, 200, true, false, ""},
  };
}

TEST_F(PictureTest, StudyPlotDrawsTheCampaignOverTheReferenceWithItsBound) {
  // The reference: every point in grey, its front as a darker line; the
  // campaign's four points as red triangles.
  std::vector<ParetoPlotPoint> reference = StudyPoints();
  std::vector<ParetoPlotPoint> points;
  for (const auto& [cost, time_s, feasible] :
       {std::tuple{9.0, 505.0, false}, std::tuple{12.0, 380.0, true},
        std::tuple{20.0, 240.0, true}, std::tuple{40.0, 200.0, true}}) {
    ParetoPlotPoint p;
    p.cost = cost;
    p.nav_time_s = time_s;
    p.feasible = feasible;
    points.push_back(p);
  }
  StudyPlotOptions options;
  options.time_bounds_s = {400};
  options.title = "agent over the exhaustive study";
  Result<std::string> png = StudyPlotPng(points, reference, options);
  ASSERT_TRUE(png.ok()) << png.status().ToString();
  {
    std::ofstream out(Path("study.png"), std::ios::binary);
    out << *png;
  }
  Result<RgbImage> img = ReadImage(Path("study.png"));
  ASSERT_TRUE(img.ok()) << img.status().ToString();
  EXPECT_EQ(img->width_px, 1000);
  EXPECT_GT(CountColour(*img, kStudyPointRgb), 4 * 15);
  EXPECT_GT(CountColour(*img, kReferenceRgb), 4 * 10);
  EXPECT_GT(CountColour(*img, kReferenceFrontRgb), 200);  // the front line
  // The campaign's cheapest feasible design is ringed in black.
  std::vector<ParetoPlotPoint> ringed = points;
  ringed[1].highlight = true;
  Result<std::string> ringed_png = StudyPlotPng(ringed, reference, options);
  ASSERT_TRUE(ringed_png.ok());
  {
    std::ofstream out(Path("ringed_study.png"), std::ios::binary);
    out << *ringed_png;
  }
  Result<RgbImage> ringed_img = ReadImage(Path("ringed_study.png"));
  ASSERT_TRUE(ringed_img.ok());
  // The ring, and its sample in the legend.
  EXPECT_GT(CountColour(*ringed_img, Rgb{0, 0, 0}),
            CountColour(*img, Rgb{0, 0, 0}) + 40);
  // Without a reference only the campaign's own points are drawn.
  Result<std::string> alone = StudyPlotPng(points, {}, options);
  ASSERT_TRUE(alone.ok());
  {
    std::ofstream out(Path("alone.png"), std::ios::binary);
    out << *alone;
  }
  Result<RgbImage> bare = ReadImage(Path("alone.png"));
  ASSERT_TRUE(bare.ok());
  EXPECT_EQ(CountColour(*bare, kReferenceFrontRgb), 0);
  EXPECT_GT(CountColour(*bare, kStudyPointRgb), 4 * 15);
  // Nothing finite to draw, or a bad size, is refused.
  EXPECT_FALSE(StudyPlotPng({}, {}, options).ok());
  options.width_px = 10;
  EXPECT_FALSE(StudyPlotPng(points, reference, options).ok());
}

TEST_F(PictureTest, ARunFarPastTheBoundSitsOnTheTimeAxisEdgeInTheStudysForm) {
  // A 6000 s timeout in each set beside a front of 165-380 s and a 400 s
  // bound: the axis ends near what matters, not at 6000 s.
  std::vector<ParetoPlotPoint> reference = StudyPoints();
  reference.push_back({3.6, 6000, false, false, ""});
  std::vector<ParetoPlotPoint> points(2);
  points[0].cost = 12.0;
  points[0].nav_time_s = 380.0;
  points[1].cost = 3.6;
  points[1].nav_time_s = 6000.0;
  points[1].feasible = false;
  StudyPlotOptions options;
  options.time_bounds_s = {400};
  Result<std::string> png = StudyPlotPng(points, reference, options);
  ASSERT_TRUE(png.ok()) << png.status().ToString();
  {
    std::ofstream out(Path("study_clipped.png"), std::ios::binary);
    out << *png;
  }
  Result<RgbImage> img = ReadImage(Path("study_clipped.png"));
  ASSERT_TRUE(img.ok());
  // The dashed 400 s bound: the column about half black (the frame's are
  // wholly black). Past 40 % of the width when the axis ends near 600 s;
  // at 6000 s it would sit at about 7 %.
  int bound_column = -1;
  for (int c = 0; c < img->width_px; ++c) {
    int black = 0;
    for (int r = 0; r < img->height_px; ++r) {
      black += img->At(c, r) == Rgb{0, 0, 0};
    }
    if (black > img->height_px / 4 && black < img->height_px * 3 / 4) {
      bound_column = c;
      break;
    }
  }
  EXPECT_GT(bound_column, img->width_px * 2 / 5) << bound_column;
  // The slow runs are wedges on the right edge, low down (cost 3.6), the
  // campaign's in red; the legend's samples are at the top.
  int red_far_right = 0;
  for (int r = img->height_px / 2; r < img->height_px; ++r) {
    for (int c = bound_column + 100; c < img->width_px; ++c) {
      red_far_right += img->At(c, r) == kStudyPointRgb;
    }
  }
  EXPECT_GT(red_far_right, 10);
}

// Rows in which a shade of `colour` (antialiased lines have few pixels of
// the exact colour) runs, then up to 12 pixels of others with the
// background among them, then the shade again: a hollow mark's sides.
int HollowRows(const RgbImage& img, Rgb colour) {
  auto shade = [&](int c, int r) {
    const Rgb p = img.At(c, r);
    return std::abs(p.r - colour.r) + std::abs(p.g - colour.g) +
               std::abs(p.b - colour.b) <
           120;
  };
  int rows = 0;
  for (int r = 0; r < img.height_px; ++r) {
    bool hollow = false;
    for (int c = 1; c < img.width_px && !hollow; ++c) {
      if (!shade(c - 1, r) || shade(c, r)) continue;
      bool background = false;
      for (int k = c; k < std::min(img.width_px, c + 12); ++k) {
        if (shade(k, r)) {
          hollow = background;
          break;
        }
        background = background || img.At(k, r) == kBackgroundRgb;
      }
    }
    rows += hollow;
  }
  return rows;
}

TEST_F(PictureTest,
       AnInfeasibleTriangleReadsHollowAndTheLegendOnlyWhatIsDrawn) {
  // One infeasible campaign point on a reference dot, another beside it:
  // its triangle and its legend sample are hollow (white inside, hiding
  // the dot under it); with one feasible point alone nothing is hollow,
  // so the legend has no infeasible sample.
  ParetoPlotPoint p{10, 100, false, false, ""};
  auto render = [&](const std::vector<ParetoPlotPoint>& points,
                    const std::string& name) {
    Result<std::string> png = StudyPlotPng(
        points, {{10, 100, true, false, ""}, {30, 300, true, false, ""}}, {});
    EXPECT_TRUE(png.ok());
    std::ofstream(Path(name), std::ios::binary) << *png;
    Result<RgbImage> img = ReadImage(Path(name));
    EXPECT_TRUE(img.ok());
    return img.ok() ? *img : RgbImage{};
  };
  const RgbImage hollow = render({p}, "hollow.png");
  p.feasible = true;
  const RgbImage filled = render({p}, "filled.png");
  EXPECT_GE(HollowRows(hollow, kStudyPointRgb), 4);
  EXPECT_EQ(HollowRows(filled, kStudyPointRgb), 0);
}

TEST_F(PictureTest, ParetoPlotRendersPointsFrontAndConstraints) {
  ParetoPlotOptions options;
  options.horizontal_lines = {400};
  options.title = "robotaxi: cost vs time";
  const std::string path = Path("pareto.png");
  ASSERT_TRUE(RenderParetoPlot(StudyPoints(), path, options).ok());
  Result<RgbImage> img = ReadImage(path);
  ASSERT_TRUE(img.ok()) << img.status().ToString();
  EXPECT_EQ(img->width_px, 1000);
  EXPECT_EQ(img->height_px, 700);
  // The front's points and joining line: far more than the dots alone.
  EXPECT_GT(CountColour(*img, kFrontRgb), 4 * 80 + 300);
  EXPECT_GT(CountColour(*img, kFeasibleRgb), 3 * 20);
  EXPECT_GT(CountColour(*img, kInfeasibleRgb), 5);
  EXPECT_GT(CountColour(*img, kConstraintRgb), 200);  // dashed line
  EXPECT_EQ(img->At(2, 2), kBackgroundRgb);
  EXPECT_EQ(img->At(img->width_px - 3, img->height_px - 3), kBackgroundRgb);

  // Without constraint lines there is no constraint colour at all.
  ASSERT_TRUE(RenderParetoPlot(StudyPoints(), Path("plain.png")).ok());
  Result<RgbImage> plain = ReadImage(Path("plain.png"));
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(CountColour(*plain, kConstraintRgb), 0);
}

TEST_F(PictureTest,
       AStoppedRunAtTheRingedDesignsCostDrawsItsArrowAboveTheRing) {
  // The cheapest design arrives just inside a 90 s bound; a design of the
  // same cost was stopped at the bound. Its arrow shows whole, above the
  // ring, as much of it as of an arrow in the open; drawn through the
  // ring, the dot and the ring would hide part of it.
  auto arrow_pixels = [&](double stopped_cost, const std::string& name) {
    std::vector<ParetoPlotPoint> points = {
        {8.4, 89.85, true, true, "7/1.2/7", true},
        {16.8, 34.9, true, true, "8/2.1/7"},
        {stopped_cost, 90.0, false, false, "", false, true}};
    EXPECT_TRUE(RenderParetoPlot(points, Path(name)).ok());
    Result<RgbImage> img = ReadImage(Path(name));
    EXPECT_TRUE(img.ok());
    return img.ok() ? CountColour(*img, kInfeasibleRgb) : 0;
  };
  const int open = arrow_pixels(12.0, "arrow_open.png");
  const int at_ring = arrow_pixels(8.4, "arrow_at_ring.png");
  EXPECT_GT(open, 20);
  EXPECT_GE(at_ring, open * 95 / 100) << "the ring hides part of the arrow";
}

TEST_F(PictureTest, ParetoPlotKeepsTheFrontReadableBelowFarOutliers) {
  // Feasible designs between 30 and 80 s and one timeout at 6000 s: drawn
  // to scale, the feasible dots would share a few rows at the bottom.
  std::vector<ParetoPlotPoint> points = {{2, 6000, false, false, ""}};
  for (int i = 0; i < 6; ++i) {
    points.push_back({3.0 + i, 80.0 - 10.0 * i, true, false, ""});
  }
  ASSERT_TRUE(RenderParetoPlot(points, Path("outlier.png")).ok());
  Result<RgbImage> img = ReadImage(Path("outlier.png"));
  ASSERT_TRUE(img.ok());
  // Rows with a feasible dot: six separate dots of about 9 rows each (and
  // the legend's sample); squashed, they would share about a dozen rows.
  int rows_with_dots = 0;
  for (int r = 0; r < img->height_px; ++r) {
    for (int c = 0; c < img->width_px; ++c) {
      if (img->At(c, r) == kFeasibleRgb) {
        ++rows_with_dots;
        break;
      }
    }
  }
  EXPECT_GT(rows_with_dots, 40);
  // The timeout is still shown, as an arrow on the top edge.
  EXPECT_GT(CountColour(*img, kInfeasibleRgb), 5);
}

TEST_F(PictureTest, TheLegendListsOnlyTheMarksDrawn) {
  // A front of feasible designs alone: no feasible dot off the front, no
  // infeasible cross, so neither colour anywhere (the legend's samples
  // included).
  std::vector<ParetoPlotPoint> points = {{5, 100, true, true, ""},
                                         {10, 50, true, true, ""}};
  ASSERT_TRUE(RenderParetoPlot(points, Path("front_only.png")).ok());
  Result<RgbImage> front_only = ReadImage(Path("front_only.png"));
  ASSERT_TRUE(front_only.ok());
  // (A stray antialiased pixel of the text may match; a sample is dozens.)
  EXPECT_LT(CountColour(*front_only, kFeasibleRgb), 5);
  EXPECT_LT(CountColour(*front_only, kInfeasibleRgb), 5);
  EXPECT_GT(CountColour(*front_only, kFrontRgb), 100);
  // One run stopped early and nothing else: its arrow, no front.
  ParetoPlotPoint stopped{1, 60, false, false, ""};
  stopped.censored = true;
  ASSERT_TRUE(RenderParetoPlot({stopped}, Path("stopped.png")).ok());
  Result<RgbImage> alone = ReadImage(Path("stopped.png"));
  ASSERT_TRUE(alone.ok());
  EXPECT_LT(CountColour(*alone, kFrontRgb), 5);
  EXPECT_LT(CountColour(*alone, kFeasibleRgb), 5);
  EXPECT_GT(CountColour(*alone, kInfeasibleRgb), 10);  // arrow and sample
}

TEST_F(PictureTest, APointAboveThePlotIsAWedgeUnlikeAStoppedRunsArrow) {
  // The same design far above the rest (a timeout at 6000 s) and stopped
  // early inside the plot: a solid wedge has rows of grey as wide as its
  // base, an arrow only where its lines meet.
  std::vector<ParetoPlotPoint> points;
  for (int i = 0; i < 6; ++i) {
    points.push_back({3.0 + i, 80.0 - 10.0 * i, true, true, ""});
  }
  std::vector<ParetoPlotPoint> above = points, stopped = points;
  above.push_back({2, 6000, false, false, ""});
  ParetoPlotPoint censored{2, 85, false, false, ""};
  censored.censored = true;
  stopped.push_back(censored);
  ASSERT_TRUE(RenderParetoPlot(above, Path("above.png")).ok());
  ASSERT_TRUE(RenderParetoPlot(stopped, Path("arrow.png")).ok());
  Result<RgbImage> wedge = ReadImage(Path("above.png"));
  Result<RgbImage> arrow = ReadImage(Path("arrow.png"));
  ASSERT_TRUE(wedge.ok() && arrow.ok());
  auto widest_run = [](const RgbImage& img) {
    int widest = 0;
    for (int r = 0; r < img.height_px; ++r) {
      int run = 0;
      for (int c = 0; c < img.width_px; ++c) {
        run = img.At(c, r) == kInfeasibleRgb ? run + 1 : 0;
        widest = std::max(widest, run);
      }
    }
    return widest;
  };
  EXPECT_GE(widest_run(*wedge), 12);
  EXPECT_LE(widest_run(*arrow), 10);
}

TEST_F(PictureTest, AFrontLabelGoesWhereItHidesNoOtherDesign) {
  // A dominated design just above and right of a front point, where that
  // point's label would go (its right is the staircase's): the label takes
  // another place, and every pixel of the design's dot stays in sight.
  std::vector<ParetoPlotPoint> points = {{5, 100, true, true, "5/1.5/7"},
                                         {5.3, 103, true, false, ""},
                                         {10, 50, true, true, "10/2.1/7"}};
  RgbImage labelled, unlabelled;
  ASSERT_NO_FATAL_FAILURE(
      RenderWithAndWithoutLabels(points, "labelled", &labelled, &unlabelled));
  EXPECT_GT(CountColour(unlabelled, kFeasibleRgb), 40);
  EXPECT_EQ(CountColour(labelled, kFeasibleRgb),
            CountColour(unlabelled, kFeasibleRgb));
}

TEST_F(PictureTest, FrontLabelsNeverOverlapOneAnother) {
  // Two front designs a few pixels apart, the second inside the place the
  // first one's label takes: the second label goes elsewhere or is left
  // out (and counted), never over the first, whose text stays whole (a
  // label drawn over another garbled both: "1?/1.2/7").
  const ParetoPlotPoint a{5.0, 100.0, true, true, "14/1.2/7"};
  const ParetoPlotPoint b{5.04, 99.7, true, true, "17/1/7"};
  // The front's last point close by in cost (no staircase to the right of
  // the two), a dominated design far off setting the scale.
  const ParetoPlotPoint far{5.1, 50.0, true, true, ""};
  const ParetoPlotPoint scale{10.0, 120.0, true, false, ""};
  ParetoPlotPoint a_bare = a, b_bare = b;
  a_bare.label.clear();
  b_bare.label.clear();
  auto render = [&](const std::vector<ParetoPlotPoint>& points,
                    const std::string& name) {
    EXPECT_TRUE(RenderParetoPlot(points, Path(name)).ok());
    Result<RgbImage> img = ReadImage(Path(name));
    EXPECT_TRUE(img.ok());
    return img.ok() ? *img : RgbImage{};
  };
  const RgbImage none = render({a_bare, b_bare, far, scale}, "none.png");
  const RgbImage only_a = render({a, b_bare, far, scale}, "only_a.png");
  const RgbImage both = render({a, b, far, scale}, "both.png");
  ASSERT_EQ(none.width_px, both.width_px);
  int a_text = 0, a_changed = 0;
  for (int r = 0; r < none.height_px; ++r) {
    for (int c = 0; c < none.width_px; ++c) {
      if (only_a.At(c, r) == none.At(c, r)) continue;  // not A's label
      ++a_text;
      a_changed += both.At(c, r) != only_a.At(c, r);
    }
  }
  EXPECT_GT(a_text, 100);
  EXPECT_EQ(a_changed, 0);
}

TEST_F(PictureTest, ARingedDesignsRingStaysWholeBesideItsLabel) {
  // The ringed design is the front's last, so its label takes the place
  // to its right, where the ring is; a dominated design far off sets the
  // scale.
  std::vector<ParetoPlotPoint> points = {{5, 100, true, true, "6/1.5/7"},
                                         {10, 50, true, true, "10/2.1/7"},
                                         {20, 120, true, false, ""}};
  points[1].highlight = true;
  RgbImage labelled, bare;
  ASSERT_NO_FATAL_FAILURE(
      RenderWithAndWithoutLabels(points, "ringed", &labelled, &bare));
  // The ring is the picture's only black besides the frame, the ticks and
  // the axes' text, which the labels (dark grey) leave alone.
  EXPECT_EQ(CountColour(labelled, Rgb{0, 0, 0}),
            CountColour(bare, Rgb{0, 0, 0}));
}

TEST_F(PictureTest, FrontDesignsThatTieShareOneLabelNamingThemAll) {
  // 4 cores at 3 GHz and 6 at 2 GHz: the same cost and time, one marker.
  // The picture is the one drawn with a single label naming both, not two
  // labels placed apart (which would say nothing of which one the marker
  // is) nor one hiding the other.
  std::vector<ParetoPlotPoint> tied = {{12, 47.55, true, true, "4/3"},
                                       {12, 47.55, true, true, "6/2"},
                                       {9, 80, true, true, "3/3"},
                                       {20, 40, true, true, "10/2"}};
  std::vector<ParetoPlotPoint> joined = tied;
  joined[0].label = "4/3, 6/2";
  joined[1].label.clear();
  Result<std::string> tied_png = ParetoPlotPng(tied);
  Result<std::string> joined_png = ParetoPlotPng(joined);
  ASSERT_TRUE(tied_png.ok() && joined_png.ok());
  EXPECT_TRUE(*tied_png == *joined_png);
  // And the joined label is drawn: more text than with one name alone.
  std::vector<ParetoPlotPoint> one_name = joined;
  one_name[0].label = "4/3";
  Result<std::string> one_png = ParetoPlotPng(one_name);
  ASSERT_TRUE(one_png.ok());
  EXPECT_FALSE(*one_png == *joined_png);

  // Four copies of one design (a knob that changes nothing): two named,
  // the others counted.
  std::vector<ParetoPlotPoint> copies = {{12, 47.55, true, true, "6/2/1"},
                                         {12, 47.55, true, true, "6/2/2"},
                                         {12, 47.55, true, true, "6/2/3"},
                                         {12, 47.55, true, true, "6/2/4"},
                                         {20, 40, true, true, "10/2/1"}};
  std::vector<ParetoPlotPoint> counted = copies;
  counted[0].label = "6/2/1, 6/2/2 +2 more";
  for (int i = 1; i < 4; ++i) counted[i].label.clear();
  Result<std::string> copies_png = ParetoPlotPng(copies);
  Result<std::string> counted_png = ParetoPlotPng(counted);
  ASSERT_TRUE(copies_png.ok() && counted_png.ok());
  EXPECT_TRUE(*copies_png == *counted_png);
}

TEST_F(PictureTest, EveryFeasibleDesignWhoseRunsDisagreeIsRingedAndNamed) {
  // A front point and a dominated design, each stable or not: every
  // unstable feasible design adds a violet ring, the first one also the
  // legend's sample; an infeasible one gets none.
  auto render = [&](bool front_unstable, bool other_unstable,
                    bool infeasible_unstable, const std::string& name) {
    std::vector<ParetoPlotPoint> points = {{5, 100, true, true, "5/1.5/7"},
                                           {8, 110, true, false, ""},
                                           {3, 120, false, false, ""},
                                           {10, 50, true, true, "10/2.1/7"}};
    points[0].unstable = front_unstable;
    points[1].unstable = other_unstable;
    points[2].unstable = infeasible_unstable;
    EXPECT_TRUE(RenderParetoPlot(points, Path(name)).ok());
    Result<RgbImage> img = ReadImage(Path(name));
    EXPECT_TRUE(img.ok());
    return img.ok() ? CountColour(*img, kUnstableRgb) : -1;
  };
  const int none = render(false, false, true, "stable.png");
  const int one = render(true, false, false, "one.png");
  const int two = render(true, true, false, "two.png");
  EXPECT_EQ(none, 0);
  EXPECT_GT(one, 20);
  // `one` is the front point's ring and the legend's sample; `two` adds
  // the dominated design's ring.
  EXPECT_GT(two, one + 10);
}

TEST_F(PictureTest, ParetoPlotEdgeCases) {
  // One point; equal values; non-finite points left out with a note.
  EXPECT_TRUE(
      RenderParetoPlot({{5, 100, true, true, "only"}}, Path("one.png")).ok());
  std::vector<ParetoPlotPoint> points = {{5, 100, true, true, ""},
                                         {5, 100, true, true, ""},
                                         {6, INFINITY, false, false, ""},
                                         {NAN, 3, false, false, ""}};
  ParetoPlotOptions options;
  options.width_px = 300;
  options.height_px = 300;
  options.y_label = std::string(500, 'y');  // longer than the plot
  options.vertical_lines = {NAN, 4};
  EXPECT_TRUE(RenderParetoPlot(points, Path("same.png"), options).ok());
  Result<RgbImage> img = ReadImage(Path("same.png"));
  ASSERT_TRUE(img.ok());
  EXPECT_EQ(img->width_px, 300);
  ParetoPlotOptions big_options;
  big_options.width_px = big_options.height_px = 4000;
  Result<std::string> big = ParetoPlotPng(StudyPoints(), big_options);
  EXPECT_TRUE(big.ok()) << big.status().ToString();
}

TEST_F(PictureTest, ParetoPlotErrorsLeaveNoFile) {
  EXPECT_EQ(RenderParetoPlot({}, Path("empty.png")).code(),
            Status::Code::kInvalidArgument);
  EXPECT_EQ(
      RenderParetoPlot({{NAN, 1, true, true, ""}}, Path("nan.png")).code(),
      Status::Code::kInvalidArgument);
  ParetoPlotOptions tiny;
  tiny.width_px = 100;
  EXPECT_EQ(RenderParetoPlot(StudyPoints(), Path("tiny.png"), tiny).code(),
            Status::Code::kInvalidArgument);
  EXPECT_TRUE(Listing().empty());
  fs::create_directories(Path("taken.png"));
  EXPECT_FALSE(RenderParetoPlot(StudyPoints(), Path("taken.png")).ok());
  EXPECT_EQ(Listing(), std::vector<std::string>{"taken.png"});
}

}  // namespace
}  // namespace adse::analysis
