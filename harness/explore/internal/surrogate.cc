#include "harness/explore/internal/surrogate.h"

#include <ceres/ceres.h>
#include <ceres/normal_prior.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace adse::explore::internal {
namespace {

// Prior slopes of a 0/1 metric (run completed) per unit of a knob that
// helps, and their sd.
constexpr double kFlagSlope = 0.3;
constexpr double kFlagSlopeSd = 0.5;
// Prior of a saturating trend's level: this far beyond the best value
// seen (model units, i.e. log for positive metrics), give or take the sd.
constexpr double kSaturationRoom = 0.3;
constexpr double kSaturationSd = 0.4;
// How far beyond the best run seen an objective's prediction may go.
constexpr double kOptimismRoom = 0.025;
// How far past its bound a censored value is taken, in model units (log
// for positive metrics: about 10 %; standard deviations otherwise).
constexpr double kCensoredMargin = 0.1;
// Measured runs a time needs before its rate is tried as its model: a
// leave-one-out comparison of fewer runs chose badly
// (docs/agent_development.md, "The nav time's rate model").
constexpr int kMinRateChoicePoints = 10;

template <typename T>
T Softplus(const T& x) {
  using std::exp;
  using std::log;
  if (x > T(0.0)) return x + log(T(1.0) + exp(-x));
  return log(T(1.0) + exp(x));
}

template <typename T>
T TrendValue(TrendShape shape, const T* a, const T* b, const T* f,
             const std::vector<double>& u) {
  T lin = a[0];
  for (size_t i = 0; i < u.size(); ++i) lin += b[i] * T(u[i]);
  switch (shape) {
    case TrendShape::kFloor:
      return f[0] + Softplus(lin - f[0]);
    case TrendShape::kCeiling:
      return f[0] - Softplus(f[0] - lin);
    case TrendShape::kLinear:
      break;
  }
  return lin;
}

struct TrendResidual {
  TrendShape shape;
  std::vector<double> u;
  double t;
  // 0: t was measured; +1 / -1: the value is known only to be at least /
  // at most t (a censored run), so only a trend on the wrong side of t
  // costs anything (a one-sided, Tobit-like residual).
  int side;
  double inv_sigma;

  template <typename T>
  bool operator()(T const* const* parameters, T* residual) const {
    const T* f = shape == TrendShape::kLinear ? nullptr : parameters[2];
    const T value = TrendValue(shape, parameters[0], parameters[1], f, u);
    const bool wrong_side =
        side == 0 || (side > 0 ? value < T(t) : value > T(t));
    residual[0] = wrong_side ? (T(t) - value) * T(inv_sigma) : T(0.0);
    return true;
  }
};

}  // namespace

double NormalQuantile(double p) {
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,
                             -2.759285104469687e+02, 1.383577518672690e+02,
                             -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02,
                             -1.556989798598866e+02, 6.680131188771972e+01,
                             -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01,
                             -2.400758277161838e+00, -2.549732539343734e+00,
                             4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01,
                             2.445134137142996e+00, 3.754408661907416e+00};
  const double low = 0.02425;
  if (p <= 0.0) return -8.0;
  if (p >= 1.0) return 8.0;
  if (p < low) {
    const double q = std::sqrt(-2 * std::log(p));
    return (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q +
            c[5]) /
           ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  }
  if (p > 1 - low) {
    const double q = std::sqrt(-2 * std::log(1 - p));
    return -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q +
             c[5]) /
           ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  }
  const double q = p - 0.5;
  const double r = q * q;
  return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) *
         q / (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
}

double Trend::Value(const std::vector<double>& u) const {
  return TrendValue(shape, &a, b.data(), &f, u);
}

double ResidualGp::Fit(const std::vector<std::vector<double>>& x,
                       const std::vector<double>& r, const Hyper& hyper) {
  hyper_ = hyper;
  x_ = x;
  const int n = static_cast<int>(x.size());
  if (n == 0) return 0.0;
  Eigen::MatrixXd k(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j <= i; ++j) {
      k(i, j) = k(j, i) = Kernel(x[i], x[j]);
    }
    k(i, i) += hyper.noise2;
  }
  llt_.compute(k);
  if (llt_.info() != Eigen::Success) return -kInf;
  Eigen::VectorXd y(n);
  for (int i = 0; i < n; ++i) y(i) = r[i];
  alpha_ = llt_.solve(y);
  y_ = y;
  double log_det = 0.0;
  const Eigen::MatrixXd& l = llt_.matrixLLT();
  for (int i = 0; i < n; ++i) log_det += 2.0 * std::log(l(i, i));
  return -0.5 * y.dot(alpha_) - 0.5 * log_det;
}

