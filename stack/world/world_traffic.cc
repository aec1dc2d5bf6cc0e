// The traffic around the ego: SUMO's flows and standing cars, and what
// SUMO's drivers do about the ego. The ego is a SUMO vehicle placed by
// moveToXY each step; SUMO matches it to a lane, but neither its insertion
// nor its drivers see it everywhere: a flow's car is inserted where the ego
// stands turning onto the edge, and a car stopped short of the ego standing
// across its lane in a junction drives on once moveToXY matches the ego to
// another internal lane (its leader is then a car far ahead). Here a car
// enters only when the ego is clear of where it would, and a driver with
// the ego in the lanes ahead slows to stop short of it, as a person would.
#include <fmt/format.h>
#include <libsumo/libsumo.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "stack/world/internal/world_impl.h"
#include "stack/world/roadside_poles.h"
#include "stack/world/traffic_yield.h"

namespace adse::world {
namespace {

using internal::InternalChain;
using internal::kEgoId;
using internal::kOffRoadSlackM;
using internal::ShapeS;
using internal::Slice;
using internal::SumoAngleToYaw;
using internal::ToPoints;
using internal::Vec2;

// A car entering with a flow is this long (SUMO's default type); it enters
// with its rear at the lane's start ("base").
constexpr double kEnteringLengthM = 5.0;
// SUMO's default deceleration, m/s^2.
constexpr double kDefaultDecelMps2 = 4.5;

// The ego's body this close to a flow's first lane's start counts as
// about to drive onto it.
constexpr double kAboutToEnterM = 1.5;
// A turn's manoeuvre as the ego's body this often along it, m, grown by
// this on every side.
constexpr double kTurnSweepStepM = 1.0;
constexpr double kTurnSweepMarginM = 1.5;
// Drivers on the ego's own road (queued behind it, or coming on along the
// lane it turns onto) wait this much farther back still: along the road
// the stack's moves stray farther from the world's plan (on square's
// dead end 1.6 m past its longest reverse; a driver queued there then
// boxed the car in until the stall timeout). Across a junction the margin
// stays as it is, so that a driver coming out of a side road does not
// stop in the car's way on.
constexpr double kTurnQueueExtraM = 1.5;
// Drivers wait for a turn from when the ego is this far from its start
// (it brakes there to stand), m.
constexpr double kTurnApproachM = 15.0;
// The ego's way through a junction as its body this often, m, grown by
// this on every side.
constexpr double kClaimStepM = 1.0;
constexpr double kClaimMarginM = 0.5;
// Drivers whose link yields see the ego coming when its front is within
// this of the junction, m, or this long at its speed, s (SUMO's minor
// links wait for a foe arriving within a few seconds).
constexpr double kClaimMinM = 5.0;
constexpr double kClaimHorizonS = 4.0;
// The ego's claim lapses while it has stood this long, s: a driver it
// stopped for is not held for it in turn.
constexpr double kClaimLapseS = 2.0;
// The ego counts as standing below this speed, m/s.
constexpr double kStandingMps = 0.05;
// A driver SUMO holds for the ego, though the ego is clear of its way, is
// let go once both have stood this long, s.
constexpr double kMutualWaitS = 3.0;

// Appends `piece` to `path`, skipping a repeat of its last point; returns
// the length added.
double Append(const std::vector<Vec2>& piece, std::vector<Vec2>* path) {
  double added = 0.0;
  for (const Vec2& p : piece) {
    if (!path->empty()) {
      const double step = (p - path->back()).norm();
      if (step <= 1e-6) continue;
      added += step;
    }
    path->push_back(p);
  }
  return added;
}

}  // namespace

Status World::Impl::SetUpTraffic() {
  traffic_random = std::make_unique<Random>(
      Random::DeriveSeed(setup.world.traffic.seed, "traffic.flows"));
  const auto& flows_in = setup.world.traffic.flows;
  for (size_t i = 0; i < flows_in.size(); ++i) {
    const Flow& flow = flows_in[i];
    const std::string field = fmt::format("world.traffic.flows[{}]", i);
    try {
      const std::vector<std::string> edges = libsumo::Edge::getIDList();
      for (const std::string* e : {&flow.from_edge, &flow.to_edge}) {
        if (std::find(edges.begin(), edges.end(), *e) == edges.end()) {
          return Status::InvalidArgument(
              fmt::format("{}.{}: no edge '{}' in the network", field,
                          e == &flow.from_edge ? "from" : "to", *e));
        }
      }
      const libsumo::TraCIStage stage =
          libsumo::Simulation::findRoute(flow.from_edge, flow.to_edge);
      if (stage.edges.empty()) {
        return Status::InvalidArgument(
            fmt::format("{}: no route from '{}' to '{}'", field, flow.from_edge,
                        flow.to_edge));
      }
      FlowState state;
      state.route_id = fmt::format("adse_flow_{}", i);
      for (int k = 0; k < libsumo::Edge::getLaneNumber(flow.from_edge); ++k) {
        state.depart_lanes.push_back(fmt::format("{}_{}", flow.from_edge, k));
      }
      libsumo::Route::add(state.route_id, stage.edges);
      state.probability_per_step =
          std::min(1.0, flow.vehicles_per_hour / 3600.0 * setup.world.step_s);
      flows.push_back(state);
    } catch (const std::exception& e) {
      return Status::InvalidArgument(field + ": " + e.what());
    }
  }
  const auto& stopped = setup.world.traffic.stopped_vehicles;
  for (size_t i = 0; i < stopped.size(); ++i) {
    const std::string field =
        fmt::format("world.traffic.stopped_vehicles[{}]", i);
    Result<RoadLocation> at = Resolve(stopped[i], field, kOffRoadSlackM);
    if (!at.ok()) return at.status();
    try {
      // A one-edge route, inserted where it stands and held there.
      const std::string id = fmt::format("stopped{}", i);
      libsumo::Route::add("adse_" + id, {at->edge});
      libsumo::Vehicle::add(id, "adse_" + id, "DEFAULT_VEHTYPE", "now",
                            std::to_string(at->lane),
                            fmt::format("{}", at->pos_m), "0");
      libsumo::Vehicle::setSpeed(id, 0.0);
      held_still.insert(id);
    } catch (const std::exception& e) {
      return Status::InvalidArgument(field + ": " + e.what());
    }
  }
  return Status::Ok();
}

const std::vector<Vec2>& World::Impl::LaneShape(const std::string& lane_id) {
  auto it = lane_shapes.find(lane_id);
  if (it == lane_shapes.end()) {
    it =
        lane_shapes.emplace(lane_id, ToPoints(libsumo::Lane::getShape(lane_id)))
            .first;
  }
  return it->second;
}

void World::Impl::InsertFlows() {
  const geometry::OrientedBox body = ego->Body();
  for (size_t i = 0; i < flows.size(); ++i) {
    FlowState& flow = flows[i];
    // One draw per flow and step, whether or not the car can enter now, so
    // the traffic's random stream does not depend on the ego.
    if (traffic_random->Bernoulli(flow.probability_per_step)) ++flow.pending;
    if (flow.pending == 0) continue;
    bool clear = true;
    for (const std::string& lane : flow.depart_lanes) {
      const std::vector<Vec2>& shape = LaneShape(lane);
      const double reach =
          kEnteringLengthM +
          YieldLookaheadM(libsumo::Lane::getMaxSpeed(lane), kDefaultDecelMps2);
      // The ego about to drive onto the edge counts as on it.
      if (YieldSpeedMps(Slice(shape, 0, reach), libsumo::Lane::getWidth(lane),
                        kDefaultDecelMps2, body, Vec2::Zero()) >= 0 ||
          (!shape.empty() && (body.center - shape.front()).norm() <
                                 body.length_m + kAboutToEnterM)) {
        clear = false;
        break;
      }
    }
    if (!clear) continue;
    libsumo::Vehicle::add(fmt::format("flow{}.{}", i, flow.spawned++),
                          flow.route_id, "DEFAULT_VEHTYPE", "now", "best",
                          "base", "max");
    --flow.pending;
  }
}

const World::Impl::JunctionClaim* World::Impl::ActiveJunctionClaim() {
  const double front_m = (setup.ego.wheelbase_m + setup.ego.length_m) / 2;
  const double rear_m = (setup.ego.length_m - setup.ego.wheelbase_m) / 2;
  if (junction_claims.size() != crossings.size()) {
    junction_claims.clear();
    for (const Crossing& c : crossings) {
      JunctionClaim claim;
      if (!c.tight_uturn) {
        double through_m = 0.0;
        if (!c.via_lane.empty()) {
          for (const std::string& l : InternalChain(c.via_lane, nullptr)) {
            through_m += libsumo::Lane::getLength(l);
          }
        }
        claim.from_edge = libsumo::Lane::getEdgeID(c.from_lane);
        claim.entry_s_m = RoadS(c.raw_s_m);
        const double exit_s = RoadS(c.raw_s_m + through_m);
        claim.last_s_m = exit_s + rear_m;
        for (double s = claim.entry_s_m - front_m; s <= claim.last_s_m;
             s += kClaimStepM) {
          const Vec2 p = road.PointAt(s);
          geometry::OrientedBox b =
              BodyAt({p.x(), p.y(), road.HeadingAt(s)}, setup.ego);
          b.length_m += 2 * kClaimMarginM;
          b.width_m += 2 * kClaimMarginM;
          claim.bodies.push_back({s, b});
        }
      }
      junction_claims.push_back(std::move(claim));
    }
  }
  const double front_s = road_progress_m + front_m;
  for (size_t k = 0; k < crossings.size(); ++k) {
    const JunctionClaim& claim = junction_claims[k];
    if (claim.bodies.empty() || road_progress_m > claim.last_s_m) continue;
    const double gap_m = claim.entry_s_m - front_s;
    if (gap_m <= 0) return &claim;  // in it: committed
    if (gap_m > kClaimMinM + std::abs(ego->state().v_mps) * kClaimHorizonS) {
      return nullptr;
    }
    const Crossing& c = crossings[k];
    for (const libsumo::TraCIConnection& link :
         libsumo::Lane::getLinks(c.from_lane)) {
      const bool ours = c.via_lane.empty()
                            ? link.approachedLane == c.to_lane
                            : link.approachedInternal == c.via_lane;
      if (ours) return link.hasPrio ? &claim : nullptr;
    }
    return nullptr;
  }
  return nullptr;
}

bool World::Impl::CameInYielding(const std::string& lane) {
  if (!internal_ways_built) {
    for (const std::string& from : libsumo::Lane::getIDList()) {
      if (from.empty() || from[0] == ':') continue;
      for (const libsumo::TraCIConnection& link :
           libsumo::Lane::getLinks(from)) {
        if (link.approachedInternal.empty()) continue;
        const std::vector<std::string> chain =
            InternalChain(link.approachedInternal, nullptr);
        for (size_t i = 0; i < chain.size(); ++i) {
          internal_ways.emplace(
              chain[i], InternalWay{from, {chain.begin(), chain.begin() + i}});
        }
      }
    }
    internal_ways_built = true;
  }
  const auto way = internal_ways.find(lane);
  if (way == internal_ways.end()) return false;
  const std::string& first =
      way->second.before.empty() ? lane : way->second.before.front();
  // The link from its lane into the junction (a signal's state changes
  // it), then the internal junctions it has passed.
  for (const libsumo::TraCIConnection& link :
       libsumo::Lane::getLinks(way->second.approach_lane)) {
    if (link.approachedInternal != first) continue;
    if (!link.hasPrio) return true;
    break;
  }
  for (const std::string& passed : way->second.before) {
    const auto links = libsumo::Lane::getLinks(passed);
    if (!links.empty() && !links.front().hasPrio) return true;
  }
  return false;
}

void World::Impl::YieldToEgo() {
  const geometry::OrientedBox body = ego->Body();
  const VehicleState& state = ego->state();
  const Vec2 ego_velocity =
      state.v_mps * Vec2(std::cos(state.yaw_rad), std::sin(state.yaw_rad));
  if (turn_sweeps.size() != turnarounds.size()) {
    for (const RouteTurnaround& turn : turnarounds) {
      std::vector<geometry::OrientedBox> sweep;
      double since_m = INFINITY;
      for (size_t i = 0; i < turn.reference.size(); ++i) {
        const geometry::Pose2& p = turn.reference[i].pose;
        if (i > 0) {
          const geometry::Pose2& q = turn.reference[i - 1].pose;
          since_m += std::hypot(p.x_m - q.x_m, p.y_m - q.y_m);
        }
        if (since_m < kTurnSweepStepM && i + 1 < turn.reference.size()) {
          continue;
        }
        geometry::OrientedBox b = BodyAt(p, setup.ego);
        // The stack plans its own manoeuvre, which strays from this one.
        b.length_m += 2 * kTurnSweepMarginM;
        b.width_m += 2 * kTurnSweepMarginM;
        sweep.push_back(b);
        since_m = 0.0;
      }
      turn_sweeps.push_back(std::move(sweep));
    }
  }
  // Turning round in several moves (from its approach to the turn's end),
  // the ego needs the space of its manoeuvre: drivers wait short of it, as
  // they would for a car they see turning, unless already in it.
  std::vector<const geometry::OrientedBox*> turn;
  for (size_t k = 0; k < turnarounds.size(); ++k) {
    if (road_progress_m >= turnarounds[k].start_s_m - kTurnApproachM &&
        road_progress_m < turnarounds[k].end_s_m) {
      for (const geometry::OrientedBox& b : turn_sweeps[k]) turn.push_back(&b);
      break;
    }
  }
  // Crossing a junction with the right of way, the ego's way through it
  // is kept free by drivers whose link yields, as SUMO's junction model
  // would if it saw the ego (a car standing in the junction turned across
  // the ego's way out of a turn).
  std::vector<const geometry::OrientedBox*> claim;
  ego_standing_s = std::abs(state.v_mps) < kStandingMps
                       ? ego_standing_s + setup.world.step_s
                       : 0.0;
  const JunctionClaim* junction =
      ego_standing_s < kClaimLapseS ? ActiveJunctionClaim() : nullptr;
  if (junction != nullptr) {
    for (const auto& [s, b] : junction->bodies) {
      if (s >= road_progress_m - kClaimStepM) claim.push_back(&b);
    }
  }
  double reach_m = body.length_m;
  for (const auto* way : {&turn, &claim}) {
    for (const geometry::OrientedBox* b : *way) {
      reach_m =
          std::max(reach_m, (b->center - body.center).norm() + b->length_m);
    }
  }
  std::set<std::string> still_yielding;
  for (const OtherVehicle& v : others) {
    // A driver touching the ego is left to SUMO: held for the ego, a car
    // that had run into the ego in its turn waited for it for ever while
    // the ego waited for it.
    if (held_still.count(v.id) || in_contact.count(v.id)) continue;
    const double decel = types.at(v.id).decel_mps2;
    const double lookahead = YieldLookaheadM(v.speed_mps, decel);
    // Too far for any part of the ego (or the way it needs) to lie within
    // its lookahead.
    if ((v.box.center - body.center).norm() >
        lookahead + v.box.length_m + reach_m) {
      continue;
    }
    const std::string lane = libsumo::Vehicle::getLaneID(v.id);
    if (lane.empty()) continue;
    // Whether the link it drives next must yield (lower-case state).
    bool minor_link = false;
    // The lanes it drives next, from its front bumper: the rest of its
    // lane, then through the next junction onto the next lane of its best
    // continuation.
    std::vector<Vec2> path;
    const double pos = ShapeS(LaneShape(lane), libsumo::Lane::getLength(lane),
                              libsumo::Vehicle::getLanePosition(v.id));
    double length_m =
        Append(Slice(LaneShape(lane), pos, pos + lookahead), &path);
    std::vector<std::string> next;
    if (lane[0] == ':') {
      std::string arrives_on;
      next = InternalChain(lane, &arrives_on);
      next.erase(next.begin());
      if (!arrives_on.empty()) next.push_back(arrives_on);
      // Its turn yields: at its waiting point in the junction or past it
      // (on square's B1 a driver crept past it and, its next link having
      // the right of way, turned into the car turning into the same lane).
      const auto links = libsumo::Lane::getLinks(lane);
      minor_link =
          (!links.empty() && !links.front().hasPrio) || CameInYielding(lane);
    } else {
      for (const libsumo::TraCIBestLanesData& best :
           libsumo::Vehicle::getBestLanes(v.id)) {
        if (best.laneID != lane) continue;
        const auto& c = best.continuationLanes;
        const auto at = std::find(c.begin(), c.end(), lane);
        if (at == c.end() || at + 1 == c.end()) break;
        for (const libsumo::TraCIConnection& link :
             libsumo::Lane::getLinks(lane)) {
          if (link.approachedLane != *(at + 1)) continue;
          minor_link = !link.hasPrio;
          if (!link.approachedInternal.empty()) {
            next = InternalChain(link.approachedInternal, nullptr);
          }
          next.push_back(link.approachedLane);
          break;
        }
        break;
      }
    }
    for (const std::string& l : next) {
      if (length_m >= lookahead) break;
      length_m += Append(Slice(LaneShape(l), 0, lookahead - length_m), &path);
    }
    double safe = YieldSpeedMps(path, v.box.width_m, decel, body, ego_velocity);
    const auto in_way =
        [&](const std::vector<const geometry::OrientedBox*>& way) {
          return std::any_of(way.begin(), way.end(),
                             [&](const geometry::OrientedBox* b) {
                               return geometry::BoxesOverlap(v.box, *b);
                             });
        };
    // Waits short of `way` (it is not in it), grown by `extra_m`.
    const auto wait_short_of =
        [&](const std::vector<const geometry::OrientedBox*>& way,
            double extra_m) {
          for (const geometry::OrientedBox* b : way) {
            geometry::OrientedBox grown = *b;
            grown.length_m += 2 * extra_m;
            grown.width_m += 2 * extra_m;
            const double wait =
                YieldSpeedMps(path, v.box.width_m, decel, grown, Vec2::Zero());
            if (wait >= 0) safe = safe < 0 ? wait : std::min(safe, wait);
          }
        };
    if (!in_way(turn)) {
      const bool on_ego_road =
          lane[0] != ':' && std::find(route.begin(), route.end(),
                                      EdgeOfLane(lane)) != route.end();
      wait_short_of(turn, on_ego_road ? kTurnQueueExtraM : 0.0);
    } else if (safe >= 0) {
      // In the turn's way it drives on to clear it, but with the car in
      // its own it keeps its place rather than creep after the car: the
      // car's next move may back into the space the car has just left
      // (at A10KW's sharpest corner a driver crept 0.8 m in 10 s, and the
      // car, boxed in, stood until the stall timeout).
      safe = 0.0;
    }
    // On the ego's own road it leads or follows the ego, unless already
    // in the way it claims (it drives on to clear it).
    if (junction != nullptr && minor_link &&
        libsumo::Lane::getEdgeID(lane) != junction->from_edge &&
        !in_way(claim)) {
      wait_short_of(claim, 0.0);
    }
    if (safe < 0) {
      // Not while the ego turns in several moves: its next move is the
      // freespace planner's, which the driver's corridor does not
      // foresee, and it may back into a driver let go beside it.
      if (turn.empty()) ReleaseFromEgo(v, lane, lookahead);
      continue;
    }
    // Slower than it would drive anyway: a cap, never a push.
    if (safe >= libsumo::Vehicle::getAllowedSpeed(v.id) *
                    libsumo::Vehicle::getSpeedFactor(v.id)) {
      continue;
    }
    libsumo::Vehicle::setSpeed(v.id, safe);
    still_yielding.insert(v.id);
  }
  // Back to SUMO's own driving for those the ego no longer holds up.
  for (const std::string& id : yielding) {
    if (!still_yielding.count(id) &&
        std::find_if(others.begin(), others.end(), [&](const OtherVehicle& v) {
          return v.id == id;
        }) != others.end()) {
      libsumo::Vehicle::setSpeed(id, -1);
    }
  }
  yielding = std::move(still_yielding);
  // Those let past the ego see it again once off the lane they were held
  // on.
  for (auto it = ignoring_ego.begin(); it != ignoring_ego.end();) {
    const bool present =
        std::any_of(others.begin(), others.end(),
                    [&](const OtherVehicle& v) { return v.id == it->first; });
    if (present && libsumo::Vehicle::getLaneID(it->first) == it->second) {
      ++it;
      continue;
    }
    if (present) {
      libsumo::Vehicle::setParameter(it->first, "junctionModel.ignoreIDs", "");
    }
    it = ignoring_ego.erase(it);
  }
}

void World::Impl::ReleaseFromEgo(const OtherVehicle& v, const std::string& lane,
                                 double lookahead_m) {
  if (ignoring_ego.count(v.id)) return;
  // moveToXY matches the ego to one of the junction's internal lanes, and
  // SUMO's junction model then holds a driver whose lane crosses that one
  // for the ego as its leader, though the ego's body is clear of the
  // driver's way (safe < 0 above). On the reference study's lot such a
  // driver stood with its front 0.4 m into the ego's left turn, and the
  // two waited for each other until the stall timeout. Both standing, the
  // driver drives on; this function's caller still caps its speed should
  // the ego come into its way.
  if (ego_standing_s < kMutualWaitS ||
      libsumo::Vehicle::getWaitingTime(v.id) < kMutualWaitS) {
    return;
  }
  if (libsumo::Vehicle::getLeader(v.id, lookahead_m).first != kEgoId) return;
  libsumo::Vehicle::setParameter(v.id, "junctionModel.ignoreIDs", kEgoId);
  ignoring_ego.emplace(v.id, lane);
}

void World::Impl::ReadOthers() {
  others.clear();
  std::map<std::string, double> yaw_now;
  for (const std::string& id : libsumo::Vehicle::getIDList()) {
    if (id == kEgoId) continue;
    auto it = types.find(id);
    if (it == types.end()) {
      it = types
               .emplace(id, VehicleType{libsumo::Vehicle::getLength(id),
                                        libsumo::Vehicle::getWidth(id),
                                        libsumo::Vehicle::getDecel(id)})
               .first;
    }
    const auto p = libsumo::Vehicle::getPosition(id);
    const double yaw = SumoAngleToYaw(libsumo::Vehicle::getAngle(id));
    OtherVehicle v;
    v.id = id;
    v.box.yaw_rad = yaw;
    v.box.length_m = it->second.length_m;
    v.box.width_m = it->second.width_m;
    v.box.height_m = 1.5;
    v.box.center = Vec2(p.x, p.y) -
                   v.box.length_m / 2 * Vec2(std::cos(yaw), std::sin(yaw));
    v.speed_mps = libsumo::Vehicle::getSpeed(id);
    if (auto last = last_yaw_rad.find(id); last != last_yaw_rad.end()) {
      v.yaw_rate_rps =
          std::remainder(yaw - last->second, 2.0 * M_PI) / setup.world.step_s;
    }
    yaw_now.emplace(id, yaw);
    others.push_back(v);
  }
  last_yaw_rad = std::move(yaw_now);
}

}  // namespace adse::world
