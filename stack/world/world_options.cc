#include "stack/world/world_options.h"

#include "stack/base/vocabulary.h"
#include "stack/world/map_builder.h"

namespace adse::world {
namespace {

const std::vector<Term<Weather>>& WeatherTerms() {
  static const std::vector<Term<Weather>> kTerms = {{Weather::kClear, "clear"},
                                                    {Weather::kRain, "rain"},
                                                    {Weather::kFog, "fog"}};
  return kTerms;
}

const std::vector<Term<TaskKind>>& TaskKindTerms() {
  static const std::vector<Term<TaskKind>> kTerms = {
      {TaskKind::kLaneDriving, "lane_driving"},
      {TaskKind::kValetParking, "valet_parking"}};
  return kTerms;
}

struct Generator {
  const char* name;
  std::vector<MapGeneratorParam> params;
};

const std::vector<Generator>& Generators() {
  // The parking lot's defaults are its layout's, which the scene shares.
  static const ParkingLotLayout kLot;
  static const std::vector<Generator> kGenerators = {
      {"parking_lot",
       {{"rows", true, 1, 20, double(kLot.rows), "rows of parking slots"},
        {"slots_per_row", true, 1, 60, double(kLot.slots_per_row),
         "slots on each side of a row"},
        {"aisle_width_m", false, 5, 15, kLot.aisle_width_m,
         "width of the driving aisles, m"},
        {"slot_width_m", false, 2.0, 4.0, kLot.slot_width_m,
         "width of a slot, m"},
        {"slot_depth_m", false, 4.0, 7.0, kLot.slot_depth_m,
         "depth of a slot, m"}}},
      {"grid",
       {{"number", true, 2, 12, 3, "junctions per side"},
        {"length_m", false, 20, 500, 100, "length of a block, m"},
        {"lanes", true, 1, 4, 1, "lanes per direction"}}}};
  return kGenerators;
}

}  // namespace

const char* WeatherToString(Weather weather) {
  return NameOf(WeatherTerms(), weather);
}
bool StringToWeather(std::string_view name, Weather* weather) {
  return ValueOf(WeatherTerms(), name, weather);
}
std::vector<std::string> WeatherNames() { return NamesOf(WeatherTerms()); }

const char* TaskKindToString(TaskKind kind) {
  return NameOf(TaskKindTerms(), kind);
}
bool StringToTaskKind(std::string_view name, TaskKind* kind) {
  return ValueOf(TaskKindTerms(), name, kind);
}
std::vector<std::string> TaskKindNames() { return NamesOf(TaskKindTerms()); }

std::vector<std::string> MapGeneratorNames() {
  std::vector<std::string> names;
  for (const Generator& g : Generators()) names.push_back(g.name);
  return names;
}

const std::vector<MapGeneratorParam>* MapGeneratorParams(
    std::string_view generator) {
  for (const Generator& g : Generators()) {
    if (generator == g.name) return &g.params;
  }
  return nullptr;
}

double MapGeneratorParamValue(const MapOptions& options,
                              const std::string& name) {
  if (auto it = options.generator_params.find(name);
      it != options.generator_params.end()) {
    return it->second;
  }
  if (const auto* params = MapGeneratorParams(options.generator)) {
    for (const MapGeneratorParam& p : *params) {
      if (name == p.name) return p.default_value;
    }
  }
  return 0.0;
}

}  // namespace adse::world
