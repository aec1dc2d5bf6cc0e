// Where a campaign keeps its results, and the shared evaluation cache.
// Run files are named by content key and written atomically (temporary
// name, then rename within the folder), so the set of complete run files is
// the campaign's truth; everything else in the folder is rebuilt from them.
#ifndef ADSE_HARNESS_CAMPAIGN_RUN_STORE_H_
#define ADSE_HARNESS_CAMPAIGN_RUN_STORE_H_

#include <optional>
#include <string>

#include "analysis/runfile/campaign_file.h"
#include "stack/base/env.h"
#include "stack/base/status.h"

namespace adse::campaign {

// The layout of a campaign folder:
//   runs/<key>.h5           one complete run (the truth)
//   runs/<key>.report.json  its analysis (RunReport JSON), rebuilt from the
//                           run file when missing
//   runs/<key>.failed.json  a run that failed after its retries
//   runs/<key>.cost.json    what a run that worked took: attempts, wall time
//   logs/<key>.<attempt>.log  each worker attempt's stdout and stderr
//   images/<key>/trajectory.png  the run's picture
//   campaign.h5, report.md, summary.json, pareto.png   rebuilt views
//   .lock                   held by the running coordinator
class CampaignFolder {
 public:
  // Everything the coordinator writes into the folder goes through `env`.
  explicit CampaignFolder(std::string root, Env* env = Env::Default())
      : root_(std::move(root)), env_(env) {}
  // Creates the folder and its subfolders.
  Status Create() const;

  const std::string& root() const { return root_; }
  Env* env() const { return env_; }
  std::string RunPath(const std::string& key) const;
  std::string ReportPath(const std::string& key) const;
  std::string FailurePath(const std::string& key) const;
  std::string CostPath(const std::string& key) const;
  std::string LogPath(const std::string& key, int attempt) const;
  // Folder of a run's pictures, and its trajectory picture in it.
  std::string ImageDir(const std::string& key) const;
  std::string TrajectoryImagePath(const std::string& key) const;
  std::string Path(const std::string& name) const { return root_ + "/" + name; }

 private:
  std::string root_;
  Env* env_;
};

// Exclusive use of a campaign folder by one coordinator: an flock on
// <folder>/.lock, released by the kernel however the process ends (so a
// killed coordinator never leaves a stale lock). On NFS, Linux maps flock
// to POSIX byte-range locks (NFSv4, or NFSv3 with lockd); on a filesystem
// without locks Acquire fails rather than pretending.
class CampaignLock {
 public:
  // Unavailable naming the holder's pid and host when another process
  // holds it; IoError when the lock file cannot be created or locked.
  static Result<CampaignLock> Acquire(const std::string& folder);
  CampaignLock(CampaignLock&& other) noexcept;
  CampaignLock& operator=(CampaignLock&&) = delete;
  ~CampaignLock();

 private:
  explicit CampaignLock(int fd) : fd_(fd) {}
  int fd_ = -1;
};

// Why a run failed for good, kept as runs/<key>.failed.json.
struct FailureRecord {
  std::string content_key;
  std::string point;  // FormatPoint text
  uint64_t seed = 0;
  std::string outcome;  // timeout | out_of_memory | crashed | exit_error | ...
  int exit_code = -1;
  int signal = 0;
  int attempts = 0;
  double wall_s = 0.0;
  std::string detail;  // one line: what happened
  std::string stderr_tail;
};
Status WriteFailureRecord(const std::string& path, const FailureRecord& record,
                          Env* env = Env::Default());
Result<FailureRecord> ReadFailureRecord(const std::string& path);

// What a run that worked took, kept as runs/<key>.cost.json, so that a
// resumed campaign's index keeps it (the run file holds only the run).
struct RunCost {
  std::string content_key;
  int attempts = 0;
  double wall_s = 0.0;
};
Status WriteRunCost(const std::string& path, const RunCost& cost,
                    Env* env = Env::Default());
Result<RunCost> ReadRunCost(const std::string& path);

// The shared evaluation cache: <dir>/<key>.h5, filled by every campaign
// that does not opt out, read by all. Entries are immutable (a key fixes
// the content), so concurrent campaigns can share it without locks.
class RunCache {
 public:
  explicit RunCache(std::string dir, Env* env = Env::Default())
      : dir_(std::move(dir)), env_(env) {}
  const std::string& dir() const { return dir_; }
  // The cached file for `key`, if any.
  std::optional<std::string> Find(const std::string& key) const;
  // Copies (hard-links when on the same filesystem) `run_file` in.
  Status Insert(const std::string& key, const std::string& run_file) const;
  // Copies the cached run for `key` to `destination` atomically.
  Status CopyOut(const std::string& key, const std::string& destination) const;

 private:
  std::string dir_;
  Env* env_;
};

// Copies `from` to `to` through a temporary name in `to`'s folder (hard
// link when possible), so `to` never exists half-written.
Status CopyFileAtomic(const std::string& from, const std::string& to,
                      Env* env = Env::Default());

}  // namespace adse::campaign

#endif  // ADSE_HARNESS_CAMPAIGN_RUN_STORE_H_