void ResidualGp::LeaveOneOut(std::vector<double>* mean,
                             std::vector<double>* variance) const {
  const int n = static_cast<int>(x_.size());
  mean->assign(n, 0.0);
  variance->assign(n, 1.0);
  if (n == 0 || alpha_.size() != n) return;
  const Eigen::MatrixXd inverse = llt_.solve(Eigen::MatrixXd::Identity(n, n));
  for (int i = 0; i < n; ++i) {
    const double d = inverse(i, i);
    if (!(d > 0.0)) continue;
    (*mean)[i] = y_(i) - alpha_(i) / d;
    (*variance)[i] = 1.0 / d;
  }
}

void ResidualGp::Predict(const std::vector<double>& u, double* mean,
                         double* variance) const {
  const int n = static_cast<int>(x_.size());
  const double prior = Kernel(u, u) + hyper_.noise2;
  if (n == 0) {
    *mean = 0.0;
    *variance = prior;
    return;
  }
  Eigen::VectorXd k(n);
  for (int i = 0; i < n; ++i) k(i) = Kernel(u, x_[i]);
  *mean = k.dot(alpha_);
  const Eigen::VectorXd v = llt_.matrixL().solve(k);
  *variance = std::max(prior - v.squaredNorm(), hyper_.noise2);
}

double ResidualGp::Kernel(const std::vector<double>& a,
                          const std::vector<double>& b) const {
  double dot = 0.0;
  double scaled2 = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    dot += (a[i] - 0.5) * (b[i] - 0.5);
    const double d = (a[i] - b[i]) / hyper_.lengths[i];
    scaled2 += d * d;
  }
  return hyper_.constant2 + hyper_.linear2 * dot +
         hyper_.signal2 * std::exp(-0.5 * scaled2);
}

void MetricModel::Fit(const std::vector<std::vector<double>>& u,
                      const std::vector<double>& values,
                      const std::vector<int>& sides,
                      const std::vector<double>& prior_slope,
                      const std::vector<double>& lengths) {
  int measured = 0;
  bool positive = true;
  for (size_t i = 0; i < values.size(); ++i) {
    positive = positive && values[i] > 0.0;
    measured += (i >= sides.size() || sides[i] == 0) ? 1 : 0;
  }
  if (!rate_hint || boolean_hint || !positive ||
      measured < kMinRateChoicePoints) {
    FitIn(u, values, sides, prior_slope, lengths, nullptr);
    return;
  }
  MetricModel as_log = *this;
  MetricSpace log_space = MetricSpace::kLog;
  as_log.FitIn(u, values, sides, prior_slope, lengths, &log_space);
  MetricModel as_rate = *this;
  MetricSpace rate_space = MetricSpace::kReciprocal;
  as_rate.FitIn(u, values, sides, prior_slope, lengths, &rate_space);
  const double log_score = as_log.LeaveOneOutLogDensity(u, values, sides);
  const double rate_score = as_rate.LeaveOneOutLogDensity(u, values, sides);
  *this = rate_score > log_score ? std::move(as_rate) : std::move(as_log);
}

double MetricModel::LeaveOneOutLogDensity(
    const std::vector<std::vector<double>>& u,
    const std::vector<double>& values, const std::vector<int>& sides) const {
  std::vector<double> mean, variance;
  gp_.LeaveOneOut(&mean, &variance);
  double sum = 0.0;
  for (size_t i = 0; i < values.size() && i < mean.size(); ++i) {
    if (i < sides.size() && sides[i] != 0) continue;
    const double y = values[i];
    const double t =
        space_ == MetricSpace::kReciprocal ? scale_ / y : std::log(y);
    // |dt/dy| carries the density from model units to metric units.
    const double jacobian =
        space_ == MetricSpace::kReciprocal ? scale_ / (y * y) : 1.0 / y;
    const double sd = std::sqrt(std::max(variance[i], 1e-12));
    const double z = (t - trend_.Value(u[i]) - mean[i]) / sd;
    sum += -0.5 * z * z - std::log(sd) + std::log(jacobian);
  }
  return sum;
}

