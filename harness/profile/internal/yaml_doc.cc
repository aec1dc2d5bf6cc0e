#include "harness/profile/internal/yaml_doc.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <sstream>

#include "harness/spec/yaml_limits.h"
#include "stack/base/files.h"

namespace adse::profile::internal {
namespace {

// CARET stats files are a few hundred kB; profiles and mappings far less.
constexpr size_t kMaxYamlBytes = 16u << 20;
// Bounds checked on parser events before yaml-cpp builds any node, so that
// an alias bomb or absurd nesting costs little.
constexpr int kMaxNodes = 2'000'000;
constexpr int kMaxDepth = 64;
constexpr int kMaxAliases = 1000;

int LineOf(const YAML::Mark& mark) {
  return mark.is_null() ? 1 : mark.line + 1;
}
int ColumnOf(const YAML::Mark& mark) {
  return mark.is_null() ? 1 : mark.column + 1;
}

int EditDistance(const std::string& a, const std::string& b) {
  std::vector<int> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = static_cast<int>(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    int diagonal = row[0];
    row[0] = static_cast<int>(i);
    for (size_t j = 1; j <= b.size(); ++j) {
      const int up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1,
                         diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

}  // namespace

std::string Range::Describe() const {
  const std::string kind = integer ? "an integer" : "a number";
  if (has_lo && has_hi) {
    return fmt::format("{} in {}{}, {}]", kind, lo_open ? "(" : "[",
                       FormatNumber(lo), FormatNumber(hi));
  }
  if (has_lo) {
    return fmt::format("{} {} {}", kind,
                       lo_open ? ">" : ">=", FormatNumber(lo));
  }
  if (has_hi) return fmt::format("{} <= {}", kind, FormatNumber(hi));
  return integer ? "an integer" : "a finite number";
}

Result<YamlDoc> YamlDoc::Load(const std::string& path,
                              const std::string& what) {
  // A path that names no file gets the same sentence whatever it is.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    return Status::InvalidArgument(
        fmt::format("{}: error: expected {}, found a directory", path, what));
  }
  Result<std::string> text = ReadFile(path, kMaxYamlBytes);
  if (!text.ok()) {
    if (text.status().code() == Status::Code::kNotFound) {
      return Status::NotFound(fmt::format(
          "{}: error: expected {}, found no such file", path, what));
    }
    return Status(text.status()).WithContext(fmt::format("reading {}", what));
  }
  YamlDoc doc;
  doc.path_ = path;
  try {
    std::istringstream in(*text);
    YAML::Parser parser(in);
    spec::YamlLimitScanner scanner(
        spec::YamlLimits{kMaxDepth, kMaxAliases, kMaxNodes});
    parser.HandleNextDocument(scanner);
    if (parser.HandleNextDocument(scanner) && scanner.documents() > 1) {
      return doc.Error(YAML::Mark(), "(file)", "one YAML document with " + what,
                       "several ('---' separators)");
    }
    doc.root_ = YAML::Load(*text);
    ADSE_RETURN_IF_ERROR(doc.CheckKeysOnce(doc.root_, ""));
  } catch (const spec::YamlLimitExceeded& e) {
    return doc.Error(e.mark, "(file)", e.expected, e.found);
  } catch (const YAML::Exception& e) {
    return doc.Error(e.mark, "(file)", "valid YAML with " + what,
                     "a syntax error: " + e.msg);
  } catch (const std::exception& e) {
    return doc.Error(YAML::Mark(), "(file)", "valid YAML with " + what,
                     e.what());
  }
  return doc;
}

Status YamlDoc::CheckKeysOnce(const YAML::Node& node,
                              const std::string& path) const {
  if (node.IsSequence()) {
    for (size_t i = 0; i < node.size(); ++i) {
      ADSE_RETURN_IF_ERROR(
          CheckKeysOnce(node[i], fmt::format("{}[{}]", path, i)));
    }
  }
  if (!node.IsMap()) return Status::Ok();
  // yaml-cpp keeps both entries of a repeated key, and a lookup finds the
  // first: a value added below an old one would be ignored.
  std::map<std::string, YAML::Mark> seen;
  for (auto it = node.begin(); it != node.end(); ++it) {
    if (!it->first.IsScalar()) continue;
    const std::string& key = it->first.Scalar();
    const auto [first, fresh] = seen.emplace(key, it->first.Mark());
    if (!fresh) {
      return Error(it->first.Mark(), JoinPath(path, key), "each key once",
                   fmt::format("'{}' again (first at line {})", key,
                               LineOf(first->second)));
    }
    ADSE_RETURN_IF_ERROR(CheckKeysOnce(it->second, JoinPath(path, key)));
  }
  return Status::Ok();
}

Status YamlDoc::Error(const YAML::Mark& mark, const std::string& field,
                      const std::string& expected,
                      const std::string& found) const {
  return Status::InvalidArgument(fmt::format(
      "{}:{}:{}: error: {}: expected {}, found {}", path_, LineOf(mark),
      ColumnOf(mark), field.empty() ? "(top level)" : field, expected, found));
}

Status YamlDoc::ErrorAt(const YAML::Node& node, const std::string& field,
                        const std::string& expected) const {
  return Error(node.Mark(), field, expected, Describe(node));
}

std::string Describe(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsMap()) return "a map";
  if (node.IsSequence()) return "a list";
  std::string text = node.Scalar();
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return "'" + text + "'";
}

std::string JoinPath(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}

MapReader::MapReader(const YamlDoc* doc, YAML::Node node, std::string path,
                     YAML::Mark mark)
    : doc_(doc), node_(std::move(node)), path_(std::move(path)), mark_(mark) {}

MapReader::MapReader(const YamlDoc* doc)
    : doc_(doc), node_(doc->root()), path_(), mark_(doc->root().Mark()) {}

Status MapReader::CheckIsMap() const {
  if (node_.IsDefined() && node_.IsMap()) return Status::Ok();
  return doc_->Error(node_.IsDefined() ? node_.Mark() : mark_, path_, "a map",
                     Describe(node_));
}

Status MapReader::CheckKeys(const std::vector<std::string>& allowed) const {
  std::vector<YAML::Mark> marks;
  const auto entries = Entries(&marks);
  for (size_t i = 0; i < entries.size(); ++i) {
    const std::string& key = entries[i].first;
    if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) {
      continue;
    }
    std::string list;
    for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
    return doc_->Error(marks[i], PathOf(key), "one of the keys " + list,
                       "'" + key + "'" + DidYouMean(key, allowed));
  }
  return Status::Ok();
}

