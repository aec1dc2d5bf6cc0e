#include "harness/pool/cgroup.h"

#include <fcntl.h>
#include <linux/magic.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/statfs.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>

#include <fmt/format.h>

namespace adse::pool::internal {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr const char* kDelegateHint =
    "run adse in a cgroup delegated to it, e.g. `systemd-run --user --scope "
    "-p Delegate=yes adse run ...` (as root: without --user)";
constexpr const char* kV1Hint =
    "cgroup v1 cannot be delegated to a user safely: run adse as root";
// How long removal waits for killed tasks to leave a group.
constexpr auto kDrainTime = std::chrono::seconds(1);

}  // namespace

std::string Trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\n");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t\n");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> Split(const std::string& s, char sep) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= s.size()) {
    size_t end = s.find(sep, start);
    if (end == std::string::npos) end = s.size();
    if (end > start) out.push_back(s.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

bool Contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

bool Exists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

// Read with read(2) to EOF: cgroupfs reports sizes of 0 or 4096.
Result<std::string> ReadControl(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return Status::IoError(path + ": " + std::strerror(errno));
  std::string out;
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof(buffer));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      ::close(fd);
      return Status::IoError(path + ": " + std::strerror(err));
    }
    if (n == 0 || out.size() > (1u << 20)) break;
    out.append(buffer, static_cast<size_t>(n));
  }
  ::close(fd);
  return out;
}

// 0 or the errno of the failure: callers turn EACCES/EBUSY into advice.
int WriteControlErrno(const std::string& path, const std::string& value,
                      bool fake) {
  return WriteValueErrno(path, value, fake ? O_CREAT | O_TRUNC : 0);
}

Status ValidateCpuList(const std::vector<int>& cpus) {
  if (cpus.empty()) {
    return Status::InvalidArgument("cpus: at least one CPU is needed");
  }
  std::set<int> seen;
  for (int cpu : cpus) {
    if (cpu < 0 || !seen.insert(cpu).second) {
      return Status::InvalidArgument(
          fmt::format("cpus: {} is negative or listed twice", cpu));
    }
  }
  return Status::Ok();
}

int WriteValueErrno(const std::string& path, const std::string& value,
                    int extra_flags) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC | extra_flags, 0644);
  if (fd < 0) return errno;
  ssize_t n;
  do {
    n = ::write(fd, value.data(), value.size());
  } while (n < 0 && errno == EINTR);
  const int err =
      n < 0 ? errno : (static_cast<size_t>(n) != value.size() ? EIO : 0);
  ::close(fd);
  return err;
}

Status WriteControl(int version, const std::string& path,
                    const std::string& value, bool fake) {
  const int err = WriteControlErrno(path, value, fake);
  if (err == 0) return Status::Ok();
  return Status::Unavailable(fmt::format("cgroup v{}: writing '{}' to {}: {}",
                                         version, value, path,
                                         std::strerror(err)));
}

Status MakeGroup(int version, const std::string& dir) {
  if (::mkdir(dir.c_str(), 0755) == 0) return Status::Ok();
  const int err = errno;
  std::string msg = fmt::format("cgroup v{}: cannot create {}: {}", version,
                                dir, std::strerror(err));
  if (err == EACCES || err == EPERM || err == EROFS) {
    msg += std::string("; ") + (version == 2 ? kDelegateHint : kV1Hint);
  }
  return Status::Unavailable(msg);
}

bool IsCgroupFs(const std::string& dir) {
  struct statfs st;
  // Unknown counts as real: then nothing is created or unlinked.
  if (::statfs(dir.c_str(), &st) != 0) return true;
  return st.f_type == CGROUP_SUPER_MAGIC || st.f_type == CGROUP2_SUPER_MAGIC;
}

