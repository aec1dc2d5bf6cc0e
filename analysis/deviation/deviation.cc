// Trajectory deviation: the method is described in deviation.h.
#include "analysis/deviation/deviation.h"

#include <ceres/ceres.h>
#include <fmt/format.h>

#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <deque>
#include <exception>
#include <limits>
#include <memory>
#include <thread>
#include <utility>

namespace adse::analysis {
namespace {

// Each vertex of the ideal path is rounded by a fillet over this length
// either side of it (less on shorter segments). A rounded corner has a
// unique nearest point for samples up to about this far inside it, which
// the fit needs to converge quickly; a vehicle cannot follow a sharper
// corner anyway.
constexpr double kFilletHalfLengthM = 1.0;
// Path vertices closer than this to the previous one are dropped (a
// reference run standing still or creeping would otherwise give segments
// of random direction).
constexpr double kMinVertexSpacingM = 0.05;
// Initial projection: the forward search window is this plus
// kSearchAheadFactor times the distance driven since the previous sample
// (the projection can run ahead of the car on the inside of a curve).
constexpr double kSearchAheadMinM = 10.0;
constexpr double kSearchAheadFactor = 3.0;
// Candidates on later segments are charged this many metres of distance per
// metre of s ahead: where the path crosses itself, the earlier pass wins.
constexpr double kAheadPenaltyPerM = 0.1;
// First sample: among projections this close to the nearest one, the one
// with the smallest s wins (a loop's start, not its end).
constexpr double kFirstSampleTieM = 0.5;
// When the windowed projection is this far from the car, also look along
// the whole rest of the path (the car skipped a detour of the path).
constexpr double kRelocateDistanceM = 5.0;
// sqrt of the monotonicity penalty weight: a step backwards of d metres
// costs as much as a (10 d) metre gap to the path.
constexpr double kMonotonicitySqrtWeight = 10.0;
// Time steps are floored here in the difference operators so that two
// samples microseconds apart do not make the systems ill-conditioned.
constexpr double kMinDtS = 1e-3;
// Light smoothing of e(t) before differentiating it for zigzag_index.
constexpr double kVelocitySmoothingTauS = 0.25;
// Reversal rate that maps to zigzag_index = 1.
constexpr double kZigzagFullScaleHz = 1.0;
// "Reached the end of the path".
constexpr double kCompleteToleranceM = 2.0;
// Below this progress along the path the means fall back to time weights.
constexpr double kMinDrivenForDistanceWeightsM = 0.01;

// The ideal path as a polyline (for the initial projection) and as a C1
// cubic Hermite curve c(s) with filleted corners (for the fit).
class PathModel {
 public:
  // `vertices` has at least 2 points, no two consecutive ones equal.
  explicit PathModel(std::vector<Eigen::Vector2d> vertices)
      : vertices_(std::move(vertices)) {
    vertex_s_.resize(vertices_.size(), 0.0);
    for (size_t k = 1; k < vertices_.size(); ++k) {
      vertex_s_[k] =
          vertex_s_[k - 1] + (vertices_[k] - vertices_[k - 1]).norm();
    }
    BuildKnots();
  }

  double length_m() const { return vertex_s_.back(); }
  size_t segments() const { return vertices_.size() - 1; }
  double vertex_s(size_t k) const { return vertex_s_[k]; }

