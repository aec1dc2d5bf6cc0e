// Runs a child program with checked exit status, its output captured.
#ifndef ADSE_STACK_BASE_SUBPROCESS_H_
#define ADSE_STACK_BASE_SUBPROCESS_H_

#include <string>
#include <vector>

#include "stack/base/status.h"

namespace adse {

struct ProcessResult {
  int exit_code = -1;  // exit status, or -1 when killed by a signal
  int signal = 0;      // the signal that ended it, or 0
  std::string output;  // stdout and stderr, interleaved (tail kept)
};

// Runs argv[0] (searched on PATH) and waits. An error Status only when the
// program could not be started; a non-zero exit is reported in the result.
Result<ProcessResult> RunProcess(const std::vector<std::string>& argv,
                                 size_t max_output_bytes = 64 * 1024);

// Like RunProcess, but a non-zero exit becomes IoError naming the program,
// the exit status and the last lines of its output.
Status RunChecked(const std::vector<std::string>& argv);

// The running program's path (/proc/self/exe), for starting adse again
// (workers, validation); "adse" (looked up on PATH) when it cannot be read.
std::string SelfExecutable();

}  // namespace adse

#endif  // ADSE_STACK_BASE_SUBPROCESS_H_
