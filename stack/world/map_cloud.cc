#include "stack/world/map_cloud.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string_view>

#include "stack/base/files.h"
#include "stack/geometry/geometry.h"

namespace adse::world {
namespace {

// The binary layout below is the host's; PCD binary is little-endian.
static_assert(std::endian::native == std::endian::little,
              "PCD binary I/O assumes a little-endian host");

// Finer faces than this would only blow up memory.
constexpr double kMinSpacingM = 0.01;
// A ground grid is coarsened to stay below this many points (huge maps).
constexpr double kMaxGroundPoints = 4.0e6;
// Map clouds larger than this are refused rather than read.
constexpr size_t kMaxPcdBytes = size_t{1} << 30;

int Steps(double length, double spacing) {
  return std::max(1, static_cast<int>(std::ceil(length / spacing - 1e-9)));
}

// The cells of a grid over [lo, hi] whose centre lies within the half
// width (plus half a cell's diagonal, so no point within the half width is
// lost) of a polyline. Without a polyline every place is inside.
class CorridorMask {
 public:
  CorridorMask(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
               const std::vector<Eigen::Vector2d>& path, double half_width_m)
      : lo_(lo), active_(!path.empty()) {
    if (!active_) return;
    const Eigen::Vector2d extent = (hi - lo).cwiseMax(0.0);
    nx_ = static_cast<int>(extent.x() / kCellM) + 1;
    ny_ = static_cast<int>(extent.y() / kCellM) + 1;
    inside_.assign(static_cast<size_t>(nx_) * ny_, 0);
    const double reach = half_width_m + kCellM * std::sqrt(0.5);
    for (size_t i = 0; i < path.size(); ++i) {
      const Eigen::Vector2d a = path[i];
      const Eigen::Vector2d b = path[std::min(i + 1, path.size() - 1)];
      const Eigen::Vector2d pmin = a.cwiseMin(b).array() - reach;
      const Eigen::Vector2d pmax = a.cwiseMax(b).array() + reach;
      const int x0 = std::max(0, Cell(pmin.x() - lo_.x()));
      const int x1 = std::min(nx_ - 1, Cell(pmax.x() - lo_.x()));
      const int y0 = std::max(0, Cell(pmin.y() - lo_.y()));
      const int y1 = std::min(ny_ - 1, Cell(pmax.y() - lo_.y()));
      for (int y = y0; y <= y1; ++y) {
        for (int x = x0; x <= x1; ++x) {
          const Eigen::Vector2d c =
              lo_ + kCellM * Eigen::Vector2d(x + 0.5, y + 0.5);
          if (geometry::DistanceToSegment(c, a, b) <= reach)
            inside_[static_cast<size_t>(y) * nx_ + x] = 1;
        }
      }
    }
    for (const char cell : inside_) area_m2_ += cell ? kCellM * kCellM : 0.0;
  }

  bool Contains(double x, double y) const {
    if (!active_) return true;
    const int cx = Cell(x - lo_.x());
    const int cy = Cell(y - lo_.y());
    return cx >= 0 && cy >= 0 && cx < nx_ && cy < ny_ &&
           inside_[static_cast<size_t>(cy) * nx_ + cx] != 0;
  }

  // The area inside, m²; negative without a polyline.
  double area_m2() const { return active_ ? area_m2_ : -1.0; }

 private:
  static constexpr double kCellM = 8.0;
  static int Cell(double offset_m) {
    return static_cast<int>(std::floor(offset_m / kCellM));
  }

