// Typed, located reading of the profile module's YAML files (profiles,
// mappings, CARET stats): every error names the file, the 1-based line and
// column, the field path and what was expected, in the scenario reader's
// words ("f.yaml:3:7: error: reference.ghz: expected a number > 0, found
// 'fast'"). yaml-cpp appears only behind this header, which only this
// module's .cc files include; its exceptions end here.
#ifndef ADSE_HARNESS_PROFILE_INTERNAL_YAML_DOC_H_
#define ADSE_HARNESS_PROFILE_INTERNAL_YAML_DOC_H_

#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>
#include <vector>

#include "harness/profile/profile.h"
#include "stack/base/status.h"

namespace adse::profile::internal {

// Allowed range of a number, and how to say it.
struct Range {
  double lo = 0.0;
  double hi = 0.0;
  bool has_lo = false;
  bool has_hi = false;
  bool lo_open = false;  // lo itself is not allowed
  bool integer = false;

  static Range NonNegative() { return {0.0, 0.0, true, false, false, false}; }
  static Range Positive() { return {0.0, 0.0, true, false, true, false}; }
  static Range Between(double lo, double hi) {
    return {lo, hi, true, true, false, false};
  }
  static Range IntegerAtLeast(double lo) {
    return {lo, 0.0, true, false, false, true};
  }
  // "a number >= 0", "an integer >= 1", "a number in [0, 1]".
  std::string Describe() const;
};

// One parsed YAML file.
class YamlDoc {
 public:
  // Reads and parses `path`. A missing file is NotFound; a file that is too
  // large, nests too deep, is not YAML or writes a key twice in one map is
  // InvalidArgument at its line.
  // `what` names the expected content in messages ("a cost profile").
  static Result<YamlDoc> Load(const std::string& path, const std::string& what);

  const std::string& path() const { return path_; }
  const YAML::Node& root() const { return root_; }

  // "<file>:<line>:<col>: error: <field>: expected <expected>, found <found>"
  Status Error(const YAML::Mark& mark, const std::string& field,
               const std::string& expected, const std::string& found) const;
  // The same for a value: found is Describe(node), at the node's mark.
  Status ErrorAt(const YAML::Node& node, const std::string& field,
                 const std::string& expected) const;

 private:
  // InvalidArgument at the second of a key written twice in one map.
  Status CheckKeysOnce(const YAML::Node& node, const std::string& path) const;

  std::string path_;
  YAML::Node root_;
};

// "a map", "a list", "nothing", "'text'" (shortened), for "found ...".
std::string Describe(const YAML::Node& node);

// "a.b" (or "b" at the top level).
std::string JoinPath(const std::string& parent, const std::string& key);

// A map in a YamlDoc with its field path, read key by key.
class MapReader {
 public:
  // `mark` locates the map when `node` is missing (e.g. its key).
  MapReader(const YamlDoc* doc, YAML::Node node, std::string path,
            YAML::Mark mark);
  // Reader of the document's root.
  explicit MapReader(const YamlDoc* doc);

  // InvalidArgument unless the node is a map.
  Status CheckIsMap() const;
  // InvalidArgument at the first key not in `allowed` (with a "did you
  // mean").
  Status CheckKeys(const std::vector<std::string>& allowed) const;

  bool Has(const std::string& key) const;
  YAML::Node Get(const std::string& key) const;
  // The key's own position, or the map's when the key is missing.
  YAML::Mark KeyMark(const std::string& key) const;
  std::string PathOf(const std::string& key) const {
    return JoinPath(path_, key);
  }
  const std::string& path() const { return path_; }
  const YAML::Node& node() const { return node_; }
  const YamlDoc& doc() const { return *doc_; }

  // A nested map (required).
  Result<MapReader> Map(const std::string& key) const;
  // A number in `range`; missing: `fallback`, or an error without one.
  Result<double> Number(const std::string& key, const Range& range,
                        std::optional<double> fallback = std::nullopt) const;
  Result<int> Integer(const std::string& key, const Range& range,
                      std::optional<int> fallback = std::nullopt) const;
  Result<bool> Bool(const std::string& key,
                    std::optional<bool> fallback = std::nullopt) const;
  // A string; missing: `fallback`, or an error. Non-empty when
  // `non_empty`.
  Result<std::string> String(const std::string& key,
                             std::optional<std::string> fallback = std::nullopt,
                             bool non_empty = false) const;
  // A non-empty list of non-empty strings, with each item's mark.
  Result<std::vector<std::string>> StringList(
      const std::string& key, std::vector<YAML::Mark>* marks = nullptr) const;

  // The entries in file order (keys as text, with their marks).
  std::vector<std::pair<std::string, YAML::Node>> Entries(
      std::vector<YAML::Mark>* key_marks = nullptr) const;

 private:
  Status Missing(const std::string& key, const std::string& expected) const;

  const YamlDoc* doc_;
  YAML::Node node_;
  std::string path_;
  YAML::Mark mark_;
};

// Parses a YAML scalar as a number: decimal or exponent notation, and
// YAML's .nan / .inf (so that callers can refuse them by name). False for
// anything else (text, '---', "10 ms").
bool ParseYamlNumber(const std::string& text, double* value);

// A number as text that reads back as the same double ("4.9", "10",
// "0.0213").
std::string FormatNumber(double value);

// Candidates close to `word` by edit distance, best first, at most `n`:
// " (did you mean 'a' or 'b'?)", or "" when none is close.
std::string DidYouMean(const std::string& word,
                       const std::vector<std::string>& candidates,
                       size_t n = 1);

// The `source:` map that profiles and mappings share: description
// (required), license, cpu and note.
Result<ProfileSource> ReadSource(const MapReader& parent);

}  // namespace adse::profile::internal

#endif  // ADSE_HARNESS_PROFILE_INTERNAL_YAML_DOC_H_
