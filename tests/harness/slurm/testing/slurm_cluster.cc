#include "tests/harness/slurm/testing/slurm_cluster.h"

#include <fcntl.h>
#include <netinet/in.h>
#include <pwd.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include "harness/slurm/client.h"
#include "stack/base/files.h"

namespace adse::slurm::testing {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

const char* const kPrograms[] = {"munged", "slurmctld", "slurmd",  "sbatch",
                                 "srun",   "squeue",    "scancel", "scontrol",
                                 "sinfo",  "salloc",    "setpriv"};

// A TCP port nothing listens on right now (the kernel's choice).
int FreePort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;
  socklen_t length = sizeof(address);
  int port = -1;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) == 0) {
    port = ntohs(address.sin_port);
  }
  ::close(fd);
  return port;
}

// Starts argv in its own session with output to `log`; it gets SIGTERM
// should this process die first.
pid_t Launch(const std::vector<std::string>& argv, const std::string& log) {
  std::vector<char*> args;
  for (const std::string& a : argv)
    args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const int out =
      ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::setsid();
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(127);
    const int null = ::open("/dev/null", O_RDONLY);
    ::dup2(null, STDIN_FILENO);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(out, STDERR_FILENO);
    ::execvp(args[0], args.data());
    ::_exit(127);
  }
  if (out >= 0) ::close(out);
  return pid;
}

// Whether `pid` (our child) has exited; reaps it.
bool Exited(pid_t pid) {
  int status;
  return ::waitpid(pid, &status, WNOHANG) == pid;
}

void StopProcess(pid_t pid, double grace_s) {
  if (pid <= 0) return;
  ::kill(pid, SIGTERM);
  const auto until = Clock::now() + std::chrono::duration<double>(grace_s);
  while (Clock::now() < until) {
    if (Exited(pid)) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(pid, SIGKILL);
  int status;
  ::waitpid(pid, &status, 0);
}

std::string Tail(const std::string& path, size_t lines) {
  std::ifstream in(path);
  std::vector<std::string> all;
  std::string line;
  while (std::getline(in, line)) all.push_back(line);
  std::string out;
  for (size_t i = all.size() > lines ? all.size() - lines : 0; i < all.size();
       ++i) {
    out += all[i] + "\n";
  }
  return out;
}

// "NodeName=vm CPUs=2 Boards=1 ... RealMemory=24105" -> its fields.
std::map<std::string, std::string> Fields(const std::string& line) {
  std::map<std::string, std::string> fields;
  std::istringstream in(line);
  std::string word;
  while (in >> word) {
    const size_t eq = word.find('=');
    if (eq != std::string::npos)
      fields[word.substr(0, eq)] = word.substr(eq + 1);
  }
  return fields;
}

}  // namespace

std::string SlurmSkipReason() {
  if (::geteuid() != 0) {
    return "not root: these tests start munged, slurmctld and slurmd, which "
           "needs root (CI runs them as root)";
  }
  std::vector<std::string> missing;
  for (const char* program : kPrograms) {
    if (!FindProgram(program)) missing.push_back(program);
  }
  if (!missing.empty()) {
    return fmt::format(
        "{} not found: install Debian's slurm-wlm and munge (scripts/setup.sh)",
        fmt::join(missing, ", "));
  }
  if (::getpwnam("munge") == nullptr) {
    return "no 'munge' user to run munged as: install Debian's munge package";
  }
  return "";
}

Result<std::unique_ptr<SlurmCluster>> SlurmCluster::Start() {
  if (std::string why = SlurmSkipReason(); !why.empty()) {
    return Status::Unavailable(why);
  }
  std::unique_ptr<SlurmCluster> cluster(new SlurmCluster());
  if (Status s = cluster->Launch(); !s.ok()) {
    return Status::Unavailable(s.message() + "\n" + cluster->LogTail());
  }
  return cluster;
}

