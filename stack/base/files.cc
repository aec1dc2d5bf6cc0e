#include "stack/base/files.h"

#include <fcntl.h>
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

// Writes all of `data` to `fd`, flushes it to disk and closes it (also on
// failure); errors name `path`.
Status WriteAllAndClose(int fd, const std::string& data,
                        const std::string& path) {
  size_t written = 0;
  while (written < data.size()) {
    const ssize_t n = ::write(fd, data.data() + written, data.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string err = std::strerror(errno);
      ::close(fd);
      return Status::IoError(path + ": " + err);
    }
    written += static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const std::string err = std::strerror(errno);
    ::close(fd);
    return Status::IoError(path + ": " + err);
  }
  if (::close(fd) != 0)
    return Status::IoError(path + ": " + std::strerror(errno));
  return Status::Ok();
}

}  // namespace

Status WriteFileAtomic(const std::string& path, const std::string& data) {
  const fs::path target(path);
  if (target.has_parent_path()) {
    ADSE_RETURN_IF_ERROR(MakeDirs(target.parent_path().string()));
  }
  const std::string tmp = TemporaryPathFor(path);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) return Status::IoError(tmp + ": " + std::strerror(errno));
  if (Status s = WriteAllAndClose(fd, data, tmp); !s.ok()) {
    ::unlink(tmp.c_str());
    return s;
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string err = std::strerror(errno);
    ::unlink(tmp.c_str());
    return Status::IoError(path + ": rename failed: " + err);
  }
  return Status::Ok();
}

Status AppendLineDurable(const std::string& path, const std::string& line) {
  const std::string data = line + "\n";
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  if (fd < 0) return Status::IoError(path + ": " + std::strerror(errno));
  return WriteAllAndClose(fd, data, path);
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

Status MakeDirs(const std::string& path) {
  std::error_code ec;
  fs::create_directories(path, ec);
  if (ec)
    return Status::IoError(path + ": cannot create folder: " + ec.message());
  return Status::Ok();
}

std::string TemporaryPathFor(const std::string& path) {
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
  return path + ".tmp." + name + "." +
         std::to_string(static_cast<long>(::getpid()));
}

}  // namespace adse
