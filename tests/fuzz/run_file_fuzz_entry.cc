#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "analysis/runfile/campaign_file.h"
#include "analysis/runfile/run_file.h"
#include "tests/fuzz/fuzz_entries.h"

namespace adse::fuzz {
namespace {

// One scratch file per process, rewritten for every input (the readers take
// paths). TMPDIR on a tmpfs keeps this cheap.
const std::string& ScratchPath() {
  static const std::string path =
      (std::filesystem::temp_directory_path() /
       ("adse-fuzz-run-file-" + std::to_string(::getpid()) + ".h5"))
          .string();
  return path;
}

}  // namespace

Status FuzzRunFile(const uint8_t* data, size_t size) {
  const std::string& path = ScratchPath();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data),
              static_cast<std::streamsize>(size));
    if (!out) return Status::IoError(path + ": cannot write the input");
  }
  // Errors are the expected answer to most inputs; what matters is that
  // none of the readers crashes, hangs or trips a sanitizer.
  (void)runfile::ReadRunFile(path);
  (void)runfile::ReadCampaignIndex(path);
  std::vector<std::string> problems;
  (void)runfile::CheckRunFile(path, &problems);
  ::unlink(path.c_str());
  return Status::Ok();
}

}  // namespace adse::fuzz
