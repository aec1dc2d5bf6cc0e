#include "harness/slurm/batch_script.h"

#include <fmt/format.h>

namespace adse::slurm {

std::string ShellQuote(const std::string& text) {
  const bool safe =
      !text.empty() && text.find_first_not_of(
                           "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUV"
                           "WXYZ0123456789_-./=:,+%@") == std::string::npos;
  if (safe) return text;
  std::string quoted = "'";
  for (char c : text) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  return quoted + "'";
}

std::string RenderScript(const BatchScript& script) {
  std::string text = "#!/bin/bash\n";
  for (const std::string& line : script.header) {
    text += line.empty() ? "#\n" : "# " + line + "\n";
  }
  for (const std::string& option : script.directives) {
    std::string line = option;
    const size_t eq = option.find('=');
    if (option.find(' ') != std::string::npos && eq != std::string::npos) {
      line = option.substr(0, eq + 1) + "\"" + option.substr(eq + 1) + "\"";
    }
    text += "#SBATCH " + line + "\n";
  }
  text += "\n";
  for (const std::string& line : script.body) text += line + "\n";
  return text;
}

std::vector<std::string> SupervisedBody(const std::string& command,
                                        const std::string& requeue_id,
                                        int max_requeues) {
  return {
      command + " &",
      "pid=$!",
      "# Slurm's warning before the time limit (--signal=B:USR1@...) reaches",
      "# only this shell: pass it on. adse then proposes nothing more, lets",
      "# running steps finish while it can and exits 138 (128 + SIGUSR1).",
      "trap 'echo \"adse: time-limit warning: asking adse to stop\"; "
      "kill -USR1 \"$pid\"' USR1",
      "# scancel and the time limit send SIGTERM to this shell (and to the",
      "# job steps) but not to adse: pass it on, as SIGINT, so that adse",
      "# does not take a second SIGTERM (where Slurm signals it too) for",
      "# \"stop at once\"; it cancels its steps, saves its views and exits.",
      "trap 'echo \"adse: SIGTERM: stopping adse\"; kill -INT \"$pid\"' TERM",
      "while kill -0 \"$pid\" 2>/dev/null; do wait \"$pid\"; done",
      "wait \"$pid\"; rc=$?",
      "echo \"adse: exit status $rc\"",
      "# Unfinished work is found again by content key: requeue to go on.",
      fmt::format(
          "if [ \"$rc\" -eq 138 ] && [ \"${{SLURM_RESTART_COUNT:-0}}\" -lt {} "
          "]; then",
          max_requeues),
      fmt::format("  echo \"adse: not finished; requeueing {} (restart "
                  "${{SLURM_RESTART_COUNT:-0}})\"",
                  requeue_id),
      fmt::format("  scontrol requeue \"{}\"", requeue_id),
      "fi",
      "exit \"$rc\"",
  };
}

}  // namespace adse::slurm