  // Closest point of polyline segment k to q with s >= s_min; returns
  // {s, distance}.
  std::pair<double, double> ProjectOnSegment(size_t k, const Eigen::Vector2d& q,
                                             double s_min) const {
    const Eigen::Vector2d a = vertices_[k];
    const Eigen::Vector2d ab = vertices_[k + 1] - a;
    const double len = vertex_s_[k + 1] - vertex_s_[k];
    double t = std::clamp((q - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
    const double t_min = (s_min - vertex_s_[k]) / len;
    if (t < t_min) t = std::min(t_min, 1.0);
    return {vertex_s_[k] + t * len, (a + t * ab - q).norm()};
  }

  // Segment of the polyline that contains s.
  size_t SegmentAt(double s) const {
    auto it = std::upper_bound(vertex_s_.begin(), vertex_s_.end(), s);
    const size_t k = static_cast<size_t>(it - vertex_s_.begin());
    return std::clamp<size_t>(k == 0 ? 0 : k - 1, 0, segments() - 1);
  }

  // c(s) and dc/ds; s is clamped to [0, L].
  void Eval(double s, Eigen::Vector2d* c, Eigen::Vector2d* dc) const {
    s = std::clamp(s, 0.0, length_m());
    auto it = std::upper_bound(knot_s_.begin(), knot_s_.end(), s);
    size_t k = static_cast<size_t>(it - knot_s_.begin());
    k = std::min(k == 0 ? 0 : k - 1, knot_s_.size() - 2);
    const double h = knot_s_[k + 1] - knot_s_[k];
    const double u = (s - knot_s_[k]) / h;
    const double u2 = u * u;
    const double u3 = u2 * u;
    const Eigen::Vector2d& p0 = knot_p_[k];
    const Eigen::Vector2d& p1 = knot_p_[k + 1];
    const Eigen::Vector2d m0 = h * knot_m_[k];
    const Eigen::Vector2d m1 = h * knot_m_[k + 1];
    *c = (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * m0 +
         (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * m1;
    *dc = ((6 * u2 - 6 * u) * p0 + (3 * u2 - 4 * u + 1) * m0 +
           (-6 * u2 + 6 * u) * p1 + (3 * u2 - 2 * u) * m1) /
          h;
  }

  // Left unit normal of c at s.
  Eigen::Vector2d Normal(double s) const {
    Eigen::Vector2d c, dc;
    Eval(s, &c, &dc);
    const double n = dc.norm();
    if (n <= 0.0) return Eigen::Vector2d(0.0, 0.0);
    return Eigen::Vector2d(-dc.y(), dc.x()) / n;
  }

 private:
  // Fillet knots: on every segment, one knot where the fillet of each end
  // vertex begins (at the path's ends: the end itself), tangent = the
  // segment's direction with unit speed. Between two knots of one segment
  // the Hermite piece is that segment, exactly and at unit speed; between
  // the knots either side of a vertex it is a C1 fillet that cuts the
  // corner by 0.35 h at 90 degrees (h: the fillet's half-length).
  void BuildKnots() {
    const size_t nv = vertices_.size();
    std::vector<double> half(nv, 0.0);
    for (size_t v = 1; v + 1 < nv; ++v) {
      half[v] =
          std::min({kFilletHalfLengthM, 0.5 * (vertex_s_[v] - vertex_s_[v - 1]),
                    0.5 * (vertex_s_[v + 1] - vertex_s_[v])});
    }
    for (size_t k = 0; k + 1 < nv; ++k) {
      const Eigen::Vector2d dir =
          (vertices_[k + 1] - vertices_[k]) / (vertex_s_[k + 1] - vertex_s_[k]);
      AddKnot(vertex_s_[k] + half[k], vertices_[k] + half[k] * dir, dir);
      AddKnot(vertex_s_[k + 1] - half[k + 1],
              vertices_[k + 1] - half[k + 1] * dir, dir);
    }
  }

  void AddKnot(double s, const Eigen::Vector2d& p, const Eigen::Vector2d& m) {
    // A segment split in two halves by its fillets gives the same knot
    // twice.
    if (!knot_s_.empty() && s <= knot_s_.back() + 1e-9) return;
    knot_s_.push_back(s);
    knot_p_.push_back(p);
    knot_m_.push_back(m);
  }

  std::vector<Eigen::Vector2d> vertices_;
  std::vector<double> vertex_s_;
  std::vector<double> knot_s_;
  std::vector<Eigen::Vector2d> knot_p_;
  std::vector<Eigen::Vector2d> knot_m_;
};

// Step 2 of the method: monotone initial arc lengths.
std::vector<double> InitialArcLengths(const PathModel& path,
                                      const std::vector<TimedXy>& actual) {
  std::vector<double> s(actual.size(), 0.0);
  const size_t segments = path.segments();
  auto point = [&](size_t i) {
    return Eigen::Vector2d(actual[i].x_m, actual[i].y_m);
  };
  // First sample: the earliest of the (near-)nearest projections.
  {
    const Eigen::Vector2d q = point(0);
    std::vector<std::pair<double, double>> proj(segments);
    double best = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < segments; ++k) {
      proj[k] = path.ProjectOnSegment(k, q, 0.0);
      best = std::min(best, proj[k].second);
    }
    for (size_t k = 0; k < segments; ++k) {
      if (proj[k].second <= best + kFirstSampleTieM) {
        s[0] = proj[k].first;
        break;
      }
    }
  }
  for (size_t i = 1; i < actual.size(); ++i) {
    const Eigen::Vector2d q = point(i);
    const double s0 = s[i - 1];
    const double budget =
        kSearchAheadMinM + kSearchAheadFactor * (q - point(i - 1)).norm();
    double best_score = std::numeric_limits<double>::infinity();
    double best_s = s0;
    double best_dist = std::numeric_limits<double>::infinity();
    for (size_t k = path.SegmentAt(s0);
         k < segments && path.vertex_s(k) <= s0 + budget; ++k) {
      const auto [sk, dk] = path.ProjectOnSegment(k, q, s0);
      const double score = dk + kAheadPenaltyPerM * (sk - s0);
      if (score < best_score) {
        best_score = score;
        best_s = sk;
        best_dist = dk;
      }
    }
    if (best_dist > kRelocateDistanceM) {
      // Only a much nearer point counts: a far-off car must not jump to a
      // later pass of the path just because it happens to be a bit closer.
      double far_dist = std::numeric_limits<double>::infinity();
      double far_s = s0;
      for (size_t k = path.SegmentAt(s0); k < segments; ++k) {
        const auto [sk, dk] = path.ProjectOnSegment(k, q, s0);
        if (dk < far_dist) {
          far_dist = dk;
          far_s = sk;
        }
      }
      if (far_dist < 0.5 * best_dist) best_s = far_s;
    }
    s[i] = best_s;
  }
  return s;
}

// (a) 2D gap between sample p and c(s).
class GapCost final : public ceres::SizedCostFunction<2, 1> {
 public:
  GapCost(const PathModel* path, Eigen::Vector2d p) : path_(path), p_(p) {}
  bool Evaluate(double const* const* params, double* residuals,
                double** jacobians) const override {
    Eigen::Vector2d c, dc;
    path_->Eval(params[0][0], &c, &dc);
    residuals[0] = p_.x() - c.x();
    residuals[1] = p_.y() - c.y();
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      jacobians[0][0] = -dc.x();
      jacobians[0][1] = -dc.y();
    }
    return true;
  }

 private:
  const PathModel* path_;
  Eigen::Vector2d p_;
};

// (c) One-sided penalty on s_next < s (squared hinge: C1 in the cost).
inline double MonotonicityResidual(double s, double s_next, double* grad) {
  const bool active = s > s_next;
  *grad = active ? kMonotonicitySqrtWeight : 0.0;
  return active ? kMonotonicitySqrtWeight * (s - s_next) : 0.0;
}

class MonotonicityCost final : public ceres::SizedCostFunction<1, 1, 1> {
 public:
  bool Evaluate(double const* const* params, double* residuals,
                double** jacobians) const override {
    double g = 0.0;
    residuals[0] = MonotonicityResidual(params[0][0], params[1][0], &g);
    if (jacobians != nullptr) {
      if (jacobians[0] != nullptr) jacobians[0][0] = g;
      if (jacobians[1] != nullptr) jacobians[1][0] = -g;
    }
    return true;
  }
};

// (b) + (c) in one block (fewer blocks, less Ceres overhead) over
// (s_prev, s, s_next): the generalised second difference
// a*s_prev + b*s + c*s_next, and the monotonicity of (s_prev, s).
class LinkCost final : public ceres::SizedCostFunction<2, 1, 1, 1> {
 public:
  LinkCost(double a, double b, double c) : a_(a), b_(b), c_(c) {}
  bool Evaluate(double const* const* params, double* residuals,
                double** jacobians) const override {
    residuals[0] = a_ * params[0][0] + b_ * params[1][0] + c_ * params[2][0];
    double g = 0.0;
    residuals[1] = MonotonicityResidual(params[0][0], params[1][0], &g);
    if (jacobians != nullptr) {
      // Row-major 2 x 1 per parameter block.
      if (jacobians[0] != nullptr) {
        jacobians[0][0] = a_;
        jacobians[0][1] = g;
      }
      if (jacobians[1] != nullptr) {
        jacobians[1][0] = b_;
        jacobians[1][1] = -g;
      }
      if (jacobians[2] != nullptr) {
        jacobians[2][0] = c_;
        jacobians[2][1] = 0.0;
      }
    }
    return true;
  }

 private:
  double a_, b_, c_;
};

struct ArcLengthFit {
  int iterations = 0;
  bool converged = false;
};

// Step 3: refines `s` in place.
ArcLengthFit FitArcLengths(const PathModel& path,
                           const std::vector<TimedXy>& actual,
                           const DeviationOptions& options,
                           std::vector<double>* s) {
  const size_t n = actual.size();
  ceres::Problem::Options problem_options;
  // Cost and loss objects are owned here; one loss and one monotonicity
  // cost are shared by many blocks.
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  // Deques: few allocations, and pointers stay valid as they grow.
  std::deque<GapCost> gaps;
  std::deque<LinkCost> links;
  std::unique_ptr<ceres::LossFunction> loss;
  if (options.robust_loss_scale_m > 0.0) {
    loss = std::make_unique<ceres::HuberLoss>(options.robust_loss_scale_m);
  }
  MonotonicityCost monotonicity;
  const double L = path.length_m();
  for (size_t i = 0; i < n; ++i) {
    gaps.emplace_back(&path, Eigen::Vector2d(actual[i].x_m, actual[i].y_m));
    problem.AddResidualBlock(&gaps.back(), loss.get(), &(*s)[i]);
    problem.SetParameterLowerBound(&(*s)[i], 0, 0.0);
    problem.SetParameterUpperBound(&(*s)[i], 0, L);
  }
  const double sqrt_w = std::sqrt(options.smoothness_weight);
  size_t first_plain_monotonicity = 0;
  if (sqrt_w > 0.0 && n >= 3) {
    for (size_t i = 1; i + 1 < n; ++i) {
      const double dt0 = std::max(actual[i].t_s - actual[i - 1].t_s, kMinDtS);
      const double dt1 = std::max(actual[i + 1].t_s - actual[i].t_s, kMinDtS);
      const double k = sqrt_w * 0.5 * (dt0 + dt1);
      links.emplace_back(k / dt0, -k * (1.0 / dt0 + 1.0 / dt1), k / dt1);
      problem.AddResidualBlock(&links.back(), nullptr, &(*s)[i - 1], &(*s)[i],
                               &(*s)[i + 1]);
    }
    first_plain_monotonicity = n - 2;  // links hold pairs (0,1)..(n-3,n-2)
  }
  for (size_t i = first_plain_monotonicity; i + 1 < n; ++i) {
    problem.AddResidualBlock(&monotonicity, nullptr, &(*s)[i], &(*s)[i + 1]);
  }

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver_options.sparse_linear_algebra_library_type =
      ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE)
          ? ceres::SUITE_SPARSE
          : ceres::EIGEN_SPARSE;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.num_threads =
      static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 4u));
  solver_options.logging_type = ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = false;
  // The lateral error hardly depends on small along-track errors of s (not
  // at all on straight pieces), so stop once the cost settles: a tighter
  // tolerance only buys millimetres of s at a few corner samples, at a
  // full iteration each.
  solver_options.function_tolerance = 1e-6;
  solver_options.gradient_tolerance = 1e-8;
  solver_options.parameter_tolerance = 1e-8;

