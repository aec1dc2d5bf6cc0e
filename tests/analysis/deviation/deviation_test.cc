#include "analysis/deviation/deviation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <vector>

namespace adse::analysis {
namespace {

constexpr double kLaneWidthM = 3.5;
constexpr double kHalfLaneM = kLaneWidthM / 2.0;
constexpr double kPi = 3.14159265358979323846;
constexpr double kSpeedMps = 5.0;

// A polyline with its arc-length parametrisation, used to synthesise
// trajectories with a known lateral error.
struct TestPath {
  std::vector<Eigen::Vector2d> points;

  double Length() const {
    double l = 0.0;
    for (size_t k = 1; k < points.size(); ++k) {
      l += (points[k] - points[k - 1]).norm();
    }
    return l;
  }
  // Point at arc length s and the left normal of its segment.
  void At(double s, Eigen::Vector2d* p, Eigen::Vector2d* n) const {
    *p = points.back();
    *n = Eigen::Vector2d(0.0, 1.0);
    for (size_t k = 1; k < points.size(); ++k) {
      const double len = (points[k] - points[k - 1]).norm();
      if (s <= len || k + 1 == points.size()) {
        const Eigen::Vector2d dir = (points[k] - points[k - 1]) / len;
        *p = points[k - 1] + std::min(s, len) * dir;
        *n = Eigen::Vector2d(-dir.y(), dir.x());
        return;
      }
      s -= len;
    }
  }
};

TestPath Straight() { return {{{0.0, 0.0}, {300.0, 0.0}}}; }

// Left turn: 150 m east, then 150 m north.
TestPath LShape() { return {{{0.0, 0.0}, {150.0, 0.0}, {150.0, 150.0}}}; }

// Counter-clockwise 270-degree arc of radius 50 m, a vertex every degree.
TestPath Arc() {
  TestPath path;
  for (int deg = 0; deg <= 270; ++deg) {
    const double a = deg * kPi / 180.0;
    path.points.emplace_back(50.0 * std::sin(a), 50.0 - 50.0 * std::cos(a));
  }
  return path;
}

// Sample times: every `dt_s`, or random steps in [0.01, 0.3] s when
// `irregular`.
std::vector<double> Times(double duration_s, bool irregular,
                          double dt_s = 0.05) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> step(0.01, 0.3);
  std::vector<double> t;
  for (double x = 0.0; x <= duration_s; x += irregular ? step(rng) : dt_s) {
    t.push_back(x);
  }
  return t;
}

// Drives `path` with arc length s(t) and lateral offset lat(t) (left +).
std::vector<TimedXy> Drive(const TestPath& path, const std::vector<double>& t,
                           const std::function<double(double)>& s_of_t,
                           const std::function<double(double)>& lat_of_t) {
  std::vector<TimedXy> out;
  for (double ti : t) {
    Eigen::Vector2d p = Eigen::Vector2d::Zero();
    Eigen::Vector2d n = Eigen::Vector2d::Zero();
    path.At(s_of_t(ti), &p, &n);
    p += lat_of_t(ti) * n;
    out.push_back({ti, p.x(), p.y()});
  }
  return out;
}

// Full-length drive at constant speed.
std::vector<TimedXy> DriveAll(const TestPath& path, bool irregular,
                              const std::function<double(double)>& lat) {
  const double length = path.Length();
  return Drive(
      path, Times(length / kSpeedMps, irregular),
      [](double t) { return kSpeedMps * t; }, lat);
}

double Zero(double) { return 0.0; }
double LeftHalfMetre(double) { return 0.5; }
double Weave(double t) { return 0.4 * std::sin(2.0 * kPi * t / 4.0); }

DeviationResult Fit(const TestPath& path, const std::vector<TimedXy>& actual) {
  Result<DeviationResult> r = FitDeviation(path.points, actual, kLaneWidthM);
  EXPECT_TRUE(r.ok()) << r.status().ToString();
  if (!r.ok()) return {};
  return std::move(r).value();
}

void ExpectMonotone(const DeviationResult& r) {
  for (size_t i = 1; i < r.s_m.size(); ++i) {
    ASSERT_LE(r.s_m[i - 1], r.s_m[i]) << "at sample " << i;
  }
}

struct Case {
  const char* name;
  TestPath (*path)();
};
const Case kCases[] = {
    {"straight", Straight}, {"l_shape", LShape}, {"arc", Arc}};

TEST(DeviationTest, ExactTrajectoryScoresZero) {
  for (const Case& c : kCases) {
    for (bool irregular : {false, true}) {
      SCOPED_TRACE(testing::Message() << c.name << " irregular=" << irregular);
      const TestPath path = c.path();
      const std::vector<TimedXy> actual = DriveAll(path, irregular, Zero);
      const DeviationResult r = Fit(path, actual);
      EXPECT_LT(r.deviation_score, 0.005);
      EXPECT_LT(r.mean_abs_lateral_m, 0.005);
      // The L's sharp corner is rounded by a fillet that cuts it by 0.35 m
      // (no vehicle drives a sharp corner); elsewhere the fit is exact.
      EXPECT_LT(r.max_deviation_m, c.path == LShape ? 0.36 : 0.01);
      EXPECT_NEAR(r.offset_m, 0.0, 0.005);
      EXPECT_LT(r.zigzag_index, 0.05);
      EXPECT_TRUE(r.complete);
      EXPECT_NEAR(r.driven_fraction, 1.0, 0.01);
      EXPECT_TRUE(r.converged);
      ASSERT_EQ(r.s_m.size(), actual.size());
      ASSERT_EQ(r.lateral_m.size(), actual.size());
      ASSERT_EQ(r.smooth_lateral_m.size(), actual.size());
      ExpectMonotone(r);
      // The fitted arc length is the one the trajectory was made with.
      for (size_t i = 0; i < actual.size(); i += 50) {
        EXPECT_NEAR(r.s_m[i], kSpeedMps * actual[i].t_s, 0.05) << i;
      }
    }
  }
}

TEST(DeviationTest, ConstantLeftOffset) {
  for (const Case& c : kCases) {
    for (bool irregular : {false, true}) {
      SCOPED_TRACE(testing::Message() << c.name << " irregular=" << irregular);
      const TestPath path = c.path();
      const DeviationResult r =
          Fit(path, DriveAll(path, irregular, LeftHalfMetre));
      EXPECT_NEAR(r.offset_m, 0.5, 0.03);
      EXPECT_NEAR(r.mean_abs_lateral_m, 0.5, 0.03);
      EXPECT_NEAR(r.deviation_score, 0.5 / kHalfLaneM, 0.02);
      EXPECT_LT(r.oscillation_rms_m, 0.03);
      EXPECT_LT(r.zigzag_index, 0.05);
      EXPECT_TRUE(r.complete);
      ExpectMonotone(r);
    }
  }
}

TEST(DeviationTest, RightOffsetIsNegative) {
  const TestPath path = LShape();
  const DeviationResult r =
      Fit(path, DriveAll(path, false, [](double) { return -0.3; }));
  EXPECT_NEAR(r.offset_m, -0.3, 0.03);
  EXPECT_NEAR(r.mean_abs_lateral_m, 0.3, 0.03);
  EXPECT_NEAR(r.deviation_score, 0.3 / kHalfLaneM, 0.02);
}

TEST(DeviationTest, WeaveIsOscillationNotOffset) {
  for (const Case& c : kCases) {
    for (bool irregular : {false, true}) {
      SCOPED_TRACE(testing::Message() << c.name << " irregular=" << irregular);
      const TestPath path = c.path();
      const DeviationResult weave = Fit(path, DriveAll(path, irregular, Weave));
      const DeviationResult offset =
          Fit(path, DriveAll(path, irregular, LeftHalfMetre));
      const double rms = 0.4 / std::sqrt(2.0);
      EXPECT_NEAR(weave.oscillation_rms_m, rms, 0.15 * rms);
      EXPECT_NEAR(weave.offset_m, 0.0, 0.05);
      // Mean |0.4 sin| = 0.8 / pi.
      EXPECT_NEAR(weave.mean_abs_lateral_m, 0.8 / kPi, 0.03);
      EXPECT_NEAR(weave.max_deviation_m, 0.4, 0.05);
      // Two reversals per 4 s period.
      EXPECT_NEAR(weave.zigzag_index, 0.5, 0.05);
      EXPECT_GT(weave.zigzag_index, offset.zigzag_index + 0.3);
      ExpectMonotone(weave);
    }
  }
}

TEST(DeviationTest, WeaveAroundAnOffset) {
  const TestPath path = Straight();
  const DeviationResult r =
      Fit(path, DriveAll(path, false, [](double t) { return 0.5 + Weave(t); }));
  EXPECT_NEAR(r.offset_m, 0.5, 0.03);
  EXPECT_NEAR(r.oscillation_rms_m, 0.4 / std::sqrt(2.0), 0.04);
  // Smooth part follows the offset, not the weave.
  for (size_t i = 200; i + 200 < r.smooth_lateral_m.size(); i += 100) {
    EXPECT_NEAR(r.smooth_lateral_m[i], 0.5, 0.05) << i;
  }
}

TEST(DeviationTest, StoppingHalfwayIsIncomplete) {
  for (const Case& c : kCases) {
    for (bool irregular : {false, true}) {
      SCOPED_TRACE(testing::Message() << c.name << " irregular=" << irregular);
      const TestPath path = c.path();
      const double half = 0.5 * path.Length();
      // Drives half the path, then stands for 20 s.
      const std::vector<TimedXy> actual = Drive(
          path, Times(half / kSpeedMps + 20.0, irregular),
          [&](double t) { return std::min(kSpeedMps * t, half); },
          LeftHalfMetre);
      const DeviationResult r = Fit(path, actual);
      EXPECT_FALSE(r.complete);
      EXPECT_NEAR(r.driven_fraction, 0.5, 0.01);
      // Scored on the driven half.
      EXPECT_NEAR(r.offset_m, 0.5, 0.03);
      EXPECT_NEAR(r.deviation_score, 0.5 / kHalfLaneM, 0.02);
      ExpectMonotone(r);
    }
  }
}

TEST(DeviationTest, StandingStillKeepsArcLengthMonotone) {
  const TestPath path = LShape();
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.02);
  // 40 s at 20 Hz standing 10 m before the corner, with 2 cm position noise
  // (which alone would make the projection step back and forth).
  std::vector<TimedXy> actual = Drive(
      path, Times(80.0, false),
      [](double t) {
        return t < 28.0 ? kSpeedMps * t
                        : (t < 68.0 ? 140.0 : 140.0 + kSpeedMps * (t - 68.0));
      },
      Zero);
  for (TimedXy& a : actual) {
    a.x_m += noise(rng);
    a.y_m += noise(rng);
  }
  const DeviationResult r = Fit(path, actual);
  ExpectMonotone(r);
  EXPECT_LT(r.mean_abs_lateral_m, 0.03);
  EXPECT_LT(r.max_deviation_m, 0.45);  // the corner's fillet plus noise
  EXPECT_NEAR(r.s_m[static_cast<size_t>(48.0 / 0.05)], 140.0, 0.05);
  EXPECT_FALSE(r.complete);
  EXPECT_NEAR(r.driven_fraction, 200.0 / 300.0, 0.01);
}

