#include "harness/spec/internal/yaml_reader.h"

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <tuple>
#include <utility>

namespace adse::spec::internal {

namespace fs = std::filesystem;

std::string Quote(const std::string& text) {
  constexpr size_t kMaxShown = 60;
  std::string shown;
  for (char c : text.substr(0, kMaxShown)) {
    if (c == '\n') {
      shown += "\\n";
    } else if (static_cast<unsigned char>(c) < 0x20) {
      shown += '?';
    } else {
      shown += c;
    }
  }
  if (text.size() > kMaxShown) shown += "...";
  return "'" + shown + "'";
}

std::string Describe(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsScalar()) {
    double number = 0;
    // Numbers read better bare: "found 0", "found 'fast'".
    if (node.Scalar().size() < 32 && ParseNumber(node.Scalar(), &number)) {
      return node.Scalar();
    }
    return Quote(node.Scalar());
  }
  if (node.IsSequence()) {
    return node.size() == 1 ? "a list of 1 item"
                            : fmt::format("a list of {} items", node.size());
  }
  if (node.IsMap()) return "a map";
  return "something else";
}

std::string Join(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

std::vector<Diagnostic> YamlReader::TakeErrors() {
  std::stable_sort(errors_.begin(), errors_.end(),
                   [](const Diagnostic& a, const Diagnostic& b) {
                     return std::tie(a.line, a.column, a.sequence) <
                            std::tie(b.line, b.column, b.sequence);
                   });
  return std::move(errors_);
}

// --- diagnostics ---
void YamlReader::Error(const YAML::Mark& mark, const std::string& path,
                       const std::string& expected, const std::string& found,
                       const std::string& suffix) {
  if (full()) return;
  Diagnostic d;
  d.line = mark.is_null() ? 1 : mark.line + 1;
  d.column = mark.is_null() ? 1 : mark.column + 1;
  d.sequence = errors_.size();
  d.text = fmt::format(
      "{}:{}:{}: error: {}: expected {}, found {}{}", source_path_, d.line,
      d.column, path.empty() ? "(top level)" : path, expected, found, suffix);
  errors_.push_back(std::move(d));
}
void YamlReader::Error(const Val& v, const std::string& expected,
                       const std::string& suffix) {
  Error(v.mark, v.path, expected, Describe(v.node), suffix);
}
void YamlReader::Missing(const Val& parent, const std::string& key,
                         const std::string& expected) {
  Error(parent.key_mark, Join(parent.path, key), expected + " (required)",
        "nothing");
}
void YamlReader::Mark(const std::string& path, const YAML::Mark& mark) {
  if (mark.is_null()) return;
  (*marks_)[path] = SourceMark{mark.line + 1, mark.column + 1};
}

// --- structure ---
// Reads a map's entries; reports a non-map, non-scalar keys, duplicate
// keys and (when `allowed` is given) unknown keys. False when not a map.
bool YamlReader::ReadFields(const Val& v,
                            const std::vector<std::string>* allowed,
                            Fields* out, const std::string& expected) {
  if (!v.node.IsMap()) {
    Error(v, expected);
    return false;
  }
  std::map<std::string, int> first_line;
  for (auto it = v.node.begin(); it != v.node.end(); ++it) {
    if (full()) return true;
    const YAML::Node key = it->first;
    const YAML::Node value = it->second;
    if (!key.IsScalar()) {
      Error(key.Mark(), v.path, "plain keys", Describe(key) + " as a key");
      continue;
    }
    const std::string name = key.Scalar();
    const std::string path = Join(v.path, name);
    if (auto seen = first_line.find(name); seen != first_line.end()) {
      Error(key.Mark(), path, "each key once",
            fmt::format("'{}' again (first at line {})", name, seen->second));
      continue;
    }
    first_line[name] = key.Mark().line + 1;
    if (allowed != nullptr &&
        std::find(allowed->begin(), allowed->end(), name) == allowed->end()) {
      Error(key.Mark(), path, "a key among {" + JoinList(*allowed) + "}",
            Quote(name), DidYouMean(name, *allowed));
      continue;
    }
    Val entry;
    entry.node = value;
    entry.key_mark = key.Mark();
    // An empty value (`key:`) has no useful mark of its own.
    entry.mark = value.IsNull() ? key.Mark() : value.Mark();
    entry.path = path;
    Mark(path, key.Mark());
    out->order.push_back(name);
    out->by_key.emplace(name, std::move(entry));
  }
  return true;
}

bool YamlReader::ReadList(const Val& v, std::vector<Val>* items,
                          const std::string& expected) {
  if (!v.node.IsSequence()) {
    Error(v, expected);
    return false;
  }
  size_t index = 0;
  for (const YAML::Node& item : v.node) {
    Val entry;
    entry.node = item;
    entry.mark = item.IsNull() ? v.mark : item.Mark();
    entry.key_mark = entry.mark;
    entry.path = fmt::format("{}[{}]", v.path, index++);
    Mark(entry.path, entry.mark);
    items->push_back(std::move(entry));
  }
  return true;
}

// --- scalars ---
bool YamlReader::ReadNumber(const Val& v, double* out, const Bounds& bounds,
                            const char* noun) {
  double value = 0;
  if (!v.node.IsScalar() || !ParseNumber(v.node.Scalar(), &value) ||
      !bounds.Contains(value)) {
    Error(v, bounds.Describe(noun));
    return false;
  }
  *out = value;
  return true;
}
bool YamlReader::ReadInt(const Val& v, int* out, const Bounds& bounds) {
  double value = 0;
  const Bounds limited{std::max(bounds.lo, -1e9), std::min(bounds.hi, 1e9),
                       bounds.lo_open, bounds.hi_open};
  if (!v.node.IsScalar() || !ParseNumber(v.node.Scalar(), &value) ||
      value != std::floor(value) || !limited.Contains(value)) {
    Error(v, bounds.Describe("an integer"));
    return false;
  }
  *out = static_cast<int>(value);
  return true;
}
bool YamlReader::ReadBool(const Val& v, bool* out) {
  // Only YAML 1.2's spelling: `yes`, `on` or `1` for a flag is more often a
  // slip than a choice.
  const std::string text = v.node.IsScalar() ? v.node.Scalar() : "";
  if (text != "true" && text != "false") {
    Error(v, "true or false");
    return false;
  }
  *out = text == "true";
  return true;
}
bool YamlReader::ReadSeed(const Val& v, uint64_t* out) {
  const std::string text = v.node.IsScalar() ? v.node.Scalar() : "";
  uint64_t value = 0;
  const auto [end, ec] =
      std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size()) {
    Error(v, "an integer in [0, 18446744073709551615]");
    return false;
  }
  *out = value;
  return true;
}
bool YamlReader::ReadString(const Val& v, std::string* out,
                            const std::string& expected) {
  if (!v.node.IsScalar() || v.node.Scalar().empty()) {
    Error(v, expected);
    return false;
  }
  *out = v.node.Scalar();
  return true;
}
bool YamlReader::ReadEnum(const Val& v, std::string* out,
                          const std::vector<std::string>& options) {
  const std::string expected = "one of " + JoinList(options);
  if (!v.node.IsScalar()) {
    Error(v, expected);
    return false;
  }
  const std::string& text = v.node.Scalar();
  if (std::find(options.begin(), options.end(), text) == options.end()) {
    Error(v, expected, DidYouMean(text, options));
    return false;
  }
  *out = text;
  return true;
}
// A path written in the file, made absolute from the file's folder.
bool YamlReader::ReadPath(const Val& v, std::string* out,
                          const std::string& what) {
  std::string written;
  if (!ReadString(v, &written, what)) return false;
  fs::path path(written);
  if (path.is_relative()) path = fs::path(base_dir_) / path;
  *out = path.lexically_normal().string();
  return true;
}

}  // namespace adse::spec::internal
