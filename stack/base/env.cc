#include "stack/base/env.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace adse {
namespace {

namespace fs = std::filesystem;

Status Errno(const std::string& path, const char* what, int error) {
  return Status::IoError(path + ": " + what + ": " + std::strerror(error));
}

// Owns a file descriptor; closed on every path.
class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  int get() const { return fd_; }
  int Close() {
    const int rc = ::close(fd_);
    fd_ = -1;
    return rc;
  }

 private:
  int fd_;
};

Status WriteAll(int fd, std::string_view data, const std::string& path) {
  size_t written = 0;
  while (written < data.size()) {
    const ssize_t n = ::write(fd, data.data() + written, data.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      return Errno(path, "write", errno);
    }
    written += static_cast<size_t>(n);
  }
  return Status::Ok();
}

Status OpenWriteClose(const std::string& path, int flags, std::string_view data,
                      bool sync) {
  Fd fd(::open(path.c_str(), flags | O_WRONLY | O_CREAT | O_CLOEXEC, 0644));
  if (fd.get() < 0) return Errno(path, "open", errno);
  ADSE_RETURN_IF_ERROR(WriteAll(fd.get(), data, path));
  if (sync && ::fsync(fd.get()) != 0) return Errno(path, "fsync", errno);
  if (fd.Close() != 0) return Errno(path, "close", errno);
  return Status::Ok();
}

Status SyncPath(const std::string& path, bool directory) {
  Fd fd(::open(path.c_str(),
               O_RDONLY | O_CLOEXEC | (directory ? O_DIRECTORY : 0)));
  if (fd.get() < 0) return Errno(path, "open", errno);
  if (::fsync(fd.get()) != 0) {
    const int error = errno;
    // Some filesystems refuse fsync on a folder; its renames still hold.
    if (directory && (error == EINVAL || error == EBADF)) return Status::Ok();
    return Errno(path, "fsync", error);
  }
  return Status::Ok();
}

class PosixEnv : public Env {
 public:
  Status CreateDir(const std::string& path) override {
    std::error_code ec;
    fs::create_directories(path, ec);
    if (ec) {
      return Status::IoError(path + ": cannot create folder: " + ec.message());
    }
    return Status::Ok();
  }
  Status WriteFile(const std::string& path, std::string_view data) override {
    return OpenWriteClose(path, O_TRUNC, data, /*sync=*/false);
  }
  Status AppendFile(const std::string& path, std::string_view data) override {
    return OpenWriteClose(path, O_APPEND, data, /*sync=*/true);
  }
  Status SyncFile(const std::string& path) override {
    return SyncPath(path, /*directory=*/false);
  }
  Status SyncDir(const std::string& path) override {
    return SyncPath(path, /*directory=*/true);
  }
  Status RenameFile(const std::string& from, const std::string& to) override {
    if (::rename(from.c_str(), to.c_str()) != 0) {
      return Status::IoError(to + ": rename from " + from +
                             " failed: " + std::strerror(errno));
    }
    return Status::Ok();
  }
  Status CopyFile(const std::string& from, const std::string& to) override {
    if (::link(from.c_str(), to.c_str()) == 0) return Status::Ok();
    std::error_code ec;
    fs::copy_file(from, to, ec);
    if (ec) {
      return Status::IoError(to + ": cannot copy " + from + ": " +
                             ec.message());
    }
    return SyncPath(to, /*directory=*/false);
  }
  Status RemoveFile(const std::string& path) override {
    if (::unlink(path.c_str()) != 0 && errno != ENOENT) {
      return Errno(path, "remove", errno);
    }
    return Status::Ok();
  }
};

}  // namespace

Env* Env::Default() {
  static PosixEnv* const env = new PosixEnv;
  return env;
}

}  // namespace adse
