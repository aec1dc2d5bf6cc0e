// Typed access to a YAML document for the scenario reader: every value
// with its file, line, column and field path, bounds on numbers, enums from
// a vocabulary, and diagnostics collected (sorted, at most kMaxSpecErrors)
// instead of thrown. yaml-cpp appears only behind this header, which only
// the spec module's .cc files include.
#ifndef ADSE_HARNESS_SPEC_INTERNAL_YAML_READER_H_
#define ADSE_HARNESS_SPEC_INTERNAL_YAML_READER_H_

#include <fmt/format.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "harness/spec/spec.h"
#include "harness/spec/spec_parser.h"
#include "harness/spec/text_util.h"

namespace adse::spec::internal {

// A value in the file: its node, where it is, and its field path.
struct Val {
  YAML::Node node;
  YAML::Mark mark;      // of the value (or of the key when the value is empty)
  YAML::Mark key_mark;  // of the key; equals `mark` for list items
  std::string path;
};

// The entries of a map, in file order, by key.
struct Fields {
  std::vector<std::string> order;
  std::map<std::string, Val> by_key;
  const Val* Get(const std::string& key) const {
    auto it = by_key.find(key);
    return it == by_key.end() ? nullptr : &it->second;
  }
};

struct Diagnostic {
  int line = 0;  // 1-based; 0 when unknown
  int column = 0;
  size_t sequence = 0;
  std::string text;
};

struct Bounds {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;

  static Bounds Positive() { return {0, Bounds().hi, true, false}; }
  static Bounds NonNegative() { return {0, Bounds().hi, false, false}; }
  static Bounds Closed(double lo, double hi) { return {lo, hi, false, false}; }

  bool Contains(double v) const {
    if (lo_open ? v <= lo : v < lo) return false;
    if (hi_open ? v >= hi : v > hi) return false;
    return true;
  }
  std::string Describe(const char* noun) const {
    const bool has_lo = std::isfinite(lo);
    const bool has_hi = std::isfinite(hi);
    if (has_lo && has_hi) {
      return fmt::format("{} in {}{}, {}{}", noun, lo_open ? "(" : "[",
                         FormatNumber(lo), FormatNumber(hi),
                         hi_open ? ")" : "]");
    }
    if (has_lo) {
      return fmt::format("{} {} {}", noun,
                         lo_open ? ">" : ">=", FormatNumber(lo));
    }
    if (has_hi) {
      return fmt::format("{} {} {}", noun,
                         hi_open ? "<" : "<=", FormatNumber(hi));
    }
    return noun;
  }
};

// `text` quoted for a message, cut at 60 characters, control characters
// shown harmlessly.
std::string Quote(const std::string& text);
// What a node is, for "found ...": a bare number, a quoted string, "a map".
std::string Describe(const YAML::Node& node);
// "a.b" from "a" and "b"; "b" at the top level.
std::string Join(const std::string& path, const std::string& key);

class YamlReader {
 public:
  // `marks` receives where each field was written; it outlives the reader.
  YamlReader(std::string source_path, std::string base_dir,
             std::map<std::string, SourceMark>* marks)
      : source_path_(std::move(source_path)),
        base_dir_(std::move(base_dir)),
        marks_(marks) {}

  // Diagnostic for a whole-file problem (no node).
  void FileError(const YAML::Mark& mark, const std::string& path,
                 const std::string& expected, const std::string& found) {
    Error(mark, path, expected, found);
  }
  // The diagnostics in file order.
  std::vector<Diagnostic> TakeErrors();
  bool full() const { return errors_.size() >= kMaxSpecErrors; }
  bool has_errors() const { return !errors_.empty(); }
  size_t error_count() const { return errors_.size(); }

 protected:
  // --- diagnostics: "file:line:col: error: path: expected X, found Y" ---
  void Error(const YAML::Mark& mark, const std::string& path,
             const std::string& expected, const std::string& found,
             const std::string& suffix = "");
  void Error(const Val& v, const std::string& expected,
             const std::string& suffix = "");
  void Missing(const Val& parent, const std::string& key,
               const std::string& expected);
  void Mark(const std::string& path, const YAML::Mark& mark);

  // --- structure ---
  // Reads a map's entries; reports a non-map, non-scalar keys, duplicate
  // keys and (when `allowed` is given) unknown keys. False when not a map.
  bool ReadFields(const Val& v, const std::vector<std::string>* allowed,
                  Fields* out, const std::string& expected = "a map");
  bool ReadList(const Val& v, std::vector<Val>* items,
                const std::string& expected = "a list");

  // --- scalars; each reports what it expected and returns false ---
  bool ReadNumber(const Val& v, double* out, const Bounds& bounds,
                  const char* noun = "a number");
  bool ReadInt(const Val& v, int* out, const Bounds& bounds);
  bool ReadBool(const Val& v, bool* out);
  bool ReadSeed(const Val& v, uint64_t* out);
  bool ReadString(const Val& v, std::string* out,
                  const std::string& expected = "a non-empty string");
  // One of `options` (a vocabulary list), with a "did you mean" hint.
  bool ReadEnum(const Val& v, std::string* out,
                const std::vector<std::string>& options);
  // An enum through its vocabulary's StringToX.
  template <typename E>
  bool ReadEnum(const Val& v, E* out, const std::vector<std::string>& options,
                bool (*from_string)(std::string_view, E*)) {
    std::string name;
    return ReadEnum(v, &name, options) && from_string(name, out);
  }
  // A path written in the file, made absolute from the file's folder.
  bool ReadPath(const Val& v, std::string* out, const std::string& what);

  const std::string& source_path() const { return source_path_; }

 private:
  std::string source_path_;
  std::string base_dir_;
  std::map<std::string, SourceMark>* marks_;
  std::vector<Diagnostic> errors_;
};

}  // namespace adse::spec::internal

#endif  // ADSE_HARNESS_SPEC_INTERNAL_YAML_READER_H_
