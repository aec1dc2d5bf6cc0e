#include "stack/world/map_builder.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <sstream>

#include "stack/base/files.h"
#include "stack/base/hash.h"
#include "stack/base/subprocess.h"

namespace adse::world {
namespace {

namespace fs = std::filesystem;

// Bump when generated maps change, so old cache entries are not reused.
constexpr char kGeneratorVersion[] = "adse-map-v1";

std::string Poly(const std::string& id, const std::string& type,
                 const std::vector<std::pair<double, double>>& shape,
                 double height_m) {
  std::string points;
  for (const auto& [x, y] : shape) {
    if (!points.empty()) points += ' ';
    points += fmt::format("{:.3f},{:.3f}", x, y);
  }
  return fmt::format(
      "  <poly id=\"{}\" type=\"{}\" color=\"128,128,128\" fill=\"1\" "
      "layer=\"1\" shape=\"{}\">\n    <param key=\"height_m\" "
      "value=\"{:.2f}\"/>\n  </poly>\n",
      id, type, points, height_m);
}

std::vector<std::pair<double, double>> Rect(double x0, double y0, double x1,
                                            double y1) {
  return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}, {x0, y0}};
}

// A parking lot: a two-way ring road around the lot, two-way aisles across
// it, parking slots perpendicular to the aisles on both sides, lamp poles on
// the islands and along the ring, and a perimeter wall.
struct ParkingLotFiles {
  std::string nodes, edges, polygons;
};

ParkingLotFiles MakeParkingLot(const ParkingLotLayout& p) {
  const int aisles = (p.rows + 1) / 2;
  const double ring_half = p.ring_lane_width_m;  // two lanes: one each way
  const double a = p.aisle_width_m;
  const double d = p.slot_depth_m;
  const double margin_x = ring_half + 6.0;  // keeps slots clear of junctions
  const double lot_length = p.slots_per_row * p.slot_width_m;
  const double x_max = 2 * margin_x + lot_length;
  // Aisle k's centreline; rows 2k (below) and 2k+1 (above) face it.
  auto aisle_y = [&](int k) {
    return ring_half + 2.0 + d + a / 2 + k * (a + 2 * d);
  };
  const bool last_single = p.rows % 2 == 1;
  const double top_rows_edge =
      aisle_y(aisles - 1) + a / 2 + (last_single ? 0.0 : d);
  const double y_max = top_rows_edge + 2.0 + ring_half;

  std::ostringstream nodes, edges, polys;
  nodes << "<nodes>\n";
  edges << "<edges>\n";
  polys << "<additional>\n";
  std::vector<double> ys = {0.0};
  for (int k = 0; k < aisles; ++k) ys.push_back(aisle_y(k));
  ys.push_back(y_max);
  for (size_t i = 0; i < ys.size(); ++i) {
    nodes << fmt::format(
        "  <node id=\"W{0}\" x=\"0\" y=\"{1:.3f}\"/>\n"
        "  <node id=\"E{0}\" x=\"{2:.3f}\" y=\"{1:.3f}\"/>\n",
        i, ys[i], x_max);
  }
  auto two_way = [&](const std::string& from, const std::string& to,
                     double width) {
    const double speed = p.speed_mps;
    edges << fmt::format(
        "  <edge id=\"{0}_{1}\" from=\"{0}\" to=\"{1}\" numLanes=\"1\" "
        "speed=\"{2:.3f}\" width=\"{3:.2f}\"/>\n"
        "  <edge id=\"{1}_{0}\" from=\"{1}\" to=\"{0}\" numLanes=\"1\" "
        "speed=\"{2:.3f}\" width=\"{3:.2f}\"/>\n",
        from, to, speed, width);
  };
  for (size_t i = 0; i + 1 < ys.size(); ++i) {
    two_way("W" + std::to_string(i), "W" + std::to_string(i + 1),
            p.ring_lane_width_m);
    two_way("E" + std::to_string(i), "E" + std::to_string(i + 1),
            p.ring_lane_width_m);
  }
  const size_t top = ys.size() - 1;
  two_way("W0", "E0", p.ring_lane_width_m);
  two_way("W" + std::to_string(top), "E" + std::to_string(top),
          p.ring_lane_width_m);
  for (int k = 0; k < aisles; ++k) {
    two_way("W" + std::to_string(k + 1), "E" + std::to_string(k + 1), a / 2);
  }

  // Slots, numbered by row then position along the row.
  for (int row = 0; row < p.rows; ++row) {
    const int k = row / 2;
    const bool below = row % 2 == 0;
    const double y0 = below ? aisle_y(k) - a / 2 - d : aisle_y(k) + a / 2;
    for (int s = 0; s < p.slots_per_row; ++s) {
      const double x0 = margin_x + s * p.slot_width_m;
      polys << Poly(fmt::format("slot_r{}_s{}", row, s), "adse.parking_slot",
                    Rect(x0, y0, x0 + p.slot_width_m, y0 + d), 0.0);
    }
  }
  // Lamp poles: at both ends of every row, and every 20 m along the ring's
  // outer side; they give the localization map longitudinal structure.
  int pole = 0;
  auto add_pole = [&](double x, double y) {
    const double r = 0.15;
    polys << Poly(fmt::format("pole_{}", pole++), "adse.pole",
                  Rect(x - r, y - r, x + r, y + r), 5.0);
  };
  for (int row = 0; row < p.rows; ++row) {
    const int k = row / 2;
    const bool below = row % 2 == 0;
    const double y =
        below ? aisle_y(k) - a / 2 - d / 2 : aisle_y(k) + a / 2 + d / 2;
    add_pole(margin_x - 1.0, y);
    add_pole(margin_x + lot_length + 1.0, y);
  }
  const double out = ring_half + 1.5;  // beyond the ring's outer lane edge
  for (double x = 10.0; x < x_max - 5.0; x += 20.0) {
    add_pole(x, -out);
    add_pole(x, y_max + out);
  }
  for (double y = 10.0; y < y_max - 5.0; y += 20.0) {
    add_pole(-out, y);
    add_pole(x_max + out, y);
  }
  // Perimeter wall, and a small building (kiosk) by the south-west corner
  // that breaks the symmetry of the lot for the scan matcher.
  const double w = ring_half + 4.0;
  const std::vector<std::pair<double, double>> wall = {{-w, -w},
                                                       {x_max + w, -w},
                                                       {x_max + w, y_max + w},
                                                       {-w, y_max + w},
                                                       {-w, -w}};
  for (size_t i = 0; i + 1 < wall.size(); ++i) {
    polys << Poly(fmt::format("wall_{}", i), "adse.wall",
                  {wall[i], wall[i + 1]}, 2.5);
  }
  polys << Poly(
      "kiosk", "building",
      Rect(margin_x + 2.0, ring_half + 1.0, margin_x + 6.0, ring_half + 1.8),
      3.0);
  nodes << "</nodes>\n";
  edges << "</edges>\n";
  polys << "</additional>\n";
  return {nodes.str(), edges.str(), polys.str()};
}