void MetricModel::FitIn(const std::vector<std::vector<double>>& u,
                        const std::vector<double>& values,
                        const std::vector<int>& sides,
                        const std::vector<double>& prior_slope,
                        const std::vector<double>& lengths,
                        const MetricSpace* forced) {
  fitted_ = false;
  points_ = static_cast<int>(values.size());
  if (values.empty()) return;
  const size_t dims = u.front().size();
  // Empty `sides`: every value measured.
  std::vector<int> sided = sides;
  sided.resize(values.size(), 0);
  bool all_positive = true;
  bool all_flags = true;
  bool any_measured = false;
  for (size_t i = 0; i < values.size(); ++i) {
    const double v = values[i];
    all_positive = all_positive && v > 0.0;
    all_flags = all_flags && (v == 0.0 || v == 1.0);
    any_measured = any_measured || sided[i] == 0;
  }
  if (forced != nullptr) {
    space_ = *forced;
  } else if (boolean_hint || (all_flags && !all_positive && any_measured)) {
    space_ = MetricSpace::kBoolean;
  } else if (all_positive) {
    space_ = MetricSpace::kLog;
  } else {
    space_ = MetricSpace::kLinear;
  }
  if (space_ == MetricSpace::kBoolean &&
      std::any_of(sides.begin(), sides.end(), [](int v) { return v != 0; })) {
    // A 0/1 flag's bound says nothing beyond the flag: fit the measured
    // values alone.
    std::vector<std::vector<double>> measured_u;
    std::vector<double> measured;
    for (size_t i = 0; i < values.size(); ++i) {
      if (sided[i] != 0) continue;
      measured_u.push_back(u[i]);
      measured.push_back(values[i]);
    }
    FitIn(measured_u, measured, {}, prior_slope, lengths, nullptr);
    return;
  }
  std::vector<double> t(values.size());
  shift_ = 0.0;
  scale_ = 1.0;
  if (space_ == MetricSpace::kReciprocal) {
    std::vector<double> sorted = values;
    std::sort(sorted.begin(), sorted.end());
    scale_ = sorted[sorted.size() / 2];
  }
  if (space_ == MetricSpace::kLinear) {
    const double mean =
        std::accumulate(values.begin(), values.end(), 0.0) / values.size();
    double var = 0.0;
    for (double v : values) var += (v - mean) * (v - mean);
    var /= values.size();
    shift_ = mean;
    scale_ = var > 1e-18 ? std::sqrt(var) : std::max(1.0, std::abs(mean));
  }
  // A censored bound is taken a margin beyond itself (in model units): the
  // run was stopped because its value was certainly past the bound.
  // In reciprocal space a rate is modelled: its direction is the time's
  // reversed, and so is a censored bound's side.
  const int sign = space_ == MetricSpace::kReciprocal ? -1 : 1;
  const int direction = sign * good_direction;
  for (size_t i = 0; i < values.size(); ++i) {
    sided[i] *= sign;
    if (space_ == MetricSpace::kReciprocal) {
      t[i] = scale_ / values[i];
    } else {
      t[i] = space_ == MetricSpace::kLog ? std::log(values[i])
                                         : (values[i] - shift_) / scale_;
    }
    t[i] += sided[i] * kCensoredMargin;
  }
  // Residual scale of the trend and the prior slope size, in model units.
  const double sigma =
      space_ == MetricSpace::kLog || space_ == MetricSpace::kReciprocal ? 0.1
      : space_ == MetricSpace::kBoolean                                 ? 0.25
                                                                        : 0.3;
  const double slope_size = space_ == MetricSpace::kBoolean ? kFlagSlope : 1.0;
  std::vector<double> mu(dims, 0.0);
  for (size_t i = 0; i < dims; ++i) {
    mu[i] = direction * slope_size * prior_slope[i];
  }
  const double slope_sd = space_ == MetricSpace::kBoolean ? kFlagSlopeSd : 1.5;

  // Metrics that resources improve saturate (navigation time cannot
  // drop below driving the route, the control rate has a cap): the trend
  // starts saturating towards the good side; with data enough the shapes
  // compete, a little penalised per extra parameter.
  TrendShape preferred = TrendShape::kLinear;
  if (space_ != MetricSpace::kBoolean && direction != 0) {
    preferred = direction < 0 ? TrendShape::kFloor : TrendShape::kCeiling;
  }
  trend_ = FitTrend(preferred, u, t, sided, mu, signed_slopes, slope_sd, sigma);
  if (space_ != MetricSpace::kBoolean && values.size() >= dims + 3) {
    const double penalty = 0.5 * std::log(static_cast<double>(values.size()));
    for (TrendShape shape :
         {TrendShape::kLinear, TrendShape::kFloor, TrendShape::kCeiling}) {
      if (shape == preferred) continue;
      Trend other =
          FitTrend(shape, u, t, sided, mu, signed_slopes, slope_sd, sigma);
      const double extra = shape == TrendShape::kLinear ? 0.0 : penalty;
      const double mine = trend_.shape == TrendShape::kLinear ? 0.0 : penalty;
      if (other.cost + extra < trend_.cost + mine) trend_ = other;
    }
  }
  std::vector<double> residuals(t.size());
  double rms = 0.0;
  for (size_t i = 0; i < t.size(); ++i) {
    // A censored value is imputed as the trend, or its bound when the
    // trend does not reach past it.
    const double trend = trend_.Value(u[i]);
    double value = t[i];
    if (sided[i] > 0) value = std::max(t[i], trend);
    if (sided[i] < 0) value = std::min(t[i], trend);
    residuals[i] = value - trend;
    rms += residuals[i] * residuals[i];
  }
  rms = std::sqrt(rms / t.size());
  // Hyperparameters: a small grid by marginal likelihood once there is
  // data enough, defaults scaled to the metric otherwise.
  const double base_noise =
      space_ == MetricSpace::kLog || space_ == MetricSpace::kReciprocal ? 0.03
                                                                        : 0.1;
  const double signal = std::max(rms, 2.0 * base_noise);
  ResidualGp::Hyper hyper;
  hyper.constant2 = 0.01;
  hyper.linear2 = space_ == MetricSpace::kBoolean ? 0.1 : 0.3;
  hyper.signal2 = signal * signal;
  hyper.lengths = lengths;
  hyper.noise2 = base_noise * base_noise;
  if (values.size() >= 6) {
    double best = -kInf;
    ResidualGp::Hyper best_hyper = hyper;
    for (double scale : {0.5, 1.0, 2.0}) {
      for (double noise : {base_noise, std::max(base_noise, 0.5 * rms)}) {
        ResidualGp::Hyper h = hyper;
        for (double& length : h.lengths) length *= scale;
        h.noise2 = noise * noise;
        const double ll = gp_.Fit(u, residuals, h);
        if (ll > best + 1e-9) {
          best = ll;
          best_hyper = h;
        }
      }
    }
    hyper = best_hyper;
  }
  if (!std::isfinite(gp_.Fit(u, residuals, hyper))) {
    hyper.noise2 += 0.01;
    gp_.Fit(u, residuals, hyper);
  }
  // The most a prediction may promise beyond the best run seen: a
  // surrogate extrapolates too eagerly, which would send the search
  // after improvements that saturated long ago.
  best_ = kNaN;
  for (size_t i = 0; i < values.size(); ++i) {
    const double v = values[i];
    if (good_direction == 0) break;
    if (sided[i] != 0) continue;
    if (std::isnan(best_) || (good_direction < 0 ? v < best_ : v > best_)) {
      best_ = v;
    }
  }
  fitted_ = true;
}

