#include "harness/campaign/run_store.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "stack/base/files.h"

namespace adse::campaign {
namespace fs = std::filesystem;

Status CampaignFolder::Create() const {
  for (const char* sub : {"", "/runs", "/logs", "/images"}) {
    ADSE_RETURN_IF_ERROR(MakeDirs(root_ + sub, env_));
  }
  return Status::Ok();
}

std::string CampaignFolder::RunPath(const std::string& key) const {
  return root_ + "/runs/" + key + ".h5";
}
std::string CampaignFolder::ReportPath(const std::string& key) const {
  return root_ + "/runs/" + key + ".report.json";
}
std::string CampaignFolder::FailurePath(const std::string& key) const {
  return root_ + "/runs/" + key + ".failed.json";
}
std::string CampaignFolder::CostPath(const std::string& key) const {
  return root_ + "/runs/" + key + ".cost.json";
}
std::string CampaignFolder::LogPath(const std::string& key, int attempt) const {
  return fmt::format("{}/logs/{}.{}.log", root_, key, attempt);
}
std::string CampaignFolder::ImageDir(const std::string& key) const {
  return root_ + "/images/" + key;
}

std::string CampaignFolder::TrajectoryImagePath(const std::string& key) const {
  return ImageDir(key) + "/trajectory.png";
}

Result<CampaignLock> CampaignLock::Acquire(const std::string& folder) {
  const std::string path = folder + "/.lock";
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) {
    return Status::IoError(fmt::format("cannot create the campaign lock {}: {}",
                                       path, std::strerror(errno)));
  }
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    std::string holder;
    char buffer[256] = {};
    const ssize_t n = ::pread(fd, buffer, sizeof(buffer) - 1, 0);
    if (n > 0) holder = std::string(buffer, static_cast<size_t>(n));
    while (!holder.empty() && (holder.back() == '\n')) holder.pop_back();
    ::close(fd);
    if (error == EWOULDBLOCK) {
      return Status::Unavailable(fmt::format(
          "another adse run ({}) is using {}; wait for it to finish or stop "
          "it (Ctrl-C), then run again to resume",
          holder.empty() ? "unknown process" : holder, folder));
    }
    return Status::IoError(
        fmt::format("cannot lock {}: {}", path, std::strerror(error)));
  }
  char host[256] = {};
  ::gethostname(host, sizeof(host) - 1);
  const char* job = std::getenv("SLURM_JOB_ID");
  const std::string who = fmt::format("pid {} on {}{}\n", ::getpid(), host,
                                      job != nullptr && *job != '\0'
                                          ? fmt::format(" (Slurm job {})", job)
                                          : std::string());
  if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, who.data(), who.size(), 0) !=
                                     static_cast<ssize_t>(who.size())) {
    // The holder text is informational; the lock itself is what counts.
  }
  return CampaignLock(fd);
}

CampaignLock::CampaignLock(CampaignLock&& other) noexcept : fd_(other.fd_) {
  other.fd_ = -1;
}

CampaignLock::~CampaignLock() {
  if (fd_ >= 0) {
    ::ftruncate(fd_, 0);
    ::close(fd_);  // releases the flock
  }
}

Status WriteFailureRecord(const std::string& path, const FailureRecord& r,
                          Env* env) {
  const nlohmann::json j = {{"content_key", r.content_key},
                            {"point", r.point},
                            {"seed", r.seed},
                            {"outcome", r.outcome},
                            {"exit_code", r.exit_code},
                            {"signal", r.signal},
                            {"attempts", r.attempts},
                            {"wall_s", r.wall_s},
                            {"detail", r.detail},
                            {"stderr_tail", r.stderr_tail}};
  // Worker output may hold invalid UTF-8; replace rather than fail.
  return WriteFileAtomic(
      path,
      j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n",
      env);
}

Result<FailureRecord> ReadFailureRecord(const std::string& path) {
  Result<std::string> text = ReadFile(path, 1 << 20);
  if (!text.ok()) return text.status();
  const nlohmann::json j = nlohmann::json::parse(*text, nullptr, false);
  if (!j.is_object() || !j.contains("outcome") || !j["outcome"].is_string()) {
    return Status::Corruption(
        path + ": expected a failure record (JSON object with \"outcome\")");
  }
  FailureRecord r;
  try {
    r.content_key = j.value("content_key", "");
    r.point = j.value("point", "");
    r.seed = j.value("seed", uint64_t{0});
    r.outcome = j.value("outcome", "");
    r.exit_code = j.value("exit_code", -1);
    r.signal = j.value("signal", 0);
    r.attempts = j.value("attempts", 0);
    r.wall_s = j.value("wall_s", 0.0);
    r.detail = j.value("detail", "");
    r.stderr_tail = j.value("stderr_tail", "");
  } catch (const nlohmann::json::exception& e) {
    return Status::Corruption(path + ": " + e.what());
  }
  return r;
}

Status WriteRunCost(const std::string& path, const RunCost& cost, Env* env) {
  const nlohmann::json j = {{"content_key", cost.content_key},
                            {"attempts", cost.attempts},
                            {"wall_s", cost.wall_s}};
  return WriteFileAtomic(path, j.dump(2) + "\n", env);
}

Result<RunCost> ReadRunCost(const std::string& path) {
  Result<std::string> text = ReadFile(path, 1 << 16);
  if (!text.ok()) return text.status();
  const nlohmann::json j = nlohmann::json::parse(*text, nullptr, false);
  if (!j.is_object() || !j.contains("content_key") ||
      !j["content_key"].is_string() || !j.contains("attempts") ||
      !j["attempts"].is_number_integer() || !j.contains("wall_s") ||
      !j["wall_s"].is_number()) {
    return Status::Corruption(
        path +
        ": expected a run's cost (JSON object with \"content_key\", "
        "\"attempts\" and \"wall_s\")");
  }
  RunCost cost;
  cost.content_key = j["content_key"].get<std::string>();
  cost.attempts = j["attempts"].get<int>();
  cost.wall_s = j["wall_s"].get<double>();
  return cost;
}

Status CopyFileAtomic(const std::string& from, const std::string& to,
                      Env* env) {
  ADSE_RETURN_IF_ERROR(MakeDirs(fs::path(to).parent_path().string(), env));
  const std::string temp = TemporaryPathFor(to);
  (void)env->RemoveFile(temp);  // left by a crashed copy of this process id
  if (Status copied = env->CopyFile(from, temp); !copied.ok()) {
    (void)env->RemoveFile(temp);
    return copied;
  }
  return CommitTemporary(temp, to, env);
}

std::optional<std::string> RunCache::Find(const std::string& key) const {
  const std::string path = dir_ + "/" + key + ".h5";
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) return path;
  return std::nullopt;
}

Status RunCache::Insert(const std::string& key,
                        const std::string& run_file) const {
  return CopyFileAtomic(run_file, dir_ + "/" + key + ".h5", env_);
}

Status RunCache::CopyOut(const std::string& key,
                         const std::string& destination) const {
  return CopyFileAtomic(dir_ + "/" + key + ".h5", destination, env_);
}

}  // namespace adse::campaign
