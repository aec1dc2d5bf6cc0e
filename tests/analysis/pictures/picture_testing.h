// What the picture tests share: a fixture with a scratch folder, and
// probes of decoded pixels by colour.
#ifndef ADSE_TESTS_ANALYSIS_PICTURES_PICTURE_TESTING_H_
#define ADSE_TESTS_ANALYSIS_PICTURES_PICTURE_TESTING_H_

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "analysis/pictures/pictures.h"
#include "tests/analysis/testing/temp_dir_test.h"

namespace adse::analysis::testing {

inline std::string Name(Rgb c) {
  return "rgb(" + std::to_string(c.r) + "," + std::to_string(c.g) + "," +
         std::to_string(c.b) + ")";
}

// True if some pixel within `radius` of (column, row) has exactly `colour`.
inline bool ColourNear(const RgbImage& img, double column, double row,
                       Rgb colour, int radius = 1) {
  const int c0 = static_cast<int>(std::lround(column));
  const int r0 = static_cast<int>(std::lround(row));
  for (int r = r0 - radius; r <= r0 + radius; ++r) {
    for (int c = c0 - radius; c <= c0 + radius; ++c) {
      if (r >= 0 && c >= 0 && r < img.height_px && c < img.width_px &&
          img.At(c, r) == colour) {
        return true;
      }
    }
  }
  return false;
}

inline int CountColour(const RgbImage& img, Rgb colour) {
  int n = 0;
  for (int r = 0; r < img.height_px; ++r) {
    for (int c = 0; c < img.width_px; ++c) n += img.At(c, r) == colour;
  }
  return n;
}

class PictureTest : public adse::testing::TempDirTest {
 protected:
  std::vector<std::string> Listing() const {
    return TempDirTest::Listing(/*recursive=*/true);
  }

  // `points` drawn as given (`name`.png) and with every label cleared
  // (`name`_bare.png), read back: what differs is what the labels cover.
  // Call under ASSERT_NO_FATAL_FAILURE.
  void RenderWithAndWithoutLabels(std::vector<ParetoPlotPoint> points,
                                  const std::string& name, RgbImage* labelled,
                                  RgbImage* bare) {
    ASSERT_TRUE(RenderParetoPlot(points, Path(name + ".png")).ok());
    for (ParetoPlotPoint& p : points) p.label.clear();
    ASSERT_TRUE(RenderParetoPlot(points, Path(name + "_bare.png")).ok());
    Result<RgbImage> with = ReadImage(Path(name + ".png"));
    Result<RgbImage> without = ReadImage(Path(name + "_bare.png"));
    ASSERT_TRUE(with.ok() && without.ok());
    *labelled = std::move(with).value();
    *bare = std::move(without).value();
  }
};

}  // namespace adse::analysis::testing

#endif  // ADSE_TESTS_ANALYSIS_PICTURES_PICTURE_TESTING_H_