void MetricModel::Predict(const std::vector<double>& u, double* mean,
                          double* sd) const {
  double m = 0.0;
  double var = 1.0;
  gp_.Predict(u, &m, &var);
  *mean = trend_.Value(u) + m;
  *sd = std::sqrt(std::max(var, 0.0));
}

double MetricModel::Bounded(double value) const {
  if (std::isnan(best_) || good_direction == 0) return value;
  double bound;
  if (space_ == MetricSpace::kLog || space_ == MetricSpace::kReciprocal) {
    bound = best_ * std::exp(good_direction * kOptimismRoom);
  } else {
    bound = best_ + good_direction * kOptimismRoom * scale_;
  }
  return good_direction < 0 ? std::max(value, bound) : std::min(value, bound);
}

double MetricModel::ToMetric(double t) const {
  double value = 0.0;
  switch (space_) {
    case MetricSpace::kLog:
      value = std::exp(std::clamp(t, -700.0, 700.0));
      break;
    case MetricSpace::kBoolean:
      return t >= 0.5 ? 1.0 : 0.0;
    case MetricSpace::kReciprocal:
      return t > 0.0 ? scale_ / t : kInf;  // a rate of 0: never done
    case MetricSpace::kLinear:
      value = shift_ + scale_ * t;
      break;
  }
  return count_hint ? std::max(0.0, std::round(value)) : value;
}