namespace {

std::string Join(const std::vector<std::string>& parts, const char* sep) {
  std::string out;
  for (const std::string& p : parts) {
    if (!out.empty()) out += sep;
    out += p;
  }
  return out;
}

std::string Basename(const std::string& path) {
  const size_t slash = path.rfind('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string Dirname(const std::string& path) {
  const size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

std::vector<pid_t> ReadPids(const std::string& procs_file) {
  std::vector<pid_t> pids;
  Result<std::string> text = ReadControl(procs_file);
  if (!text.ok()) return pids;
  for (const std::string& line : Split(*text, '\n')) {
    const long pid = std::strtol(line.c_str(), nullptr, 10);
    if (pid > 0) pids.push_back(static_cast<pid_t>(pid));
  }
  return pids;
}

// The value after `key` in a "key value" per line file (memory.events).
int64_t ReadKeyed(const std::string& path, const std::string& key) {
  Result<std::string> text = ReadControl(path);
  if (!text.ok()) return -1;
  for (const std::string& line : Split(*text, '\n')) {
    if (line.compare(0, key.size() + 1, key + " ") == 0) {
      return std::strtoll(line.c_str() + key.size() + 1, nullptr, 10);
    }
  }
  return -1;
}

// SIGKILLs the tasks listed in `dir` (but `spare` and this process) until
// none is left alive. A listed pid that no longer exists counts as gone:
// that is how a fake root's static file reads, and how cgroupfs reads for
// the instant a task takes to leave.
bool KillTasksIn(const std::string& dir, pid_t spare, Clock::time_point until) {
  const std::string kill_file = dir + "/cgroup.kill";
  if (Exists(kill_file)) WriteControlErrno(kill_file, "1", false);  // v2
  const pid_t self = ::getpid();
  for (;;) {
    bool alive = false;
    for (pid_t pid : ReadPids(dir + "/cgroup.procs")) {
      if (pid == spare || pid == self) continue;
      if (::kill(pid, SIGKILL) == 0) alive = true;
    }
    if (!alive) return true;
    if (Clock::now() >= until) return false;
    ::usleep(1000);
  }
}

std::string DecodeMountPath(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '\\' && i + 3 < s.size() && s[i + 1] >= '0' &&
        s[i + 1] <= '7') {
      out += static_cast<char>((s[i + 1] - '0') * 64 + (s[i + 2] - '0') * 8 +
                               (s[i + 3] - '0'));
      i += 3;
    } else {
      out += s[i];
    }
  }
  return out;
}

}  // namespace

// Kills the tasks of `dir` and its sub-groups and removes them, children
// first. rmdir is retried while killed tasks drain (EBUSY).
bool RemoveTree(const std::string& dir, bool fake, Clock::time_point until) {
  std::error_code ec;
  std::vector<std::string> children;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    std::error_code type_ec;
    if (entry.is_directory(type_ec) && !entry.is_symlink(type_ec)) {
      children.push_back(entry.path().string());
    }
  }
  if (ec && ec != std::errc::no_such_file_or_directory) {
    std::fprintf(stderr, "warning: cannot list cgroup %s: %s\n", dir.c_str(),
                 ec.message().c_str());
  }
  bool ok = true;
  for (const std::string& child : children) {
    ok = RemoveTree(child, fake, until) && ok;
  }
  for (;;) {
    KillTasksIn(dir, 0, until);
    if (fake) {
      // A test folder: its "control files" are plain files.
      for (const auto& entry : fs::directory_iterator(dir, ec)) {
        std::error_code type_ec;
        if (!entry.is_directory(type_ec)) ::unlink(entry.path().c_str());
      }
    }
    if (::rmdir(dir.c_str()) == 0 || errno == ENOENT) return ok;
    const int err = errno;
    if ((err != EBUSY && err != ENOTEMPTY) || Clock::now() >= until) {
      std::fprintf(stderr, "warning: cannot remove cgroup %s: %s\n",
                   dir.c_str(), std::strerror(err));
      return false;
    }
    ::usleep(2000);
  }
}

// The process's own group directory in a mount: its path with the mount's
// root taken off, below the mount point.
Result<std::string> OwnDir(const CgroupMount& mount, const std::string& path,
                           bool* is_root) {
  std::string rel;
  if (mount.root == "/") {
    rel = path;
  } else if (path == mount.root ||
             path.compare(0, mount.root.size() + 1, mount.root + "/") == 0) {
    rel = path.substr(mount.root.size());
  } else {
    return Status::Unavailable(fmt::format(
        "cgroup v{}: the process's group {} lies outside the mount of {} at {}",
        mount.version, path, mount.root, mount.mount_point));
  }
  if (rel.empty() || rel == "/") {
    *is_root = true;
    rel.clear();
  }
  const std::string dir = mount.mount_point + rel;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    return Status::Unavailable(
        fmt::format("cgroup v{}: the process's group {} does not exist",
                    mount.version, dir));
  }
  return dir;
}

