// Hostile YAML: bounded time and memory, and a clear error.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "harness/spec/spec_parser.h"

namespace adse::spec {
namespace {

using ::testing::HasSubstr;

constexpr char kHead[] = R"(adse: 1
world: {map: {generate: grid}}
task: {start: {x: 0, y: 0}, goal: {x: 100, y: 0}}
)";

// Parses and checks it fails within `seconds`; returns the message.
std::string FailsFast(const std::string& text, double seconds = 2.0) {
  const auto start = std::chrono::steady_clock::now();
  Result<Spec> spec = ParseSpec(text, "evil.yaml", "");
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  EXPECT_LT(elapsed, seconds);
  EXPECT_FALSE(spec.ok());
  return spec.ok() ? "" : spec.status().message();
}

// Level 0 holds `width` strings; level i holds `width` aliases of level i-1.
std::string Laughs(int levels, int width) {
  std::string text = "l0: &l0 [";
  for (int j = 0; j < width; ++j) text += j ? ",lol" : "lol";
  text += "]\n";
  for (int i = 1; i < levels; ++i) {
    text += "l" + std::to_string(i) + ": &l" + std::to_string(i) + " [";
    for (int j = 0; j < width; ++j) {
      text += (j ? ",*l" : "*l") + std::to_string(i - 1);
    }
    text += "]\n";
  }
  return text;
}

TEST(SpecHostileTest, BillionLaughsIsRefusedBeforeBuildingNodes) {
  // 10^12 strings when expanded; 110 aliases.
  const std::string message = FailsFast(std::string(kHead) + Laughs(12, 10));
  EXPECT_THAT(message, HasSubstr("evil.yaml:"));
  EXPECT_THAT(message, HasSubstr("error: (file): expected at most 100 "
                                 "aliases"));
}

// The same bomb as one nested value: level i is defined inside level i+1,
// so it can sit in any single field. 81 aliases, 10^9 strings expanded.
std::string NestedLaughs(int levels, int width) {
  std::string text = "&l0 [";
  for (int j = 0; j < width; ++j) text += j ? ",lol" : "lol";
  text += "]";
  for (int i = 1; i < levels; ++i) {
    std::string next = "&l" + std::to_string(i) + " [" + text;
    for (int j = 1; j < width; ++j) next += ",*l" + std::to_string(i - 1);
    text = next + "]";
  }
  return text;
}

TEST(SpecHostileTest, AliasBombUnderTheLimitIsNotExpanded) {
  // Placed where the reader does look: lists it walks and maps it descends
  // into. Each must fail fast without expanding.
  const std::string bomb = NestedLaughs(10, 10);
  const std::string head = kHead;
  EXPECT_THAT(FailsFast(head +
                        "design_space: {n: {bind: platform.cores, "
                        "values: " +
                        bomb + "}}\n"),
              HasSubstr("evil.yaml:4:55: error: design_space.n.values[0]: "
                        "expected a number, found a list of 10 items"));
  EXPECT_THAT(FailsFast(head + "constraints: " + bomb + "\n"),
              HasSubstr("error: constraints[0]: expected a condition"));
  EXPECT_THAT(FailsFast(head + "stack: {lidar: " + bomb + "}\n"),
              HasSubstr("error: stack.lidar: expected a map"));
  EXPECT_THAT(FailsFast(head + "exploration: {start_from: " + bomb + "}\n"),
              HasSubstr("error: exploration.start_from: expected a design "
                        "point"));
  EXPECT_THAT(FailsFast(head + "bomb: " + bomb + "\n"),
              HasSubstr("error: bomb: expected a key among"));
  EXPECT_THAT(FailsFast(head + "world: {map: {generate: grid, params: " + bomb +
                        "}}\n"),
              HasSubstr("expected each key once"));
}

TEST(SpecHostileTest, SelfReferencingAliasDoesNotLoop) {
  const std::string message = FailsFast(
      std::string(kHead) +
      "design_space: &d {n: {bind: platform.cores, values: [1]}, m: *d}\n");
  EXPECT_THAT(message, HasSubstr("evil.yaml:"));
}

TEST(SpecHostileTest, DeepFlowSequenceNesting) {
  const std::string text = std::string(kHead) +
                           "design_space: " + std::string(10000, '[') +
                           std::string(10000, ']') + "\n";
  const std::string message = FailsFast(text);
  EXPECT_THAT(message, HasSubstr("evil.yaml:4:"));
  EXPECT_THAT(message, HasSubstr("expected nesting at most 64 levels deep"));
}

TEST(SpecHostileTest, DeepFlowMapNesting) {
  std::string text = std::string(kHead) + "stack: ";
  for (int i = 0; i < 10000; ++i) text += "{a: ";
  text += "1";
  text += std::string(10000, '}');
  text += "\n";
  EXPECT_THAT(FailsFast(text), HasSubstr("nesting at most 64 levels deep"));
}

TEST(SpecHostileTest, DeepBlockNesting) {
  std::string text = std::string(kHead) + "stack:\n";
  // Block style grows quadratically with indentation; 1000 levels suffice.
  for (int i = 1; i <= 1000; ++i) {
    text += std::string(static_cast<size_t>(i), ' ') + "- \n";
  }
  EXPECT_THAT(FailsFast(text), HasSubstr("nesting at most 64"));
}

TEST(SpecHostileTest, TooManyNodes) {
  std::string text =
      std::string(kHead) + "design_space: {n: {bind: platform.cores, values: [";
  for (int i = 0; i < 150000; ++i) text += i ? ",1" : "1";
  text += "]}}\n";
  EXPECT_THAT(FailsFast(text), HasSubstr("expected at most 100000 nodes"));
}

TEST(SpecHostileTest, FilesOverOneMebibyteAreRefusedUnread) {
  std::string text = std::string(kHead) + "# ";
  text += std::string(kMaxSpecBytes, 'x');
  EXPECT_THAT(FailsFast(text),
              HasSubstr("evil.yaml:1:1: error: (file): expected at most "
                        "1048576 bytes"));
}

TEST(SpecHostileTest, HugeRangeIsRefused) {
  const std::string message =
      FailsFast(std::string(kHead) +
                "design_space: {r: {bind: stack.lidar.range_m, range: [1, "
                "300], step: 0.000000001}}\n");
  EXPECT_THAT(message, HasSubstr("design_space.r.range: expected at most "
                                 "100000 values"));
}

TEST(SpecHostileTest, MultipleDocumentsAreRefused) {
  const std::string message = FailsFast(
      std::string(kHead) +
      "design_space: {n: {bind: platform.cores, values: [1]}}\n---\nadse: 1\n");
  EXPECT_THAT(message, HasSubstr("evil.yaml:5:1: error: (file): expected one "
                                 "YAML document, found a second from line 5"));
  // '...' ends a document too: what follows it is another.
  EXPECT_THAT(FailsFast(std::string(kHead) + "...\noutput: x\n"),
              HasSubstr("found a second from line 5"));
}

TEST(SpecHostileTest, TextThatIsNotUtf8IsNamedByItsEncoding) {
  std::string utf16("\xFF\xFE", 2);
  for (char c : std::string(kHead)) utf16 += std::string{c, '\0'};
  EXPECT_THAT(FailsFast(utf16),
              HasSubstr("evil.yaml:1:1: error: (file): expected UTF-8 text, "
                        "found a UTF-16 byte-order mark; save the file as "
                        "UTF-8"));
  EXPECT_THAT(FailsFast(std::string(kHead) + std::string("x: \0\n", 5)),
              HasSubstr("found a NUL byte"));
}

TEST(SpecHostileTest, ATabInTheIndentationIsNamed) {
  EXPECT_THAT(FailsFast(std::string(kHead) + "platform:\n\tkind: virtual\n"),
              HasSubstr("(a tab in the indentation of line 5: YAML indents "
                        "with spaces)"));
}

TEST(SpecHostileTest, NonScalarKeysAndControlCharacters) {
  const std::string message =
      FailsFast(std::string(kHead) + "? [a, b]\n: 1\n\"x\\u0001\\ny\": 2\n");
  EXPECT_THAT(message, HasSubstr("expected plain keys, found a list"));
  EXPECT_THAT(message, HasSubstr("found 'x?\\ny'"));
}

}  // namespace
}  // namespace adse::spec
