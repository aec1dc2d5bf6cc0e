#include "stack/algorithms/reeds_shepp.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <string>

namespace adse::algorithms {
namespace {

using geometry::Pose2;

double AngleDiff(double a, double b) { return std::remainder(a - b, 2 * M_PI); }

// "L+S-R+": the word of a path, for counting distinct words.
std::string Word(const ReedsSheppPath& path) {
  std::string w;
  for (const RsSegment& s : path.segments) {
    w += s.steer == SteerKind::kLeft    ? "L"
         : s.steer == SteerKind::kRight ? "R"
                                        : "S";
    w += s.length_m < 0 ? "-" : "+";
  }
  return w;
}

TEST(ReedsShepp, EveryCandidateEndsAtTheGoal) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> xy(-12.0, 12.0);
  std::uniform_real_distribution<double> yaw(-M_PI, M_PI);
  std::set<std::string> words;
  for (int i = 0; i < 3000; ++i) {
    const Pose2 from{xy(rng), xy(rng), yaw(rng)};
    const Pose2 to{xy(rng), xy(rng), yaw(rng)};
    const std::vector<ReedsSheppPath> paths =
        ReedsSheppCandidates(from, to, 4.5);
    ASSERT_FALSE(paths.empty());
    for (size_t k = 0; k < paths.size(); ++k) {
      const std::vector<GearedPose> poses =
          SampleReedsShepp(from, paths[k], 4.5, 0.3);
      const Pose2& end = poses.back().pose;
      ASSERT_NEAR(end.x_m, to.x_m, 1e-6) << Word(paths[k]);
      ASSERT_NEAR(end.y_m, to.y_m, 1e-6) << Word(paths[k]);
      ASSERT_NEAR(AngleDiff(end.yaw_rad, to.yaw_rad), 0.0, 1e-6)
          << Word(paths[k]);
      if (k > 0) {
        EXPECT_LE(paths[k - 1].length_m(), paths[k].length_m());
      }
      words.insert(Word(paths[k]));
    }
    EXPECT_GE(paths.front().length_m() + 1e-9,
              std::hypot(to.x_m - from.x_m, to.y_m - from.y_m));
  }
  // All five families with their mirror images and reversals: dozens of
  // distinct words, so no solver is silently dead.
  EXPECT_GE(words.size(), 40u);
}

TEST(ReedsShepp, StraightAheadAndStraightBack) {
  const Pose2 from{1.0, 2.0, 0.3};
  const Pose2 ahead{1.0 + 6 * std::cos(0.3), 2.0 + 6 * std::sin(0.3), 0.3};
  ReedsSheppPath best = ReedsSheppCandidates(from, ahead, 5.0).front();
  ASSERT_EQ(best.segments.size(), 1u);
  EXPECT_EQ(best.segments[0].steer, SteerKind::kStraight);
  EXPECT_NEAR(best.segments[0].length_m, 6.0, 1e-9);

  const Pose2 behind{1.0 - 4 * std::cos(0.3), 2.0 - 4 * std::sin(0.3), 0.3};
  best = ReedsSheppCandidates(from, behind, 5.0).front();
  ASSERT_EQ(best.segments.size(), 1u);
  EXPECT_NEAR(best.segments[0].length_m, -4.0, 1e-9);
  EXPECT_EQ(best.gear_changes(), 0);
  const std::vector<GearedPose> poses = SampleReedsShepp(from, best, 5.0, 0.5);
  EXPECT_EQ(poses.size(), 9u);
  for (const GearedPose& p : poses) EXPECT_TRUE(p.reverse);
}

TEST(ReedsShepp, SidewaysShiftNeedsAGearChange) {
  // One car length to the side with the same heading: no forward-only
  // path this short exists, the shortest turns back and forth.
  const Pose2 from{0, 0, 0};
  const Pose2 to{0, 2.5, 0};
  const ReedsSheppPath best = ReedsSheppCandidates(from, to, 5.0).front();
  EXPECT_GE(best.gear_changes(), 1);
  EXPECT_LT(best.length_m(), 2 * M_PI * 5.0);
  EXPECT_NEAR(ReedsSheppDistance(from, to, 5.0), best.length_m(), 1e-12);
}

TEST(ReedsShepp, AdvanceArcQuarterTurn) {
  const Pose2 p = AdvanceArc(Pose2{0, 0, 0}, 1.0 / 4.0, M_PI / 2 * 4.0);
  EXPECT_NEAR(p.x_m, 4.0, 1e-9);
  EXPECT_NEAR(p.y_m, 4.0, 1e-9);
  EXPECT_NEAR(p.yaw_rad, M_PI / 2, 1e-9);
  // In reverse on the same circle: the mirror image behind.
  const Pose2 q = AdvanceArc(Pose2{0, 0, 0}, 1.0 / 4.0, -M_PI / 2 * 4.0);
  EXPECT_NEAR(q.x_m, -4.0, 1e-9);
  EXPECT_NEAR(q.y_m, 4.0, 1e-9);
  EXPECT_NEAR(q.yaw_rad, -M_PI / 2, 1e-9);
}

}  // namespace
}  // namespace adse::algorithms