  Eigen::Vector2d lo_;
  bool active_;
  int nx_ = 0, ny_ = 0;
  std::vector<char> inside_;
  double area_m2_ = 0.0;
};

// The scene's bounds grown by the ground margin: all a map can hold.
std::pair<Eigen::Vector2d, Eigen::Vector2d> MapBounds(
    const Scene& scene, const MapCloudOptions& options) {
  const Eigen::Vector2d margin =
      Eigen::Vector2d::Constant(options.ground_margin_m);
  return {scene.min_corner() - margin, scene.max_corner() + margin};
}

void SampleGround(const Scene& scene, const MapCloudOptions& options,
                  const CorridorMask& mask,
                  std::vector<Eigen::Vector3f>* points) {
  const auto [lo, hi] = MapBounds(scene, options);
  const Eigen::Vector2d extent = (hi - lo).cwiseMax(0.0);
  double step = options.ground_spacing_m;
  // The area sampled, and about how many points that gives: with a
  // corridor, its own (smaller) area.
  double area = extent.x() * extent.y();
  double estimate = (extent.x() / step + 1) * (extent.y() / step + 1);
  if (mask.area_m2() >= 0) {
    area = std::min(area, mask.area_m2());
    estimate = area / (step * step);
  }
  if (estimate > kMaxGroundPoints) {
    step = std::sqrt(area / kMaxGroundPoints) * 1.01 + 1e-9;
  }
  const int nx = static_cast<int>(std::floor(extent.x() / step + 1e-9)) + 1;
  const int ny = static_cast<int>(std::floor(extent.y() / step + 1e-9)) + 1;

  // Bucket closed footprints by bounding box so each ground point tests
  // only the few polygons near it.
  constexpr double kBucketM = 16.0;
  const int bx = static_cast<int>(extent.x() / kBucketM) + 1;
  const int by = static_cast<int>(extent.y() / kBucketM) + 1;
  std::vector<std::vector<int>> buckets(static_cast<size_t>(bx) * by);
  const auto& obstacles = scene.obstacles();
  for (size_t i = 0; i < obstacles.size(); ++i) {
    const auto& fp = obstacles[i].footprint;
    if (fp.size() < 3) continue;  // a thin wall hides no ground
    Eigen::Vector2d pmin = fp[0], pmax = fp[0];
    for (const auto& p : fp) {
      pmin = pmin.cwiseMin(p);
      pmax = pmax.cwiseMax(p);
    }
    const int x0 =
        std::clamp(static_cast<int>((pmin.x() - lo.x()) / kBucketM), 0, bx - 1);
    const int x1 =
        std::clamp(static_cast<int>((pmax.x() - lo.x()) / kBucketM), 0, bx - 1);
    const int y0 =
        std::clamp(static_cast<int>((pmin.y() - lo.y()) / kBucketM), 0, by - 1);
    const int y1 =
        std::clamp(static_cast<int>((pmax.y() - lo.y()) / kBucketM), 0, by - 1);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        buckets[static_cast<size_t>(y) * bx + x].push_back(static_cast<int>(i));
      }
    }
  }
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      const double x = lo.x() + ix * step;
      const double y = lo.y() + iy * step;
      if (!mask.Contains(x, y)) continue;
      const int cx =
          std::clamp(static_cast<int>((x - lo.x()) / kBucketM), 0, bx - 1);
      const int cy =
          std::clamp(static_cast<int>((y - lo.y()) / kBucketM), 0, by - 1);
      bool hidden = false;
      for (const int i : buckets[static_cast<size_t>(cy) * bx + cx]) {
        if (geometry::InsidePolygon(obstacles[i].footprint, {x, y})) {
          hidden = true;
          break;
        }
      }
      if (!hidden) points->emplace_back(x, y, 0.0f);
    }
  }
}

Status Corrupt(const std::string& path, const std::string& what) {
  return Status::Corruption(path + ": " + what);
}

std::vector<std::string_view> Tokens(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

bool ParseU64(std::string_view s, uint64_t* out) {
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), *out);
  return ec == std::errc() && ptr == s.data() + s.size();
}

bool ParseDouble(std::string_view s, double* out) {
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), *out);
  return ec == std::errc() && ptr == s.data() + s.size();
}

struct Field {
  std::string name;
  uint64_t size = 0;
  char type = 0;
  uint64_t count = 1;
  uint64_t offset = 0;  // bytes into a binary point
  uint64_t column = 0;  // token index in an ascii line
};

struct PcdHeader {
  std::vector<Field> fields;
  uint64_t width = 0, height = 0, points = 0;
  std::string data;
  size_t data_offset = 0;  // first byte after the DATA line
  uint64_t point_bytes = 0;
  uint64_t point_tokens = 0;
  int xyz[3] = {-1, -1, -1};  // field index of x, y, z
};