// City blocks of a netgenerate grid as building footprints.
std::string GridBuildings(int number, double length_m, int lanes) {
  std::ostringstream polys;
  polys << "<additional>\n";
  const double inset = 3.2 * lanes + 4.0;  // road half width plus sidewalk
  int id = 0;
  for (int i = 0; i + 1 < number; ++i) {
    for (int j = 0; j + 1 < number; ++j) {
      polys << Poly(
          fmt::format("building_{}", id++), "building",
          Rect(i * length_m + inset, j * length_m + inset,
               (i + 1) * length_m - inset, (j + 1) * length_m - inset),
          10.0);
    }
  }
  polys << "</additional>\n";
  return polys.str();
}

Status Generate(const MapOptions& options, const std::string& folder) {
  const std::string net = folder + "/map.net.xml";
  const std::string poly = folder + "/map.poly.xml";
  if (options.generator == "parking_lot") {
    ParkingLotLayout layout;
    layout.rows = static_cast<int>(MapGeneratorParamValue(options, "rows"));
    layout.slots_per_row =
        static_cast<int>(MapGeneratorParamValue(options, "slots_per_row"));
    layout.aisle_width_m = MapGeneratorParamValue(options, "aisle_width_m");
    layout.slot_width_m = MapGeneratorParamValue(options, "slot_width_m");
    layout.slot_depth_m = MapGeneratorParamValue(options, "slot_depth_m");
    if (layout.rows < 1 || layout.slots_per_row < 1) {
      return Status::InvalidArgument(
          "parking_lot needs rows >= 1 and slots_per_row >= 1");
    }
    const ParkingLotFiles files = MakeParkingLot(layout);
    ADSE_RETURN_IF_ERROR(WriteFileAtomic(folder + "/map.nod.xml", files.nodes));
    ADSE_RETURN_IF_ERROR(WriteFileAtomic(folder + "/map.edg.xml", files.edges));
    ADSE_RETURN_IF_ERROR(WriteFileAtomic(poly, files.polygons));
    return RunChecked({ADSE_NETCONVERT, "--node-files", folder + "/map.nod.xml",
                       "--edge-files", folder + "/map.edg.xml", "--output-file",
                       net, "--offset.disable-normalization", "true",
                       "--no-turnarounds", "true", "--default.junctions.radius",
                       "4", "--junctions.corner-detail", "6", "--no-warnings",
                       "true"});
  }
  if (options.generator == "grid") {
    const int number =
        static_cast<int>(MapGeneratorParamValue(options, "number"));
    const double length = MapGeneratorParamValue(options, "length_m");
    const int lanes =
        static_cast<int>(MapGeneratorParamValue(options, "lanes"));
    ADSE_RETURN_IF_ERROR(
        WriteFileAtomic(poly, GridBuildings(number, length, lanes)));
    return RunChecked(
        {ADSE_NETGENERATE, "--grid", "--grid.number", std::to_string(number),
         "--grid.length", fmt::format("{}", length), "--default.lanenumber",
         std::to_string(lanes), "--default.speed", "13.89", "--no-turnarounds",
         "true", "--output-file", net, "--no-warnings", "true"});
  }
  return Status::InvalidArgument(
      fmt::format("unknown map generator '{}' (expected one of {})",
                  options.generator, fmt::join(MapGeneratorNames(), ", ")));
}

}  // namespace

