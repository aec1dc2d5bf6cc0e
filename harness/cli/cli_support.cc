#include "harness/cli/cli_support.h"

#include <fmt/core.h>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "analysis/runfile/run_file.h"
#include "harness/sim/run_key.h"
#include "harness/sim/simulator.h"
#include "harness/spec/spec_parser.h"
#include "stack/base/env.h"
#include "stack/base/files.h"

namespace adse::cli {

namespace {

// Whether `path` is the current folder or one above it.
bool CurrentOrAbove(const std::filesystem::path& path) {
  std::error_code ec;
  const std::filesystem::path relative =
      std::filesystem::current_path(ec).lexically_relative(
          std::filesystem::weakly_canonical(path, ec));
  return relative.native().rfind("..", 0) != 0;
}

std::optional<spec::Spec> ParseScenarioOrReport(const std::string& path) {
  Result<spec::Spec> loaded = spec::LoadSpec(path);
  if (!loaded.ok()) {
    // Parser messages carry their own locations, one error per line.
    std::fprintf(stderr, "%s\n", loaded.status().message().c_str());
    return std::nullopt;
  }
  return std::move(loaded).value();
}

std::optional<spec::Spec> CaseOrReport(std::optional<spec::Spec> loaded,
                                       const std::string& name) {
  if (!loaded) return std::nullopt;
  const spec::Spec& spec = *loaded;
  if (spec.cases.empty()) {
    if (name.empty()) return loaded;
    std::fprintf(stderr, "error: --case: %s has no task.cases\n",
                 spec.source_path.c_str());
    return std::nullopt;
  }
  if (name.empty()) {
    std::fprintf(stderr,
                 "error: --case: %s has %zu task.cases (%s); name the one "
                 "to run\n",
                 spec.source_path.c_str(), spec.cases.size(),
                 spec::CaseNames(spec).c_str());
    return std::nullopt;
  }
  const int index = spec::FindCase(spec, name);
  if (index < 0) {
    std::fprintf(stderr, "error: --case: %s has no case '%s' (its cases: %s)\n",
                 spec.source_path.c_str(), name.c_str(),
                 spec::CaseNames(spec).c_str());
    return std::nullopt;
  }
  return spec::ForCase(spec, index);
}

}  // namespace

std::optional<spec::Spec> LoadScenarioOrReport(const std::string& path) {
  std::optional<spec::Spec> loaded = ParseScenarioOrReport(path);
  if (!loaded) return std::nullopt;
  for (const Status& checked :
       {spec::CheckCostOverSpace(*loaded), sim::CheckKnobsAct(*loaded),
        sim::CheckCostModelFile(*loaded)}) {
    if (!checked.ok()) {
      ReportError(*loaded, checked);
      return std::nullopt;
    }
  }
  return loaded;
}

std::optional<spec::Spec> LoadCaseOrReport(const std::string& path,
                                           const std::string& name) {
  return CaseOrReport(LoadScenarioOrReport(path), name);
}

std::optional<spec::Spec> LoadWorkerCaseOrReport(const std::string& path,
                                                 const std::string& name) {
  return CaseOrReport(ParseScenarioOrReport(path), name);
}

void ReportError(const spec::Spec& spec, const Status& status) {
  const std::string& message = status.message();
  const size_t colon = message.find(": ");
  std::string field;
  if (colon != std::string::npos) {
    field = message.substr(0, colon);
    for (char c : field) {
      if (!(std::islower(static_cast<unsigned char>(c)) ||
            std::isdigit(static_cast<unsigned char>(c)) || c == '_' ||
            c == '.' || c == '[' || c == ']')) {
        field.clear();
        break;
      }
    }
  }
  const std::string where =
      field.empty() ? spec.source_path + ": " : spec.Where(field);
  std::fprintf(stderr, "%serror: %s\n", where.c_str(), message.c_str());
}

Status CheckOutputFolder(const std::string& out,
                         const OutputFolderLayout& layout) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path path(out);
  // Written beside itself first, then renamed into place.
  ADSE_RETURN_IF_ERROR(CheckFolderPath(
      path.lexically_normal().parent_path().string(), "-o " + out));
  if (!fs::exists(path, ec)) return Status::Ok();
  const std::string hint =
      "; give a new folder (or an earlier output's, which is replaced)";
  if (!fs::is_directory(path, ec)) {
    return Status::InvalidArgument("-o " + out + ": a file is there" + hint);
  }
  if (CurrentOrAbove(path)) {
    return Status::InvalidArgument(
        "-o " + out + ": the current folder or one above it" + hint);
  }
  for (const auto& entry : fs::directory_iterator(path, ec)) {
    const std::string name = entry.path().filename().string();
    bool ours = std::find(layout.files.begin(), layout.files.end(), name) !=
                layout.files.end();
    if (!layout.subfolder.empty() && name == layout.subfolder &&
        entry.is_directory(ec)) {
      ours = true;
      for (const auto& file : fs::directory_iterator(entry.path(), ec)) {
        ours = ours && file.path().extension() == layout.subfolder_extension;
      }
    }
    if (!ours) {
      return Status::InvalidArgument(
          "-o " + out + ": the folder holds " + (path / name).string() +
          ", which this command does not write" + hint);
    }
  }
  return Status::Ok();
}