Result<PcdHeader> ParseHeader(const std::string& path,
                              const std::string& text) {
  PcdHeader h;
  bool have_size = false, have_type = false, have_count = false;
  bool have_width = false, have_height = false, have_points = false;
  size_t pos = 0;
  int line_no = 0;
  while (h.data.empty()) {
    const size_t nl = text.find('\n', pos);
    if (nl == std::string::npos) {
      return Corrupt(path, "header ends before its DATA line");
    }
    ++line_no;
    std::string_view line(text.data() + pos, nl - pos);
    pos = nl + 1;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const auto tok = Tokens(line);
    if (tok.empty() || tok[0][0] == '#') continue;
    const std::string key(tok[0]);
    const std::string where =
        "header line " + std::to_string(line_no) + " (" + key + "): ";
    auto list_size_ok = [&](size_t n) {
      return !h.fields.empty() && n == h.fields.size();
    };
    if (key == "VERSION" || key == "VIEWPOINT") {
      continue;
    } else if (key == "FIELDS") {
      if (tok.size() < 2) return Corrupt(path, where + "no fields");
      for (size_t i = 1; i < tok.size(); ++i) {
        h.fields.push_back(Field{std::string(tok[i])});
      }
    } else if (key == "SIZE") {
      if (!list_size_ok(tok.size() - 1)) {
        return Corrupt(path, where + "needs one entry per field, after FIELDS");
      }
      for (size_t i = 1; i < tok.size(); ++i) {
        uint64_t v = 0;
        if (!ParseU64(tok[i], &v) || (v != 1 && v != 2 && v != 4 && v != 8)) {
          return Corrupt(path,
                         where + "bad size '" + std::string(tok[i]) + "'");
        }
        h.fields[i - 1].size = v;
      }
      have_size = true;
    } else if (key == "TYPE") {
      if (!list_size_ok(tok.size() - 1)) {
        return Corrupt(path, where + "needs one entry per field, after FIELDS");
      }
      for (size_t i = 1; i < tok.size(); ++i) {
        if (tok[i].size() != 1 ||
            std::string_view("FIU").find(tok[i][0]) == std::string_view::npos) {
          return Corrupt(path,
                         where + "bad type '" + std::string(tok[i]) + "'");
        }
        h.fields[i - 1].type = tok[i][0];
      }
      have_type = true;
    } else if (key == "COUNT") {
      if (!list_size_ok(tok.size() - 1)) {
        return Corrupt(path, where + "needs one entry per field, after FIELDS");
      }
      for (size_t i = 1; i < tok.size(); ++i) {
        uint64_t v = 0;
        if (!ParseU64(tok[i], &v) || v == 0 || v > 1000000) {
          return Corrupt(path,
                         where + "bad count '" + std::string(tok[i]) + "'");
        }
        h.fields[i - 1].count = v;
      }
      have_count = true;
    } else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
      uint64_t v = 0;
      if (tok.size() != 2 || !ParseU64(tok[1], &v)) {
        return Corrupt(path, where + "expected one non-negative integer");
      }
      if (key == "WIDTH") h.width = v, have_width = true;
      if (key == "HEIGHT") h.height = v, have_height = true;
      if (key == "POINTS") h.points = v, have_points = true;
    } else if (key == "DATA") {
      if (tok.size() != 2) return Corrupt(path, where + "expected one word");
      h.data = std::string(tok[1]);
    } else {
      return Corrupt(path, where + "unknown header entry");
    }
  }
  h.data_offset = pos;
  (void)have_count;  // COUNT is optional: 1 per field

  if (h.fields.empty()) return Corrupt(path, "header has no FIELDS");
  if (!have_size || !have_type) {
    return Corrupt(path, "header lacks SIZE or TYPE");
  }
  if (!have_width || !have_height) {
    return Corrupt(path, "header lacks WIDTH or HEIGHT");
  }
  if (h.height != 0 &&
      h.width > std::numeric_limits<uint64_t>::max() / h.height) {
    return Corrupt(path, "WIDTH x HEIGHT overflows");
  }
  if (!have_points) h.points = h.width * h.height;
  if (h.points != h.width * h.height) {
    return Corrupt(path, "POINTS " + std::to_string(h.points) +
                             " does not match WIDTH x HEIGHT " +
                             std::to_string(h.width) + " x " +
                             std::to_string(h.height));
  }
  for (size_t i = 0; i < h.fields.size(); ++i) {
    Field& f = h.fields[i];
    f.offset = h.point_bytes;
    f.column = h.point_tokens;
    h.point_bytes += f.size * f.count;
    h.point_tokens += f.count;
    for (int k = 0; k < 3; ++k) {
      if (f.name == std::string(1, "xyz"[k])) {
        if (f.type != 'F' || f.count != 1 || (f.size != 4 && f.size != 8)) {
          return Corrupt(path,
                         "field " + f.name + " must be one float32 or float64");
        }
        h.xyz[k] = static_cast<int>(i);
      }
    }
  }
  for (int k = 0; k < 3; ++k) {
    if (h.xyz[k] < 0) {
      return Corrupt(path, std::string("no field ") + "xyz"[k]);
    }
  }
  if (h.data == "binary_compressed") {
    return Status::InvalidArgument(
        path + ": binary_compressed PCD is not supported; save it as binary");
  }
  if (h.data != "binary" && h.data != "ascii") {
    return Corrupt(path, "unknown DATA kind '" + h.data + "'");
  }
  return h;
}