Status SlurmCluster::Launch() {
  std::string pattern =
      (fs::temp_directory_path() / "adse-slurm-XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    return Status::IoError(std::string("mkdtemp: ") + std::strerror(errno));
  }
  dir_ = pattern;
  // munged (not root) must reach its socket and key below this folder.
  ::chmod(dir_.c_str(), 0755);
  for (const char* sub : {"munge", "state", "spool", "log"}) {
    ADSE_RETURN_IF_ERROR(MakeDirs(dir_ + "/" + sub));
  }
  const passwd* munge = ::getpwnam("munge");
  const std::string munge_dir = dir_ + "/munge";
  const std::string key = munge_dir + "/munge.key";
  {
    std::ifstream random("/dev/urandom", std::ios::binary);
    std::string bytes(1024, '\0');
    random.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    std::ofstream(key, std::ios::binary) << bytes;
  }
  if (::chown(munge_dir.c_str(), munge->pw_uid, munge->pw_gid) != 0 ||
      ::chown(key.c_str(), munge->pw_uid, munge->pw_gid) != 0 ||
      ::chmod(munge_dir.c_str(), 0755) != 0 ||
      ::chmod(key.c_str(), 0400) != 0) {
    return Status::IoError("cannot hand the munge key to the munge user: " +
                           std::string(std::strerror(errno)));
  }
  const std::string socket = munge_dir + "/munge.socket";
  munged_ = ::adse::slurm::testing::Launch(
      {"setpriv", "--reuid=munge", "--regid=munge", "--init-groups", "munged",
       "--foreground", "--socket=" + socket, "--key-file=" + key,
       "--log-file=" + munge_dir + "/munged.log",
       "--pid-file=" + munge_dir + "/munged.pid",
       "--seed-file=" + munge_dir + "/munged.seed"},
      dir_ + "/log/munged.out");
  for (auto until = Clock::now() + std::chrono::seconds(10);
       !fs::exists(socket);
       std::this_thread::sleep_for(std::chrono::milliseconds(20))) {
    if (Clock::now() > until || Exited(munged_)) {
      munged_ = -1;
      return Status::Unavailable("munged did not start:\n" +
                                 Tail(dir_ + "/log/munged.out", 20));
    }
  }

  Result<ProcessResult> probe = RunProcess({"slurmd", "-C"});
  if (!probe.ok() || probe->exit_code != 0) {
    return Status::Unavailable(
        "slurmd -C failed: " +
        (probe.ok() ? probe->output : probe.status().message()));
  }
  std::map<std::string, std::string> hw =
      Fields(probe->output.substr(0, probe->output.find('\n')));
  node_ = hw["NodeName"];
  cpus_ = std::atoi(hw["CPUs"].c_str());
  if (node_.empty() || cpus_ < 1 || hw["RealMemory"].empty()) {
    return Status::Unavailable("cannot read the node from slurmd -C: " +
                               probe->output);
  }
  // The v1 memory controller makes task/cgroup enforce a step's --mem.
  memory_enforced_ = fs::exists("/sys/fs/cgroup/memory/memory.limit_in_bytes");
  const int ctld_port = FreePort();
  int slurmd_port = FreePort();
  while (slurmd_port == ctld_port) slurmd_port = FreePort();
  // Job ids of clusters started by different test processes differ, so
  // their cgroups (named by job id) cannot collide.
  const int first_job = 1000 + static_cast<int>(::getpid() % 100000) * 100;

  conf_ = dir_ + "/slurm.conf";
  std::ofstream conf(conf_);
  conf << "# A one-node test cluster (tests/harness/slurm/testing).\n"
       << "ClusterName=adsetest\n"
       << fmt::format("SlurmctldHost={}(127.0.0.1)\n", node_)
       << fmt::format("SlurmctldPort={}\nSlurmdPort={}\n", ctld_port,
                      slurmd_port)
       << "SlurmUser=root\nSlurmdUser=root\n"
       << "AuthType=auth/munge\nCredType=cred/munge\n"
       << "AuthInfo=socket=" << socket << "\n"
       << "StateSaveLocation=" << dir_ << "/state\n"
       << "SlurmdSpoolDir=" << dir_ << "/spool\n"
       << "SlurmctldPidFile=" << dir_ << "/slurmctld.pid\n"
       << "SlurmdPidFile=" << dir_ << "/slurmd.pid\n"
       << "SlurmctldLogFile=" << dir_ << "/log/slurmctld.log\n"
       << "SlurmdLogFile=" << dir_ << "/log/slurmd.log\n"
       << (memory_enforced_ ? "ProctrackType=proctrack/cgroup\n"
                              "TaskPlugin=task/cgroup\n"
                            : "ProctrackType=proctrack/linuxproc\n"
                              "TaskPlugin=task/none\n")
       << "SelectType=select/cons_tres\nSelectTypeParameters=CR_Core_Memory\n"
       << "DefMemPerCPU=512\n"
       << "MailProg=/bin/true\n"
       << "SchedulerParameters=batch_sched_delay=0\n"
       << "ReturnToService=2\nKillWait=5\nMinJobAge=300\nMpiDefault=none\n"
       << "JobAcctGatherType=jobacct_gather/none\n"
       << "AccountingStorageType=accounting_storage/none\n"
       << fmt::format("FirstJobId={}\n", first_job)
       << fmt::format(
              "NodeName={} NodeAddr=127.0.0.1 CPUs={} Boards={} "
              "SocketsPerBoard={} CoresPerSocket={} ThreadsPerCore={} "
              "RealMemory={} State=UNKNOWN\n",
              node_, cpus_, hw["Boards"], hw["SocketsPerBoard"],
              hw["CoresPerSocket"], hw["ThreadsPerCore"], hw["RealMemory"])
       << "PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE "
          "State=UP\n";
  conf.close();
  std::ofstream(dir_ + "/cgroup.conf")
      << "CgroupPlugin=cgroup/v1\nConstrainCores=yes\nConstrainRAMSpace=yes\n";
  ::setenv("SLURM_CONF", conf_.c_str(), 1);
  // Not inside any allocation, whatever the caller's environment.
  ::unsetenv("SLURM_JOB_ID");

  slurmctld_ = ::adse::slurm::testing::Launch({"slurmctld", "-D", "-f", conf_},
                                              dir_ + "/log/slurmctld.out");
  slurmd_ = ::adse::slurm::testing::Launch({"slurmd", "-D", "-f", conf_},
                                           dir_ + "/log/slurmd.out");
  const auto until = Clock::now() + std::chrono::seconds(30);
  for (;;) {
    Result<ProcessResult> state =
        Run({"sinfo", "--noheader", "--nodes=" + node_, "--format=%T"});
    if (state.ok() && state->exit_code == 0 &&
        state->output.rfind("idle", 0) == 0) {
      return Status::Ok();
    }
    if (Exited(slurmctld_)) {
      slurmctld_ = -1;
      return Status::Unavailable("slurmctld exited");
    }
    if (Exited(slurmd_)) {
      slurmd_ = -1;
      return Status::Unavailable("slurmd exited");
    }
    if (Clock::now() > until) {
      return Status::Unavailable(
          "the node did not become idle within 30 s (sinfo: " +
          (state.ok() ? state->output : state.status().message()) + ")");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

SlurmCluster::~SlurmCluster() { Stop(); }

void SlurmCluster::Stop() {
  if (slurmctld_ > 0) {
    // Cancel every job first, so that no step outlives slurmd.
    Result<ProcessResult> jobs = Run({"squeue", "--noheader", "--format=%A"});
    if (jobs.ok() && jobs->exit_code == 0) {
      std::istringstream ids(jobs->output);
      std::string id;
      bool any = false;
      std::vector<std::string> cancel = {"scancel"};
      while (ids >> id) {
        cancel.push_back(id);
        any = true;
      }
      if (any) {
        (void)Run(cancel);
        const auto until = Clock::now() + std::chrono::seconds(20);
        while (Clock::now() < until) {
          Result<ProcessResult> left =
              Run({"squeue", "--noheader", "--format=%A"});
          if (!left.ok() ||
              left->output.find_first_not_of(" \n") == std::string::npos) {
            break;
          }
          std::this_thread::sleep_for(std::chrono::milliseconds(200));
        }
      }
    }
  }
  StopProcess(slurmd_, 10);
  StopProcess(slurmctld_, 10);
  StopProcess(munged_, 5);
  slurmd_ = slurmctld_ = munged_ = -1;
  if (!dir_.empty() && std::getenv("ADSE_KEEP_SLURM_DIR") == nullptr) {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
}

Result<ProcessResult> SlurmCluster::Run(
    const std::vector<std::string>& argv) const {
  return RunProcess(argv);
}

std::string SlurmCluster::JobState(const std::string& job_id) const {
  Result<ProcessResult> r =
      Run({"squeue", "--noheader", "--array", "--states=all",
           "--jobs=" + job_id, "--format=%T"});
  if (!r.ok() || r->exit_code != 0) return "";
  std::string states;
  std::istringstream in(r->output);
  std::string state;
  while (in >> state) states += (states.empty() ? "" : ",") + state;
  return states;
}

Status SlurmCluster::WaitForJobEnd(const std::string& job_id,
                                   double timeout_s) const {
  const auto until = Clock::now() + std::chrono::duration<double>(timeout_s);
  std::string states;
  while (Clock::now() < until) {
    states = JobState(job_id);
    bool active = false;
    std::istringstream in(states);
    std::string state;
    while (std::getline(in, state, ','))
      active = active || IsActiveState(state);
    if (!active) return Status::Ok();
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
  return Status::Unavailable(fmt::format("job {} still {} after {:g} s\n{}",
                                         job_id, states, timeout_s, LogTail()));
}

std::string SlurmCluster::LogTail() const {
  std::string out;
  for (const char* log : {"slurmctld.log", "slurmd.log", "slurmctld.out",
                          "slurmd.out", "munged.out"}) {
    const std::string path = dir_ + "/log/" + log;
    if (fs::exists(path)) {
      out += fmt::format("--- {} (last lines)\n{}", path, Tail(path, 15));
    }
  }
  return out;
}

}  // namespace adse::slurm::testing
