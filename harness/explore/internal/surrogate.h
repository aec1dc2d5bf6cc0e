// The built-in agent's surrogate of one metric: a parametric trend over
// the normalised knobs (fitted with Ceres under a robust loss) plus a small
// Gaussian process on its residuals, which interpolates the runs and gives
// an uncertainty that grows with the distance from them. Internal to the
// agent (harness/explore/agent*.cc).
#ifndef ADSE_HARNESS_EXPLORE_INTERNAL_SURROGATE_H_
#define ADSE_HARNESS_EXPLORE_INTERNAL_SURROGATE_H_

#include <Eigen/Dense>
#include <limits>
#include <string>
#include <vector>

namespace adse::explore::internal {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr double kInf = std::numeric_limits<double>::infinity();

// Inverse of the standard normal CDF (Acklam's rational approximation,
// relative error < 1.2e-9), for stratified samples.
double NormalQuantile(double p);

// The parametric trend over normalised knobs u (fitted with Ceres).
enum class TrendShape { kLinear, kFloor, kCeiling };

struct Trend {
  TrendShape shape = TrendShape::kLinear;
  double a = 0.0;
  std::vector<double> b;
  double f = 0.0;
  double cost = kInf;  // final Ceres cost
                       // (data + priors)

  double Value(const std::vector<double>& u) const;
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

  // Leave-one-out predictions of the fitted residuals (mean, variance),
  // in closed form (Rasmussen & Williams, 5.12).
  void LeaveOneOut(std::vector<double>* mean,
                   std::vector<double>* variance) const;

  // Returns the log marginal likelihood (or -inf when singular).
  double Fit(const std::vector<std::vector<double>>& x,
             const std::vector<double>& r, const Hyper& hyper);

  // Mean and variance of an observation at u (noise included).
  void Predict(const std::vector<double>& u, double* mean,
               double* variance) const;

 private:
  double Kernel(const std::vector<double>& a,
                const std::vector<double>& b) const;

  Hyper hyper_;
  std::vector<std::vector<double>> x_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
  Eigen::VectorXd alpha_;
  Eigen::VectorXd y_;
};

// How a metric is modelled: log of a positive metric, a standardised
// value, a 0/1 flag, or the reciprocal of a time (its rate, scaled by the
// runs' median time).
enum class MetricSpace { kLog, kLinear, kBoolean, kReciprocal };

class MetricModel {
 public:
  std::string name;
  // +1: higher is better (maximised, or a constraint wants it high), -1:
  // lower is better, 0: unknown. Used for the prior slopes.
  int good_direction = 0;
  bool in_constraint = false;
  bool boolean_hint = false;  // documented as 0/1
  // Documented as a count: a sample is rounded to a whole number of
  // events, so that a bound such as `== 0` can hold on it.
  bool count_hint = false;
  // Documented as a precision metric (spec::MetricInfo::precision): a knob
  // that thins the stack's data makes it worse, not better.
  bool precision_hint = false;
  // A time to finish, which may also be modelled as its rate (1 / time,
  // falling to zero where a computer cannot keep up); the space whose
  // leave-one-out predictions fit the runs better is used.
  bool rate_hint = false;
  // Per knob (may be empty: none): the prior slope's sign is certain, as
  // a knob's role says which way it moves the metric (more cores never
  // slow the stack, a faster sensor never lightens it), so the trend's
  // slope is bounded to that side of zero. Without it a few runs that
  // change several knobs at once can credit one knob with another's
  // effect.
  std::vector<bool> signed_slopes;

  bool fitted() const { return fitted_; }
  int points() const { return points_; }
  MetricSpace space() const { return space_; }

  // Fits the trend and the residual GP to (u, value) pairs. `sides` (may be
  // empty: all measured) marks censored values: +1 when the true value is
  // known only to be above `value` (a run stopped early past a time bound),
  // -1 below it, 0 measured. `prior_slope` holds one prior mean per knob in
  // model units (before the direction), `lengths` the GP's default length
  // scale per knob.
  void Fit(const std::vector<std::vector<double>>& u,
           const std::vector<double>& values, const std::vector<int>& sides,
           const std::vector<double>& prior_slope,
           const std::vector<double>& lengths);

  // Mean and standard deviation in model units.
  void Predict(const std::vector<double>& u, double* mean, double* sd) const;

  // A sampled value as an objective may use it: no better than the best
  // run seen by more than kOptimismRoom (model units), since a surrogate
  // extrapolates too eagerly.
  double Bounded(double value) const;

  // A model value back in metric units.
  double ToMetric(double t) const;

 private:
  // Fits in `*forced` (kLog or kReciprocal for a positive metric), or in
  // the space the values suggest when it is null.
  void FitIn(const std::vector<std::vector<double>>& u,
             const std::vector<double>& values, const std::vector<int>& sides,
             const std::vector<double>& prior_slope,
             const std::vector<double>& lengths, const MetricSpace* forced);

  // Sum over the measured runs of the log density (in metric units) of
  // each run's value under the leave-one-out prediction at its point.
  double LeaveOneOutLogDensity(const std::vector<std::vector<double>>& u,
                               const std::vector<double>& values,
                               const std::vector<int>& sides) const;

  static Trend FitTrend(TrendShape shape,
                        const std::vector<std::vector<double>>& u,
                        const std::vector<double>& t,
                        const std::vector<int>& sides,
                        const std::vector<double>& mu,
                        const std::vector<bool>& signed_slopes, double slope_sd,
                        double sigma);

  bool fitted_ = false;
  int points_ = 0;
  double best_ = kNaN;
  MetricSpace space_ = MetricSpace::kLog;
  double shift_ = 0.0;
  double scale_ = 1.0;
  Trend trend_;
  ResidualGp gp_;
};

}  // namespace adse::explore::internal

#endif  // ADSE_HARNESS_EXPLORE_INTERNAL_SURROGATE_H_