std::vector<CgroupMount> ParseMountInfo(const std::string& text,
                                        const std::string& under) {
  std::string base = under;
  while (base.size() > 1 && base.back() == '/') base.pop_back();
  std::vector<CgroupMount> mounts;
  for (const std::string& line : Split(text, '\n')) {
    const std::vector<std::string> f = Split(line, ' ');
    // id parent dev root mount_point options [optional...] - type source super
    size_t sep = 6;
    while (sep < f.size() && f[sep] != "-") ++sep;
    if (sep + 1 >= f.size()) continue;
    const std::string& type = f[sep + 1];
    if (type != "cgroup" && type != "cgroup2") continue;
    CgroupMount m;
    m.version = type == "cgroup2" ? 2 : 1;
    m.root = DecodeMountPath(f[3]);
    m.mount_point = DecodeMountPath(f[4]);
    if (!(base == "/" || m.mount_point == base ||
          m.mount_point.compare(0, base.size() + 1, base + "/") == 0)) {
      continue;
    }
    if (m.version == 1 && sep + 3 < f.size()) {
      m.controllers = Split(f[sep + 3], ',');
    }
    mounts.push_back(m);
  }
  return mounts;
}

std::map<std::string, std::string> ParseProcCgroup(const std::string& text) {
  std::map<std::string, std::string> groups;
  for (const std::string& line : Split(text, '\n')) {
    const size_t a = line.find(':');
    const size_t b = a == std::string::npos ? a : line.find(':', a + 1);
    if (b == std::string::npos) continue;
    const std::string controllers = line.substr(a + 1, b - a - 1);
    const std::string path = line.substr(b + 1);
    if (controllers.empty()) {
      if (line.compare(0, a, "0") == 0) groups[""] = path;
      continue;
    }
    for (const std::string& c : Split(controllers, ',')) groups[c] = path;
  }
  return groups;
}

std::string FormatCpuList(const std::vector<int>& cpus) {
  std::vector<int> sorted = cpus;
  std::sort(sorted.begin(), sorted.end());
  std::string out;
  for (size_t i = 0; i < sorted.size();) {
    size_t j = i;
    while (j + 1 < sorted.size() && sorted[j + 1] == sorted[j] + 1) ++j;
    if (!out.empty()) out += ',';
    out += std::to_string(sorted[i]);
    if (j > i) out += "-" + std::to_string(sorted[j]);
    i = j + 1;
  }
  return out;
}

int GroupNamePid(const std::string& name) {
  if (name.compare(0, 4, "adse") != 0) return -1;
  const size_t dash = name.rfind('-');
  if (dash == std::string::npos || dash + 1 >= name.size() ||
      name.size() - dash - 1 > 9) {
    return -1;
  }
  int pid = 0;
  for (size_t i = dash + 1; i < name.size(); ++i) {
    if (name[i] < '0' || name[i] > '9') return -1;
    pid = pid * 10 + (name[i] - '0');
  }
  return pid > 0 ? pid : -1;
}

bool DefaultPidAlive(int pid) { return ::kill(pid, 0) == 0 || errno != ESRCH; }

void RemoveStaleGroups(const std::string& dir, bool fake,
                       const PidAlive& pid_alive) {
  std::error_code ec;
  std::vector<std::string> stale;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    std::error_code type_ec;
    if (!entry.is_directory(type_ec)) continue;
    const int pid = GroupNamePid(entry.path().filename().string());
    if (pid > 0 && pid != ::getpid() && !pid_alive(pid)) {
      stale.push_back(entry.path().string());
    }
  }
  for (const std::string& group : stale) {
    RemoveTree(group, fake, Clock::now() + kDrainTime);
  }
}

