#include "stack/runtime/cost_profile.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace adse::stack {

double SampleCost(const CallbackCost& cost, double u) {
  const std::vector<CostQuantile>& qs = cost.quantiles;
  if (qs.empty()) return 0.0;
  u = std::clamp(u, 0.0, 1.0);
  // The first point whose quantile is >= u; quantiles start at 0.
  const auto hi = std::lower_bound(
      qs.begin(), qs.end(), u,
      [](const CostQuantile& point, double q) { return point.q < q; });
  if (hi == qs.begin()) return hi->cost_s;
  if (hi == qs.end()) return qs.back().cost_s;
  const auto lo = hi - 1;
  const double t = (u - lo->q) / (hi->q - lo->q);
  return lo->cost_s + t * (hi->cost_s - lo->cost_s);
}

double InvocationUniform(uint64_t seed, uint64_t i) {
  uint64_t z = seed + (i + 1) * 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-53;
}

double DrawnCostS(const CallbackCost& cost, double u, double units) {
  double s = SampleCost(cost, u);
  if (cost.reference_units > 0.0) {
    s *= (std::isfinite(units) && units > 0.0 ? units : 0.0) /
         cost.reference_units;
  }
  return s;
}

double FrequencyFactor(const CallbackCost& cost, double reference_ghz,
                       double freq_ghz, double cost_scale) {
  return std::pow(reference_ghz / freq_ghz, cost.freq_exponent) * cost_scale;
}

namespace {

Status Invalid(const std::string& callback, const std::string& message) {
  return Status::InvalidArgument(
      fmt::format("cost profile: callbacks.{}: {}", callback, message));
}

Status ValidateCallbackCost(const std::string& name, const CallbackCost& c) {
  const std::vector<CostQuantile>& qs = c.quantiles;
  if (qs.size() < 2) {
    return Invalid(name, "quantiles need at least the minimum and maximum");
  }
  if (qs.front().q != 0.0 || qs.back().q != 1.0) {
    return Invalid(name, fmt::format("quantiles must run from q = 0 to q = 1, "
                                     "got {} to {}",
                                     qs.front().q, qs.back().q));
  }
  for (size_t i = 0; i < qs.size(); ++i) {
    if (!std::isfinite(qs[i].cost_s) || qs[i].cost_s < 0.0) {
      return Invalid(name, fmt::format("cost at q = {} must be finite and "
                                       ">= 0, got {}",
                                       qs[i].q, qs[i].cost_s));
    }
    if (i == 0) continue;
    if (!(qs[i].q > qs[i - 1].q)) {
      return Invalid(name, fmt::format("quantiles must increase, got {} after "
                                       "{}",
                                       qs[i].q, qs[i - 1].q));
    }
    if (qs[i].cost_s < qs[i - 1].cost_s) {
      return Invalid(
          name,
          fmt::format("cost must not fall with the quantile: {} s "
                      "at q = {} after {} s at q = {}",
                      qs[i].cost_s, qs[i].q, qs[i - 1].cost_s, qs[i - 1].q));
    }
  }
  if (!std::isfinite(c.reference_units) || c.reference_units < 0.0) {
    return Invalid(name, fmt::format("reference_units must be finite and "
                                     ">= 0, got {}",
                                     c.reference_units));
  }
  if (!std::isfinite(c.freq_exponent) || c.freq_exponent < 0.0 ||
      c.freq_exponent > 4.0) {
    return Invalid(name, fmt::format("freq_exponent must be in [0, 4], got {}",
                                     c.freq_exponent));
  }
  if (!std::isfinite(c.parallel_fraction) || c.parallel_fraction < 0.0 ||
      c.parallel_fraction > 1.0) {
    return Invalid(name,
                   fmt::format("parallel_fraction must be in [0, 1], got {}",
                               c.parallel_fraction));
  }
  if (c.max_threads < 1) {
    return Invalid(
        name, fmt::format("max_threads must be >= 1, got {}", c.max_threads));
  }
  return Status::Ok();
}

}  // namespace

Status ValidateCostProfile(const CostProfile& profile) {
  if (!std::isfinite(profile.reference_ghz) || profile.reference_ghz <= 0.0) {
    return Status::InvalidArgument(fmt::format(
        "cost profile: reference_ghz must be finite and > 0, got {}",
        profile.reference_ghz));
  }
  if (profile.callbacks.empty()) {
    return Status::InvalidArgument("cost profile: no callbacks");
  }
  for (const auto& [name, cost] : profile.callbacks) {
    ADSE_RETURN_IF_ERROR(ValidateCallbackCost(name, cost));
  }
  return Status::Ok();
}

}  // namespace adse::stack
