#include "stack/base/files.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace adse {
namespace fs = std::filesystem;

Result<std::string> ReadFile(const std::string& path, size_t max_bytes) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return Status::NotFound(path + ": no such file");
  if (fs::is_directory(path, ec)) {
    return Status::InvalidArgument(path + ": is a directory, expected a file");
  }
  const auto size = fs::file_size(path, ec);
  if (ec) return Status::IoError(path + ": " + ec.message());
  if (size > max_bytes) {
    return Status::InvalidArgument(path + ": file is " + std::to_string(size) +
                                   " bytes, larger than the limit of " +
                                   std::to_string(max_bytes));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::IoError(path + ": " + std::strerror(errno));
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

namespace {

std::string FolderOf(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? "." : parent.string();
}

}  // namespace

Status WriteFileAtomic(const std::string& path, const std::string& data,
                       Env* env) {
  ADSE_RETURN_IF_ERROR(env->CreateDir(FolderOf(path)));
  const std::string tmp = TemporaryPathFor(path);
  if (Status s = env->WriteFile(tmp, data); !s.ok()) {
    (void)env->RemoveFile(tmp);
    return s;
  }
  return CommitTemporary(tmp, path, env);
}

Status CommitTemporary(const std::string& temporary, const std::string& path,
                       Env* env) {
  Status s = env->SyncFile(temporary);
  if (s.ok()) s = env->RenameFile(temporary, path);
  if (!s.ok()) {
    (void)env->RemoveFile(temporary);
    return s;
  }
  return env->SyncDir(FolderOf(path));
}

Status AppendLineDurable(const std::string& path, const std::string& line,
                         Env* env) {
  return env->AppendFile(path, line + "\n");
}

std::string DefaultCacheDir() {
  if (const char* dir = std::getenv("ADSE_CACHE_DIR"); dir && *dir) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) {
    return std::string(xdg) + "/adse";
  }
  if (const char* home = std::getenv("HOME"); home && *home) {
    return std::string(home) + "/.cache/adse";
  }
  return (fs::temp_directory_path() / "adse-cache").string();
}

Status MakeDirs(const std::string& path, Env* env) {
  return env->CreateDir(path);
}

namespace {

// This host's name as temporary paths carry it.
std::string HostLabel() {
  char host[256] = {};
  if (::gethostname(host, sizeof(host) - 1) != 0 || host[0] == '\0') {
    std::snprintf(host, sizeof(host), "host");
  }
  // A hostname is a file-name-safe label; keep only its first part.
  std::string name(host);
  name = name.substr(0, name.find('.'));
  for (char& c : name) {
    if (c == '/') c = '_';
  }
  return name;
}

}  // namespace

std::string TemporaryPathFor(const std::string& path) {
  return path + ".tmp." + HostLabel() + "." +
         std::to_string(static_cast<long>(::getpid()));
}

int RemoveAbandonedTemporaries(const std::string& folder) {
  const std::string marker = ".tmp." + HostLabel() + ".";
  int removed = 0;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    const size_t at = name.rfind(marker);
    if (at == std::string::npos || at == 0) continue;
    const std::string digits = name.substr(at + marker.size());
    if (digits.empty() || digits.size() > 9 ||
        digits.find_first_not_of("0123456789") != std::string::npos) {
      continue;
    }
    const long pid = std::stol(digits);
    // Alive, or someone else's to signal: not ours to remove.
    if (pid <= 0 || ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) {
      continue;
    }
    std::error_code remove_ec;
    if (fs::remove_all(entry.path(), remove_ec) > 0 && !remove_ec) ++removed;
  }
  return removed;
}

}  // namespace adse