Status CheckFolderPath(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  for (fs::path up = path.empty() ? "." : path; !up.empty();
       up = up.parent_path()) {
    if (fs::exists(up, ec)) {
      if (!fs::is_directory(up, ec)) {
        return Status::InvalidArgument(what + ": " + up.string() +
                                       " is a file, not a folder");
      }
      // Found now rather than when the work is done and its result is
      // written (a read-only folder or file system).
      if (access(up.c_str(), W_OK | X_OK) != 0) {
        return Status::InvalidArgument(
            fmt::format("{}: cannot write in {} ({})", what, up.string(),
                        std::strerror(errno)));
      }
      return Status::Ok();
    }
    if (up == up.parent_path()) break;
  }
  return Status::Ok();
}

std::string CampaignOfRunsFolder(const std::string& target) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path path = fs::absolute(target, ec).lexically_normal();
  if (ec) return target;
  if (path.filename().empty()) path = path.parent_path();
  const fs::path campaign = path.parent_path();
  if (path.filename() != "runs" || !fs::exists(campaign / "campaign.h5", ec)) {
    return target;
  }
  return campaign.string();
}

Status CheckCampaignFolder(const std::string& folder, const std::string& what) {
  namespace fs = std::filesystem;
  ADSE_RETURN_IF_ERROR(CheckFolderPath(folder, what));
  std::error_code ec;
  const fs::path path(folder);
  if (!fs::exists(path, ec)) return Status::Ok();
  const std::string hint = "; give a new folder, or a campaign's to resume it";
  if (fs::exists(path / "campaign.h5", ec)) return Status::Ok();
  if (CurrentOrAbove(path)) {
    return Status::InvalidArgument(
        what + ": " + folder + " is the current folder or one above it" + hint);
  }
  // No campaign's yet: nothing there that a campaign writes, which it
  // would replace (the user's own report.md, say). Other files (a log the
  // shell opened for this run) stay beside it untouched.
  for (const char* name : {"report.md", "summary.json", "pareto.png"}) {
    if (fs::exists(path / name, ec)) {
      return Status::InvalidArgument(
          what + ": " + folder + " is no campaign's folder (no campaign.h5) " +
          "and holds " + (path / name).string() +
          ", which a campaign would write over" + hint);
    }
  }
  for (const char* name : {"runs", "images", "logs"}) {
    if (fs::exists(path / name, ec) && !fs::is_directory(path / name, ec)) {
      return Status::InvalidArgument(what + ": " + folder + " holds a file " +
                                     (path / name).string() +
                                     " where a campaign keeps a folder" + hint);
    }
  }
  return Status::Ok();
}

Status CheckCampaignFolderOf(const spec::Spec& spec, const std::string& out) {
  return CheckCampaignFolder(
      out.empty() ? spec.ResolvedOutput() : out,
      out.empty() ? spec.Where("output") + "output" : "-o " + out);
}