bool MapReader::Has(const std::string& key) const {
  if (!node_.IsMap()) return false;
  const YAML::Node& map = node_;
  return map[key].IsDefined();
}

YAML::Node MapReader::Get(const std::string& key) const {
  const YAML::Node& map = node_;
  return map[key];
}

YAML::Mark MapReader::KeyMark(const std::string& key) const {
  if (node_.IsMap()) {
    for (auto it = node_.begin(); it != node_.end(); ++it) {
      if (it->first.IsScalar() && it->first.Scalar() == key) {
        return it->first.Mark();
      }
    }
  }
  return node_.IsDefined() ? node_.Mark() : mark_;
}

Status MapReader::Missing(const std::string& key,
                          const std::string& expected) const {
  return doc_->Error(KeyMark(key), PathOf(key), expected + " (required)",
                     "nothing");
}

Result<MapReader> MapReader::Map(const std::string& key) const {
  if (!Has(key)) return Missing(key, "a map");
  MapReader inner(doc_, Get(key), PathOf(key), KeyMark(key));
  ADSE_RETURN_IF_ERROR(inner.CheckIsMap());
  return inner;
}

Result<double> MapReader::Number(const std::string& key, const Range& range,
                                 std::optional<double> fallback) const {
  if (!Has(key) || Get(key).IsNull()) {
    if (fallback.has_value()) return *fallback;
    return Missing(key, range.Describe());
  }
  const YAML::Node value = Get(key);
  double x = 0.0;
  if (!value.IsScalar() || !ParseYamlNumber(value.Scalar(), &x) ||
      !std::isfinite(x) || (range.integer && x != std::floor(x)) ||
      (range.has_lo && (range.lo_open ? !(x > range.lo) : !(x >= range.lo))) ||
      (range.has_hi && !(x <= range.hi))) {
    return doc_->ErrorAt(value, PathOf(key), range.Describe());
  }
  return x;
}

Result<int> MapReader::Integer(const std::string& key, const Range& range,
                               std::optional<int> fallback) const {
  Range r = range;
  r.integer = true;
  Result<double> x = Number(
      key, r,
      fallback.has_value() ? std::optional<double>(*fallback) : std::nullopt);
  if (!x.ok()) return x.status();
  if (std::abs(*x) > std::numeric_limits<int>::max()) {
    return doc_->ErrorAt(Get(key), PathOf(key), r.Describe());
  }
  return static_cast<int>(*x);
}

Result<bool> MapReader::Bool(const std::string& key,
                             std::optional<bool> fallback) const {
  if (!Has(key) || Get(key).IsNull()) {
    if (fallback.has_value()) return *fallback;
    return Missing(key, "true or false");
  }
  const YAML::Node value = Get(key);
  if (value.IsScalar()) {
    const std::string& s = value.Scalar();
    if (s == "true" || s == "True" || s == "TRUE") return true;
    if (s == "false" || s == "False" || s == "FALSE") return false;
  }
  return doc_->ErrorAt(value, PathOf(key), "true or false");
}

