#include "stack/algorithms/ekf.h"

#include <gtest/gtest.h>

#include <cmath>

#include "stack/base/random.h"
#include "stack/config/stack_config.h"

namespace adse::algorithms {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Matrix3d PoseCov(double pos_std, double yaw_std) {
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  c.diagonal() << pos_std * pos_std, pos_std * pos_std, yaw_std * yaw_std;
  return c;
}

TEST(Ekf, ConvergesToPoseUpdates) {
  Ekf ekf;
  EXPECT_TRUE(ekf.Lost());  // not initialized
  ekf.Initialize(geometry::Pose2{0, 0, 0}, 0.0, 0.0);
  Random random(2);
  const geometry::Pose2 truth{1.0, 2.0, 0.1};
  for (int k = 0; k < 100; ++k) {
    ekf.Predict(0.1);
    ekf.UpdateOdometry(0.0, 0.0, 0.05, 0.01);  // standing still
    const geometry::Pose2 meas{truth.x_m + random.Normal(0, 0.05),
                               truth.y_m + random.Normal(0, 0.05),
                               truth.yaw_rad + random.Normal(0, 0.01)};
    EXPECT_TRUE(ekf.UpdatePose(meas, PoseCov(0.1, 0.02))) << "at " << k;
  }
  EXPECT_NEAR(ekf.pose().x_m, truth.x_m, 0.05);
  EXPECT_NEAR(ekf.pose().y_m, truth.y_m, 0.05);
  EXPECT_NEAR(ekf.pose().yaw_rad, truth.yaw_rad, 0.01);
  EXPECT_LT(ekf.PositionStdM(), 0.1);
  EXPECT_FALSE(ekf.Lost());
  EXPECT_NEAR(ekf.time_s(), 10.0, 1e-9);
}

TEST(Ekf, DeadReckoningIntegratesACircle) {
  EkfParams params;
  params.lost_after_s = 100.0;  // no pose updates in this test
  params.max_position_std_m = 100.0;
  Ekf ekf(params);
  ekf.Initialize(geometry::Pose2{0, 0, 0}, 5.0, 0.0);
  const double v = 5.0, w = 0.25;  // radius 20 m, centre (0, 20)
  const double dt = 0.02;
  const int steps = static_cast<int>(std::round(2 * kPi / w / dt));
  for (int k = 0; k < steps; ++k) {
    ekf.Predict(dt);
    ekf.UpdateOdometry(v, w, 0.02, 0.002);
    if (k == steps / 2 - 1) {
      // Half way round: opposite side of the circle, heading backwards.
      EXPECT_NEAR(ekf.pose().x_m, 0.0, 0.1);
      EXPECT_NEAR(ekf.pose().y_m, 40.0, 0.1);
      EXPECT_NEAR(std::abs(ekf.pose().yaw_rad), kPi, 0.01);
    }
    const double r = std::hypot(ekf.pose().x_m, ekf.pose().y_m - 20.0);
    ASSERT_NEAR(r, 20.0, 0.1) << "at step " << k;
  }
  // Full circle (steps x dt is 2 pi / w to within one step).
  const double t = steps * dt;
  EXPECT_NEAR(ekf.pose().x_m, 20.0 * std::sin(w * t), 0.1);
  EXPECT_NEAR(ekf.pose().y_m, 20.0 - 20.0 * std::cos(w * t), 0.1);
  EXPECT_NEAR(ekf.v_mps(), v, 0.01);
  EXPECT_NEAR(ekf.yaw_rate_rps(), w, 0.001);
  // Without pose updates the position uncertainty only grows.
  EXPECT_GT(ekf.PositionStdM(), 1.0);
}

TEST(Ekf, RejectsOutlierPose) {
  Ekf ekf;
  ekf.Initialize(geometry::Pose2{10, 5, 0.5}, PoseCov(0.1, 0.01), 0.0, 0.0);
  for (int k = 0; k < 20; ++k) {
    ekf.Predict(0.1);
    ASSERT_TRUE(
        ekf.UpdatePose(geometry::Pose2{10, 5, 0.5}, PoseCov(0.1, 0.01)));
  }
  const geometry::Pose2 before = ekf.pose();
  // A scan match 3 m off (a wrong local minimum) is rejected.
  ekf.Predict(0.1);
  EXPECT_FALSE(ekf.UpdatePose(geometry::Pose2{13, 5, 0.5}, PoseCov(0.1, 0.01)));
  EXPECT_GT(ekf.last_mahalanobis2(), 16.27);
  EXPECT_EQ(ekf.rejected_pose_updates(), 1);
  EXPECT_NEAR(ekf.pose().x_m, before.x_m, 1e-9);
  // So is a yaw outlier, even across the +-pi wrap it is measured right.
  EXPECT_FALSE(
      ekf.UpdatePose(geometry::Pose2{10, 5, 0.5 + 0.5}, PoseCov(0.1, 0.01)));
  Ekf wrap;
  wrap.Initialize(geometry::Pose2{0, 0, kPi - 0.01}, PoseCov(0.1, 0.02), 0, 0);
  EXPECT_TRUE(
      wrap.UpdatePose(geometry::Pose2{0, 0, -kPi + 0.01}, PoseCov(0.1, 0.02)));
  EXPECT_LT(wrap.last_mahalanobis2(), 1.0);
}

TEST(Ekf, LostAfterTimeoutAndReinitialized) {
  EkfParams params;
  params.lost_after_s = 1.0;
  Ekf ekf(params);
  ekf.Initialize(geometry::Pose2{0, 0, 0}, PoseCov(0.1, 0.01), 2.0, 0.0);
  for (int k = 0; k < 9; ++k) ekf.Predict(0.1);
  EXPECT_FALSE(ekf.Lost());
  ekf.Predict(0.2);
  EXPECT_TRUE(ekf.Lost());
  // While lost, a pose far from the estimate re-initializes the filter.
  EXPECT_TRUE(ekf.UpdatePose(geometry::Pose2{50, 50, 1.0}, PoseCov(0.2, 0.02)));
  EXPECT_FALSE(ekf.Lost());
  EXPECT_NEAR(ekf.pose().x_m, 50.0, 1e-9);
  EXPECT_NEAR(ekf.v_mps(), 2.0, 0.5);  // speed kept from before
}

TEST(Ekf, LostWhenPositionUncertaintyGrows) {
  EkfParams params;
  params.lost_after_s = 1e9;
  params.max_position_std_m = 0.5;
  params.position_noise_mps = 0.5;
  params.initial_speed_std_mps = 0.01;  // else speed doubt dominates
  Ekf ekf(params);
  ekf.Initialize(geometry::Pose2{0, 0, 0}, PoseCov(0.1, 0.01), 0.0, 0.0);
  EXPECT_FALSE(ekf.Lost());
  int k = 0;
  while (!ekf.Lost() && k < 1000) {
    ekf.Predict(0.1);
    ++k;
  }
  EXPECT_TRUE(ekf.Lost());
  EXPECT_GT(ekf.PositionStdM(), 0.5);
  // ~ (0.5^2 - 0.1^2) / 0.5^2 = 0.96 s of random walk.
  EXPECT_NEAR(k, 10, 2);
}

TEST(Ekf, OdometryWithoutNoiseArgumentsUsesTheParameters) {
  EkfParams params;
  params.odometry_speed_std_mps = 0.3;
  params.odometry_yaw_rate_std_rps = 0.04;
  Ekf a(params), b(params);
  for (Ekf* e : {&a, &b}) e->Initialize(geometry::Pose2{0, 0, 0}, 1.0, 0.0);
  a.Predict(0.1);
  b.Predict(0.1);
  a.UpdateOdometry(2.0, 0.1);
  b.UpdateOdometry(2.0, 0.1, 0.3, 0.04);
  EXPECT_EQ(a.state(), b.state());
  EXPECT_EQ(a.covariance(), b.covariance());
}

TEST(Ekf, RemembersPosesForTheHistoryWindowOnly) {
  EkfParams params;
  params.history_window_s = 1.0;
  Ekf ekf(params);
  ekf.Initialize(geometry::Pose2{0, 0, 0}, 1.0, 0.0);
  for (int k = 0; k <= 30; ++k) ekf.RememberPose(0.1 * k);
  // t = 2.0 .. 3.0: eleven poses within one second of the newest.
  EXPECT_EQ(ekf.remembered_poses(), 11u);
  EkfParams none;
  none.history_window_s = 0.0;
  Ekf newest(none);
  newest.Initialize(geometry::Pose2{0, 0, 0}, 1.0, 0.0);
  newest.RememberPose(0.0);
  newest.RememberPose(1.0);
  EXPECT_EQ(newest.remembered_poses(), 1u) << "the newest is always kept";
}

// A vehicle drives straight at 10 m/s; a scan matched at t = 1.0 s arrives
// at t = 1.3 s. Taken as if it were now, it is 3 m behind and gated out as
// an outlier; carried forward by the motion since then, it agrees with the
// truth.
TEST(Ekf, ADelayedPoseIsCarriedForwardByTheMotionSinceItsStamp) {
  auto drive = [](Ekf* ekf) {
    ekf->Initialize(geometry::Pose2{0, 0, 0}, PoseCov(0.05, 0.01), 10.0, 0.0);
    for (int k = 1; k <= 13; ++k) {
      ekf->Predict(0.1);
      ekf->UpdateOdometry(10.0, 0.0);
      ekf->RememberPose(0.1 * k);
    }
  };
  const geometry::Pose2 at_stamp{10.0, 0.0, 0.0};  // true pose at t = 1.0
  const double truth_now_x = 13.0;
  Ekf compensated, naive;
  drive(&compensated);
  drive(&naive);
  ASSERT_TRUE(compensated.UpdateDelayedPose(at_stamp, PoseCov(0.05, 0.01),
                                            /*stamp_s=*/1.0));
  EXPECT_NEAR(compensated.pose().x_m, truth_now_x, 0.05);
  EXPECT_FALSE(naive.UpdatePose(at_stamp, PoseCov(0.05, 0.01)))
      << "uncompensated, the right match looks like a 3 m outlier";

  // With nothing remembered that recent, the pose is used as it is.
  Ekf fresh;
  fresh.Initialize(geometry::Pose2{0, 0, 0}, PoseCov(1.0, 0.1), 0.0, 0.0);
  ASSERT_TRUE(
      fresh.UpdateDelayedPose({0.5, 0.0, 0.0}, PoseCov(0.05, 0.01), 5.0));
  Ekf plain;
  plain.Initialize(geometry::Pose2{0, 0, 0}, PoseCov(1.0, 0.1), 0.0, 0.0);
  plain.UpdatePose({0.5, 0.0, 0.0}, PoseCov(0.05, 0.01));
  EXPECT_EQ(fresh.state(), plain.state());
}

// The stack's knob and the filter agree on when localization is lost.
TEST(Ekf, TheLostTimeoutDefaultIsTheKnobDefault) {
  const KnobInfo* knob = FindStackKnob("localization.lost_after_s");
  ASSERT_NE(knob, nullptr);
  EXPECT_EQ(knob->default_value, EkfParams{}.lost_after_s);
}

}  // namespace
}  // namespace adse::algorithms