Result<Layout> DetectLayout(const PoolOptions& options) {
  Result<std::string> mountinfo = ReadControl(options.proc_self_mountinfo);
  if (!mountinfo.ok()) {
    return Status::Unavailable("cannot read " + mountinfo.status().message());
  }
  Result<std::string> self = ReadControl(options.proc_self_cgroup);
  if (!self.ok()) {
    return Status::Unavailable("cannot read " + self.status().message());
  }
  const std::vector<CgroupMount> mounts =
      ParseMountInfo(*mountinfo, options.cgroup_root);
  std::map<std::string, std::string> groups = ParseProcCgroup(*self);
  if (mounts.empty()) {
    return Status::Unavailable(
        fmt::format("no cgroup filesystem is mounted at {} (per {})",
                    options.cgroup_root, options.proc_self_mountinfo));
  }

  // v2 when its hierarchy offers memory to the process's group. On hybrid
  // systems the controllers sit in v1 and the v2 tree offers none.
  std::vector<std::string> problems;
  for (const CgroupMount& m : mounts) {
    if (m.version != 2) continue;
    if (!groups.count("")) {
      problems.push_back(
          fmt::format("cgroup v2 is mounted at {} but {} names "
                      "no v2 group (\"0::/path\")",
                      m.mount_point, options.proc_self_cgroup));
      break;
    }
    bool is_root = false;
    Result<std::string> dir = OwnDir(m, groups[""], &is_root);
    if (!dir.ok()) {
      problems.push_back(dir.status().message());
      break;
    }
    Result<std::string> offered = ReadControl(*dir + "/cgroup.controllers");
    const std::vector<std::string> controllers =
        Split(offered.ok() ? Trim(*offered) : "", ' ');
    if (!Contains(controllers, "memory")) {
      problems.push_back(
          fmt::format("cgroup v2 at {} offers no memory controller to {} "
                      "(cgroup.controllers: '{}')",
                      m.mount_point, *dir, Join(controllers, " ")));
      break;
    }
    Layout layout;
    layout.version = 2;
    Hierarchy h;
    h.own_dir = *dir;
    h.own_is_root = is_root;
    h.fake = !IsCgroupFs(*dir);
    // cpu is handed down (no limit set) so that a real-time run inside a
    // worker can give its stack's thread group a CPU quota.
    for (const char* c : {"cpuset", "cpu", "memory", "pids"}) {
      if (Contains(controllers, c)) h.controllers.push_back(c);
    }
    layout.cpuset = Contains(controllers, "cpuset");
    layout.pids = Contains(controllers, "pids");
    layout.hierarchies.push_back(h);
    return layout;
  }

  Layout layout;
  layout.version = 1;
  std::string v1_problem;
  for (const char* c : {"cpuset", "memory", "pids"}) {
    const CgroupMount* mount = nullptr;
    for (const CgroupMount& m : mounts) {
      if (m.version == 1 && Contains(m.controllers, c)) mount = &m;
    }
    const bool memory = std::string(c) == "memory";
    if (mount == nullptr || !groups.count(c)) {
      if (memory) v1_problem = "no cgroup v1 memory hierarchy is mounted";
      continue;
    }
    bool is_root = false;
    Result<std::string> dir = OwnDir(*mount, groups[c], &is_root);
    if (!dir.ok()) {
      if (memory) v1_problem = dir.status().message();
      continue;
    }
    auto same =
        std::find_if(layout.hierarchies.begin(), layout.hierarchies.end(),
                     [&](const Hierarchy& h) { return h.own_dir == *dir; });
    if (same == layout.hierarchies.end()) {
      Hierarchy h;
      h.own_dir = *dir;
      h.own_is_root = is_root;
      h.fake = !IsCgroupFs(*dir);
      layout.hierarchies.push_back(h);
      same = layout.hierarchies.end() - 1;
    }
    same->controllers.push_back(c);
    if (std::string(c) == "cpuset") layout.cpuset = true;
    if (std::string(c) == "pids") layout.pids = true;
  }
  if (v1_problem.empty()) return layout;
  bool has_v1 = false;
  for (const CgroupMount& m : mounts) has_v1 = has_v1 || m.version == 1;
  if (has_v1 || problems.empty()) problems.push_back(v1_problem);
  return Status::Unavailable(Join(problems, "; ") + "; " + kDelegateHint);
}

Result<std::unique_ptr<CampaignGroups>> CampaignGroups::Create(
    const Layout& layout, const std::string& name, const GroupLimits& limits,
    const PidAlive& pid_alive) {
  std::unique_ptr<CampaignGroups> groups(new CampaignGroups());
  groups->layout_ = layout;
  groups->name_ = name;
  // On failure the destructor removes what was made so far.
  const Status status = layout.version == 2
                            ? groups->SetupV2(limits, pid_alive)
                            : groups->SetupV1(limits, pid_alive);
  if (!status.ok()) return status;
  return groups;
}

