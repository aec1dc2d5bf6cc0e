// The built-in `agent` strategy: a reasoning loop that needs no network.
//
// It keeps every told point in memory and, before each round:
//  1. fits one surrogate per metric that an objective or a constraint reads
//     (hardware cost is computed exactly from the cost expression): a
//     parametric trend fitted with Ceres under a robust loss — in log space
//     for positive metrics, over knobs in log scale when positive — linear,
//     or saturating towards a floor or a ceiling (nav time stops improving
//     past some core count, the control rate caps), with prior slopes that
//     say more cores / GHz help, so one or two points already extrapolate;
//     plus a small Gaussian process on the trend's residuals, which
//     interpolates the runs and gives an uncertainty that grows with the
//     distance from them;
//  2. scores unseen points (all of them when the space is small, a sample
//     plus the neighbours of seen points otherwise) by the expected gain in
//     hypervolume of the feasible front, over joint samples of the predicted
//     metrics pushed through the spec's own constraint expressions: cheap
//     points that are probably feasible score high, so the search walks
//     the feasibility boundary in cost;
//  3. leans towards the diagnosis' remedies for the last runs (a CPU-bound
//     node asking for "more cores" or "higher frequency", a sensor stage
//     asking for a lower rate) and away from the neighbours of failed runs;
//  4. for a batch, picks greedily, treating each chosen point as if its
//     prediction were true and penalising points close to it.
// Every Ask writes a short rationale with the numbers behind the choice.
#include <ceres/ceres.h>
#include <ceres/normal_prior.h>
#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "harness/explore/strategy.h"
#include "harness/spec/expression.h"
#include "harness/spec/spec_parser.h"

namespace adse::explore {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Joint samples of the predicted metrics per candidate.
constexpr int kSamples = 64;
// Spaces up to this size are scored exhaustively.
constexpr uint64_t kEnumerateLimit = 4096;
// Random candidates drawn in larger spaces (plus neighbours of seen points).
constexpr int kSampledCandidates = 2000;
// In larger spaces, the neighbours of this many latest runs are scored too.
constexpr size_t kNeighbourhoods = 48;
// The surrogates learn from at most this many (most recent) runs.
constexpr size_t kMaxModelPoints = 160;
// Prior slopes of a 0/1 metric (run completed) per unit of a knob that
// helps, and their sd; a sensor rate the diagnosis of an infeasible run
// names gets this prior slope (sign from the remedy).
constexpr double kFlagSlope = 0.3;
constexpr double kFlagSlopeSd = 0.5;
constexpr double kRateVote = 0.3;
// Default GP length scales over normalised knobs: most knobs, and those
// with at most 3 values.
constexpr double kLength = 0.25;
constexpr double kFewValuesLength = 1.0;
// Prior of a saturating trend's level: this far beyond the best value
// seen (model units, i.e. log for positive metrics), give or take the sd.
constexpr double kSaturationRoom = 0.3;
constexpr double kSaturationSd = 0.4;
// Failed runs: how likely a run works is a kernel vote of the runs within
// about kRunsSteps grid steps, next to a prior of kRunsPrior worth
// kRunsPriorWeight runs.
constexpr double kRunsSteps = 1.5;
constexpr double kRunsPrior = 0.9;
constexpr double kRunsPriorWeight = 0.3;
// Weight of the (normalised) expected hypervolume gain next to the
// probability of landing on the predicted front.
constexpr double kHypervolumeWeight = 0.3;
constexpr double kClampMeanOnly = 0;
constexpr double kNoiseRoom = 0.3;
// How far beyond the best run seen an objective's prediction may go.
constexpr double kOptimismRoom = 0.025;
// The metric computed from the cost expression rather than modelled.
constexpr char kCostMetric[] = "hardware_cost";
// The flag of a run that reached its goal.
constexpr char kCompletedMetric[] = "completed";

// ---------------------------------------------------------------------------
// Small numeric helpers.

// Inverse of the standard normal CDF (Acklam's rational approximation,
// relative error < 1.2e-9), for stratified samples.
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

// a dominates b (minimisation): no worse anywhere, better somewhere.
bool Dominates(const std::vector<double>& a, const std::vector<double>& b) {
  bool better = false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i] > b[i]) return false;
    if (a[i] < b[i]) better = true;
  }
  return better;
}

bool WeaklyDominates(const std::vector<double>& a,
                     const std::vector<double>& b) {
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i] > b[i]) return false;
  }
  return true;
}

// Exact hypervolume (minimisation) of `points` bounded by `ref`, over the
// first `dims` coordinates, by slicing along the last one; the sets here
// are small (a front of tens of points), which keeps this cheap.
double SliceVolume(std::vector<std::vector<double>> points,
                   const std::vector<double>& ref, size_t dims) {
  if (points.empty()) return 0.0;
  if (dims == 1) {
    double best = ref[0];
    for (const auto& p : points) best = std::min(best, p[0]);
    return ref[0] - best;
  }
  const size_t last = dims - 1;
  std::sort(points.begin(), points.end(),
            [last](const std::vector<double>& a, const std::vector<double>& b) {
              return a[last] < b[last];
            });
  if (dims == 2) {
    double volume = 0.0;
    // Sweep along the second coordinate; keep the best first coordinate.
    double best_x = ref[0];
    for (size_t i = 0; i < points.size(); ++i) {
      best_x = std::min(best_x, points[i][0]);
      const double next = i + 1 < points.size() ? points[i + 1][1] : ref[1];
      volume += (ref[0] - best_x) * (next - points[i][1]);
    }
    return volume;
  }
  double volume = 0.0;
  std::vector<std::vector<double>> prefix;
  for (size_t i = 0; i < points.size(); ++i) {
    prefix.push_back(points[i]);
    const double next = i + 1 < points.size() ? points[i + 1][last] : ref[last];
    const double height = next - points[i][last];
    if (height > 0) volume += height * SliceVolume(prefix, ref, dims - 1);
  }
  return volume;
}

double Hypervolume(const std::vector<std::vector<double>>& points,
                   const std::vector<double>& ref) {
  if (ref.empty()) return 0.0;
  std::vector<std::vector<double>> inside;
  for (const auto& p : points) {
    bool ok = true;
    for (size_t i = 0; i < p.size(); ++i) ok = ok && p[i] < ref[i];
    if (ok) inside.push_back(p);
  }
  // Only non-dominated points matter; dropping the rest keeps slicing fast.
  std::vector<std::vector<double>> front;
  for (size_t i = 0; i < inside.size(); ++i) {
    bool dominated = false;
    for (size_t j = 0; j < inside.size() && !dominated; ++j) {
      if (j == i) continue;
      dominated =
          Dominates(inside[j], inside[i]) || (j < i && inside[j] == inside[i]);
    }
    if (!dominated) front.push_back(inside[i]);
  }
  return SliceVolume(std::move(front), ref, ref.size());
}