TEST(DeviationTest, PathPassingTheSamePlaceTwice) {
  // A square loop that ends where it starts, then goes once more along its
  // first side: s must follow the order, not jump to the second pass.
  TestPath path{{{0.0, 0.0},
                 {60.0, 0.0},
                 {60.0, 60.0},
                 {0.0, 60.0},
                 {0.0, 0.0},
                 {60.0, 0.0}}};
  const std::vector<TimedXy> actual = DriveAll(path, false, LeftHalfMetre);
  const DeviationResult r = Fit(path, actual);
  ExpectMonotone(r);
  for (size_t i = 0; i < actual.size(); i += 20) {
    EXPECT_NEAR(r.s_m[i], kSpeedMps * actual[i].t_s, 0.6) << i;
  }
  EXPECT_TRUE(r.complete);
  EXPECT_NEAR(r.offset_m, 0.5, 0.03);
}

TEST(DeviationTest, IdealPathFromAReferenceRun) {
  // The ideal path can be a run at the best configuration: dense (20 Hz at
  // 5 m/s), slightly noisy, with a 5 s stop (a cloud of near-duplicates).
  const TestPath arc = Arc();
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.01);
  TestPath reference;
  const std::vector<double> t = Times(arc.Length() / kSpeedMps + 5.0, false);
  for (const TimedXy& a : Drive(
           arc, t,
           [&](double ti) {
             const double s = kSpeedMps * ti;
             return s < 100.0 ? s : std::max(100.0, s - 5.0 * kSpeedMps);
           },
           Zero)) {
    reference.points.emplace_back(a.x_m + noise(rng), a.y_m + noise(rng));
  }
  const DeviationResult r = Fit(reference, DriveAll(arc, true, LeftHalfMetre));
  EXPECT_NEAR(r.offset_m, 0.5, 0.03);
  EXPECT_NEAR(r.mean_abs_lateral_m, 0.5, 0.03);
  EXPECT_LT(r.oscillation_rms_m, 0.03);
  EXPECT_LT(r.zigzag_index, 0.05);
  EXPECT_TRUE(r.complete);
  ExpectMonotone(r);
}

