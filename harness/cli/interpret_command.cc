// `adse interpret "<request>"`: the interpretation agent writes a scenario
// file from a request in plain words. Its answer goes through `adse
// validate` (YAML checks and the map/start/goal check in SUMO, in a child
// process); validation errors go back to the model a bounded number of
// times. Exit 0 with the file written, 2 when no valid scenario came
// (nothing written), 1 when the model cannot be reached.
#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include <fmt/format.h>

#include "harness/cli/cli_support.h"
#include "harness/cli/commands.h"
#include "harness/llm/exchange_log.h"
#include "harness/llm/interpret.h"
#include "harness/llm/prompts.h"
#include "stack/base/files.h"
#include "stack/base/subprocess.h"

namespace adse::cli {
namespace fs = std::filesystem;
namespace {

// Replaces every occurrence of `from` in `text`.
std::string ReplaceAll(std::string text, const std::string& from,
                       const std::string& to) {
  for (size_t pos = 0; (pos = text.find(from, pos)) != std::string::npos;
       pos += to.size()) {
    text.replace(pos, from.size(), to);
  }
  return text;
}

}  // namespace

int RunInterpret(const InterpretArgs& args) {
  if (args.request.find_first_not_of(" \t\r\n") == std::string::npos) {
    std::fprintf(
        stderr,
        "adse interpret: the request is empty; say what to study, e.g. "
        "\"robotaxi in a parking lot, cheapest computer that reaches the "
        "goal within 60 s\"\n");
    return 2;
  }
  spec::LlmOptions llm;
  llm.backend = args.backend;
  if (!args.endpoint.empty()) llm.endpoint = args.endpoint;
  llm.timeout_s = args.timeout_s;
  llm.retries = args.retries;
  if (args.backend == "replay" && args.replay_from.empty()) {
    std::fprintf(stderr,
                 "adse interpret: --backend replay needs --replay-from "
                 "<exchanges.jsonl>\n");
    return 2;
  }
  const std::string out =
      args.out.empty() ? ""
                       : fs::absolute(args.out).lexically_normal().string();
  const std::string folder = out.empty() ? fs::current_path().string()
                                         : fs::path(out).parent_path().string();
  if (!out.empty()) {
    if (Status usable = CheckOutputFile(out, kInterpretedScenario);
        !usable.ok()) {
      std::fprintf(stderr, "adse interpret: %s\n", usable.message().c_str());
      return 2;
    }
  }
  std::string record = args.record;
  if (record.empty() && !out.empty()) {
    record = (fs::path(out).parent_path() /
              (fs::path(out).stem().string() + ".interpret.jsonl"))
                 .string();
  }
  Result<std::unique_ptr<llm::RecordingBackend>> backend =
      llm::OpenRecordingBackend(llm, args.replay_from, record);
  if (!backend.ok()) {
    std::fprintf(stderr, "adse interpret: %s\n",
                 backend.status().message().c_str());
    return ExitCodeFor(backend.status());
  }
  Result<llm::PromptSet> prompts = llm::PromptSet::Load(args.prompts);
  if (!prompts.ok()) {
    std::fprintf(stderr, "adse interpret: %s\n",
                 prompts.status().message().c_str());
    return 2;
  }
  if (!out.empty()) {
    Status made = MakeDirs(folder);
    if (!made.ok()) {
      std::fprintf(stderr, "adse interpret: %s\n", made.message().c_str());
      return 1;
    }
  }

  // The candidate is validated where it will live, so that relative paths
  // resolve the same; the hidden file is removed whatever happens.
  const std::string shown =
      out.empty() ? "scenario.yaml" : fs::path(out).filename().string();
  const std::string check =
      (fs::path(folder) /
       fmt::format(".{}.interpret-check-{}.yaml", shown, ::getpid()))
          .string();
  const std::string self = SelfExecutable();
  llm::InterpretOptions options;
  options.model = args.model;
  options.max_corrections = args.max_corrections;
  options.validate = [&](const std::string& yaml) -> Status {
    ADSE_RETURN_IF_ERROR(WriteFileAtomic(check, yaml));
    std::vector<std::string> argv = {self, "validate", "--quiet", check};
    if (!args.check_world) argv.insert(argv.begin() + 2, "--no-world");
    Result<ProcessResult> result = RunProcess(argv);
    ::unlink(check.c_str());
    if (!result.ok()) return result.status();
    if (result->exit_code == 0) return Status::Ok();
    return Status::InvalidArgument(ReplaceAll(result->output, check, shown));
  };
  std::fprintf(stderr, "adse interpret: asking %s (%s) ...\n",
               args.model.c_str(), args.backend.c_str());
  Result<llm::InterpretResult> result =
      llm::Interpret(args.request, **backend, *prompts, options);
  ::unlink(check.c_str());
  if (!result.ok()) {
    std::fprintf(stderr, "adse interpret: %s\n",
                 result.status().message().c_str());
    std::error_code ec;
    if (!record.empty() && fs::exists(record, ec)) {
      std::fprintf(stderr, "exchanges recorded in %s\n", record.c_str());
    }
    return ExitCodeFor(result.status());
  }
  for (const std::string& d : result->dropped) {
    std::fprintf(
        stderr,
        "adse interpret: dropped section '%s' (a model does not choose it)\n",
        d.c_str());
  }
  for (const std::string& d : result->defaults) {
    std::fprintf(stderr,
                 "adse interpret: the request did not say; default used: %s\n",
                 d.c_str());
  }
  const std::string text =
      std::string(kInterpretHeader) + " from the request:\n#   " +
      ReplaceAll(args.request, "\n", "\n#   ") + "\n" + result->yaml;
  if (out.empty()) {
    std::fputs(text.c_str(), stdout);
  } else {
    Status written = WriteFileAtomic(out, text);
    if (!written.ok()) {
      std::fprintf(stderr, "adse interpret: %s\n", written.message().c_str());
      return 1;
    }
    std::fprintf(stderr,
                 "adse interpret: wrote %s (%d answers, %zu corrected)\n",
                 out.c_str(), result->answers, result->rejected.size());
  }
  if (!record.empty())
    std::fprintf(stderr, "exchanges recorded in %s\n", record.c_str());
  return 0;
}

}  // namespace adse::cli