Result<MapArtifacts> PrepareMap(const MapOptions& options,
                                const std::string& cache_dir, Env* env) {
  MapArtifacts out;
  ContentHasher hasher;
  if (options.generator.empty()) {
    if (options.net_path.empty()) {
      return Status::InvalidArgument("map: neither a net file nor a generator");
    }
    Result<std::string> net = ReadFile(options.net_path, 1u << 30);
    if (!net.ok()) return net.status().WithContext("map net");
    hasher.Add("net").Add(*net);
    if (!options.polygons_path.empty()) {
      Result<std::string> poly = ReadFile(options.polygons_path, 1u << 30);
      if (!poly.ok()) return poly.status().WithContext("map polygons");
      hasher.Add("poly").Add(*poly);
    }
    out.net_path = options.net_path;
    out.polygons_path = options.polygons_path;
    out.key = hasher.Hex();
    out.cache_folder = cache_dir + "/maps/" + out.key.substr(0, 20);
    ADSE_RETURN_IF_ERROR(MakeDirs(out.cache_folder));
    return out;
  }

  hasher.Add(kGeneratorVersion).Add(options.generator);
  for (const auto& [name, value] : options.generator_params) {
    hasher.Add(name).Add(value);
  }
  out.key = hasher.Hex();
  out.generated = true;
  out.cache_folder = cache_dir + "/maps/" + out.key.substr(0, 20);
  out.net_path = out.cache_folder + "/map.net.xml";
  out.polygons_path = out.cache_folder + "/map.poly.xml";
  std::error_code ec;
  if (fs::exists(out.cache_folder + "/DONE", ec)) return out;

  // Build in a private folder and rename it into place: concurrent builders
  // of the same map race harmlessly and nobody sees a half-built map.
  ADSE_RETURN_IF_ERROR(MakeDirs(cache_dir + "/maps", env));
  // Host and pid: builders on different nodes may share the cache (a
  // home folder on NFS) and pids repeat across hosts.
  const std::string tmp = TemporaryPathFor(out.cache_folder);
  fs::remove_all(tmp, ec);
  ADSE_RETURN_IF_ERROR(MakeDirs(tmp, env));
  Status status = Generate(options, tmp);
  if (status.ok()) {
    status = WriteFileAtomic(tmp + "/DONE", out.key + "\n", env);
  }
  if (!status.ok()) {
    fs::remove_all(tmp, ec);
    return status.WithContext("generating map '" + options.generator + "'");
  }
  // A folder without DONE is the leftover of a crashed build; one with DONE
  // was finished meanwhile by another builder and may be in use: keep it.
  if (fs::exists(out.cache_folder, ec) &&
      !fs::exists(out.cache_folder + "/DONE", ec)) {
    fs::remove_all(out.cache_folder, ec);
  }
  Status moved = env->RenameFile(tmp, out.cache_folder);
  if (moved.ok()) {
    moved = env->SyncDir(cache_dir + "/maps");
  } else {
    // Another process finished first; its copy is as good as ours.
    fs::remove_all(tmp, ec);
    if (!fs::exists(out.cache_folder + "/DONE", ec)) {
      return moved.WithContext("cannot move generated map into " +
                               out.cache_folder);
    }
    moved = Status::Ok();
  }
  if (!moved.ok()) return moved;
  return out;
}

}  // namespace adse::world