TEST(DeviationTest, MeansArePerMetreDriven) {
  const TestPath path = Straight();
  // 60 s waiting centred at the start does not dilute the 0.5 m driven.
  const std::vector<TimedXy> waited = Drive(
      path, Times(60.0 + path.Length() / kSpeedMps, false),
      [](double t) { return std::max(0.0, kSpeedMps * (t - 60.0)); },
      [](double t) { return t < 60.0 ? 0.0 : 0.5; });
  const DeviationResult w = Fit(path, waited);
  EXPECT_NEAR(w.mean_abs_lateral_m, 0.5, 0.02);
  // An 8 m excursion over 60 m of the 300 m: area / length = 1.6 m.
  const DeviationResult x = Fit(path, DriveAll(path, false, [](double t) {
                                  return t >= 20.0 && t < 32.0 ? 8.0 : 0.0;
                                }));
  EXPECT_NEAR(x.mean_abs_lateral_m, 1.6, 0.05);
  EXPECT_NEAR(x.max_deviation_m, 8.0, 1e-6);
  EXPECT_TRUE(x.complete);
  ExpectMonotone(x);
  // Single-sample 5 m spikes (1 in 50) weigh like any other sample.
  std::vector<TimedXy> spiky = DriveAll(path, false, Zero);
  for (size_t i = 25; i < spiky.size(); i += 50) spiky[i].y_m += 5.0;
  const DeviationResult p = Fit(path, spiky);
  EXPECT_NEAR(p.mean_abs_lateral_m, 5.0 / 50.0, 0.01);
  EXPECT_NEAR(p.max_deviation_m, 5.0, 1e-3);
  ExpectMonotone(p);
}