Result<std::string> MapReader::String(const std::string& key,
                                      std::optional<std::string> fallback,
                                      bool non_empty) const {
  const std::string expected = non_empty ? "a non-empty string" : "a string";
  if (!Has(key) || Get(key).IsNull()) {
    if (fallback.has_value()) return *fallback;
    return Missing(key, expected);
  }
  const YAML::Node value = Get(key);
  if (!value.IsScalar() || (non_empty && value.Scalar().empty())) {
    return doc_->ErrorAt(value, PathOf(key), expected);
  }
  return value.Scalar();
}

Result<std::vector<std::string>> MapReader::StringList(
    const std::string& key, std::vector<YAML::Mark>* marks) const {
  const std::string expected = "a non-empty list of strings";
  if (!Has(key)) return Missing(key, expected);
  const YAML::Node list = Get(key);
  if (!list.IsSequence() || list.size() == 0) {
    return doc_->ErrorAt(list, PathOf(key), expected);
  }
  std::vector<std::string> out;
  for (size_t i = 0; i < list.size(); ++i) {
    const YAML::Node item = list[i];
    const std::string path = fmt::format("{}[{}]", PathOf(key), i);
    if (!item.IsScalar() || item.Scalar().empty()) {
      return doc_->ErrorAt(item, path, "a non-empty string");
    }
    out.push_back(item.Scalar());
    if (marks != nullptr) marks->push_back(item.Mark());
  }
  return out;
}

std::vector<std::pair<std::string, YAML::Node>> MapReader::Entries(
    std::vector<YAML::Mark>* key_marks) const {
  std::vector<std::pair<std::string, YAML::Node>> out;
  if (!node_.IsMap()) return out;
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    out.emplace_back(it->first.IsScalar() ? it->first.Scalar() : "",
                     it->second);
    if (key_marks != nullptr) key_marks->push_back(it->first.Mark());
  }
  return out;
}

bool ParseYamlNumber(const std::string& text, double* value) {
  if (text == ".nan" || text == ".NaN" || text == ".NAN") {
    *value = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  for (const char* inf : {".inf", ".Inf", ".INF", "+.inf", "+.Inf", "+.INF"}) {
    if (text == inf) {
      *value = std::numeric_limits<double>::infinity();
      return true;
    }
  }
  for (const char* inf : {"-.inf", "-.Inf", "-.INF"}) {
    if (text == inf) {
      *value = -std::numeric_limits<double>::infinity();
      return true;
    }
  }
  const char* begin = text.data();
  const char* end = begin + text.size();
  if (begin != end && *begin == '+') ++begin;
  if (begin == end) return false;
  // from_chars reads "inf" and "nan" too; YAML spells them with a dot.
  if (!(std::isdigit(static_cast<unsigned char>(*begin)) || *begin == '-' ||
        *begin == '.')) {
    return false;
  }
  double x = 0.0;
  const auto [ptr, ec] = std::from_chars(begin, end, x);
  if (ec != std::errc() || ptr != end) return false;
  *value = x;
  return true;
}

std::string FormatNumber(double value) { return fmt::format("{}", value); }

std::string DidYouMean(const std::string& word,
                       const std::vector<std::string>& candidates, size_t n) {
  // Close means within a quarter of the word's length (at least 2 edits):
  // a typo, a wrong index, a missing path component.
  const int limit = std::max<int>(2, static_cast<int>(word.size()) / 4);
  std::vector<std::pair<int, std::string>> close;
  for (const std::string& c : candidates) {
    if (c == word) continue;
    const int d = EditDistance(word, c);
    if (d <= limit) close.emplace_back(d, c);
  }
  if (close.empty()) return "";
  std::sort(close.begin(), close.end());
  if (close.size() > n) close.resize(n);
  std::string out = " (did you mean ";
  for (size_t i = 0; i < close.size(); ++i) {
    if (i > 0) out += i + 1 == close.size() ? " or " : ", ";
    out += "'" + close[i].second + "'";
  }
  return out + "?)";
}

Result<ProfileSource> ReadSource(const MapReader& parent) {
  Result<MapReader> source = parent.Map("source");
  if (!source.ok()) return source.status();
  ADSE_RETURN_IF_ERROR(
      source->CheckKeys({"description", "license", "cpu", "note"}));
  Result<std::string> description =
      source->String("description", std::nullopt, true);
  Result<std::string> license = source->String("license", "");
  Result<std::string> cpu = source->String("cpu", "");
  Result<std::string> note = source->String("note", "");
  for (const auto* r : {&description, &license, &cpu, &note}) {
    if (!r->ok()) return r->status();
  }
  ProfileSource out;
  out.description = *description;
  out.license = *license;
  out.cpu = *cpu;
  out.note = *note;
  return out;
}

}  // namespace adse::profile::internal
