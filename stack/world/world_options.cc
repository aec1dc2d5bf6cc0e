#include "stack/world/world_options.h"

namespace adse::world {

// Names as written in scenario files and run records.
const char* WeatherName(Weather weather) {
  switch (weather) {
    case Weather::kClear:
      return "clear";
    case Weather::kRain:
      return "rain";
    case Weather::kFog:
      return "fog";
  }
  return "unknown";
}

const char* TaskKindName(TaskKind kind) {
  switch (kind) {
    case TaskKind::kLaneDriving:
      return "lane_driving";
    case TaskKind::kValetParking:
      return "valet_parking";
  }
  return "unknown";
}

}  // namespace adse::world