Result<std::vector<Eigen::Vector3f>> ReadBinary(const std::string& path,
                                                const std::string& text,
                                                const PcdHeader& h) {
  const uint64_t available = text.size() - h.data_offset;
  const bool too_many =
      h.point_bytes != 0 &&
      h.points > std::numeric_limits<uint64_t>::max() / h.point_bytes;
  const uint64_t expected = too_many ? 0 : h.points * h.point_bytes;
  if (too_many || available < expected) {
    return Corrupt(path, "truncated: " + std::to_string(available) +
                             " bytes of point data, expected " +
                             std::to_string(h.points) + " points of " +
                             std::to_string(h.point_bytes) + " bytes");
  }
  if (available > expected) {
    return Corrupt(path, std::to_string(available - expected) +
                             " unexpected bytes after the last of " +
                             std::to_string(h.points) + " points");
  }
  std::vector<Eigen::Vector3f> points;
  points.reserve(h.points);
  const char* base = text.data() + h.data_offset;
  for (uint64_t p = 0; p < h.points; ++p) {
    float xyz[3];
    for (int k = 0; k < 3; ++k) {
      const Field& f = h.fields[h.xyz[k]];
      const char* src = base + p * h.point_bytes + f.offset;
      if (f.size == 4) {
        std::memcpy(&xyz[k], src, 4);
      } else {
        double d;
        std::memcpy(&d, src, 8);
        xyz[k] = static_cast<float>(d);
      }
    }
    if (std::isfinite(xyz[0]) && std::isfinite(xyz[1]) &&
        std::isfinite(xyz[2])) {
      points.emplace_back(xyz[0], xyz[1], xyz[2]);
    }
  }
  return points;
}

Result<std::vector<Eigen::Vector3f>> ReadAscii(const std::string& path,
                                               const std::string& text,
                                               const PcdHeader& h) {
  std::vector<Eigen::Vector3f> points;
  // Each point needs at least two characters per value.
  if (h.points > (text.size() - h.data_offset) / 2 + 1) {
    return Corrupt(path, "truncated: header promises " +
                             std::to_string(h.points) +
                             " points, far more than the data holds");
  }
  points.reserve(h.points);
  uint64_t read = 0;
  size_t pos = h.data_offset;
  uint64_t line_no = 0;
  while (pos < text.size()) {
    size_t nl = text.find('\n', pos);
    if (nl == std::string::npos) nl = text.size();
    std::string_view line(text.data() + pos, nl - pos);
    pos = nl + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const auto tok = Tokens(line);
    if (tok.empty()) continue;
    const std::string where = "data line " + std::to_string(line_no) + ": ";
    if (read == h.points) {
      return Corrupt(
          path, where + "more points than POINTS " + std::to_string(h.points));
    }
    if (tok.size() != h.point_tokens) {
      return Corrupt(path, where + std::to_string(tok.size()) +
                               " values, expected " +
                               std::to_string(h.point_tokens));
    }
    double v[3] = {0.0, 0.0, 0.0};
    for (size_t t = 0; t < tok.size(); ++t) {
      double d;
      if (!ParseDouble(tok[t], &d)) {
        return Corrupt(path,
                       where + "bad number '" + std::string(tok[t]) + "'");
      }
      for (int k = 0; k < 3; ++k) {
        if (h.fields[h.xyz[k]].column == t) v[k] = d;
      }
    }
    ++read;
    if (std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])) {
      points.emplace_back(static_cast<float>(v[0]), static_cast<float>(v[1]),
                          static_cast<float>(v[2]));
    }
  }
  if (read != h.points) {
    return Corrupt(path, "truncated: " + std::to_string(read) + " of " +
                             std::to_string(h.points) + " points present");
  }
  return points;
}

}  // namespace

