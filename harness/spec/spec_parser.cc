#include "harness/spec/spec_parser.h"
#include "harness/spec/yaml_limits.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <exception>
#include <filesystem>
#include <sstream>

#include "harness/spec/internal/spec_reader.h"
#include "stack/base/files.h"

namespace adse::spec {

namespace fs = std::filesystem;

using internal::Diagnostic;
using internal::SpecReader;

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
      return Status::InvalidArgument(fmt::format(
          "{}:1:1: error: (file): expected one YAML document, found several "
          "('---' separators)",
          file_name));
    }
  } catch (const YamlLimitExceeded& e) {
    reader.FileError(e.mark, "(file)", e.expected, e.found);
  } catch (const YAML::Exception& e) {
    const YAML::Mark mark = e.mark;
    return Status::InvalidArgument(fmt::format(
        "{}:{}:{}: error: (file): expected valid YAML, found a syntax error: "
        "{}",
        file_name, mark.is_null() ? 1 : mark.line + 1,
        mark.is_null() ? 1 : mark.column + 1, e.msg));
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
