// Runs the built adse binary as a user would, for end-to-end CLI tests.
#ifndef ADSE_TESTS_HARNESS_TESTING_ADSE_COMMAND_H_
#define ADSE_TESTS_HARNESS_TESTING_ADSE_COMMAND_H_

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace adse::testing {

struct CommandRun {
  int exit_code;
  std::string out;  // stdout and stderr
};

// `args` is shell text (quote arguments with spaces).
inline CommandRun Adse(const std::string& args) {
  const std::string command =
      std::string(ADSE_BINARY_DIR) + "/bin/adse " + args + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  std::string out;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    out.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

}  // namespace adse::testing

#endif  // ADSE_TESTS_HARNESS_TESTING_ADSE_COMMAND_H_