std::vector<Eigen::Vector3f> SampleSceneSurface(
    const Scene& scene, const MapCloudOptions& options) {
  std::vector<Eigen::Vector3f> points;
  const double spacing = std::max(kMinSpacingM, options.spacing_m);
  const auto [lo, hi] = MapBounds(scene, options);
  const CorridorMask mask(lo, hi, options.corridor,
                          options.corridor_half_width_m);
  for (const Obstacle& obstacle : scene.obstacles()) {
    const auto edges = ObstacleEdges(obstacle);
    // A closed ring's next edge starts where this one ends: sample each
    // corner once. A thin wall is one open edge: take both ends.
    const bool open = obstacle.footprint.size() == 2;
    const double dz = obstacle.z_max_m - obstacle.z_min_m;
    const int nz = dz > 0.0 ? Steps(dz, spacing) : 0;
    for (const auto& e : edges) {
      const double len = (e[1] - e[0]).norm();
      const int nu = Steps(len, spacing);
      for (int i = 0; i <= nu - (open ? 0 : 1); ++i) {
        const Eigen::Vector2d p = e[0] + (e[1] - e[0]) * (double(i) / nu);
        if (!mask.Contains(p.x(), p.y())) continue;
        for (int k = 0; k <= nz; ++k) {
          const double z =
              nz == 0 ? obstacle.z_min_m
                      : obstacle.z_min_m + dz * (static_cast<double>(k) / nz);
          points.emplace_back(static_cast<float>(p.x()),
                              static_cast<float>(p.y()), static_cast<float>(z));
        }
      }
    }
  }
  if (options.ground_spacing_m > 0.0 && !scene.obstacles().empty()) {
    SampleGround(scene, options, mask, &points);
  }
  return points;
}

Status WritePcd(const std::string& path,
                const std::vector<Eigen::Vector3f>& points) {
  const std::string n = std::to_string(points.size());
  std::string out =
      "# .PCD v0.7 - Point Cloud Data file format\n"
      "VERSION 0.7\n"
      "FIELDS x y z\n"
      "SIZE 4 4 4\n"
      "TYPE F F F\n"
      "COUNT 1 1 1\n"
      "WIDTH " +
      n +
      "\n"
      "HEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\n"
      "POINTS " +
      n +
      "\n"
      "DATA binary\n";
  const size_t header = out.size();
  out.resize(header + points.size() * 3 * sizeof(float));
  char* dst = out.data() + header;
  for (const Eigen::Vector3f& p : points) {
    const float xyz[3] = {p.x(), p.y(), p.z()};
    std::memcpy(dst, xyz, sizeof(xyz));
    dst += sizeof(xyz);
  }
  return WriteFileAtomic(path, out).WithContext("writing PCD");
}

Result<std::vector<Eigen::Vector3f>> ReadPcd(const std::string& path) {
  Result<std::string> text = ReadFile(path, kMaxPcdBytes);
  if (!text.ok()) return text.status();
  Result<PcdHeader> header = ParseHeader(path, *text);
  if (!header.ok()) return header.status();
  if (header->data == "binary") return ReadBinary(path, *text, *header);
  return ReadAscii(path, *text, *header);
}

}  // namespace adse::world
