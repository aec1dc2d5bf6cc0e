#include "stack/algorithms/ekf.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <optional>

namespace adse::algorithms {
namespace {

constexpr double kPi = 3.14159265358979323846;

double WrapAngle(double a) {
  a = std::fmod(a + kPi, 2 * kPi);
  if (a < 0) a += 2 * kPi;
  return a - kPi;
}

// sin(u)/u and its derivative, smooth through u = 0 (straight driving).
double Sinc(double u) {
  return std::abs(u) < 1e-4 ? 1.0 - u * u / 6.0 : std::sin(u) / u;
}
double SincDerivative(double u) {
  return std::abs(u) < 1e-4 ? -u / 3.0
                            : (u * std::cos(u) - std::sin(u)) / (u * u);
}

// b - a as a signed angle in (-pi, pi].
double AngleFrom(double a, double b) {
  const double d = b - a;
  return std::atan2(std::sin(d), std::cos(d));
}

}  // namespace

Ekf::Ekf(const EkfParams& params) : params_(params) {}

void Ekf::Initialize(const geometry::Pose2& pose, double v_mps, double t_s) {
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  cov.diagonal() << std::pow(params_.initial_position_std_m, 2),
      std::pow(params_.initial_position_std_m, 2),
      std::pow(params_.initial_yaw_std_rad, 2);
  Initialize(pose, cov, v_mps, t_s);
}

void Ekf::Initialize(const geometry::Pose2& pose,
                     const Eigen::Matrix3d& pose_cov, double v_mps,
                     double t_s) {
  x_ << pose.x_m, pose.y_m, WrapAngle(pose.yaw_rad), v_mps, 0.0;
  p_.setZero();
  p_.topLeftCorner<3, 3>() = pose_cov;
  p_(kV, kV) = std::pow(params_.initial_speed_std_mps, 2);
  p_(kYawRate, kYawRate) = 0.1;
  t_s_ = t_s;
  last_pose_t_s_ = t_s;
  initialized_ = true;
}

void Ekf::Predict(double dt) {
  if (!(dt > 0.0)) return;
  t_s_ += dt;
  if (!initialized_) return;
  const double yaw = x_(kYaw), v = x_(kV), w = x_(kYawRate);
  // Exact CTRV: the chord of the arc has length v dt sinc(w dt / 2) and
  // points along the mid-step heading; smooth in w, so no straight-line
  // special case and an exact circle for constant v and w.
  const double u = 0.5 * w * dt;
  const double sc = Sinc(u), dsc = SincDerivative(u);
  const double mid = yaw + u;
  const double cm = std::cos(mid), sm = std::sin(mid);
  const double chord = v * dt * sc;
  x_(kX) += chord * cm;
  x_(kY) += chord * sm;
  x_(kYaw) = WrapAngle(yaw + w * dt);

  Covariance f = Covariance::Identity();
  f(kX, kYaw) = -chord * sm;
  f(kY, kYaw) = chord * cm;
  f(kX, kV) = dt * sc * cm;
  f(kY, kV) = dt * sc * sm;
  // d/dw of chord * (cos, sin)(mid): through sinc(u) and through mid.
  const double dchord_dw = v * dt * dsc * 0.5 * dt;
  f(kX, kYawRate) = dchord_dw * cm - chord * sm * 0.5 * dt;
  f(kY, kYawRate) = dchord_dw * sm + chord * cm * 0.5 * dt;
  f(kYaw, kYawRate) = dt;

  // Random acceleration and yaw acceleration integrated over the step, plus
  // a small random walk on the pose for what the model does not know.
  Eigen::Matrix<double, 5, 2> g = Eigen::Matrix<double, 5, 2>::Zero();
  g(kX, 0) = 0.5 * dt * dt * cm;
  g(kY, 0) = 0.5 * dt * dt * sm;
  g(kV, 0) = dt;
  g(kYaw, 1) = 0.5 * dt * dt;
  g(kYawRate, 1) = dt;
  Eigen::Matrix2d qa = Eigen::Matrix2d::Zero();
  qa(0, 0) = std::pow(params_.accel_noise_mps2, 2);
  qa(1, 1) = std::pow(params_.yaw_accel_noise_rps2, 2);
  Covariance q = g * qa * g.transpose();
  q(kX, kX) += std::pow(params_.position_noise_mps, 2) * dt;
  q(kY, kY) += std::pow(params_.position_noise_mps, 2) * dt;
  q(kYaw, kYaw) += std::pow(params_.yaw_noise_rps, 2) * dt;
  p_ = f * p_ * f.transpose() + q;
  p_ = 0.5 * (p_ + p_.transpose());
}

void Ekf::UpdateOdometry(double v_mps, double yaw_rate_rps, double v_std_mps,
                         double yaw_rate_std_rps) {
  if (!initialized_) return;
  Eigen::Matrix<double, 2, 5> h = Eigen::Matrix<double, 2, 5>::Zero();
  h(0, kV) = 1.0;
  h(1, kYawRate) = 1.0;
  Eigen::Matrix2d r = Eigen::Matrix2d::Zero();
  r(0, 0) = std::max(v_std_mps * v_std_mps, 1e-8);
  r(1, 1) = std::max(yaw_rate_std_rps * yaw_rate_std_rps, 1e-8);
  const Eigen::Vector2d y(v_mps - x_(kV), yaw_rate_rps - x_(kYawRate));
  const Eigen::Matrix2d s = h * p_ * h.transpose() + r;
  const Eigen::Matrix<double, 5, 2> k = p_ * h.transpose() * s.inverse();
  x_ += k * y;
  x_(kYaw) = WrapAngle(x_(kYaw));
  const Covariance i_kh = Covariance::Identity() - k * h;
  p_ = i_kh * p_ * i_kh.transpose() + k * r * k.transpose();
}

bool Ekf::UpdatePose(const geometry::Pose2& pose, const Eigen::Matrix3d& cov) {
  if (!initialized_ || (params_.reinit_when_lost && Lost())) {
    // Keep what odometry taught us about speed and turn rate.
    const double v = initialized_ ? x_(kV) : 0.0;
    const double w = initialized_ ? x_(kYawRate) : 0.0;
    const Covariance old = p_;
    const bool was_initialized = initialized_;
    Initialize(pose, cov, v, t_s_);
    if (was_initialized) {
      x_(kYawRate) = w;
      p_.bottomRightCorner<2, 2>() = old.bottomRightCorner<2, 2>();
    }
    last_d2_ = 0.0;
    return true;
  }
  Eigen::Matrix<double, 3, 5> h = Eigen::Matrix<double, 3, 5>::Zero();
  h(0, kX) = h(1, kY) = h(2, kYaw) = 1.0;
  Eigen::Vector3d y(pose.x_m - x_(kX), pose.y_m - x_(kY),
                    WrapAngle(pose.yaw_rad - x_(kYaw)));
  const Eigen::Matrix3d s = h * p_ * h.transpose() + cov;
  const Eigen::Matrix3d s_inv = s.inverse();
  last_d2_ = y.dot(s_inv * y);
  if (!std::isfinite(last_d2_) || last_d2_ > params_.gate_chi2) {
    ++rejected_;
    return false;
  }
  const Eigen::Matrix<double, 5, 3> k = p_ * h.transpose() * s_inv;
  x_ += k * y;
  x_(kYaw) = WrapAngle(x_(kYaw));
  const Covariance i_kh = Covariance::Identity() - k * h;
  p_ = i_kh * p_ * i_kh.transpose() + k * cov * k.transpose();
  last_pose_t_s_ = t_s_;
  return true;
}

bool Ekf::Lost() const {
  if (!initialized_) return true;
  if (t_s_ - last_pose_t_s_ > params_.lost_after_s) return true;
  return PositionStdM() > params_.max_position_std_m;
}

geometry::Pose2 Ekf::pose() const {
  return geometry::Pose2{x_(kX), x_(kY), x_(kYaw)};
}

Eigen::Matrix3d Ekf::PoseCovariance() const { return p_.topLeftCorner<3, 3>(); }

double Ekf::PositionStdM() const {
  // Largest eigenvalue of the symmetric 2x2 position block, closed form.
  const double a = p_(kX, kX), b = 0.5 * (p_(kX, kY) + p_(kY, kX));
  const double c = p_(kY, kY);
  const double largest = 0.5 * (a + c) + std::hypot(0.5 * (a - c), b);
  return std::sqrt(std::max(0.0, largest));
}

void Ekf::UpdateOdometry(double v_mps, double yaw_rate_rps) {
  UpdateOdometry(v_mps, yaw_rate_rps, params_.odometry_speed_std_mps,
                 params_.odometry_yaw_rate_std_rps);
}

void Ekf::RememberPose(double t_s) { history_.Add(t_s, pose(), v_mps()); }

bool Ekf::UpdateDelayedPose(const geometry::Pose2& pose,
                            const Eigen::Matrix3d& cov, double stamp_s) {
  geometry::Pose2 measured = pose;
  if (const std::optional<geometry::Pose2> then = history_.At(stamp_s)) {
    // The motion since then, in the frame of the pose remembered then,
    // applied in the frame of the measurement.
    const geometry::Pose2 now = this->pose();
    const double dyaw = AngleFrom(then->yaw_rad, now.yaw_rad);
    const Eigen::Vector2d moved(now.x_m - then->x_m, now.y_m - then->y_m);
    const double c = std::cos(measured.yaw_rad - then->yaw_rad);
    const double s = std::sin(measured.yaw_rad - then->yaw_rad);
    measured.x_m += c * moved.x() - s * moved.y();
    measured.y_m += s * moved.x() + c * moved.y();
    measured.yaw_rad = AngleFrom(0.0, measured.yaw_rad + dyaw);
  }
  return UpdatePose(measured, cov);
}

}  // namespace adse::algorithms