Status CheckCampaignFolders(const spec::Spec& spec, const std::string& out,
                            bool use_cache, const std::string& cache_dir) {
  ADSE_RETURN_IF_ERROR(CheckCampaignFolderOf(spec, out));
  if (!use_cache) return Status::Ok();
  if (!cache_dir.empty()) {
    return CheckFolderPath(cache_dir, "--cache-dir " + cache_dir);
  }
  if (spec.harness.cache_dir.empty()) return Status::Ok();
  return CheckFolderPath(spec.harness.cache_dir,
                         spec.Where("harness.cache_dir") + "harness.cache_dir");
}

namespace {

// Whether `out` lies in a campaign's runs/ folder, whose files are the
// campaign's runs under their content keys.
bool InCampaignRuns(const std::filesystem::path& out) {
  const std::filesystem::path runs =
      std::filesystem::absolute(out).lexically_normal().parent_path();
  std::error_code ec;
  return runs.filename() == "runs" &&
         std::filesystem::exists(runs.parent_path() / "campaign.h5", ec);
}

// Whether an existing file is an earlier output of `kind`.
bool IsOutputOf(const std::string& out, OutputFileKind kind) {
  if (kind == kRunFile) return runfile::ReadRunFile(out).ok();
  Result<std::string> text = ReadFile(out, 16u << 20);
  if (!text.ok()) return false;
  switch (kind) {
    case kCalibrationFile: {
      const nlohmann::json doc = nlohmann::json::parse(*text, nullptr, false);
      return doc.is_object() && doc.contains("adse_calibration");
    }
    case kProfileFile:
      return text->find("\nadse_profile:") != std::string::npos ||
             text->rfind("adse_profile:", 0) == 0;
    case kInterpretedScenario:
      return text->rfind(kInterpretHeader, 0) == 0;
    case kRunFile:
      break;
  }
  return false;
}

}  // namespace

Status CheckOutputFile(const std::string& out, OutputFileKind kind) {
  namespace fs = std::filesystem;
  std::error_code ec;
  ADSE_RETURN_IF_ERROR(
      CheckFolderPath(fs::path(out).parent_path().string(), "-o " + out));
  if (kind == kRunFile && InCampaignRuns(out)) {
    return Status::InvalidArgument(
        "-o " + out +
        ": a campaign's runs/ folder holds its runs under their keys; give "
        "a path outside it");
  }
  if (!fs::exists(out, ec)) return Status::Ok();
  const char* what = "";
  switch (kind) {
    case kRunFile:
      what = "a run file";
      break;
    case kCalibrationFile:
      what = "a calibration (adse calibrate's JSON)";
      break;
    case kProfileFile:
      what = "a profile (adse profile import's YAML)";
      break;
    case kInterpretedScenario:
      what = "a scenario adse interpret wrote";
      break;
  }
  if (fs::is_directory(out, ec)) {
    return Status::InvalidArgument("-o " + out + ": a folder is there; give " +
                                   what + "'s path");
  }
  if (!IsOutputOf(out, kind)) {
    return Status::InvalidArgument("-o " + out + ": a file that is not " +
                                   what + " is there; give another path");
  }
  return Status::Ok();
}

namespace {

std::string FolderAbove(const std::string& out) {
  const std::filesystem::path parent = std::filesystem::path(out).parent_path();
  return parent.empty() ? std::string(".") : parent.string();
}

}  // namespace

std::string StartOutputFolder(const std::string& out) {
  RemoveAbandonedTemporaries(FolderAbove(out));
  const std::string tmp = TemporaryPathFor(out);
  std::error_code ec;
  std::filesystem::remove_all(tmp, ec);
  return tmp;
}

Status PutFolderInPlace(const std::string& tmp, const std::string& out) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const std::string parent = FolderAbove(out);
  ADSE_RETURN_IF_ERROR(MakeDirs(parent));
  const std::string earlier = TemporaryPathFor(out + ".earlier");
  const bool replacing = fs::exists(out, ec);
  Status status;
  if (replacing) status = Env::Default()->RenameFile(out, earlier);
  if (status.ok()) status = Env::Default()->RenameFile(tmp, out);
  if (status.ok()) status = Env::Default()->SyncDir(parent);
  if (replacing) {
    if (status.ok()) {
      fs::remove_all(earlier, ec);
    } else if (!fs::exists(out, ec)) {
      fs::rename(earlier, out, ec);
    }
  }
  return status;
}

}  // namespace adse::cli
