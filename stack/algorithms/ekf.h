// Pose fusion: an extended Kalman filter over (x, y, yaw, v, yaw_rate) with
// a constant turn rate and velocity (CTRV) motion model, wheel odometry
// updates and gated scan-matcher pose updates. Eigen and std types only.
#ifndef ADSE_STACK_ALGORITHMS_EKF_H_
#define ADSE_STACK_ALGORITHMS_EKF_H_

#include <Eigen/Core>
#include <cstddef>

#include "stack/algorithms/pose_buffer.h"
#include "stack/geometry/geometry.h"

namespace adse::algorithms {

struct EkfParams {
  double accel_noise_mps2 = 1.0;      // process noise on v (1 sigma)
  double yaw_accel_noise_rps2 = 0.5;  // process noise on yaw_rate
  double position_noise_mps = 0.05;   // extra random walk on x, y (slip)
  double yaw_noise_rps = 0.01;        // extra random walk on yaw
  // Pose updates with squared Mahalanobis distance above this are
  // rejected (chi-square, 3 dof: 16.27 is the 99.9 % quantile).
  double gate_chi2 = 16.27;
  double lost_after_s = 3.0;  // no accepted pose update for this long
  // Position uncertainty (1 sigma, largest axis) above which we are lost.
  double max_position_std_m = 1.5;
  // A pose update while lost re-initializes pose and covariance instead of
  // being gated (the estimate it would be checked against is not trusted).
  bool reinit_when_lost = true;
  double initial_position_std_m = 1.0;  // for Initialize without covariance
  double initial_yaw_std_rad = 0.1;
  double initial_speed_std_mps = 1.0;
  // Wheel odometry noise (1 sigma) of UpdateOdometry(v, yaw_rate).
  double odometry_speed_std_mps = 0.05;
  double odometry_yaw_rate_std_rps = 0.01;
  // How far back RememberPose keeps poses for delay compensation: longer
  // than any scan-matching latency that still deserves to be fused.
  double history_window_s = 3.0;
};

class Ekf {
 public:
  enum Index { kX = 0, kY = 1, kYaw = 2, kV = 3, kYawRate = 4 };
  using State = Eigen::Matrix<double, 5, 1>;
  using Covariance = Eigen::Matrix<double, 5, 5>;

  explicit Ekf(const EkfParams& params = {});

  // Sets the state at time t_s (the filter's clock starts here).
  void Initialize(const geometry::Pose2& pose, double v_mps, double t_s);
  void Initialize(const geometry::Pose2& pose, const Eigen::Matrix3d& pose_cov,
                  double v_mps, double t_s);
  bool initialized() const { return initialized_; }

  // Advances the state by dt_s (the filter's clock too). dt_s <= 0: no-op.
  void Predict(double dt_s);
  // Wheel odometry: measured speed and yaw rate with their 1-sigma noise.
  void UpdateOdometry(double v_mps, double yaw_rate_rps, double v_std_mps,
                      double yaw_rate_std_rps);
  // The same with the parameters' odometry noise.
  void UpdateOdometry(double v_mps, double yaw_rate_rps);
  // A pose measurement (e.g. NDT) with covariance over (x, y, yaw).
  // Returns false when it was gated out as an outlier. Uninitialized (or
  // lost, with reinit_when_lost) filters are initialized from it instead.
  bool UpdatePose(const geometry::Pose2& pose, const Eigen::Matrix3d& cov);

  // Remembers the current estimate as the pose at `t_s` (the caller's
  // clock), for UpdateDelayedPose. Poses more than history_window_s older
  // than `t_s` are forgotten; the newest is always kept.
  void RememberPose(double t_s);
  // A pose measured at `stamp_s`, before now (a scan matched late): carried
  // forward by the motion the filter estimated since the first remembered
  // pose at `stamp_s` (PoseBuffer::At), then fused by UpdatePose. Used as
  // it is when no pose was remembered.
  bool UpdateDelayedPose(const geometry::Pose2& pose,
                         const Eigen::Matrix3d& cov, double stamp_s);
  // Poses kept by RememberPose.
  size_t remembered_poses() const { return history_.size(); }

  // True before initialization, when no pose update was accepted for
  // lost_after_s, or when the position uncertainty is too large.
  bool Lost() const;

  geometry::Pose2 pose() const;
  double v_mps() const { return x_(kV); }
  double yaw_rate_rps() const { return x_(kYawRate); }
  const State& state() const { return x_; }
  const Covariance& covariance() const { return p_; }
  // Covariance of (x, y, yaw).
  Eigen::Matrix3d PoseCovariance() const;
  // Largest 1-sigma position uncertainty, m.
  double PositionStdM() const;
  double time_s() const { return t_s_; }
  double last_pose_update_s() const { return last_pose_t_s_; }
  // Squared Mahalanobis distance of the last pose measurement offered.
  double last_mahalanobis2() const { return last_d2_; }
  int rejected_pose_updates() const { return rejected_; }

 private:
  EkfParams params_;
  State x_ = State::Zero();
  Covariance p_ = Covariance::Identity();
  bool initialized_ = false;
  double t_s_ = 0.0;
  double last_pose_t_s_ = 0.0;
  double last_d2_ = 0.0;
  int rejected_ = 0;
  PoseBuffer history_{params_.history_window_s};
};

}  // namespace adse::algorithms

#endif  // ADSE_STACK_ALGORITHMS_EKF_H_