CampaignGroups::~CampaignGroups() { Remove(); }

bool CampaignGroups::fake() const {
  return !layout_.hierarchies.empty() && layout_.hierarchies[0].fake;
}

Status CampaignGroups::SetupV2(const GroupLimits& limits,
                               const PidAlive& pid_alive) {
  Hierarchy& h = layout_.hierarchies[0];
  const bool fake = h.fake;
  const std::string self = std::to_string(::getpid());
  std::vector<std::string> plus;
  for (const std::string& c : h.controllers) plus.push_back("+" + c);

  std::string parent = h.own_dir + "/" + name_;
  if (Basename(h.own_dir) == "coordinator" &&
      Basename(Dirname(h.own_dir)) == name_) {
    // An earlier pool of this process could not move it back out of its
    // leaf; take the groups over as they are.
    parent = Dirname(h.own_dir);
    h.own_dir = Dirname(parent);
    h.own_is_root = false;
    moved_self_ = true;
    enabled_in_own_ = Join(plus, " ");
  }
  const std::string& own = h.own_dir;
  RemoveStaleGroups(own, fake, pid_alive);

  if (moved_self_) {
    parents_.push_back(parent);
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(parent, ec)) {
      std::error_code type_ec;
      if (entry.is_directory(type_ec) &&
          entry.path().filename() != "coordinator") {
        RemoveTree(entry.path().string(), fake, Clock::now() + kDrainTime);
      }
    }
  } else {
    if (Exists(parent)) {
      return Status::Unavailable(fmt::format(
          "cgroup v2: {} exists already (another pool of this process?)",
          parent));
    }
    ADSE_RETURN_IF_ERROR(MakeGroup(2, parent));
    parents_.push_back(parent);
  }

  // Controllers the own group does not yet hand down.
  Result<std::string> subtree = ReadControl(own + "/cgroup.subtree_control");
  const std::vector<std::string> enabled =
      Split(subtree.ok() ? Trim(*subtree) : "", ' ');
  std::vector<std::string> missing;
  for (const std::string& c : h.controllers) {
    if (!Contains(enabled, c)) missing.push_back("+" + c);
  }
  // The no-internal-process rule: a (non-root) group that holds processes
  // cannot hand controllers down. When the only one is this process, it
  // leaves by moving into a leaf of the campaign group.
  const std::string leaf = parent + "/coordinator";
  auto move_self_out = [&]() -> Status {
    std::vector<std::string> others;
    bool holds_self = false;
    for (pid_t pid : ReadPids(own + "/cgroup.procs")) {
      if (pid == ::getpid()) {
        holds_self = true;
      } else {
        others.push_back(std::to_string(pid));
      }
    }
    if (!others.empty()) {
      if (others.size() > 5) {
        others.resize(5);
        others.push_back("...");
      }
      return Status::Unavailable(fmt::format(
          "cgroup v2: {} also holds other processes (pid {}), and a cgroup "
          "with processes cannot hand controllers to sub-groups; {}",
          own, Join(others, ", "), kDelegateHint));
    }
    if (!holds_self) return Status::Ok();
    ADSE_RETURN_IF_ERROR(MakeGroup(2, leaf));
    const int err = WriteControlErrno(leaf + "/cgroup.procs", self, fake);
    if (err != 0) {
      return Status::Unavailable(
          fmt::format("cgroup v2: cannot move adse into {}: {}; {}", leaf,
                      std::strerror(err), kDelegateHint));
    }
    moved_self_ = true;
    return Status::Ok();
  };
  if (!missing.empty() && !moved_self_ && !h.own_is_root) {
    ADSE_RETURN_IF_ERROR(move_self_out());
  }
  if (!missing.empty()) {
    const std::string path = own + "/cgroup.subtree_control";
    int err = WriteControlErrno(path, Join(missing, " "), fake);
    if (err == EBUSY && !moved_self_) {
      // A namespace root looks like the root but is not exempt.
      ADSE_RETURN_IF_ERROR(move_self_out());
      if (moved_self_) err = WriteControlErrno(path, Join(missing, " "), fake);
    }
    if (err != 0) {
      return Status::Unavailable(fmt::format(
          "cgroup v2: cannot enable {} in {}: {}{}; {}", Join(missing, " "),
          path, std::strerror(err),
          err == EBUSY ? " (the group holds processes)" : "", kDelegateHint));
    }
    enabled_in_own_ = Join(missing, " ");
  }
  ADSE_RETURN_IF_ERROR(WriteControl(2, parent + "/cgroup.subtree_control",
                                    Join(plus, " "), fake));
  enabled_in_parent_ = Join(plus, " ");

  const std::string memory = std::to_string(limits.memory_bytes);
  for (size_t i = 0; i < limits.slot_cores.size(); ++i) {
    const std::string dir = fmt::format("{}/worker-{}", parent, i);
    ADSE_RETURN_IF_ERROR(MakeGroup(2, dir));
    slots_.push_back({{dir}, {dir + "/cgroup.procs"}});
    if (layout_.cpuset) {
      ADSE_RETURN_IF_ERROR(WriteControl(
          2, dir + "/cpuset.cpus", FormatCpuList(limits.slot_cores[i]), fake));
    }
    ADSE_RETURN_IF_ERROR(WriteControl(2, dir + "/memory.max", memory, fake));
    // No swap, so swapping cannot hide an overrun; one OOM kill takes the
    // whole job, as a timeout does.
    if (Exists(dir + "/memory.swap.max")) {
      ADSE_RETURN_IF_ERROR(
          WriteControl(2, dir + "/memory.swap.max", "0", fake));
    }
    if (Exists(dir + "/memory.oom.group")) {
      ADSE_RETURN_IF_ERROR(
          WriteControl(2, dir + "/memory.oom.group", "1", fake));
    }
    if (layout_.pids) {
      ADSE_RETURN_IF_ERROR(WriteControl(2, dir + "/pids.max",
                                        std::to_string(limits.pids_max), fake));
    }
  }
  return Status::Ok();
}

