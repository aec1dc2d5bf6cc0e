// The interpretation agent: a request in plain words -> a scenario file.
// The model writes YAML; adse keeps only the sections a model may choose,
// fills in documented defaults for a missing design space, objectives or
// constraints (and says which), and puts the result through the caller's
// validator. Validation errors go back to the model, a bounded number of
// times.
#ifndef ADSE_HARNESS_LLM_INTERPRET_H_
#define ADSE_HARNESS_LLM_INTERPRET_H_

#include <functional>
#include <string>
#include <vector>

#include "harness/llm/chat.h"
#include "harness/llm/prompts.h"
#include "stack/base/status.h"

namespace adse::llm {

struct InterpretOptions {
  std::string model;  // llm.models.interpretation
  // Validation errors sent back to the model at most this many times.
  int max_corrections = 3;
  // The validator (the same one `adse validate` runs): Ok, or the errors
  // the model is told. Required.
  std::function<Status(const std::string& yaml)> validate;
};

struct InterpretResult {
  std::string yaml;                   // the validated scenario
  std::vector<std::string> defaults;  // "design_space: ..." filled in by adse
  std::vector<std::string> dropped;   // sections removed from the answer
  std::vector<std::string> rejected;  // validation errors sent back
  int answers = 0;                    // model answers read
};

// Top-level sections a model may write; others (output, harness, llm) are
// dropped: a model never chooses where results go or what runs.
const std::vector<std::string>& InterpretableSections();
// The defaults, as YAML text per section, documented in prompts/README.md.
const std::vector<std::pair<std::string, std::string>>& InterpretDefaults();

// Unavailable etc. from the backend; InvalidArgument with the last
// validation errors when the model never produced a valid scenario.
Result<InterpretResult> Interpret(const std::string& request,
                                  ChatBackend& backend,
                                  const PromptSet& prompts,
                                  const InterpretOptions& options);

}  // namespace adse::llm

#endif  // ADSE_HARNESS_LLM_INTERPRET_H_
