// The traffic lights along the route: which signal controls each link the
// road part takes through a junction, where its stop line lies on the road
// path, and what each shows now. The stack never calls this: its detector
// (traffic_signal_detector.h) does, as a camera would look.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <utility>

#include "stack/world/internal/world_impl.h"

namespace adse::world {

Status World::Impl::FindRouteSignals() {
  signals.clear();
  try {
    const std::vector<std::string> ids = libsumo::TrafficLight::getIDList();
    if (ids.empty() || crossings.empty() || road.points.size() < 2) {
      return Status::Ok();
    }
    // (lane left, first internal lane) -> (signal, link index); on nets
    // without internal lanes, (lane left, "->" lane arrived on).
    std::map<std::pair<std::string, std::string>, std::pair<std::string, int>>
        controlled;
    for (const std::string& id : ids) {
      const std::vector<std::vector<libsumo::TraCILink>> links =
          libsumo::TrafficLight::getControlledLinks(id);
      for (size_t k = 0; k < links.size(); ++k) {
        for (const libsumo::TraCILink& l : links[k]) {
          const std::pair<std::string, int> at(id, static_cast<int>(k));
          controlled.emplace(std::make_pair(l.fromLane, l.viaLane), at);
          controlled.emplace(std::make_pair(l.fromLane, "->" + l.toLane), at);
        }
      }
    }
    for (const Crossing& c : crossings) {
      const auto it = controlled.find(
          c.via_lane.empty() ? std::make_pair(c.from_lane, "->" + c.to_lane)
                             : std::make_pair(c.from_lane, c.via_lane));
      if (it == controlled.end()) continue;
      signals.push_back(
          {it->second.first, it->second.second, RoadS(c.raw_s_m)});
    }
  } catch (const std::exception& e) {
    return Status::Internal(
        fmt::format("finding the route's traffic lights: {}", e.what()));
  }
  return Status::Ok();
}

namespace {

// The link indices a program ever shows green ('G' or 'g').
std::set<size_t> GreenLinks(const libsumo::TraCILogic& logic) {
  std::set<size_t> green;
  for (const std::shared_ptr<libsumo::TraCIPhase>& phase : logic.phases) {
    for (size_t k = 0; k < phase->state.size(); ++k) {
      if (phase->state[k] == 'G' || phase->state[k] == 'g') green.insert(k);
    }
  }
  return green;
}

}  // namespace

Status World::Impl::FindSwitchedSignals() {
  switched_signals.clear();
  const double period_s = setup.world.traffic.signal_program_switch_s;
  if (period_s <= 0) return Status::Ok();
  try {
    for (const std::string& id : libsumo::TrafficLight::getIDList()) {
      const std::vector<libsumo::TraCILogic> logics =
          libsumo::TrafficLight::getAllProgramLogics(id);
      if (logics.size() < 2) continue;
      const std::string running = libsumo::TrafficLight::getProgram(id);
      SwitchedSignal s{id, {}, 0};
      std::set<size_t> running_green, other_green;
      for (const libsumo::TraCILogic& logic : logics) {
        if (logic.programID == running) {
          s.current = s.programs.size();
          running_green = GreenLinks(logic);
        } else {
          const std::set<size_t> green = GreenLinks(logic);
          other_green.insert(green.begin(), green.end());
        }
        s.programs.push_back(logic.programID);
      }
      // Only a program that starves links another one serves waits for a
      // player; a net's alternative day and night plans are left alone.
      const bool starves =
          std::any_of(other_green.begin(), other_green.end(),
                      [&](size_t k) { return running_green.count(k) == 0; });
      if (starves) switched_signals.push_back(std::move(s));
    }
  } catch (const std::exception& e) {
    return Status::Internal(
        fmt::format("reading the signals' programs: {}", e.what()));
  }
  next_program_switch_s = period_s;
  return Status::Ok();
}

void World::Impl::SwitchSignalPrograms() {
  if (switched_signals.empty() || time_s + 1e-9 < next_program_switch_s) {
    return;
  }
  next_program_switch_s += setup.world.traffic.signal_program_switch_s;
  for (SwitchedSignal& s : switched_signals) {
    s.current = (s.current + 1) % s.programs.size();
    // A program starts at its first phase: the games' yellow and all-red
    // of the links the previous program served.
    libsumo::TrafficLight::setProgram(s.id, s.programs[s.current]);
  }
}

const std::vector<RouteSignal>& World::route_signals() const {
  return impl_->signals;
}

const std::vector<algorithms::LaneChangeSection>& World::route_lane_changes()
    const {
  return impl_->lane_changes;
}

std::string World::RouteSignalStates() const {
  std::string out;
  std::map<std::string, std::string> states;  // one query per signal
  for (const RouteSignal& s : impl_->signals) {
    auto it = states.find(s.tls_id);
    if (it == states.end()) {
      std::string state;
      try {
        state = libsumo::TrafficLight::getRedYellowGreenState(s.tls_id);
      } catch (const std::exception&) {
        // Unreadable: the detector reports it as unknown.
      }
      it = states.emplace(s.tls_id, std::move(state)).first;
    }
    const std::string& state = it->second;
    out.push_back(s.link_index >= 0 &&
                          s.link_index < static_cast<int>(state.size())
                      ? state[s.link_index]
                      : 'o');
  }
  return out;
}

}  // namespace adse::world
