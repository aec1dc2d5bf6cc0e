#include "harness/pool/thread_group.h"

#include <sys/syscall.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <fmt/format.h>

#include "harness/pool/cgroup.h"

namespace adse::pool {
namespace {

using internal::CgroupMount;
using Clock = std::chrono::steady_clock;

constexpr const char* kPermissionHint =
    "run adse as root, or (cgroup v2) in a group delegated to it, e.g. "
    "`systemd-run --user --scope -p Delegate=yes adse ...`";

const CgroupMount* FindV1(const std::vector<CgroupMount>& mounts,
                          const std::string& controller) {
  for (const CgroupMount& m : mounts) {
    if (m.version == 1 && internal::Contains(m.controllers, controller)) {
      return &m;
    }
  }
  return nullptr;
}

const CgroupMount* FindV2(const std::vector<CgroupMount>& mounts) {
  for (const CgroupMount& m : mounts) {
    if (m.version == 2) return &m;
  }
  return nullptr;
}

Status Validate(const ThreadGroupOptions& o) {
  ADSE_RETURN_IF_ERROR(internal::ValidateCpuList(o.cpus));
  if (!std::isfinite(o.cpu_quota) || o.cpu_quota < 0.0 ||
      o.cpu_quota > static_cast<double>(o.cpus.size())) {
    return Status::InvalidArgument(fmt::format(
        "cpu_quota must be in [0, {}] CPUs (the cpuset's size), got {}",
        o.cpus.size(), o.cpu_quota));
  }
  if (o.quota_period_us < 1000 || o.quota_period_us > 1000000) {
    return Status::InvalidArgument(
        fmt::format("quota_period_us must be in [1000, 1000000], got {}",
                    o.quota_period_us));
  }
  if (o.name.compare(0, 4, "adse") != 0 ||
      o.name.find('/') != std::string::npos) {
    return Status::InvalidArgument(fmt::format(
        "name must start with 'adse' and hold no '/', got '{}'", o.name));
  }
  return Status::Ok();
}

// A group left by an earlier process with this pid, or a stale one.
void PrepareParent(const std::string& own, const std::string& dir, bool fake) {
  internal::RemoveStaleGroups(own, fake, internal::DefaultPidAlive);
  if (internal::Exists(dir)) {
    internal::RemoveTree(dir, fake, Clock::now() + std::chrono::seconds(1));
  }
}

std::string Tid() { return std::to_string(::syscall(SYS_gettid)); }

}  // namespace

Result<std::unique_ptr<ThreadGroup>> ThreadGroup::Create(
    const ThreadGroupOptions& options) {
  ADSE_RETURN_IF_ERROR(Validate(options));
  Result<std::string> mountinfo =
      internal::ReadControl(options.proc_self_mountinfo);
  if (!mountinfo.ok()) {
    return Status::Unavailable("cannot read " + mountinfo.status().message());
  }
  Result<std::string> self = internal::ReadControl(options.proc_self_cgroup);
  if (!self.ok()) {
    return Status::Unavailable("cannot read " + self.status().message());
  }
  const std::vector<CgroupMount> mounts =
      internal::ParseMountInfo(*mountinfo, options.cgroup_root);
  const Groups groups = internal::ParseProcCgroup(*self);
  std::unique_ptr<ThreadGroup> group(new ThreadGroup());
  // v1 where a cpuset hierarchy is mounted (hybrid systems keep their
  // controllers there), else v2. On failure the destructor removes what
  // was made so far.
  const Status status = FindV1(mounts, "cpuset") != nullptr
                            ? group->SetupV1(options, mounts, groups)
                            : group->SetupV2(options, mounts, groups);
  if (!status.ok()) return status;
  return group;
}

Status ThreadGroup::SetupV1(const ThreadGroupOptions& options,
                            const std::vector<CgroupMount>& mounts,
                            const Groups& groups) {
  const CgroupMount* cpuset = FindV1(mounts, "cpuset");
  if (!groups.count("cpuset")) {
    return Status::Unavailable(fmt::format(
        "a cgroup v1 cpuset hierarchy is mounted at {} but {} names no "
        "cpuset group for this process",
        cpuset->mount_point, options.proc_self_cgroup));
  }
  version_ = 1;
  const std::string name = fmt::format("{}-{}", options.name, ::getpid());
  // Adds the group in one v1 hierarchy.
  auto place = [&](const CgroupMount& mount,
                   const std::string& path) -> Result<Place> {
    bool is_root = false;
    Result<std::string> own = internal::OwnDir(mount, path, &is_root);
    if (!own.ok()) return own.status();
    Place p;
    p.own_dir = *own;
    p.dir = *own + "/" + name;
    p.threads_file = p.dir + "/tasks";
    p.fake = !internal::IsCgroupFs(*own);
    PrepareParent(p.own_dir, p.dir, p.fake);
    // MakeGroup's error says how to get permission.
    ADSE_RETURN_IF_ERROR(internal::MakeGroup(1, p.dir));
    places_.push_back(p);
    dirs_.push_back(p.dir);
    return p;
  };

  Result<Place> set = place(*cpuset, groups.at("cpuset"));
  if (!set.ok()) return set.status();
  // A v1 cpuset takes no task until both cpus and mems are set.
  std::string mems;
  for (const char* file : {"/cpuset.mems", "/cpuset.effective_mems"}) {
    Result<std::string> text = internal::ReadControl(set->own_dir + file);
    if (text.ok() && !internal::Trim(*text).empty()) {
      mems = internal::Trim(*text);
      break;
    }
  }
  if (mems.empty()) mems = "0";
  const std::string cpus = internal::FormatCpuList(options.cpus);
  const bool fake = set->fake;
  const std::string dir = set->dir;
  ADSE_RETURN_IF_ERROR(
      internal::WriteControl(1, dir + "/cpuset.cpus", cpus, fake));
  ADSE_RETURN_IF_ERROR(
      internal::WriteControl(1, dir + "/cpuset.mems", mems, fake));
  description_ = fmt::format("cgroup v1 cpuset {}", cpus);

  if (options.cpu_quota > 0.0) {
    const CgroupMount* cpu = FindV1(mounts, "cpu");
    if (cpu == nullptr || !groups.count("cpu")) {
      return Status::Unavailable(fmt::format(
          "a CPU quota needs the cgroup v1 cpu controller, and no cpu "
          "hierarchy is mounted under {} (per {})",
          options.cgroup_root, options.proc_self_mountinfo));
    }
    Result<Place> quota = place(*cpu, groups.at("cpu"));
    if (!quota.ok()) return quota.status();
    const std::string& qdir = quota->dir;
    const long long quota_us =
        std::llround(options.cpu_quota * options.quota_period_us);
    ADSE_RETURN_IF_ERROR(internal::WriteControl(
        1, qdir + "/cpu.cfs_period_us", std::to_string(options.quota_period_us),
        quota->fake));
    ADSE_RETURN_IF_ERROR(internal::WriteControl(
        1, qdir + "/cpu.cfs_quota_us", std::to_string(quota_us), quota->fake));
    description_ +=
        fmt::format(", cpu quota {:.3g} CPUs per {:g} ms", options.cpu_quota,
                    options.quota_period_us / 1000.0);
  }
  description_ += ": " + fmt::format("{}", fmt::join(dirs_, ", "));
  return Status::Ok();
}

Status ThreadGroup::SetupV2(const ThreadGroupOptions& options,
                            const std::vector<CgroupMount>& mounts,
                            const Groups& groups) {
  const CgroupMount* v2 = FindV2(mounts);
  if (v2 == nullptr || !groups.count("")) {
    return Status::Unavailable(fmt::format(
        "platform.kind cgroup needs the cpuset controller, and no cgroup "
        "hierarchy under {} offers it (no v1 cpuset hierarchy and no v2 "
        "group for this process, per {} and {})",
        options.cgroup_root, options.proc_self_mountinfo,
        options.proc_self_cgroup));
  }
  bool is_root = false;
  Result<std::string> own = internal::OwnDir(*v2, groups.at(""), &is_root);
  if (!own.ok()) return own.status();
  version_ = 2;
  Place p;
  p.own_dir = *own;
  p.fake = !internal::IsCgroupFs(*own);
  p.dir = fmt::format("{}/{}-{}", *own, options.name, ::getpid());
  p.threads_file = p.dir + "/cgroup.threads";

  // The controllers must reach the process's own group from above.
  Result<std::string> offered =
      internal::ReadControl(p.own_dir + "/cgroup.controllers");
  const std::vector<std::string> controllers =
      internal::Split(offered.ok() ? internal::Trim(*offered) : "", ' ');
  std::vector<std::string> needed = {"cpuset"};
  if (options.cpu_quota > 0.0) needed.push_back("cpu");
  for (const std::string& c : needed) {
    if (!internal::Contains(controllers, c)) {
      return Status::Unavailable(fmt::format(
          "cgroup v2 at {} offers no {} controller to {} (cgroup.controllers: "
          "'{}'); enable it in the parent's cgroup.subtree_control{}",
          v2->mount_point, c, p.own_dir, fmt::join(controllers, " "),
          c == "cpu" ? " (it is needed for the CPU quota)" : ""));
    }
  }
  // cpuset and cpu are threaded controllers: a group with processes may
  // hand them to threaded children.
  Result<std::string> subtree =
      internal::ReadControl(p.own_dir + "/cgroup.subtree_control");
  const std::vector<std::string> enabled =
      internal::Split(subtree.ok() ? internal::Trim(*subtree) : "", ' ');
  std::vector<std::string> plus;
  for (const std::string& c : needed) {
    if (!internal::Contains(enabled, c)) plus.push_back("+" + c);
  }
  PrepareParent(p.own_dir, p.dir, p.fake);
  if (!plus.empty()) {
    const std::string text = fmt::format("{}", fmt::join(plus, " "));
    const Status status = internal::WriteControl(
        2, p.own_dir + "/cgroup.subtree_control", text, p.fake);
    if (!status.ok()) {
      return Status::Unavailable(status.message() + "; " + kPermissionHint);
    }
    enabled_in_own_ = text;
  }
  ADSE_RETURN_IF_ERROR(internal::MakeGroup(2, p.dir));
  places_.push_back(p);
  dirs_.push_back(p.dir);
  ADSE_RETURN_IF_ERROR(
      internal::WriteControl(2, p.dir + "/cgroup.type", "threaded", p.fake));
  const std::string cpus = internal::FormatCpuList(options.cpus);
  ADSE_RETURN_IF_ERROR(
      internal::WriteControl(2, p.dir + "/cpuset.cpus", cpus, p.fake));
  description_ = fmt::format("cgroup v2 (threaded) cpuset {}", cpus);
  if (options.cpu_quota > 0.0) {
    const long long quota_us =
        std::llround(options.cpu_quota * options.quota_period_us);
    ADSE_RETURN_IF_ERROR(internal::WriteControl(
        2, p.dir + "/cpu.max",
        fmt::format("{} {}", quota_us, options.quota_period_us), p.fake));
    description_ +=
        fmt::format(", cpu quota {:.3g} CPUs per {:g} ms", options.cpu_quota,
                    options.quota_period_us / 1000.0);
  }
  description_ += ": " + p.dir;
  return Status::Ok();
}

ThreadGroup::~ThreadGroup() { Remove(); }

Status ThreadGroup::AddCurrentThread() const {
  const std::string tid = Tid();
  for (const Place& p : places_) {
    ADSE_RETURN_IF_ERROR(
        internal::WriteControl(version_, p.threads_file, tid, p.fake));
  }
  return Status::Ok();
}

std::string ThreadGroup::Describe() const { return description_; }

void ThreadGroup::Remove() {
  for (auto it = places_.rbegin(); it != places_.rend(); ++it) {
    const Place& p = *it;
    // Threads of this process still inside go back to its own group (a
    // group with tasks cannot be removed; RemoveTree never kills us).
    const std::string own_threads =
        p.own_dir + (version_ == 2 ? "/cgroup.threads" : "/tasks");
    Result<std::string> listed = internal::ReadControl(p.threads_file);
    if (listed.ok()) {
      for (const std::string& id : internal::Split(*listed, '\n')) {
        if (internal::Exists("/proc/self/task/" + internal::Trim(id))) {
          internal::WriteControlErrno(own_threads, internal::Trim(id), p.fake);
        }
      }
    }
    internal::RemoveTree(p.dir, p.fake, Clock::now() + std::chrono::seconds(1));
  }
  if (!enabled_in_own_.empty() && !places_.empty()) {
    std::string minus = enabled_in_own_;
    for (char& c : minus) {
      if (c == '+') c = '-';
    }
    const Place& p = places_.front();
    const int err = internal::WriteControlErrno(
        p.own_dir + "/cgroup.subtree_control", minus, p.fake);
    if (err != 0) {
      std::fprintf(
          stderr, "warning: cannot write '%s' to %s: %s\n", minus.c_str(),
          (p.own_dir + "/cgroup.subtree_control").c_str(), std::strerror(err));
    }
  }
  places_.clear();
}

}  // namespace adse::pool