std::string Num(double value) {
  if (!std::isfinite(value)) return std::isnan(value) ? "n/a" : "inf";
  return fmt::format("{:.3g}", value);
}

// ---------------------------------------------------------------------------
// The surrogate of one metric.

// The parametric trend over normalised knobs u (fitted with Ceres).
enum class TrendShape { kLinear, kFloor, kCeiling };

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
  double inv_sigma;

  template <typename T>
  bool operator()(T const* const* parameters, T* residual) const {
    const T* f = shape == TrendShape::kLinear ? nullptr : parameters[2];
    residual[0] =
        (T(t) - TrendValue(shape, parameters[0], parameters[1], f, u)) *
        T(inv_sigma);
    return true;
  }
};

struct Trend {
  TrendShape shape = TrendShape::kLinear;
  double a = 0.0;
  std::vector<double> b;
  double f = 0.0;
  double cost = kInf;  // final Ceres cost (data + priors)

  double Value(const std::vector<double>& u) const {
    return TrendValue(shape, &a, b.data(), &f, u);
  }
};

// Gaussian process on the trend's residuals: a constant, a linear and a
// squared-exponential kernel plus noise.
class ResidualGp {
 public:
  struct Hyper {
    double constant2 = 0.01;
    double linear2 = 0.25;
    double signal2 = 0.01;
    std::vector<double> lengths;  // per knob
    double noise2 = 4e-4;
  };

  // Returns the log marginal likelihood (or -inf when singular).
  double Fit(const std::vector<std::vector<double>>& x,
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
    double log_det = 0.0;
    const Eigen::MatrixXd& l = llt_.matrixLLT();
    for (int i = 0; i < n; ++i) log_det += 2.0 * std::log(l(i, i));
    return -0.5 * y.dot(alpha_) - 0.5 * log_det;
  }