  const std::vector<double> initial = *s;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  ArcLengthFit fit;
  fit.iterations =
      summary.num_successful_steps + summary.num_unsuccessful_steps;
  fit.converged = summary.termination_type == ceres::CONVERGENCE;
  if (!summary.IsSolutionUsable()) *s = initial;
  return fit;
}

// Isotonic (non-decreasing) least-squares projection, pool adjacent
// violators.
void MakeMonotone(std::vector<double>* s) {
  struct Block {
    double sum;
    size_t count;
  };
  std::vector<Block> blocks;
  blocks.reserve(s->size());
  for (double v : *s) {
    blocks.push_back({v, 1});
    while (blocks.size() > 1) {
      const Block& b = blocks.back();
      const Block& a = blocks[blocks.size() - 2];
      if (a.sum / a.count <= b.sum / b.count) break;
      const Block merged{a.sum + b.sum, a.count + b.count};
      blocks.pop_back();
      blocks.back() = merged;
    }
  }
  size_t i = 0;
  for (const Block& b : blocks) {
    const double mean = b.sum / b.count;
    for (size_t j = 0; j < b.count; ++j) (*s)[i++] = mean;
  }
}

// Trapezoidal time weights (dt floored).
std::vector<double> TimeWeights(const std::vector<double>& t) {
  const size_t n = t.size();
  std::vector<double> w(n, n == 1 ? 1.0 : 0.0);
  for (size_t i = 0; i + 1 < n; ++i) {
    const double h = std::max(t[i + 1] - t[i], kMinDtS);
    w[i] += 0.5 * h;
    w[i + 1] += 0.5 * h;
  }
  return w;
}

// Whittaker smoother of e(t) with time scale tau (see deviation.h):
// (W + tau^4 D' W' D) z = W e.
Result<std::vector<double>> WhittakerSmooth(const std::vector<double>& t,
                                            const std::vector<double>& e,
                                            double tau_s) {
  const size_t n = t.size();
  if (n < 3) return e;
  const std::vector<double> w = TimeWeights(t);
  const double mu = std::pow(tau_s, 4);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(n + 9 * n);
  for (size_t i = 0; i < n; ++i) {
    triplets.emplace_back(static_cast<int>(i), static_cast<int>(i), w[i]);
  }
  for (size_t j = 1; j + 1 < n; ++j) {
    const double h0 = std::max(t[j] - t[j - 1], kMinDtS);
    const double h1 = std::max(t[j + 1] - t[j], kMinDtS);
    const double c = 2.0 / (h0 + h1);
    const double d[3] = {c / h0, -c * (1.0 / h0 + 1.0 / h1), c / h1};
    const double scale = mu * 0.5 * (h0 + h1);
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        triplets.emplace_back(static_cast<int>(j) - 1 + a,
                              static_cast<int>(j) - 1 + b, scale * d[a] * d[b]);
      }
    }
  }
  Eigen::SparseMatrix<double> A(static_cast<int>(n), static_cast<int>(n));
  A.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::VectorXd rhs(static_cast<int>(n));
  for (size_t i = 0; i < n; ++i) rhs[static_cast<int>(i)] = w[i] * e[i];
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(A);
  if (solver.info() != Eigen::Success) {
    return Status::Internal("deviation: smoothing system factorisation failed");
  }
  const Eigen::VectorXd z = solver.solve(rhs);
  if (solver.info() != Eigen::Success) {
    return Status::Internal("deviation: smoothing system solve failed");
  }
  return std::vector<double>(z.data(), z.data() + n);
}

