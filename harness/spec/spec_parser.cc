#include "harness/spec/spec_parser.h"
#include "harness/spec/yaml_limits.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <exception>
#include <filesystem>
#include <sstream>
#include <string_view>

#include "harness/spec/internal/spec_reader.h"
#include "stack/base/files.h"

namespace adse::spec {

namespace fs = std::filesystem;

using internal::Diagnostic;
using internal::SpecReader;

namespace {

// What a text that is not UTF-8 starts with (a UTF-16 or UTF-32 byte-order
// mark, a NUL byte of a wide or binary file), or "" for UTF-8.
std::string ForeignEncoding(std::string_view text) {
  auto starts = [&](std::string_view prefix) {
    return text.substr(0, prefix.size()) == prefix;
  };
  if (starts(std::string_view("\xFF\xFE\0\0", 4)) ||
      starts(std::string_view("\0\0\xFE\xFF", 4))) {
    return "a UTF-32 byte-order mark";
  }
  if (starts("\xFF\xFE") || starts("\xFE\xFF")) {
    return "a UTF-16 byte-order mark";
  }
  if (text.find('\0') != std::string_view::npos) {
    return "a NUL byte (UTF-16 text or a binary file)";
  }
  return "";
}

// " (a tab in the indentation of line N: YAML indents with spaces)" when
// the line of a syntax error, or the one before it, indents with a tab.
std::string TabNear(const std::string& text, const YAML::Mark& mark) {
  if (mark.is_null()) return "";
  std::istringstream in(text);
  std::string line;
  for (int n = 0; std::getline(in, line) && n <= mark.line; ++n) {
    if (n + 1 < mark.line) continue;
    const size_t indent = line.find_first_not_of(" \t");
    if (line.substr(0, indent).find('\t') != std::string::npos) {
      return fmt::format(
          " (a tab in the indentation of line {}: YAML indents with spaces)",
          n + 1);
    }
  }
  return "";
}

}  // namespace

Result<Spec> ParseSpec(std::string_view text, const std::string& file_name,
                       const std::string& base_dir,
                       const ParseOptions& options) {
  Spec spec;
  spec.source_path = file_name;
  std::error_code ec;
  spec.base_dir =
      fs::absolute(base_dir.empty() ? fs::path(".") : fs::path(base_dir), ec)
          .lexically_normal()
          .string();
  if (spec.base_dir.size() > 1 && spec.base_dir.back() == '/') {
    spec.base_dir.pop_back();
  }
  if (text.size() > kMaxSpecBytes) {
    return Status::InvalidArgument(
        fmt::format("{}:1:1: error: (file): expected at most {} bytes, found "
                    "{} bytes",
                    file_name, kMaxSpecBytes, text.size()));
  }
  if (std::string encoding = ForeignEncoding(text); !encoding.empty()) {
    return Status::InvalidArgument(fmt::format(
        "{}:1:1: error: (file): expected UTF-8 text, found {}; save the file "
        "as UTF-8",
        file_name, encoding));
  }
  spec.source_text = std::string(text);
  spec.name = internal::NameFromFile(file_name);
  SpecReader reader(&spec, options.check_files);

  // Scan events first: limits are enforced before any node exists.
  try {
    std::istringstream in(spec.source_text);
    YAML::Parser parser(in);
    YamlLimitScanner scanner(
        YamlLimits{kMaxYamlDepth, kMaxYamlAliases, kMaxYamlNodes});
    parser.HandleNextDocument(scanner);
    if (parser.HandleNextDocument(scanner) && scanner.documents() > 1) {
      const YAML::Mark& second = scanner.second_document();
      const int line = second.is_null() ? 1 : second.line + 1;
      return Status::InvalidArgument(fmt::format(
          "{}:{}:1: error: (file): expected one YAML document, found a second "
          "from line {} (a line '---' starts a document, '...' ends one)",
          file_name, line, line));
    }
  } catch (const YamlLimitExceeded& e) {
    reader.FileError(e.mark, "(file)", e.expected, e.found);
  } catch (const YAML::Exception& e) {
    const YAML::Mark mark = e.mark;
    return Status::InvalidArgument(fmt::format(
        "{}:{}:{}: error: (file): expected valid YAML, found a syntax error: "
        "{}{}",
        file_name, mark.is_null() ? 1 : mark.line + 1,
        mark.is_null() ? 1 : mark.column + 1, e.msg,
        TabNear(spec.source_text, mark)));
  } catch (const std::exception& e) {
    return Status::InvalidArgument(
        fmt::format("{}:1:1: error: (file): expected valid YAML, found {}",
                    file_name, e.what()));
  }

  if (!reader.has_errors()) {
    try {
      const YAML::Node root = YAML::Load(spec.source_text);
      reader.Read(root);
    } catch (const YAML::Exception& e) {
      const YAML::Mark mark = e.mark;
      reader.FileError(mark, "(file)", "valid YAML",
                       std::string("a syntax error: ") + e.msg);
    } catch (const std::exception& e) {
      reader.FileError(YAML::Mark(), "(file)", "a readable scenario", e.what());
    }
  }

  std::vector<Diagnostic> errors = reader.TakeErrors();
  if (errors.empty()) return spec;
  std::string message;
  for (const Diagnostic& d : errors) {
    if (!message.empty()) message += '\n';
    message += d.text;
  }
  if (errors.size() >= static_cast<size_t>(kMaxSpecErrors)) {
    message += fmt::format("\n{}: note: stopped after {} errors", file_name,
                           kMaxSpecErrors);
  }
  return Status::InvalidArgument(message);
}

Result<Spec> LoadSpec(const std::string& path) {
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) {
    const auto size = fs::file_size(path, ec);
    if (!ec && size > kMaxSpecBytes) {
      return Status::InvalidArgument(fmt::format(
          "{}:1:1: error: (file): expected a scenario of at most {} bytes, "
          "found {} bytes",
          path, kMaxSpecBytes, size));
    }
  }
  Result<std::string> text = ReadFile(path, kMaxSpecBytes);
  if (!text.ok()) return text.status();
  const fs::path dir = fs::absolute(path, ec).parent_path();
  return ParseSpec(*text, path, dir.string());
}
}  // namespace adse::spec
