// Bounds on a YAML text checked on the parser's events, before yaml-cpp
// builds any node, so that deep nesting, alias bombs and huge node counts
// cost little. Shared by adse's YAML readers (the scenario parser, the cost
// profiles); included by their .cc files only.
#ifndef ADSE_HARNESS_SPEC_YAML_LIMITS_H_
#define ADSE_HARNESS_SPEC_YAML_LIMITS_H_

#include <fmt/format.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/mark.h>

#include <string>

namespace adse::spec {

struct YamlLimits {
  int max_depth = 64;
  int max_aliases = 100;
  int max_nodes = 100000;
};

// Thrown by YamlLimitScanner at the first bound a text exceeds.
struct YamlLimitExceeded {
  YAML::Mark mark;
  std::string expected;
  std::string found;
};

class YamlLimitScanner : public YAML::EventHandler {
 public:
  explicit YamlLimitScanner(const YamlLimits& limits) : limits_(limits) {}

  void OnDocumentStart(const YAML::Mark& mark) override {
    if (documents_ == 1) second_document_ = mark;
    ++documents_;
  }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t) override { Count(mark); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override {
    Count(mark);
    if (++aliases_ > limits_.max_aliases) {
      throw YamlLimitExceeded{
          mark, fmt::format("at most {} aliases (*name)", limits_.max_aliases),
          "more (an alias bomb?)"};
    }
  }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string&) override {
    Count(mark);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&,
                       YAML::anchor_t, YAML::EmitterStyle::value) override {
    Open(mark);
  }
  void OnSequenceEnd() override { --depth_; }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    Open(mark);
  }
  void OnMapEnd() override { --depth_; }

  int documents() const { return documents_; }
  // Where the second document starts (when documents() > 1).
  const YAML::Mark& second_document() const { return second_document_; }

 private:
  void Count(const YAML::Mark& mark) {
    if (++nodes_ > limits_.max_nodes) {
      throw YamlLimitExceeded{
          mark, fmt::format("at most {} nodes", limits_.max_nodes), "more"};
    }
  }
  // Throwing here stops yaml-cpp's recursive descent at our depth, long
  // before its own (much larger) guard or the stack.
  void Open(const YAML::Mark& mark) {
    Count(mark);
    if (++depth_ > limits_.max_depth) {
      throw YamlLimitExceeded{
          mark,
          fmt::format("nesting at most {} levels deep", limits_.max_depth),
          "deeper nesting"};
    }
  }

  YamlLimits limits_;
  int documents_ = 0;
  int depth_ = 0;
  int nodes_ = 0;
  int aliases_ = 0;
  YAML::Mark second_document_ = YAML::Mark::null_mark();
};

}  // namespace adse::spec

#endif  // ADSE_HARNESS_SPEC_YAML_LIMITS_H_