// Schmitt-trigger count of sign reversals of de/dt.
int CountReversals(const std::vector<double>& t, const std::vector<double>& e,
                   double threshold_mps) {
  const size_t n = t.size();
  if (n < 2) return 0;
  int state = 0;  // +1 / -1 once the speed has crossed +/- the threshold
  int reversals = 0;
  for (size_t i = 0; i < n; ++i) {
    const size_t a = i == 0 ? 0 : i - 1;
    const size_t b = i + 1 == n ? n - 1 : i + 1;
    const double v = (e[b] - e[a]) / (t[b] - t[a]);
    if (v >= threshold_mps && state <= 0) {
      if (state < 0) ++reversals;
      state = 1;
    } else if (v <= -threshold_mps && state >= 0) {
      if (state > 0) ++reversals;
      state = -1;
    }
  }
  return reversals;
}

bool Finite(double v) { return std::isfinite(v); }

Status Validate(const std::vector<Eigen::Vector2d>& ideal_path,
                const std::vector<TimedXy>& actual, double lane_width_m,
                const DeviationOptions& o) {
  if (ideal_path.size() < 2) {
    return Status::InvalidArgument(
        fmt::format("deviation: the ideal path needs at least 2 points, got {}",
                    ideal_path.size()));
  }
  for (size_t k = 0; k < ideal_path.size(); ++k) {
    if (!ideal_path[k].allFinite()) {
      return Status::InvalidArgument(
          fmt::format("deviation: ideal path point {} is not finite", k));
    }
  }
  if (actual.empty()) {
    return Status::InvalidArgument("deviation: the actual trajectory is empty");
  }
  for (size_t i = 0; i < actual.size(); ++i) {
    const TimedXy& a = actual[i];
    if (!Finite(a.t_s) || !Finite(a.x_m) || !Finite(a.y_m)) {
      return Status::InvalidArgument(
          fmt::format("deviation: trajectory sample {} is not finite", i));
    }
    if (i > 0 && !(a.t_s > actual[i - 1].t_s)) {
      return Status::InvalidArgument(fmt::format(
          "deviation: trajectory times must increase, but sample {} has "
          "t={} s after t={} s",
          i, a.t_s, actual[i - 1].t_s));
    }
  }
  if (!Finite(o.normalize_by_m) || o.normalize_by_m < 0.0) {
    return Status::InvalidArgument(fmt::format(
        "deviation: normalize_by_m must be >= 0, got {}", o.normalize_by_m));
  }
  if (o.normalize_by_m == 0.0 &&
      !(Finite(lane_width_m) && lane_width_m > 0.0)) {
    return Status::InvalidArgument(fmt::format(
        "deviation: lane_width_m must be > 0 (or set normalize_by_m), got {}",
        lane_width_m));
  }
  if (!Finite(o.smoothness_weight) || o.smoothness_weight < 0.0) {
    return Status::InvalidArgument(
        fmt::format("deviation: smoothness_weight must be >= 0, got {}",
                    o.smoothness_weight));
  }
  if (!Finite(o.robust_loss_scale_m) || o.robust_loss_scale_m < 0.0) {
    return Status::InvalidArgument(
        fmt::format("deviation: robust_loss_scale_m must be >= 0, got {}",
                    o.robust_loss_scale_m));
  }
  if (!Finite(o.smoothing_window_s) || o.smoothing_window_s <= 0.0) {
    return Status::InvalidArgument(
        fmt::format("deviation: smoothing_window_s must be > 0, got {}",
                    o.smoothing_window_s));
  }
  if (!Finite(o.zigzag_threshold_mps) || o.zigzag_threshold_mps < 0.0) {
    return Status::InvalidArgument(
        fmt::format("deviation: zigzag_threshold_mps must be >= 0, got {}",
                    o.zigzag_threshold_mps));
  }
  if (o.max_iterations < 1) {
    return Status::InvalidArgument(fmt::format(
        "deviation: max_iterations must be >= 1, got {}", o.max_iterations));
  }
  return Status::Ok();
}

