#include "harness/pool/child_log.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>

namespace adse::pool {

std::string ReadLogTail(const std::string& path, size_t max_bytes) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return "";
  std::string tail;
  struct stat st;
  if (::fstat(fd, &st) == 0) {
    const off_t start =
        std::max<off_t>(0, st.st_size - static_cast<off_t>(max_bytes));
    tail.resize(static_cast<size_t>(st.st_size - start));
    size_t got = 0;
    while (got < tail.size()) {
      const ssize_t n = ::pread(fd, &tail[got], tail.size() - got,
                                start + static_cast<off_t>(got));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      got += static_cast<size_t>(n);
    }
    tail.resize(got);
    if (start > 0) {
      const size_t newline = tail.find('\n');
      if (newline != std::string::npos && newline + 1 < tail.size()) {
        tail.erase(0, newline + 1);
      }
    }
  }
  ::close(fd);
  return tail;
}

}  // namespace adse::pool
