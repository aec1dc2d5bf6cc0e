// sbatch scripts as adse writes them: a comment header saying what the job
// is and how to follow it, one #SBATCH line per option, and a bash body.
#ifndef ADSE_HARNESS_SLURM_BATCH_SCRIPT_H_
#define ADSE_HARNESS_SLURM_BATCH_SCRIPT_H_

#include <string>
#include <vector>

namespace adse::slurm {

struct BatchScript {
  std::vector<std::string> header;      // comment lines, without "# "
  std::vector<std::string> directives;  // sbatch options: "--time=02:00:00"
  std::vector<std::string> body;        // bash lines
};

// The script's text: "#!/bin/bash", the header, the #SBATCH lines (a value
// with spaces is double-quoted), a blank line and the body.
std::string RenderScript(const BatchScript& script);

// `text` as one bash word: single-quoted unless it is plainly safe.
std::string ShellQuote(const std::string& text);

// The body lines that run `command` (already quoted) as the job's main
// process and stay with it: Slurm's time-limit warning (B:USR1, sent to
// this shell only) is passed on to it; SIGTERM from scancel or the time
// limit, which Slurm sends to the batch shell only, is passed on as SIGINT
// (adse takes a second SIGTERM as "stop at once", and some setups signal
// every process of the job). When adse exits 138 (stopped by the
// warning before finishing) the job requeues itself, at most
// `max_requeues` times, using `requeue_id` (e.g. "$SLURM_JOB_ID").
std::vector<std::string> SupervisedBody(const std::string& command,
                                        const std::string& requeue_id,
                                        int max_requeues);

}  // namespace adse::slurm

#endif  // ADSE_HARNESS_SLURM_BATCH_SCRIPT_H_