double WeightedMean(const std::vector<double>& w,
                    const std::vector<double>& v) {
  double sw = 0.0, swv = 0.0;
  for (size_t i = 0; i < v.size(); ++i) {
    sw += w[i];
    swv += w[i] * v[i];
  }
  return sw > 0.0 ? swv / sw : 0.0;
}

Result<DeviationResult> FitDeviationImpl(
    const std::vector<Eigen::Vector2d>& ideal_path,
    const std::vector<TimedXy>& actual, double lane_width_m,
    const DeviationOptions& options) {
  ADSE_RETURN_IF_ERROR(Validate(ideal_path, actual, lane_width_m, options));
  std::vector<Eigen::Vector2d> vertices;
  vertices.reserve(ideal_path.size());
  for (const Eigen::Vector2d& p : ideal_path) {
    if (vertices.empty() ||
        (p - vertices.back()).norm() >= kMinVertexSpacingM) {
      vertices.push_back(p);
    }
  }
  // Keep the true end point: it defines where the path ends.
  if ((ideal_path.back() - vertices.back()).norm() > 0.0) {
    if (vertices.size() > 1) vertices.pop_back();
    if ((ideal_path.back() - vertices.back()).norm() > 1e-9) {
      vertices.push_back(ideal_path.back());
    }
  }
  if (vertices.size() < 2) {
    return Status::InvalidArgument(
        "deviation: the ideal path has zero length (all its points coincide)");
  }
  const PathModel path(std::move(vertices));
  const size_t n = actual.size();

  DeviationResult r;
  r.path_length_m = path.length_m();
  r.normalizer_m = options.normalize_by_m > 0.0 ? options.normalize_by_m
                                                : 0.5 * lane_width_m;
  r.s_m = InitialArcLengths(path, actual);
  const ArcLengthFit fit = FitArcLengths(path, actual, options, &r.s_m);
  r.iterations = fit.iterations;
  r.converged = fit.converged;
  MakeMonotone(&r.s_m);
  for (double& s : r.s_m) s = std::clamp(s, 0.0, path.length_m());

  std::vector<double> t(n);
  r.lateral_m.resize(n);
  for (size_t i = 0; i < n; ++i) {
    t[i] = actual[i].t_s;
    Eigen::Vector2d c, dc;
    path.Eval(r.s_m[i], &c, &dc);
    r.lateral_m[i] = (Eigen::Vector2d(actual[i].x_m, actual[i].y_m) - c)
                         .dot(path.Normal(r.s_m[i]));
  }

  Result<std::vector<double>> smooth =
      WhittakerSmooth(t, r.lateral_m, options.smoothing_window_s);
  if (!smooth.ok()) return smooth.status();
  r.smooth_lateral_m = std::move(smooth).value();
  Result<std::vector<double>> fast =
      WhittakerSmooth(t, r.lateral_m, kVelocitySmoothingTauS);
  if (!fast.ok()) return fast.status();

  // Weights: progress along the path around each sample (see deviation.h).
  std::vector<double> w(n, 0.0);
  for (size_t i = 0; i + 1 < n; ++i) {
    const double ds = r.s_m[i + 1] - r.s_m[i];  // >= 0: s is monotone
    w[i] += 0.5 * ds;
    w[i + 1] += 0.5 * ds;
  }
  if (r.s_m.back() - r.s_m.front() < kMinDrivenForDistanceWeightsM) {
    w = TimeWeights(t);
  }

  std::vector<double> abs_e(n), osc2(n);
  for (size_t i = 0; i < n; ++i) {
    abs_e[i] = std::abs(r.lateral_m[i]);
    const double o = r.lateral_m[i] - r.smooth_lateral_m[i];
    osc2[i] = o * o;
    r.max_deviation_m = std::max(r.max_deviation_m, abs_e[i]);
  }
  r.mean_abs_lateral_m = WeightedMean(w, abs_e);
  r.offset_m = WeightedMean(w, r.smooth_lateral_m);
  r.oscillation_rms_m = std::sqrt(WeightedMean(w, osc2));
  r.deviation_score =
      std::clamp(r.mean_abs_lateral_m / r.normalizer_m, 0.0, 1.0);

  const double duration_s = t.back() - t.front();
  if (duration_s > 0.0) {
    const int reversals =
        CountReversals(t, fast.value(), options.zigzag_threshold_mps);
    r.zigzag_index =
        std::clamp(reversals / duration_s / kZigzagFullScaleHz, 0.0, 1.0);
  }

  const double s_last = r.s_m.back();
  r.driven_fraction = s_last / path.length_m();
  r.complete = path.length_m() - s_last <= kCompleteToleranceM;
  return r;
}

}  // namespace

Result<DeviationResult> FitDeviation(
    const std::vector<Eigen::Vector2d>& ideal_path,
    const std::vector<TimedXy>& actual, double lane_width_m,
    const DeviationOptions& options) {
  // Nothing may escape: Ceres, Eigen and the allocator can throw.
  try {
    return FitDeviationImpl(ideal_path, actual, lane_width_m, options);
  } catch (const std::exception& e) {
    return Status::Internal(fmt::format("deviation: {}", e.what()));
  } catch (...) {
    return Status::Internal("deviation: unknown exception");
  }
}

}  // namespace adse::analysis