TEST(DeviationTest, NormalizeByOverridesLaneWidth) {
  const TestPath path = Straight();
  DeviationOptions options;
  options.normalize_by_m = 2.0;
  Result<DeviationResult> r = FitDeviation(
      path.points, DriveAll(path, false, LeftHalfMetre), 0.0, options);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_NEAR(r->deviation_score, 0.25, 0.01);
  EXPECT_DOUBLE_EQ(r->normalizer_m, 2.0);
}

TEST(DeviationTest, ScoreIsClampedToOne) {
  const TestPath path = Straight();
  const DeviationResult r =
      Fit(path, DriveAll(path, false, [](double) { return 4.0; }));
  EXPECT_DOUBLE_EQ(r.deviation_score, 1.0);
  EXPECT_NEAR(r.mean_abs_lateral_m, 4.0, 0.05);
}

TEST(DeviationTest, SingleSample) {
  const TestPath path = Straight();
  Result<DeviationResult> r =
      FitDeviation(path.points, {{0.0, 10.0, 1.0}}, kLaneWidthM);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_NEAR(r->s_m[0], 10.0, 1e-6);
  EXPECT_NEAR(r->lateral_m[0], 1.0, 1e-6);
  EXPECT_NEAR(r->mean_abs_lateral_m, 1.0, 1e-6);
  EXPECT_EQ(r->zigzag_index, 0.0);
}

TEST(DeviationTest, BadInputsAreInvalidArguments) {
  const TestPath path = Straight();
  const std::vector<TimedXy> good = {{0.0, 0.0, 0.0}, {1.0, 5.0, 0.0}};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto expect_invalid = [](const Result<DeviationResult>& r,
                           const std::string& needle) {
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().code(), Status::Code::kInvalidArgument);
    EXPECT_NE(r.status().message().find(needle), std::string::npos)
        << r.status().message();
  };
  expect_invalid(FitDeviation({{0.0, 0.0}}, good, kLaneWidthM),
                 "at least 2 points");
  expect_invalid(FitDeviation({{1.0, 1.0}, {1.0, 1.0}}, good, kLaneWidthM),
                 "zero length");
  expect_invalid(FitDeviation({{0.0, 0.0}, {nan, 1.0}}, good, kLaneWidthM),
                 "not finite");
  expect_invalid(FitDeviation(path.points, {}, kLaneWidthM), "empty");
  expect_invalid(FitDeviation(path.points, {{0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}},
                              kLaneWidthM),
                 "times must increase");
  expect_invalid(FitDeviation(path.points, {{1.0, 0.0, 0.0}, {0.5, 1.0, 0.0}},
                              kLaneWidthM),
                 "times must increase");
  expect_invalid(FitDeviation(path.points, {{0.0, 0.0, 0.0}, {1.0, nan, 0.0}},
                              kLaneWidthM),
                 "not finite");
  expect_invalid(FitDeviation(path.points, {{nan, 0.0, 0.0}}, kLaneWidthM),
                 "not finite");
  expect_invalid(FitDeviation(path.points, good, 0.0), "lane_width_m");
  expect_invalid(FitDeviation(path.points, good, nan), "lane_width_m");
  DeviationOptions options;
  options.smoothing_window_s = 0.0;
  expect_invalid(FitDeviation(path.points, good, kLaneWidthM, options),
                 "smoothing_window_s");
  options = {};
  options.max_iterations = 0;
  expect_invalid(FitDeviation(path.points, good, kLaneWidthM, options),
                 "max_iterations");
  options = {};
  options.normalize_by_m = -1.0;
  expect_invalid(FitDeviation(path.points, good, kLaneWidthM, options),
                 "normalize_by_m");
}

}  // namespace
}  // namespace adse::analysis
