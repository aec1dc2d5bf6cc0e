// The filesystem operations adse's durable writes are made of, behind one
// interface (after LevelDB's Env). Env::Default() is the real filesystem;
// tests pass an implementation that fails on purpose (a full disk, EIO, a
// failed rename, a crash between write and rename) to show that no failure
// loses finished work or leaves a file that looks complete.
//
// Every error is an IoError whose message starts with the path and ends
// with the system's reason, e.g. "<path>: write: No space left on device".
#ifndef ADSE_STACK_BASE_ENV_H_
#define ADSE_STACK_BASE_ENV_H_

#include <string>
#include <string_view>

#include "stack/base/status.h"

namespace adse {

class Env {
 public:
  virtual ~Env() = default;

  // The real filesystem. Never deleted; safe to use from any thread.
  static Env* Default();

  // Creates `path` and its parents; Ok when it exists already.
  virtual Status CreateDir(const std::string& path) = 0;
  // Creates or truncates `path`, writes all of `data` and closes it; not
  // yet durable (SyncFile).
  virtual Status WriteFile(const std::string& path, std::string_view data) = 0;
  // Appends `data` to `path` (created if missing) in one write and fsyncs.
  virtual Status AppendFile(const std::string& path, std::string_view data) = 0;
  // Flushes to disk a file another writer wrote (HDF5 writes its own files).
  virtual Status SyncFile(const std::string& path) = 0;
  // Flushes a folder's entries, so a rename into it survives a power cut.
  // Filesystems that refuse fsync on a folder are tolerated.
  virtual Status SyncDir(const std::string& path) = 0;
  // Renames `from` over `to` (atomic on POSIX filesystems).
  virtual Status RenameFile(const std::string& from, const std::string& to) = 0;
  // Makes `to` a copy of `from`: a hard link where the filesystem allows,
  // else a copy, fsynced. `to` must not exist.
  virtual Status CopyFile(const std::string& from, const std::string& to) = 0;
  // Removes a file; Ok when it does not exist.
  virtual Status RemoveFile(const std::string& path) = 0;
};

// An Env that forwards every call to another; fault-injecting test Envs
// override only the calls they break.
class EnvWrapper : public Env {
 public:
  explicit EnvWrapper(Env* target) : target_(target) {}

  Status CreateDir(const std::string& path) override {
    return target_->CreateDir(path);
  }
  Status WriteFile(const std::string& path, std::string_view data) override {
    return target_->WriteFile(path, data);
  }
  Status AppendFile(const std::string& path, std::string_view data) override {
    return target_->AppendFile(path, data);
  }
  Status SyncFile(const std::string& path) override {
    return target_->SyncFile(path);
  }
  Status SyncDir(const std::string& path) override {
    return target_->SyncDir(path);
  }
  Status RenameFile(const std::string& from, const std::string& to) override {
    return target_->RenameFile(from, to);
  }
  Status CopyFile(const std::string& from, const std::string& to) override {
    return target_->CopyFile(from, to);
  }
  Status RemoveFile(const std::string& path) override {
    return target_->RemoveFile(path);
  }

 private:
  Env* target_;
};

}  // namespace adse

#endif  // ADSE_STACK_BASE_ENV_H_