  // Mean and variance of an observation at u (noise included).
  void Predict(const std::vector<double>& u, double* mean,
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

 private:
  double Kernel(const std::vector<double>& a,
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

  Hyper hyper_;
  std::vector<std::vector<double>> x_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
  Eigen::VectorXd alpha_;
};

// How a metric is modelled: log of a positive metric, a standardised
// value, or a 0/1 flag.
enum class MetricSpace { kLog, kLinear, kBoolean };

class MetricModel {
 public:
  std::string name;
  // +1: higher is better (maximised, or a constraint wants it high), -1:
  // lower is better, 0: unknown. Used for the prior slopes.
  int good_direction = 0;
  bool in_constraint = false;
  bool boolean_hint = false;  // documented as 0/1

  bool fitted() const { return fitted_; }
  int points() const { return points_; }
  MetricSpace space() const { return space_; }

  // Fits the trend and the residual GP to (u, value) pairs. `prior_slope`
  // holds one prior mean per knob in model units (before the direction),
  // `lengths` the GP's default length scale per knob.
  void Fit(const std::vector<std::vector<double>>& u,
           const std::vector<double>& values,
           const std::vector<double>& prior_slope,
           const std::vector<double>& lengths) {
    fitted_ = false;
    points_ = static_cast<int>(values.size());
    if (values.empty()) return;
    const size_t dims = u.front().size();
    bool all_positive = true;
    bool all_flags = true;
    for (double v : values) {
      all_positive = all_positive && v > 0.0;
      all_flags = all_flags && (v == 0.0 || v == 1.0);
    }
    if (boolean_hint || (all_flags && !all_positive)) {
      space_ = MetricSpace::kBoolean;
    } else if (all_positive) {
      space_ = MetricSpace::kLog;
    } else {
      space_ = MetricSpace::kLinear;
    }
    std::vector<double> t(values.size());
    shift_ = 0.0;
    scale_ = 1.0;
    if (space_ == MetricSpace::kLinear) {
      const double mean =
          std::accumulate(values.begin(), values.end(), 0.0) / values.size();
      double var = 0.0;
      for (double v : values) var += (v - mean) * (v - mean);
      var /= values.size();
      shift_ = mean;
      scale_ = var > 1e-18 ? std::sqrt(var) : std::max(1.0, std::abs(mean));
    }
    for (size_t i = 0; i < values.size(); ++i) {
      t[i] = space_ == MetricSpace::kLog ? std::log(values[i])
                                         : (values[i] - shift_) / scale_;
    }
    // Residual scale of the trend and the prior slope size, in model units.
    const double sigma = space_ == MetricSpace::kLog       ? 0.1
                         : space_ == MetricSpace::kBoolean ? 0.25
                                                           : 0.3;
    const double slope_size =
        space_ == MetricSpace::kBoolean ? kFlagSlope : 1.0;
    std::vector<double> mu(dims, 0.0);
    for (size_t i = 0; i < dims; ++i) {
      mu[i] = good_direction * slope_size * prior_slope[i];
    }
    const double slope_sd =
        space_ == MetricSpace::kBoolean ? kFlagSlopeSd : 1.5;

    // Metrics that resources improve saturate (navigation time cannot
    // drop below driving the route, the control rate has a cap): the trend
    // starts saturating towards the good side; with data enough the shapes
    // compete, a little penalised per extra parameter.
    TrendShape preferred = TrendShape::kLinear;
    if (space_ != MetricSpace::kBoolean && good_direction != 0) {
      preferred =
          good_direction < 0 ? TrendShape::kFloor : TrendShape::kCeiling;
    }
    trend_ = FitTrend(preferred, u, t, mu, slope_sd, sigma);
    if (space_ != MetricSpace::kBoolean && values.size() >= dims + 3) {
      const double penalty = 0.5 * std::log(static_cast<double>(values.size()));
      for (TrendShape shape :
           {TrendShape::kLinear, TrendShape::kFloor, TrendShape::kCeiling}) {
        if (shape == preferred) continue;
        Trend other = FitTrend(shape, u, t, mu, slope_sd, sigma);
        const double extra = shape == TrendShape::kLinear ? 0.0 : penalty;
        const double mine = trend_.shape == TrendShape::kLinear ? 0.0 : penalty;
        if (other.cost + extra < trend_.cost + mine) trend_ = other;
      }
    }
    std::vector<double> residuals(t.size());
    double rms = 0.0;
    for (size_t i = 0; i < t.size(); ++i) {
      residuals[i] = t[i] - trend_.Value(u[i]);
      rms += residuals[i] * residuals[i];
    }
    rms = std::sqrt(rms / t.size());
    // Hyperparameters: a small grid by marginal likelihood once there is
    // data enough, defaults scaled to the metric otherwise.
    const double base_noise = space_ == MetricSpace::kLog       ? 0.03
                              : space_ == MetricSpace::kBoolean ? 0.1
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
    for (double v : values) {
      if (good_direction == 0) break;
      if (std::isnan(best_) || (good_direction < 0 ? v < best_ : v > best_)) {
        best_ = v;
      }
    }
    fitted_ = true;
  }

  // Mean and standard deviation in model units.
  void Predict(const std::vector<double>& u, double* mean, double* sd) const {
    double m = 0.0;
    double var = 1.0;
    gp_.Predict(u, &m, &var);
    *mean = trend_.Value(u) + m;
    *sd = std::sqrt(std::max(var, 0.0));
  }

  // A model value back in metric units.
  // A sampled value as an objective may use it: no better than the best
  // run seen, by kOptimismRoom (model units).
  // The same bound on a mean in model units.
  double BoundedMean(double t, double room = kOptimismRoom) const {
    if (std::isnan(best_) || good_direction == 0 ||
        space_ == MetricSpace::kBoolean) {
      return t;
    }
    const double best_t = space_ == MetricSpace::kLog
                              ? std::log(best_)
                              : (best_ - shift_) / scale_;
    const double bound = best_t + good_direction * room;
    return good_direction < 0 ? std::max(t, bound) : std::min(t, bound);
  }

  double Bounded(double value) const {
    if (std::isnan(best_) || good_direction == 0) return value;
    double bound;
    if (space_ == MetricSpace::kLog) {
      bound = best_ * std::exp(good_direction * kOptimismRoom);
    } else {
      bound = best_ + good_direction * kOptimismRoom * scale_;
    }
    return good_direction < 0 ? std::max(value, bound) : std::min(value, bound);
  }

  double ToMetric(double t) const {
    switch (space_) {
      case MetricSpace::kLog:
        return std::exp(std::clamp(t, -700.0, 700.0));
      case MetricSpace::kBoolean:
        return t >= 0.5 ? 1.0 : 0.0;
      case MetricSpace::kLinear:
        break;
    }
    return shift_ + scale_ * t;
  }

 private:
  static Trend FitTrend(TrendShape shape,
                        const std::vector<std::vector<double>>& u,
                        const std::vector<double>& t,
                        const std::vector<double>& mu, double slope_sd,
                        double sigma) {
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
          new TrendResidual{shape, u[j], t[j], 1.0 / sigma});
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
    if (shape != TrendShape::kLinear) {
      Eigen::MatrixXd fa = Eigen::MatrixXd::Identity(1, 1) / kSaturationSd;
      Eigen::VectorXd fb(1);
      fb(0) = f_prior;
      problem.AddResidualBlock(new ceres::NormalPrior(fa, fb), nullptr,
                               &trend.f);
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

  bool fitted_ = false;
  int points_ = 0;
  double best_ = kNaN;
  MetricSpace space_ = MetricSpace::kLog;
  double shift_ = 0.0;
  double scale_ = 1.0;
  Trend trend_;
  ResidualGp gp_;
};

// ---------------------------------------------------------------------------
// The strategy.

enum class KnobRole { kCores, kFrequency, kRate, kOther };

struct Knob {
  const spec::DesignParameter* parameter = nullptr;
  KnobRole role = KnobRole::kOther;
  std::vector<double> u;  // normalised coordinate of each allowed value
  std::string sensor;     // for a rate: the bind's middle part ("lidar")
};

struct Record {
  Genes genes;
  Observation observation;
  std::vector<double> objectives;  // minimisation form, NaN when failed
  bool feasible = false;
  bool failed = false;
};

struct Candidate {
  Genes genes;
  std::vector<double> u;
  double cost = kNaN;        // exact, from the cost expression
  std::vector<double> mean;  // per model, model units
  std::vector<double> sd;
  double p_feasible = 0.0;
  double gain = 0.0;     // expected hypervolume gain (normalised)
  double p_front = 0.0;  // probability of joining the predicted front
  double factor = 1.0;   // diagnosis multiplier
  double runs = 1.0;     // probability that a run there does not fail
  double score = 0.0;
  std::string hint;  // the remedy it follows, if any
};

class AgentStrategy : public Strategy {
 public:
  explicit AgentStrategy(const spec::Spec& spec)
      : spec_(&spec),
        grid_(spec.design_space),
        budget_(std::max(0, spec.exploration.budget)),
        random_(Random::DeriveSeed(spec.exploration.seed,
                                   "explore.agent.candidates")) {
    SetUpKnobs();
    SetUpMetrics();
    if (!spec.exploration.start_from.empty()) {
      start_ = grid_.FromPoint(spec.exploration.start_from);
    }
    // Stratified normal draws per model, shuffled independently.
    Random draws(
        Random::DeriveSeed(spec.exploration.seed, "explore.agent.samples"));
    z_.assign(kSamples, std::vector<double>(models_.size(), 0.0));
    for (size_t m = 0; m < models_.size(); ++m) {
      std::vector<int> order(kSamples);
      std::iota(order.begin(), order.end(), 0);
      for (int i = kSamples - 1; i > 0; --i) {
        std::swap(order[i], order[draws.Below(static_cast<uint64_t>(i + 1))]);
      }
      for (int s = 0; s < kSamples; ++s) {
        z_[s][m] = NormalQuantile((order[s] + 0.5) / kSamples);
      }
    }
  }

  std::vector<spec::DesignPoint> Ask(int k) override {
    std::vector<spec::DesignPoint> points;
    const int n = std::min(std::max(k, 0), budget_ - proposed_);
    if (n <= 0) {
      rationale_ =
          proposed_ >= budget_
              ? fmt::format("agent: the budget of {} is spent", budget_)
              : std::string("agent: asked for no points");
      return points;
    }
    std::vector<Genes> chosen;
    std::string start_text;
    if (start_) {
      if (!seen_.count(*start_)) {
        chosen.push_back(*start_);
        start_text = fmt::format("Starts at start_from ({}).",
                                 Describe(grid_.ToPoint(*start_)));
      }
      start_.reset();
    }
    std::string choice_text;
    if (static_cast<int>(chosen.size()) < n) {
      try {
        choice_text = Choose(n, &chosen);
      } catch (...) {
        // Nothing may throw: fall back to random unseen points.
        choice_text = Fallback(n, &chosen);
      }
    }
    for (const Genes& genes : chosen) {
      seen_.insert(genes);
      pending_.insert(genes);
      points.push_back(grid_.ToPoint(genes));
      ++proposed_;
    }
    std::string text = LastText();
    if (!start_text.empty()) text += (text.empty() ? "" : " ") + start_text;
    if (!choice_text.empty()) text += (text.empty() ? "" : " ") + choice_text;
    if (points.empty()) text += " No unseen point is left.";
    fresh_ = 0;
    rationale_ = text.empty() ? std::string("agent") : text;
    return points;
  }

  void Tell(const Observation& observation) override {
    try {
      Remember(observation);
    } catch (...) {
      // Out of memory at worst; the run is then simply not remembered.
    }
  }

  std::string name() const override { return "agent"; }
  std::string rationale() const override { return rationale_; }

 private:
  void Remember(const Observation& observation) {
    std::optional<Genes> genes = grid_.FromPoint(observation.point);
    if (!genes || told_.count(*genes)) return;  // foreign or repeated
    told_.insert(*genes);
    seen_.insert(*genes);
    pending_.erase(*genes);
    Record record;
    record.genes = *genes;
    record.observation = observation;
    record.failed = observation.failed;
    record.feasible = observation.feasible && !observation.failed;
    record.objectives = Objectives(observation);
    records_.push_back(std::move(record));
    ++fresh_;
  }

  std::string Fallback(int n, std::vector<Genes>* chosen) {
    const size_t before = chosen->size();
    UnseenSampler sampler(&grid_, Random::DeriveSeed(spec_->exploration.seed,
                                                     "explore.agent.fallback"));
    std::set<Genes> taken = seen_;
    taken.insert(chosen->begin(), chosen->end());
    while (static_cast<int>(chosen->size()) < n) {
      std::optional<Genes> genes = sampler.Next(taken);
      if (!genes) break;
      taken.insert(*genes);
      chosen->push_back(*genes);
    }
    return fmt::format(
        "The model could not be used; {} point(s) drawn at "
        "random among unseen ones.",
        chosen->size() - before);
  }
  // ----- set-up -------------------------------------------------------------

  void SetUpKnobs() {
    for (const spec::DesignParameter& parameter :
         spec_->design_space.parameters) {
      Knob knob;
      knob.parameter = &parameter;
      if (parameter.bind == "platform.cores") {
        knob.role = KnobRole::kCores;
      } else if (parameter.bind == "platform.freq_ghz") {
        knob.role = KnobRole::kFrequency;
      } else if (parameter.bind.rfind("stack.", 0) == 0 &&
                 (parameter.bind.find("rate") != std::string::npos ||
                  parameter.bind.find("_hz") != std::string::npos)) {
        knob.role = KnobRole::kRate;
        const std::string rest = parameter.bind.substr(6);
        knob.sensor = rest.substr(0, rest.find('.'));
      }
      const std::vector<double>& values = parameter.values;
      bool positive = !values.empty() && values.front() > 0.0;
      auto transform = [positive](double v) {
        return positive ? std::log(v) : v;
      };
      const double lo = values.empty() ? 0.0 : transform(values.front());
      const double hi = values.empty() ? 0.0 : transform(values.back());
      for (double v : values) {
        knob.u.push_back(hi > lo ? (transform(v) - lo) / (hi - lo) : 0.0);
      }
      knobs_.push_back(std::move(knob));
      // A knob with few values (a sensor rate of 7 or 14 Hz) is a
      // modifier more than an axis: its levels share much of their
      // behaviour, so they stay correlated in the GP.
      lengths_.push_back(values.size() <= 3 ? kFewValuesLength : kLength);
    }
  }

  void SetUpMetrics() {
    std::vector<std::string> parameter_names = spec_->design_space.Names();
    auto add = [this](const std::string& metric) -> MetricModel* {
      for (MetricModel& model : models_) {
        if (model.name == metric) return &model;
      }
      MetricModel model;
      model.name = metric;
      for (const spec::MetricInfo& info : spec::KnownMetrics()) {
        if (info.name == metric) model.boolean_hint = info.boolean;
      }
      models_.push_back(model);
      return &models_.back();
    };
    for (const spec::Objective& objective : spec_->objectives) {
      if (objective.metric == kCostMetric) continue;
      add(objective.metric)->good_direction = objective.minimize ? -1 : +1;
    }
    const std::vector<std::string> names =
        spec::ConstraintVariableNames(spec_->design_space);
    for (const std::string& text : spec_->constraints) {
      Result<spec::Expression> expression =
          spec::Expression::Parse(text, names);
      if (!expression.ok()) continue;
      for (const std::string& variable : expression->variables()) {
        if (variable == kCostMetric) continue;
        if (std::find(parameter_names.begin(), parameter_names.end(),
                      variable) != parameter_names.end()) {
          continue;
        }
        add(variable)->in_constraint = true;
      }
      constraints_.push_back(std::move(*expression));
    }
    for (const spec::Objective& objective : spec_->objectives) {
      int index = -1;
      for (size_t m = 0; m < models_.size(); ++m) {
        if (models_[m].name == objective.metric) index = static_cast<int>(m);
      }
      objective_model_.push_back(index);
    }
  }

  std::vector<double> Objectives(const Observation& observation) const {
    std::vector<double> values = MinimizationObjectives(*spec_, observation);
    if (observation.failed) return values;
    for (size_t j = 0; j < spec_->objectives.size(); ++j) {
      if (spec_->objectives[j].metric == kCostMetric && std::isnan(values[j])) {
        // A run without the metric: the cost expression gives it.
        Result<double> cost = spec::EvaluateCost(*spec_, observation.point);
        if (cost.ok()) {
          values[j] = spec_->objectives[j].minimize ? *cost : -*cost;
        }
      }
    }
    return values;
  }

  // ----- modelling ----------------------------------------------------------

  std::vector<double> Coordinates(const Genes& genes) const {
    std::vector<double> u(genes.size());
    for (size_t d = 0; d < genes.size(); ++d) u[d] = knobs_[d].u[genes[d]];
    return u;
  }

  // Which way constraint-only metrics should move: probe each constraint
  // with the metric halved and doubled around the latest usable run.
  void ProbeDirections() {
    const Record* reference = nullptr;
    for (auto it = records_.rbegin(); it != records_.rend(); ++it) {
      if (!it->failed) {
        reference = &*it;
        break;
      }
    }
    if (reference == nullptr) return;
    for (MetricModel& model : models_) {
      if (model.good_direction != 0 || !model.in_constraint) continue;
      auto it = reference->observation.metrics.find(model.name);
      if (it == reference->observation.metrics.end()) continue;
      const double value = it->second;
      const bool flag = model.boolean_hint || value == 0.0 || value == 1.0;
      const double low = flag ? 0.0 : (value > 0 ? value * 0.5 : value - 1.0);
      const double high = flag ? 1.0 : (value > 0 ? value * 2.0 : value + 1.0);
      int score = 0;
      for (const spec::Expression& constraint : constraints_) {
        const auto& vars = constraint.variables();
        if (std::find(vars.begin(), vars.end(), model.name) == vars.end()) {
          continue;
        }
        std::map<std::string, double> values = reference->observation.metrics;
        for (const auto& [name, v] : reference->observation.point) {
          values[name] = v;
        }
        values[model.name] = low;
        const double at_low = constraint.Evaluate(values);
        values[model.name] = high;
        const double at_high = constraint.Evaluate(values);
        const bool ok_low = std::isfinite(at_low) && at_low != 0.0;
        const bool ok_high = std::isfinite(at_high) && at_high != 0.0;
        if (ok_high && !ok_low) ++score;
        if (ok_low && !ok_high) --score;
      }
      model.good_direction = score > 0 ? 1 : score < 0 ? -1 : 0;
    }
  }

  // Remedy directions (per knob, -1/0/+1) from one run's diagnosis.
  std::vector<int> RemedyDirections(const Record& record,
                                    std::string* text) const {
    std::vector<int> direction(knobs_.size(), 0);
    std::vector<std::string> parts;
    for (const BottleneckHint& hint : record.observation.bottlenecks) {
      std::vector<std::string> applied;
      const std::string& remedy = hint.remedy;
      for (size_t d = 0; d < knobs_.size(); ++d) {
        const Knob& knob = knobs_[d];
        int want = 0;
        if (knob.role == KnobRole::kCores &&
            remedy.find("more cores") != std::string::npos) {
          want = +1;
        } else if (knob.role == KnobRole::kFrequency &&
                   remedy.find("higher frequency") != std::string::npos) {
          want = +1;
        } else if (knob.role == KnobRole::kRate) {
          const bool names_sensor =
              !knob.sensor.empty() &&
              (hint.node.find(knob.sensor) != std::string::npos ||
               remedy.find(knob.sensor) != std::string::npos);
          if (remedy.find("lower sensor rate") != std::string::npos) {
            want = -1;
          } else if (remedy.find("raise the rate") != std::string::npos &&
                     (names_sensor ||
                      remedy.find("sensor") != std::string::npos)) {
            want = +1;
          }
        }
        if (want != 0 && direction[d] == 0) direction[d] = want;
      }
      if (parts.size() < 2 && !hint.node.empty()) {
        parts.push_back(fmt::format("{} {} -> {}", hint.node, hint.kind,
                                    remedy.empty() ? "?" : remedy));
      }
    }
    if (text != nullptr) *text = fmt::format("{}", fmt::join(parts, ", "));
    return direction;
  }

  void FitModels() {
    ProbeDirections();
    // Prior slope sizes per knob: resources help; the diagnosis of any
    // infeasible run strengthens the knob it names.
    std::vector<double> prior(knobs_.size(), 0.0);
    std::vector<int> votes(knobs_.size(), 0);
    for (const Record& record : records_) {
      if (record.feasible || record.failed) continue;
      const std::vector<int> direction = RemedyDirections(record, nullptr);
      for (size_t d = 0; d < knobs_.size(); ++d) votes[d] += direction[d];
    }
    for (size_t d = 0; d < knobs_.size(); ++d) {
      const KnobRole role = knobs_[d].role;
      if (role == KnobRole::kCores || role == KnobRole::kFrequency) {
        prior[d] = votes[d] > 0 ? 1.0 : 0.6;
      } else if (role == KnobRole::kRate && votes[d] != 0) {
        prior[d] = votes[d] > 0 ? kRateVote : -kRateVote;
      }
    }
    const size_t first = records_.size() > kMaxModelPoints
                             ? records_.size() - kMaxModelPoints
                             : 0;
    // Runs that did not complete (timed out) report censored metrics: when
    // a completion flag is modelled, it alone speaks for them.
    bool completion_modelled = false;
    for (const MetricModel& model : models_) {
      completion_modelled =
          completion_modelled ||
          (model.name == kCompletedMetric && model.in_constraint);
    }
    for (MetricModel& model : models_) {
      std::vector<std::vector<double>> u;
      std::vector<double> values;
      for (size_t i = first; i < records_.size(); ++i) {
        const Record& record = records_[i];
        if (record.failed) continue;
        if (completion_modelled && model.name != kCompletedMetric) {
          auto done = record.observation.metrics.find(kCompletedMetric);
          if (done != record.observation.metrics.end() && done->second == 0.0) {
            continue;
          }
        }
        auto it = record.observation.metrics.find(model.name);
        if (it == record.observation.metrics.end() ||
            !std::isfinite(it->second)) {
          continue;
        }
        u.push_back(Coordinates(record.genes));
        values.push_back(it->second);
      }
      std::vector<double> slope = prior;
      if (!model.in_constraint) {
        for (double& s : slope) s *= 0.4;
      }
      model.Fit(u, values, slope, lengths_);
    }
    any_failed_ = false;
    for (const Record& record : records_) {
      any_failed_ = any_failed_ || record.failed;
    }
  }

  // ----- candidates and scores ---------------------------------------------

  std::vector<Genes> Candidates(const std::vector<Genes>& chosen) {
    std::vector<Genes> out;
    auto usable = [&](const Genes& genes) {
      return !seen_.count(genes) &&
             std::find(chosen.begin(), chosen.end(), genes) == chosen.end();
    };
    if (!grid_.saturated() && grid_.size() <= kEnumerateLimit) {
      for (uint64_t i = 0; i < grid_.size(); ++i) {
        Genes genes = grid_.Decode(i);
        if (usable(genes)) out.push_back(std::move(genes));
      }
      return out;
    }
    std::set<Genes> pool;
    // Neighbours (one and two steps along each knob) of the latest runs,
    // then uniform draws.
    const size_t first = records_.size() > kNeighbourhoods
                             ? records_.size() - kNeighbourhoods
                             : 0;
    for (size_t i = first; i < records_.size(); ++i) {
      const Genes& around = records_[i].genes;
      for (size_t d = 0; d < around.size(); ++d) {
        for (int step : {-2, -1, 1, 2}) {
          Genes genes = around;
          genes[d] += step;
          if (genes[d] < 0 || genes[d] >= grid_.count(d)) continue;
          if (usable(genes)) pool.insert(genes);
        }
      }
    }
    const size_t target = pool.size() + kSampledCandidates;
    for (int i = 0; i < 4 * kSampledCandidates && pool.size() < target; ++i) {
      Genes genes = grid_.RandomGenes(random_);
      if (usable(genes)) pool.insert(genes);
    }
    out.assign(pool.begin(), pool.end());
    return out;
  }

  double Cost(const Genes& genes) const {
    Result<double> cost = spec::EvaluateCost(*spec_, grid_.ToPoint(genes));
    return cost.ok() ? *cost : kNaN;
  }

  // Objectives (minimisation form) and feasibility of sample s.
  bool SampleOutcome(const Candidate& c, int s, std::vector<double>* objectives,
                     std::map<std::string, double>* scratch) const {
    std::map<std::string, double>& values = *scratch;
    values.clear();
    for (size_t m = 0; m < models_.size(); ++m) {
      if (!models_[m].fitted()) continue;
      values[models_[m].name] =
          models_[m].ToMetric(c.mean[m] + c.sd[m] * z_[s][m]);
    }
    if (std::isfinite(c.cost)) values[kCostMetric] = c.cost;
    objectives->resize(spec_->objectives.size());
    for (size_t j = 0; j < spec_->objectives.size(); ++j) {
      const spec::Objective& objective = spec_->objectives[j];
      const int m = objective_model_[j];
      double v = 0.0;
      if (objective.metric == kCostMetric) {
        v = c.cost;
      } else if (m >= 0 && models_[m].fitted()) {
        if (kClampMeanOnly > 0) {
          v = models_[m].ToMetric(models_[m].BoundedMean(
              models_[m].BoundedMean(c.mean[m]) + c.sd[m] * z_[s][m],
              kNoiseRoom));
        } else {
          v = models_[m].Bounded(values[objective.metric]);
        }
      }
      (*objectives)[j] = objective.minimize ? v : -v;
    }
    for (size_t d = 0; d < knobs_.size(); ++d) {
      values[knobs_[d].parameter->name] =
          knobs_[d].parameter->values[c.genes[d]];
    }
    for (const spec::Expression& constraint : constraints_) {
      const double v = constraint.Evaluate(values);
      if (!std::isfinite(v) || v == 0.0) return false;
    }
    return true;
  }

  // The expected objectives at a candidate (sample means, minimisation).
  std::vector<double> MeanObjectives(const Candidate& c) const {
    std::vector<double> mean(spec_->objectives.size(), 0.0);
    std::vector<double> o;
    std::map<std::string, double> scratch;
    for (int s = 0; s < kSamples; ++s) {
      SampleOutcome(c, s, &o, &scratch);
      for (size_t j = 0; j < o.size(); ++j) mean[j] += o[j] / kSamples;
    }
    return mean;
  }

  // Chooses up to n points (after those already in `chosen`); returns the
  // sentence that explains the first model-based choice.
  std::string Choose(int n, std::vector<Genes>* chosen) {
    const int wanted = n - static_cast<int>(chosen->size());
    std::vector<Genes> pool = Candidates(*chosen);
    if (pool.empty()) return {};
    int usable_runs = 0;
    for (const Record& record : records_) usable_runs += record.failed ? 0 : 1;
    FitModels();

    std::vector<Candidate> candidates(pool.size());
    for (size_t i = 0; i < pool.size(); ++i) {
      Candidate& c = candidates[i];
      c.genes = pool[i];
      c.u = Coordinates(c.genes);
      c.cost = Cost(c.genes);
      c.mean.assign(models_.size(), 0.0);
      c.sd.assign(models_.size(), 1.0);
      for (size_t m = 0; m < models_.size(); ++m) {
        if (models_[m].fitted()) models_[m].Predict(c.u, &c.mean[m], &c.sd[m]);
      }
    }
    ApplyFactors(&candidates);
    for (Candidate& c : candidates) c.runs = RunsProbability(c);

    if (usable_runs == 0) {
      // Nothing to model yet: spread out, away from failures, from the
      // middle of the space.
      std::string text = SpaceFilling(&candidates, wanted, chosen);
      return text;
    }

    // Joint samples of every candidate's outcome (objectives, feasible),
    // computed once.
    const size_t nobj = spec_->objectives.size();
    std::map<std::string, double> scratch;
    std::vector<std::vector<std::vector<double>>> normalised(candidates.size());
    std::vector<std::vector<bool>> feasible(candidates.size());
    std::vector<std::vector<double>> mean_objectives(candidates.size());
    for (size_t i = 0; i < candidates.size(); ++i) {
      normalised[i].resize(kSamples);
      feasible[i].resize(kSamples);
      mean_objectives[i].assign(nobj, 0.0);
      int count = 0;
      for (int s = 0; s < kSamples; ++s) {
        feasible[i][s] =
            SampleOutcome(candidates[i], s, &normalised[i][s], &scratch);
        count += feasible[i][s] ? 1 : 0;
        for (size_t j = 0; j < nobj; ++j) {
          mean_objectives[i][j] += normalised[i][s][j] / kSamples;
        }
      }
      candidates[i].p_feasible =
          static_cast<double>(count) / kSamples * candidates[i].runs;
    }

    // Objective scales: the range over feasible runs and the predictions
    // of candidates that may well be feasible.
    std::vector<double> lo(nobj, kInf), hi(nobj, -kInf);
    auto widen = [&](const std::vector<double>& o) {
      for (size_t j = 0; j < nobj; ++j) {
        if (!std::isfinite(o[j])) continue;
        lo[j] = std::min(lo[j], o[j]);
        hi[j] = std::max(hi[j], o[j]);
      }
    };
    for (const Record& record : records_) {
      if (record.feasible) widen(record.objectives);
    }
    for (size_t i = 0; i < candidates.size(); ++i) {
      if (candidates[i].p_feasible >= 0.25) widen(mean_objectives[i]);
    }
    for (size_t j = 0; j < nobj; ++j) {
      if (!(hi[j] > lo[j])) {
        if (!std::isfinite(lo[j])) lo[j] = 0.0;
        hi[j] = lo[j] + 1.0;
      }
    }
    auto normalise = [&](const std::vector<double>& o) {
      std::vector<double> out(nobj);
      for (size_t j = 0; j < nobj; ++j) {
        out[j] = std::isfinite(o[j]) ? (o[j] - lo[j]) / (hi[j] - lo[j]) : kInf;
      }
      return out;
    };
    for (size_t i = 0; i < candidates.size(); ++i) {
      for (int s = 0; s < kSamples; ++s) {
        normalised[i][s] = normalise(normalised[i][s]);
      }
    }
    const std::vector<double> ref(nobj, 1.1);

    // The current feasible front, plus pending points as predicted.
    std::vector<std::vector<double>> front;
    for (const Record& record : records_) {
      if (record.feasible) front.push_back(normalise(record.objectives));
    }
    for (const Genes& genes : pending_) {
      Candidate c = Predicted(genes);
      if (c.p_feasible >= 0.5) front.push_back(normalise(MeanObjectives(c)));
    }

    std::string text;
    std::vector<std::string> extra;

    while (static_cast<int>(chosen->size()) < n) {
      const double base = Hypervolume(front, ref);
      // Which candidates make the Pareto front in each sampled world: the
      // samples share their draws across candidates, so sample s is one
      // plausible version of the whole space, next to the feasible runs
      // seen and the points already chosen.
      std::vector<int> on_front(candidates.size(), 0);
      for (int s = 0; s < kSamples; ++s) {
        std::vector<int> order;
        for (size_t i = 0; i < candidates.size(); ++i) {
          if (feasible[i][s] && candidates[i].runs >= 0.5 &&
              std::find(chosen->begin(), chosen->end(), candidates[i].genes) ==
                  chosen->end()) {
            order.push_back(static_cast<int>(i));
          }
        }
        // By the sum of objectives: no point is dominated by a later one.
        std::vector<double> sums(candidates.size(), 0.0);
        for (int i : order) {
          for (double v : normalised[i][s]) sums[i] += v;
        }
        std::stable_sort(order.begin(), order.end(),
                         [&sums](int a, int b) { return sums[a] < sums[b]; });
        std::vector<const std::vector<double>*> leaders;
        for (const auto& f : front) leaders.push_back(&f);
        for (int i : order) {
          const std::vector<double>& o = normalised[i][s];
          bool beaten = false;
          for (const std::vector<double>* f : leaders) {
            if (Dominates(*f, o)) {
              beaten = true;
              break;
            }
          }
          if (beaten) continue;
          ++on_front[i];
          leaders.push_back(&o);
        }
      }
      double max_gain = 0.0;
      for (size_t i = 0; i < candidates.size(); ++i) {
        Candidate& c = candidates[i];
        c.gain = 0.0;
        c.p_front = 0.0;
        if (std::find(chosen->begin(), chosen->end(), c.genes) !=
            chosen->end()) {
          continue;
        }
        double gain = 0.0;
        for (int s = 0; s < kSamples; ++s) {
          if (!feasible[i][s]) continue;
          const std::vector<double>& o = normalised[i][s];
          bool dominated = false;
          for (const auto& f : front) {
            if (WeaklyDominates(f, o)) {
              dominated = true;
              break;
            }
          }
          if (dominated) continue;
          std::vector<std::vector<double>> with = front;
          with.push_back(o);
          gain += std::max(0.0, Hypervolume(with, ref) - base);
        }
        c.gain = gain / kSamples * c.runs;
        c.p_front = static_cast<double>(on_front[i]) / kSamples * c.runs;
        max_gain = std::max(max_gain, c.gain);
      }
      int best = -1;
      for (size_t i = 0; i < candidates.size(); ++i) {
        Candidate& c = candidates[i];
        if (std::find(chosen->begin(), chosen->end(), c.genes) !=
            chosen->end()) {
          continue;
        }
        // Points likely on the true front count; the hypervolume gain
        // prefers those that widen it. A tiny uncertainty bonus breaks
        // ties.
        double spread = 0.0;
        for (size_t m = 0; m < models_.size(); ++m) spread += c.sd[m];
        spread /= std::max<size_t>(1, models_.size());
        c.score = (c.p_front + kHypervolumeWeight *
                                   (max_gain > 0 ? c.gain / max_gain : 0.0)) *
                      c.factor +
                  1e-4 * c.p_feasible * spread;
        // Diversity inside a batch.
        for (const Genes& other : *chosen) {
          const double d2 = Distance2(c.u, Coordinates(other));
          c.score *= 1.0 - std::exp(-d2 / (2.0 * 0.05 * 0.05));
        }
        if (best < 0 || c.score > candidates[best].score) {
          best = static_cast<int>(i);
        }
      }
      if (best < 0) break;
      const Candidate& pick = candidates[best];
      chosen->push_back(pick.genes);
      const std::vector<double> mean = mean_objectives[best];
      if (pick.p_feasible >= 0.5) front.push_back(normalise(mean));
      if (text.empty()) {
        text = ExplainChoice(pick, mean, base, usable_runs);
      } else {
        extra.push_back(Describe(grid_.ToPoint(pick.genes)));
      }
    }
    if (!extra.empty()) {
      text += fmt::format(
          " For the batch, also ({}), each scored as if the "
          "points before it had their predicted results.",
          fmt::join(extra, "), ("));
    }
    return text;
  }

  Candidate Predicted(const Genes& genes) const {
    Candidate c;
    c.genes = genes;
    c.u = Coordinates(genes);
    c.cost = Cost(genes);
    c.mean.assign(models_.size(), 0.0);
    c.sd.assign(models_.size(), 1.0);
    for (size_t m = 0; m < models_.size(); ++m) {
      if (models_[m].fitted()) models_[m].Predict(c.u, &c.mean[m], &c.sd[m]);
    }
    std::vector<double> o;
    std::map<std::string, double> scratch;
    int count = 0;
    for (int s = 0; s < kSamples; ++s) {
      count += SampleOutcome(c, s, &o, &scratch) ? 1 : 0;
    }
    c.p_feasible = static_cast<double>(count) / kSamples;
    return c;
  }

  static double Distance2(const std::vector<double>& a,
                          const std::vector<double>& b) {
    double d2 = 0.0;
    for (size_t i = 0; i < a.size(); ++i) d2 += (a[i] - b[i]) * (a[i] - b[i]);
    return d2;
  }

  // Grid steps between two points (Euclidean over value indices).
  static double Steps(const Genes& a, const Genes& b) {
    double d2 = 0.0;
    for (size_t i = 0; i < a.size(); ++i) {
      const double d = a[i] - b[i];
      d2 += d * d;
    }
    return std::sqrt(d2);
  }

  // How likely a run at the candidate is to work at all: a kernel-weighted
  // vote of the runs around it (in grid steps), next to a prior that runs
  // work.
  double RunsProbability(const Candidate& c) const {
    if (!any_failed_) return 1.0;
    double weight = kRunsPriorWeight;
    double works = kRunsPriorWeight * kRunsPrior;
    for (const Record& record : records_) {
      const double steps = Steps(c.genes, record.genes);
      const double w =
          std::exp(-steps * steps / (2.0 * kRunsSteps * kRunsSteps));
      weight += w;
      works += record.failed ? 0.0 : w;
    }
    return works / weight;
  }

  // Diagnosis: candidates that move from the latest runs only the way
  // their remedies say get a bonus.
  void ApplyFactors(std::vector<Candidate>* candidates) {
    struct Move {
      Genes from;
      std::vector<int> direction;
      double weight;
      std::string text;
    };
    std::vector<Move> moves;
    const size_t last_round =
        std::min(records_.size(), static_cast<size_t>(std::max(1, fresh_)));
    for (size_t i = records_.size() - last_round; i < records_.size(); ++i) {
      const Record& record = records_[i];
      if (record.failed) continue;
      std::string text;
      std::vector<int> direction = RemedyDirections(record, &text);
      bool any = false;
      for (int v : direction) any = any || v != 0;
      if (!any) continue;
      moves.push_back(
          {record.genes, direction, record.feasible ? 0.1 : 0.3, text});
    }
    for (Candidate& c : *candidates) {
      c.factor = 1.0;
      for (const Move& move : moves) {
        bool follows = true;
        bool moved = false;
        for (size_t d = 0; d < c.genes.size() && follows; ++d) {
          const int delta = c.genes[d] - move.from[d];
          if (delta == 0) continue;
          moved = true;
          follows =
              move.direction[d] != 0 && (delta > 0) == (move.direction[d] > 0);
        }
        if (follows && moved) {
          c.factor *= 1.0 + move.weight;
          if (c.hint.empty()) c.hint = move.text;
        }
      }
    }
  }

  std::string SpaceFilling(std::vector<Candidate>* candidates, int wanted,
                           std::vector<Genes>* chosen) {
    std::vector<std::vector<double>> anchors;
    for (const Genes& genes : *chosen) anchors.push_back(Coordinates(genes));
    for (const Record& record : records_) {
      anchors.push_back(Coordinates(record.genes));
    }
    std::vector<double> middle(knobs_.size(), 0.5);
    int added = 0;
    while (added < wanted) {
      int best = -1;
      double best_score = -kInf;
      for (size_t i = 0; i < candidates->size(); ++i) {
        const Candidate& c = (*candidates)[i];
        if (std::find(chosen->begin(), chosen->end(), c.genes) !=
            chosen->end()) {
          continue;
        }
        double score;
        if (anchors.empty()) {
          score = -Distance2(c.u, middle);
        } else {
          double nearest = kInf;
          for (const auto& a : anchors) {
            nearest = std::min(nearest, Distance2(c.u, a));
          }
          score = nearest;
        }
        score *= c.runs;
        if (score > best_score + 1e-12) {
          best_score = score;
          best = static_cast<int>(i);
        }
      }
      if (best < 0) break;
      chosen->push_back((*candidates)[best].genes);
      anchors.push_back((*candidates)[best].u);
      ++added;
    }
    if (added == 0) return {};
    return fmt::format(
        "No usable run to model yet: proposes {} spread-out point(s) starting "
        "with ({}), away from failed runs.",
        added, Describe(grid_.ToPoint(chosen->at(chosen->size() - added))));
  }

  // ----- words
  // ----------------------------------------------------------------

  std::string Describe(const spec::DesignPoint& point) const {
    std::vector<std::string> parts;
    for (const Knob& knob : knobs_) {
      auto it = point.find(knob.parameter->name);
      if (it == point.end()) continue;
      if (knob.role == KnobRole::kCores) {
        parts.push_back(fmt::format("{:g} cores", it->second));
      } else if (knob.role == KnobRole::kFrequency) {
        parts.push_back(fmt::format("{:g} GHz", it->second));
      } else {
        parts.push_back(
            fmt::format("{} {:g}", knob.parameter->name, it->second));
      }
    }
    return fmt::format("{}", fmt::join(parts, ", "));
  }

  // What the latest run showed.
  std::string LastText() const {
    if (records_.empty()) return {};
    const Record& last = records_.back();
    const std::string where = Describe(last.observation.point);
    if (last.failed) {
      return fmt::format(
          "Last ({}): the run failed; its neighbours are "
          "avoided.",
          where);
    }
    std::vector<std::string> values;
    for (const spec::Objective& objective : spec_->objectives) {
      auto it = last.observation.metrics.find(objective.metric);
      if (it != last.observation.metrics.end()) {
        values.push_back(
            fmt::format("{} {}", objective.metric, Num(it->second)));
      }
    }
    std::string status = "feasible";
    if (!last.feasible) {
      std::vector<std::string> violated;
      for (const std::string& constraint : spec_->constraints) {
        Result<bool> holds = spec::EvaluateConstraint(*spec_, constraint,
                                                      last.observation.metrics,
                                                      last.observation.point);
        if (!holds.ok() || !*holds) {
          std::string shown = constraint;
          for (const MetricModel& model : models_) {
            if (constraint.find(model.name) == std::string::npos) continue;
            auto it = last.observation.metrics.find(model.name);
            if (it != last.observation.metrics.end()) {
              shown = fmt::format("{} {} fails {}", model.name, Num(it->second),
                                  constraint);
              break;
            }
          }
          violated.push_back(shown);
        }
      }
      status = violated.empty()
                   ? std::string("infeasible")
                   : fmt::format("infeasible ({})", fmt::join(violated, "; "));
    }
    std::string diagnosis;
    RemedyDirections(last, &diagnosis);
    return fmt::format("Last ({}): {}, {}{}.", where, status,
                       fmt::join(values, ", "),
                       diagnosis.empty() ? "" : "; " + diagnosis);
  }

  std::string ExplainChoice(const Candidate& pick,
                            const std::vector<double>& mean, double base,
                            int usable_runs) const {
    std::vector<std::string> predicted;
    for (size_t j = 0; j < spec_->objectives.size(); ++j) {
      const spec::Objective& objective = spec_->objectives[j];
      const double v = objective.minimize ? mean[j] : -mean[j];
      predicted.push_back(fmt::format("{} {}", objective.metric, Num(v)));
    }
    std::string reason;
    if (!pick.hint.empty()) {
      reason = fmt::format(", following {}", pick.hint);
    }
    return fmt::format(
        "Model ({} run{}) predicts ({}) feasible with p={:.2f} at {}; "
        "p={:.2f} it joins the predicted Pareto front, expected hypervolume "
        "gain {:.3g} over {:.3g}{}.",
        usable_runs, usable_runs == 1 ? "" : "s",
        Describe(grid_.ToPoint(pick.genes)), pick.p_feasible,
        fmt::join(predicted, ", "), pick.p_front, pick.gain, base, reason);
  }

  const spec::Spec* spec_;
  SpaceGrid grid_;
  int budget_;
  Random random_;
  std::vector<Knob> knobs_;
  std::vector<double> lengths_;  // GP length scale per knob
  std::vector<MetricModel> models_;
  bool any_failed_ = false;
  std::vector<spec::Expression> constraints_;
  std::vector<std::vector<double>> z_;  // [sample][model]
  std::vector<int> objective_model_;    // per objective, index or -1

  std::optional<Genes> start_;
  int proposed_ = 0;
  int fresh_ = 0;  // runs told since the last Ask
  std::set<Genes> seen_;
  std::set<Genes> told_;
  std::set<Genes> pending_;
  std::vector<Record> records_;
  std::string rationale_;
};

}  // namespace

std::unique_ptr<Strategy> NewAgentStrategy(const spec::Spec& spec) {
  return std::make_unique<AgentStrategy>(spec);
}

}  // namespace adse::explore
