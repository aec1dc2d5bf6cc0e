// The comparison chart of `adse profile check`: bars as long as the values.
#include "analysis/pictures/pictures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <vector>

#include "tests/analysis/pictures/picture_testing.h"

namespace adse::analysis {
namespace {

namespace fs = std::filesystem;
using testing::PictureTest;

TEST_F(PictureTest, AComparisonChartDrawsLongerBarsForLargerValues) {
  const std::vector<ComparisonRow> rows = {{"sensing", 84.7, 85.1},
                                           {"sensing_to_control", 182.5, 370.5},
                                           {"no source", 12.0, std::nullopt}};
  ComparisonChartOptions o;
  o.title = "check";
  ASSERT_TRUE(RenderComparisonChart(rows, o, Path("c.png")).ok());
  Result<RgbImage> img = ReadImage(Path("c.png"));
  ASSERT_TRUE(img.ok()) << img.status().ToString();
  EXPECT_EQ(img->width_px, 1000);
  // Each bar's length in one pixel row through it.
  auto bar_px = [&](int row, Rgb colour) {
    int n = 0;
    for (int c = 0; c < img->width_px; ++c) n += img->At(c, row) == colour;
    return n;
  };
  std::vector<int> adse, measured;
  for (int r = 0; r < img->height_px; ++r) {
    const int a = bar_px(r, kAdseBarRgb), m = bar_px(r, kReferenceBarRgb);
    if (a > 0 && (adse.empty() || a != adse.back())) adse.push_back(a);
    if (m > 0 && (measured.empty() || m != measured.back()))
      measured.push_back(m);
  }
  // Legend swatch, then the three adse bars; swatch, then two references.
  ASSERT_EQ(adse.size(), 4u) << ::testing::PrintToString(adse);
  ASSERT_EQ(measured.size(), 3u) << ::testing::PrintToString(measured);
  EXPECT_NEAR(static_cast<double>(adse[2]) / adse[1], 182.5 / 84.7, 0.05);
  EXPECT_NEAR(static_cast<double>(measured[2]) / measured[1], 370.5 / 85.1,
              0.05);
  EXPECT_LT(adse[3], adse[1]);

  // The axis ends one round step past the longest bar (0-250 for 216.5):
  // that bar spans most of the plot, not half of it.
  ASSERT_TRUE(RenderComparisonChart({{"ndt", 216.5, 199.9}, {"ekf", 3.4, 3.6}},
                                    o, Path("tight.png"))
                  .ok());
  Result<RgbImage> tight = ReadImage(Path("tight.png"));
  ASSERT_TRUE(tight.ok()) << tight.status().ToString();
  int longest = 0;
  for (int r = 0; r < tight->height_px; ++r) {
    int n = 0;
    for (int c = 0; c < tight->width_px; ++c) {
      n += tight->At(c, r) == kAdseBarRgb;
    }
    longest = std::max(longest, n);
  }
  EXPECT_GT(longest, tight->width_px / 2);

  EXPECT_FALSE(RenderComparisonChart({}, o, Path("none.png")).ok());
  EXPECT_FALSE(
      RenderComparisonChart({{"bad", -1.0, 2.0}}, o, Path("bad.png")).ok());
  EXPECT_FALSE(fs::exists(Path("none.png")));
  EXPECT_FALSE(fs::exists(Path("bad.png")));
}

}  // namespace
}  // namespace adse::analysis