Status CampaignGroups::SetupV1(const GroupLimits& limits,
                               const PidAlive& pid_alive) {
  std::vector<int> all_cores;
  for (const auto& cores : limits.slot_cores) {
    all_cores.insert(all_cores.end(), cores.begin(), cores.end());
  }
  std::string mems;
  for (size_t k = 0; k < layout_.hierarchies.size(); ++k) {
    const Hierarchy& h = layout_.hierarchies[k];
    if (Contains(h.controllers, "memory")) memory_index_ = static_cast<int>(k);
    RemoveStaleGroups(h.own_dir, h.fake, pid_alive);
    const std::string parent = h.own_dir + "/" + name_;
    if (Exists(parent)) {
      return Status::Unavailable(fmt::format(
          "cgroup v1: {} exists already (another pool of this process?)",
          parent));
    }
    ADSE_RETURN_IF_ERROR(MakeGroup(1, parent));
    parents_.push_back(parent);
    if (Contains(h.controllers, "cpuset")) {
      // A v1 cpuset takes no task until both cpus and mems are set, on the
      // parent first.
      for (const char* file : {"/cpuset.mems", "/cpuset.effective_mems"}) {
        Result<std::string> text = ReadControl(h.own_dir + file);
        if (text.ok() && !Trim(*text).empty()) {
          mems = Trim(*text);
          break;
        }
      }
      if (mems.empty()) mems = "0";
      ADSE_RETURN_IF_ERROR(WriteControl(1, parent + "/cpuset.cpus",
                                        FormatCpuList(all_cores), h.fake));
      ADSE_RETURN_IF_ERROR(
          WriteControl(1, parent + "/cpuset.mems", mems, h.fake));
    }
  }
  const std::string memory = std::to_string(limits.memory_bytes);
  for (size_t i = 0; i < limits.slot_cores.size(); ++i) {
    slots_.emplace_back();
    for (size_t k = 0; k < layout_.hierarchies.size(); ++k) {
      const Hierarchy& h = layout_.hierarchies[k];
      const std::string dir = fmt::format("{}/worker-{}", parents_[k], i);
      ADSE_RETURN_IF_ERROR(MakeGroup(1, dir));
      slots_.back().dirs.push_back(dir);
      slots_.back().procs_files.push_back(dir + "/cgroup.procs");
      if (Contains(h.controllers, "cpuset")) {
        ADSE_RETURN_IF_ERROR(WriteControl(1, dir + "/cpuset.cpus",
                                          FormatCpuList(limits.slot_cores[i]),
                                          h.fake));
        ADSE_RETURN_IF_ERROR(
            WriteControl(1, dir + "/cpuset.mems", mems, h.fake));
      }
      if (Contains(h.controllers, "memory")) {
        ADSE_RETURN_IF_ERROR(
            WriteControl(1, dir + "/memory.limit_in_bytes", memory, h.fake));
        // Memory + swap at the same limit: swap cannot hide an overrun.
        if (Exists(dir + "/memory.memsw.limit_in_bytes")) {
          ADSE_RETURN_IF_ERROR(WriteControl(
              1, dir + "/memory.memsw.limit_in_bytes", memory, h.fake));
        }
      }
      if (Contains(h.controllers, "pids")) {
        ADSE_RETURN_IF_ERROR(WriteControl(
            1, dir + "/pids.max", std::to_string(limits.pids_max), h.fake));
      }
    }
  }
  return Status::Ok();
}