Trend MetricModel::FitTrend(TrendShape shape,
                            const std::vector<std::vector<double>>& u,
                            const std::vector<double>& t,
                            const std::vector<int>& sides,
                            const std::vector<double>& mu,
                            const std::vector<bool>& signed_slopes,
                            double slope_sd, double sigma) {
  const size_t dims = mu.size();
  Trend trend;
  trend.shape = shape;
  trend.b = mu;
  double mean_t = std::accumulate(t.begin(), t.end(), 0.0) / t.size();
  double mean_u_dot = 0.0;
  for (size_t j = 0; j < u.size(); ++j) {
    for (size_t i = 0; i < dims; ++i) mean_u_dot += mu[i] * u[j][i];
  }
  mean_u_dot /= u.size();
  trend.a = mean_t - mean_u_dot;
  const double t_min = *std::min_element(t.begin(), t.end());
  const double t_max = *std::max_element(t.begin(), t.end());
  double f_prior = 0.0;
  if (shape == TrendShape::kFloor) {
    f_prior = t_min - kSaturationRoom;
  } else if (shape == TrendShape::kCeiling) {
    f_prior = t_max + kSaturationRoom;
  }
  trend.f = f_prior;

  ceres::Problem::Options problem_options;
  ceres::Problem problem(problem_options);
  for (size_t j = 0; j < t.size(); ++j) {
    auto* cost = new ceres::DynamicAutoDiffCostFunction<TrendResidual>(
        new TrendResidual{shape, u[j], t[j], sides[j], 1.0 / sigma});
    cost->AddParameterBlock(1);
    cost->AddParameterBlock(static_cast<int>(dims));
    std::vector<double*> blocks = {&trend.a, trend.b.data()};
    if (shape != TrendShape::kLinear) {
      cost->AddParameterBlock(1);
      blocks.push_back(&trend.f);
    }
    cost->SetNumResiduals(1);
    problem.AddResidualBlock(cost, new ceres::CauchyLoss(2.0), blocks);
  }
  Eigen::MatrixXd slope_a = Eigen::MatrixXd::Identity(dims, dims) / slope_sd;
  Eigen::VectorXd slope_b(dims);
  for (size_t i = 0; i < dims; ++i) slope_b(i) = mu[i];
  problem.AddResidualBlock(new ceres::NormalPrior(slope_a, slope_b), nullptr,
                           trend.b.data());
  for (size_t i = 0; i < dims && i < signed_slopes.size(); ++i) {
    if (!signed_slopes[i] || mu[i] == 0.0) continue;
    if (mu[i] > 0.0) {
      problem.SetParameterLowerBound(trend.b.data(), static_cast<int>(i), 0.0);
    } else {
      problem.SetParameterUpperBound(trend.b.data(), static_cast<int>(i), 0.0);
    }
  }
  if (shape != TrendShape::kLinear) {
    Eigen::MatrixXd fa = Eigen::MatrixXd::Identity(1, 1) / kSaturationSd;
    Eigen::VectorXd fb(1);
    fb(0) = f_prior;
    problem.AddResidualBlock(new ceres::NormalPrior(fa, fb), nullptr, &trend.f);
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 100;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  trend.cost = summary.IsSolutionUsable() && std::isfinite(summary.final_cost)
                   ? summary.final_cost
                   : kInf;
  bool finite = std::isfinite(trend.a) && std::isfinite(trend.f);
  for (double v : trend.b) finite = finite && std::isfinite(v);
  if (!finite) {
    trend.a = mean_t;
    trend.b.assign(dims, 0.0);
    trend.shape = TrendShape::kLinear;
    trend.cost = kInf;
  }
  return trend;
}

}  // namespace adse::explore::internal
