#include "analysis/metrics/standing.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace adse::analysis {
namespace {

// Calls visit(i, dt, newest) for every ego sample i below the standing
// speed but the last, with the time it covers and the planner's newest
// stop sample at it (nullptr: none yet).
template <typename Visit>
void ForEachStandingSample(const runfile::RunData& run,
                           const StandingOptions& options, Visit visit) {
  const std::vector<runfile::StopSample>& stops = run.stop_reasons;
  size_t next = 0;  // first stop sample published after the current time
  for (size_t i = 0; i + 1 < run.ego.size(); ++i) {
    const runfile::EgoSample& e = run.ego[i];
    while (next < stops.size() && stops[next].t_s <= e.t_s + 1e-9) ++next;
    if (std::abs(e.v_mps) >= options.standing_speed_mps) continue;
    const double dt = std::max(0.0, run.ego[i + 1].t_s - e.t_s);
    visit(i, dt, next > 0 ? &stops[next - 1] : nullptr);
  }
}

}  // namespace

void ReasonTally::Add(StopReason reason, const runfile::StopSample* newest,
                      double dt) {
  per_reason_[reason] += dt;
  if (StopReasonNamesTrack(reason)) {
    TrackTime& t = per_track_[{reason, newest->track_id}];
    t.standing_s += dt;
    t.min_gap_m = std::min(t.min_gap_m, newest->obstacle_gap_m);
    t.static_structure = t.static_structure || newest->static_structure != 0;
  }
}

std::vector<StandingTime> ReasonTally::ByReason() const {
  std::vector<StandingTime> out;
  for (const auto& [reason, seconds] : per_reason_) {
    StandingTime t;
    t.reason = reason;
    t.standing_s = seconds;
    if (StopReasonNamesTrack(reason)) {
      const TrackTime* longest = nullptr;
      for (const auto& [key, track] : per_track_) {
        if (key.first != reason) continue;
        if (longest == nullptr || track.standing_s > longest->standing_s) {
          longest = &track;
          t.track_id = key.second;
        }
      }
      t.obstacle_gap_m = longest->min_gap_m;
      t.static_structure = longest->static_structure;
    }
    out.push_back(t);
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const StandingTime& a, const StandingTime& b) {
                     return a.standing_s > b.standing_s;
                   });
  return out;
}

StandingSummary SummarizeStanding(const runfile::RunData& run,
                                  const StandingOptions& options) {
  StandingSummary out;
  out.has_reasons = !run.stop_reasons.empty();
  ReasonTally tally;
  ForEachStandingSample(
      run, options,
      [&](size_t i, double dt, const runfile::StopSample* newest) {
        out.standing_s += dt;
        if (out.has_reasons) {
          tally.Add(HoldingReason(newest, run.ego[i].t_s, options), newest, dt);
        }
      });
  out.by_reason = tally.ByReason();
  return out;
}

std::vector<Stand> ListStands(const runfile::RunData& run,
                              double min_standing_s,
                              const StandingOptions& options) {
  std::vector<Stand> out;
  const bool has_reasons = !run.stop_reasons.empty();
  Stand current;
  ReasonTally tally;
  size_t last = 0;  // the previous standing sample
  bool open = false;
  auto close = [&] {
    if (!open) return;
    open = false;
    if (current.standing_s + 1e-9 < min_standing_s) return;
    if (has_reasons) current.cause = tally.ByReason().front();
    out.push_back(current);
  };
  ForEachStandingSample(
      run, options,
      [&](size_t i, double dt, const runfile::StopSample* newest) {
        if (open && i != last + 1) close();
        if (!open) {
          open = true;
          current = Stand();
          current.start_s = run.ego[i].t_s;
          current.x_m = run.ego[i].x_m;
          current.y_m = run.ego[i].y_m;
          current.known = has_reasons;
          tally = ReasonTally();
        }
        last = i;
        current.standing_s += dt;
        if (has_reasons) {
          tally.Add(HoldingReason(newest, run.ego[i].t_s, options), newest, dt);
        }
      });
  close();
  return out;
}

StopReason HoldingReason(const runfile::StopSample* newest, double t_s,
                         const StandingOptions& options) {
  if (newest == nullptr || t_s - newest->t_s > options.stale_after_s) {
    return StopReason::kNoTrajectory;
  }
  if (newest->reason != StopReason::kNone &&
      newest->stop_distance_m > options.hold_distance_m) {
    return StopReason::kNone;
  }
  return newest->reason;
}

bool TrafficWillRelease(StopReason reason, const runfile::StopSample* newest) {
  if (reason == StopReason::kRedLight) return true;
  if (reason == StopReason::kLaneChange) return true;
  return reason == StopReason::kObstacle && newest != nullptr &&
         newest->static_structure == 0;
}

StallWatch::StallWatch(double stall_timeout_s, double traffic_stall_timeout_s,
                       StandingOptions options)
    : stall_timeout_s_(stall_timeout_s),
      traffic_stall_timeout_s_(traffic_stall_timeout_s),
      options_(options) {}

bool StallWatch::Observe(double t_s, double v_mps,
                         const std::vector<runfile::StopSample>& stops) {
  const double dt = last_t_s_ < 0 ? 0.0 : std::max(0.0, t_s - last_t_s_);
  last_t_s_ = t_s;
  while (next_ < stops.size() && stops[next_].t_s <= t_s + 1e-9) ++next_;
  if (stall_timeout_s_ <= 0 && traffic_stall_timeout_s_ <= 0) return false;
  if (std::abs(v_mps) >= options_.standing_speed_mps) {
    if (in_stand_) crept_m_ += std::abs(v_mps) * dt;
    if (!in_stand_ || crept_m_ >= options_.stand_break_m) {
      in_stand_ = false;
      crept_m_ = stood_s_ = traffic_s_ = 0.0;
      stand_ = traffic_ = ReasonTally();
      return false;
    }
    // Creeping within the stand: counted as standing for its cause.
  }
  in_stand_ = true;
  const runfile::StopSample* newest = next_ > 0 ? &stops[next_ - 1] : nullptr;
  const StopReason reason = HoldingReason(newest, t_s, options_);
  if (TrafficWillRelease(reason, newest)) {
    // A red light's wait the planner bounds itself.
    if (!StopReasonNamesTrack(reason) || traffic_stall_timeout_s_ <= 0)
      return false;
    traffic_s_ += dt;
    traffic_.Add(reason, newest, dt);
    if (traffic_s_ + 1e-9 < traffic_stall_timeout_s_) return false;
    cause_ = traffic_.ByReason().front();
    stood_s_ = traffic_s_;
    held_by_traffic_ = true;
    return true;
  }
  if (stall_timeout_s_ <= 0) return false;
  stood_s_ += dt;
  stand_.Add(reason, newest, dt);
  if (stood_s_ + 1e-9 < stall_timeout_s_) return false;
  cause_ = stand_.ByReason().front();
  return true;
}

}  // namespace adse::analysis
