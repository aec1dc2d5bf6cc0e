#include "harness/slurm/client.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>
#include <string_view>

#include <fmt/format.h>

#include "stack/base/subprocess.h"

namespace adse::slurm {
namespace {

std::vector<std::string> Split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(text);
  while (std::getline(in, part, separator)) parts.push_back(part);
  if (!text.empty() && text.back() == separator) parts.emplace_back();
  return parts;
}

std::string Trim(const std::string& s) {
  const size_t begin = s.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  const size_t end = s.find_last_not_of(" \t\r\n");
  return s.substr(begin, end - begin + 1);
}

// The last line of a tool's output: where Slurm's clients say why they
// failed.
std::string LastLine(const std::string& s) {
  const std::string t = Trim(s);
  const size_t newline = t.rfind('\n');
  return newline == std::string::npos ? t : t.substr(newline + 1);
}

// Whether a squeue/sacct id ("123", "123_4", "123_[5-9]", "123.batch")
// belongs to one of `ids`.
bool Belongs(const std::string& id, const std::set<std::string>& ids) {
  const size_t end = id.find_first_of("_.");
  return ids.count(id.substr(0, end)) > 0 || ids.count(id) > 0;
}

Result<ProcessResult> Run(const std::vector<std::string>& argv) {
  if (!FindProgram(argv[0])) {
    return Status::NotFound(fmt::format(
        "{} not found on PATH: Slurm's client commands are needed (run on a "
        "login node of the cluster)",
        argv[0]));
  }
  return RunProcess(argv);
}

}  // namespace

std::optional<std::string> FindProgram(const std::string& name) {
  std::error_code ec;
  if (name.find('/') != std::string::npos) {
    if (::access(name.c_str(), X_OK) == 0) {
      return std::filesystem::absolute(name, ec).string();
    }
    return std::nullopt;
  }
  const char* path = std::getenv("PATH");
  for (std::string dir : Split(path == nullptr ? "/usr/bin:/bin" : path, ':')) {
    if (dir.empty()) dir = ".";
    const std::string candidate = dir + "/" + name;
    struct stat st;
    if (::stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) &&
        ::access(candidate.c_str(), X_OK) == 0) {
      return std::filesystem::absolute(candidate, ec).string();
    }
  }
  return std::nullopt;
}

Result<std::string> SubmitBatchScript(const std::string& script_path) {
  Result<ProcessResult> r = Run({"sbatch", "--parsable", script_path});
  if (!r.ok()) return r.status();
  const std::string out = Trim(r->output);
  // --parsable prints "<id>" or "<id>;<cluster>" on the last line.
  std::string last = out.substr(
      out.rfind('\n') == std::string::npos ? 0 : out.rfind('\n') + 1);
  last = last.substr(0, last.find(';'));
  if (r->exit_code != 0 || last.empty() ||
      last.find_first_not_of("0123456789") != std::string::npos) {
    return Status::IoError(fmt::format("sbatch refused {}: {}", script_path,
                                       out.empty() ? "no output" : out));
  }
  return last;
}

Result<std::vector<JobState>> QueryJobs(const std::vector<std::string>& ids) {
  std::vector<JobState> states;
  if (ids.empty()) return states;
  const std::set<std::string> wanted(ids.begin(), ids.end());
  std::string list;
  for (const std::string& id : ids) list += (list.empty() ? "" : ",") + id;
  Result<ProcessResult> r =
      Run({"squeue", "--noheader", "--array", "--states=all", "--jobs=" + list,
           "--format=%i|%A|%T|%r|%M"});
  if (!r.ok()) return r.status();
  std::set<std::string> seen;
  if (r->exit_code == 0) {
    for (const std::string& line : Split(r->output, '\n')) {
      const std::vector<std::string> f = Split(Trim(line), '|');
      if (f.size() < 5 || !Belongs(f[0], wanted)) continue;
      states.push_back({f[0], f[1], f[2], f[3], f[4], ""});
      seen.insert(f[0].substr(0, f[0].find('_')));
    }
  } else if (r->output.find("Invalid job id") == std::string::npos) {
    return Status::IoError("squeue failed: " + LastLine(r->output));
  }
  // Jobs squeue has forgotten: ask accounting, where there is any.
  std::string missing;
  for (const std::string& id : ids) {
    if (!seen.count(id)) missing += (missing.empty() ? "" : ",") + id;
  }
  if (!missing.empty() && FindProgram("sacct")) {
    Result<ProcessResult> acct =
        RunProcess({"sacct", "--noheader", "--parsable2", "--allocations",
                    "--jobs=" + missing,
                    "--format=JobID,JobIDRaw,State,"
                    "Elapsed,ExitCode"});
    if (acct.ok() && acct->exit_code == 0) {
      for (const std::string& line : Split(acct->output, '\n')) {
        const std::vector<std::string> f = Split(Trim(line), '|');
        if (f.size() < 5 || !Belongs(f[0], wanted)) continue;
        // "CANCELLED by 0" -> "CANCELLED".
        states.push_back(
            {f[0], f[1], f[2].substr(0, f[2].find(' ')), "", f[3], f[4]});
      }
    }
  }
  return states;
}

Result<std::vector<StepState>> QuerySteps(const std::vector<std::string>& ids) {
  std::vector<StepState> steps;
  if (ids.empty()) return steps;
  const std::set<std::string> wanted(ids.begin(), ids.end());
  // All visible steps, filtered here: squeue -s with --jobs does not
  // expand array jobs into their tasks' steps.
  Result<ProcessResult> r =
      Run({"squeue", "--noheader", "--steps", "--format=%i|%j|%M|%N"});
  if (!r.ok()) return r.status();
  if (r->exit_code != 0) {
    return Status::IoError("squeue failed: " + LastLine(r->output));
  }
  for (const std::string& line : Split(r->output, '\n')) {
    const std::vector<std::string> f = Split(Trim(line), '|');
    if (f.size() < 4 || !Belongs(f[0], wanted)) continue;
    if (f[0].find(".batch") != std::string::npos ||
        f[0].find(".extern") != std::string::npos) {
      continue;
    }
    steps.push_back({f[0], f[1], f[2], f[3]});
  }
  return steps;
}

std::string StepKeyPrefix(const StepState& step) {
  static constexpr std::string_view kPrefix = "adse-";
  if (step.name.rfind(kPrefix, 0) != 0) return "";
  return step.name.substr(kPrefix.size());
}

bool IsActiveState(const std::string& state) {
  static const std::set<std::string> kActive = {
      "PENDING",   "RUNNING",   "REQUEUED",     "REQUEUE_FED", "REQUEUE_HOLD",
      "RESIZING",  "SUSPENDED", "COMPLETING",   "CONFIGURING", "STAGE_OUT",
      "SIGNALING", "STOPPED",   "RESV_DEL_HOLD"};
  return kActive.count(state) > 0;
}

std::optional<int> MaxArraySize() {
  if (!FindProgram("scontrol")) return std::nullopt;
  Result<ProcessResult> r = RunProcess({"scontrol", "show", "config"});
  if (!r.ok() || r->exit_code != 0) return std::nullopt;
  for (const std::string& line : Split(r->output, '\n')) {
    if (line.rfind("MaxArraySize", 0) != 0) continue;
    const size_t eq = line.find('=');
    if (eq == std::string::npos) continue;
    const std::string value = Trim(line.substr(eq + 1));
    if (value.empty() || value.size() > 9 ||
        value.find_first_not_of("0123456789") != std::string::npos) {
      return std::nullopt;
    }
    return std::stoi(value);
  }
  return std::nullopt;
}

}  // namespace adse::slurm
