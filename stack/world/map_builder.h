// Map files for a scenario: a SUMO network given by path, or one generated
// from the spec with SUMO's netconvert/netgenerate. Generated maps are
// cached by content hash so a campaign builds each map once.
#ifndef ADSE_STACK_WORLD_MAP_BUILDER_H_
#define ADSE_STACK_WORLD_MAP_BUILDER_H_

#include <string>

#include "stack/base/env.h"
#include "stack/base/status.h"
#include "stack/world/world_options.h"

namespace adse::world {

struct MapArtifacts {
  std::string net_path;       // SUMO .net.xml
  std::string polygons_path;  // SUMO polygon file; may be empty
  // Content hash of the map (inputs of a generated map, or the bytes of a
  // given one); keys every artefact derived from the map.
  std::string key;
  // Folder for artefacts derived from this map (map cloud, ...).
  std::string cache_folder;
  bool generated = false;
};

// Geometry constants of the generated parking lot, shared with the world
// (scene building) and the docs.
struct ParkingLotLayout {
  int rows = 4;
  int slots_per_row = 12;
  double aisle_width_m = 7.0;
  double slot_width_m = 2.5;
  double slot_depth_m = 5.0;
  double ring_lane_width_m = 3.5;
  double speed_mps = 30.0 / 3.6;
};

// Generates (or finds in `cache_dir`) the map. Never starts SUMO; a net that
// does not load is reported when the world opens it. The cache's folders,
// marker and rename go through `env`.
Result<MapArtifacts> PrepareMap(const MapOptions& options,
                                const std::string& cache_dir,
                                Env* env = Env::Default());

}  // namespace adse::world

#endif  // ADSE_STACK_WORLD_MAP_BUILDER_H_