void CampaignGroups::Remove() {
  const auto until = Clock::now() + kDrainTime;
  for (const Slot& slot : slots_) {
    for (size_t k = 0; k < slot.dirs.size(); ++k) {
      RemoveTree(slot.dirs[k], layout_.hierarchies[k].fake, until);
    }
  }
  slots_.clear();
  if (moved_self_ && !parents_.empty()) {
    // Back to the own group: it must hand down no controllers again first,
    // which fails while a sibling uses them. Then the leaf stays (with this
    // process in it) until the process ends, and the next coordinator
    // removes it as stale.
    const Hierarchy& h = layout_.hierarchies[0];
    if (!enabled_in_parent_.empty()) {
      std::string minus = enabled_in_parent_;
      std::replace(minus.begin(), minus.end(), '+', '-');
      WriteControlErrno(parents_[0] + "/cgroup.subtree_control", minus, h.fake);
    }
    int err = 0;
    if (!enabled_in_own_.empty()) {
      std::string minus = enabled_in_own_;
      std::replace(minus.begin(), minus.end(), '+', '-');
      err = WriteControlErrno(h.own_dir + "/cgroup.subtree_control", minus,
                              h.fake);
    }
    if (err == 0) {
      err = WriteControlErrno(h.own_dir + "/cgroup.procs",
                              std::to_string(::getpid()), h.fake);
    }
    if (err != 0) return;
    moved_self_ = false;
  }
  for (size_t k = 0; k < parents_.size(); ++k) {
    RemoveTree(parents_[k], layout_.hierarchies[k].fake, until);
  }
  parents_.clear();
}

int64_t CampaignGroups::OomKills(int slot) const {
  const std::string& dir = slots_[slot].dirs[memory_index_];
  if (layout_.version == 2)
    return ReadKeyed(dir + "/memory.events", "oom_kill");
  const int64_t kills = ReadKeyed(dir + "/memory.oom_control", "oom_kill");
  if (kills >= 0) return kills;
  // Kernels before 4.13 do not count kills; a hit limit is the next best.
  Result<std::string> failcnt = ReadControl(dir + "/memory.failcnt");
  return failcnt.ok() ? std::strtoll(failcnt->c_str(), nullptr, 10) : -1;
}

void CampaignGroups::KillTasks(int slot, pid_t spare) const {
  // Every hierarchy's slot group holds the same tasks; one list suffices.
  KillTasksIn(slots_[slot].dirs[memory_index_], spare,
              Clock::now() + kDrainTime);
}

std::string CampaignGroups::Describe() const {
  std::vector<std::string> controllers;
  if (layout_.cpuset) controllers.push_back("cpuset");
  controllers.push_back("memory");
  if (layout_.pids) controllers.push_back("pids");
  std::string text = fmt::format("cgroup v{} ({}) under {}", layout_.version,
                                 Join(controllers, ", "), Join(parents_, ", "));
  if (!layout_.cpuset) text += "; cores kept apart by CPU affinity";
  return text;
}

}  // namespace adse::pool::internal
