// Prompt templates: the bundled set loads, a broken folder is refused with
// the file and line to fix, and rendering fills placeholders exactly once.
#include "harness/llm/prompts.h"
#include "tests/testing/temp_files.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>

namespace adse::llm {
namespace {

namespace fs = std::filesystem;
using adse::testing::Slurp;
using adse::testing::WriteRaw;
using ::testing::HasSubstr;
using ::testing::StartsWith;

std::string TempDir(const std::string& name) {
  return adse::testing::FreshTempDir("adse-llmunit-prompts", name);
}

// A copy of the bundled prompts that a test may break.
std::string CopyOfBundledPrompts(const std::string& name) {
  const std::string dir = TempDir(name);
  for (const TemplateInfo& info : TemplateCatalog()) {
    fs::copy_file(DefaultPromptsDir() + "/" + info.name + ".txt",
                  dir + "/" + info.name + ".txt");
  }
  return dir;
}

// Every placeholder of `name` mapped to "<placeholder>".
std::map<std::string, std::string> AllValues(const std::string& name) {
  std::map<std::string, std::string> values;
  for (const TemplateInfo& info : TemplateCatalog()) {
    if (info.name != name) continue;
    for (const std::string& p : info.placeholders) values[p] = "<" + p + ">";
  }
  return values;
}

TEST(PromptSetTest, TheCatalogueNamesSevenTemplates) {
  std::vector<std::string> names;
  for (const TemplateInfo& info : TemplateCatalog()) names.push_back(info.name);
  EXPECT_THAT(names, ::testing::ElementsAre("dse_system", "dse_step", "command",
                                            "decipher_text", "decipher_vision",
                                            "interpret", "correction"));
}

TEST(PromptSetTest, LoadsTheBundledPromptsAtTheirVersions) {
  Result<PromptSet> set = PromptSet::Load("");
  ASSERT_TRUE(set.ok()) << set.status().ToString();
  EXPECT_EQ(set->folder(), DefaultPromptsDir());
  EXPECT_EQ(set->Versions(),
            "dse_system v1, dse_step v1, command v1, decipher_text v2, "
            "decipher_vision v1, interpret v1, correction v1");

  Result<PromptSet> named = PromptSet::Load(DefaultPromptsDir());
  ASSERT_TRUE(named.ok()) << named.status().ToString();
  EXPECT_EQ(named->Versions(), set->Versions());
}

TEST(PromptSetTest, EveryBundledTemplateRendersWithItsPlaceholders) {
  Result<PromptSet> set = PromptSet::Load("");
  ASSERT_TRUE(set.ok()) << set.status().ToString();
  for (const TemplateInfo& info : TemplateCatalog()) {
    Result<std::string> text = set->Render(info.name, AllValues(info.name));
    ASSERT_TRUE(text.ok()) << info.name << ": " << text.status().ToString();
    EXPECT_EQ(text->find("{{"), std::string::npos) << info.name;
    EXPECT_EQ(text->find("# version"), std::string::npos) << info.name;
    EXPECT_FALSE(text->empty()) << info.name;
    EXPECT_NE(text->back(), '\n') << info.name;
  }
  // The correction template, whole.
  Result<std::string> correction =
      set->Render("correction", {{"problem", "P"}, {"expected", "E"}});
  ASSERT_TRUE(correction.ok());
  EXPECT_EQ(*correction,
            "Your answer cannot be used: P\nE\n"
            "Answer again with the corrected answer only.");
}

TEST(PromptSetTest, AMissingTemplateIsNotFoundNamingTheFile) {
  const std::string dir = CopyOfBundledPrompts("missing");
  fs::remove(dir + "/decipher_vision.txt");
  Result<PromptSet> set = PromptSet::Load(dir);
  ASSERT_FALSE(set.ok());
  EXPECT_EQ(set.status().code(), Status::Code::kNotFound);
  EXPECT_THAT(
      set.status().message(),
      StartsWith(dir + "/decipher_vision.txt: prompt template missing"));

  Result<PromptSet> nowhere = PromptSet::Load(dir + "/no-such-folder");
  ASSERT_FALSE(nowhere.ok());
  EXPECT_EQ(nowhere.status().code(), Status::Code::kNotFound);
  EXPECT_THAT(nowhere.status().message(),
              StartsWith(dir + "/no-such-folder/dse_system.txt: "));
}

TEST(PromptSetTest, AnUnknownPlaceholderNamesFileLineAndTheAllowedOnes) {
  const std::string dir = CopyOfBundledPrompts("unknown");
  // Two header comment lines, then the body: {{bogus}} is on file line 5.
  WriteRaw(dir + "/dse_step.txt",
           "# version: 2\n"
           "# Role: a test.\n"
           "Iteration {{iteration}}.\n"
           "\n"
           "Also {{memory}} and {{bogus}}.\n"
           "{{evaluated}}\n");
  Result<PromptSet> set = PromptSet::Load(dir);
  ASSERT_FALSE(set.ok());
  EXPECT_EQ(set.status().code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(set.status().message(),
            dir +
                "/dse_step.txt:5: unknown placeholder {{bogus}}; dse_step "
                "may use {{iteration}}, {{remaining}}, {{last_point}}, "
                "{{last_result}}, {{last_report}}, {{memory}}, "
                "{{evaluated}}");
}

TEST(PromptSetTest, LineNumbersWithoutAHeaderStartAtOne) {
  const std::string dir = CopyOfBundledPrompts("no-header");
  WriteRaw(dir + "/correction.txt", "{{problem}} {{problem_text}}\n");
  Result<PromptSet> set = PromptSet::Load(dir);
  ASSERT_FALSE(set.ok());
  EXPECT_EQ(set.status().code(), Status::Code::kInvalidArgument);
  EXPECT_THAT(set.status().message(),
              StartsWith(dir + "/correction.txt:1: unknown placeholder "
                               "{{problem_text}}; correction may use "
                               "{{problem}}, {{expected}}"));
}

TEST(PromptSetTest, APlaceholderOfAnotherTemplateIsUnknown) {
  const std::string dir = CopyOfBundledPrompts("other-template");
  WriteRaw(dir + "/command.txt",
           "# version: 1\nPoint {{point}} at {{iteration}}\n");
  Result<PromptSet> set = PromptSet::Load(dir);
  ASSERT_FALSE(set.ok());
  EXPECT_EQ(set.status().code(), Status::Code::kInvalidArgument);
  EXPECT_THAT(set.status().message(),
              StartsWith(dir + "/command.txt:2: unknown placeholder "
                               "{{iteration}}; command may use {{point}}, "
                               "{{bindings}}, {{world}}, {{tracing_options}}"));
}

TEST(PromptSetTest, AnUnclosedPlaceholderIsInvalidArgumentNamingItsLine) {
  const std::string dir = CopyOfBundledPrompts("unclosed");
  // Closed only on the next line: still unclosed.
  WriteRaw(dir + "/decipher_text.txt",
           "# version: 1\n"
           "Point {{point}}\n"
           "Summary {{trace_summary\n"
           "}}\n");
  Result<PromptSet> set = PromptSet::Load(dir);
  ASSERT_FALSE(set.ok());
  EXPECT_EQ(set.status().code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(set.status().message(),
            dir +
                "/decipher_text.txt:3: '{{' without a closing '}}' on the "
                "same line");

  WriteRaw(dir + "/decipher_text.txt", "# version: 1\nPoint {{point");
  set = PromptSet::Load(dir);
  ASSERT_FALSE(set.ok());
  EXPECT_EQ(set.status().code(), Status::Code::kInvalidArgument);
  EXPECT_THAT(set.status().message(),
              StartsWith(dir + "/decipher_text.txt:2: '{{' without"));
}

TEST(PromptSetTest, HeaderCommentsAreNeitherTextNorPlaceholders) {
  const std::string dir = CopyOfBundledPrompts("header");
  WriteRaw(dir + "/correction.txt",
           "# version: 7\n"
           "# Uses {{problem}}; {{not_a_placeholder}} here is a comment.\n"
           "Problem: {{problem}}\n"
           "# not a comment any more\n"
           "Expected: {{expected}}\n\n\n");
  Result<PromptSet> set = PromptSet::Load(dir);
  ASSERT_TRUE(set.ok()) << set.status().ToString();
  Result<std::string> text =
      set->Render("correction", {{"problem", "P"}, {"expected", "E"}});
  ASSERT_TRUE(text.ok()) << text.status().ToString();
  EXPECT_EQ(*text, "Problem: P\n# not a comment any more\nExpected: E");
  EXPECT_THAT(set->Versions(), HasSubstr("correction v7"));
}

TEST(PromptSetTest, VersionsSayWhichTemplatesHaveNone) {
  const std::string dir = CopyOfBundledPrompts("versions");
  WriteRaw(dir + "/command.txt", "# Role: command, no version.\n{{point}}\n");
  WriteRaw(dir + "/interpret.txt", "# version:   12  \n{{request}}\n");
  WriteRaw(dir + "/decipher_text.txt", "# version: 2\r\n{{point}}\r\n");
  Result<PromptSet> set = PromptSet::Load(dir);
  ASSERT_TRUE(set.ok()) << set.status().ToString();
  EXPECT_EQ(set->Versions(),
            "dse_system v1, dse_step v1, command unversioned, "
            "decipher_text v2, decipher_vision v1, interpret v12, "
            "correction v1");
}

TEST(PromptSetTest, RenderFillsEveryPlaceholderOnceWithoutReexpandingValues) {
  const std::string dir = CopyOfBundledPrompts("render");
  WriteRaw(dir + "/correction.txt",
           "# version: 1\n"
           "{{problem}}: expected {{expected}}, again {{problem}}.\n"
           "Braces {stay} and }} alone.\n");
  Result<PromptSet> set = PromptSet::Load(dir);
  ASSERT_TRUE(set.ok()) << set.status().ToString();
  Result<std::string> text = set->Render(
      "correction", {{"problem", "{{expected}}"}, {"expected", "{{problem"}});
  ASSERT_TRUE(text.ok()) << text.status().ToString();
  EXPECT_EQ(*text,
            "{{expected}}: expected {{problem, again {{expected}}.\n"
            "Braces {stay} and }} alone.");
  // Values the template does not use are ignored.
  text = set->Render("correction",
                     {{"problem", "p"}, {"expected", "e"}, {"extra", "x"}});
  ASSERT_TRUE(text.ok());
  EXPECT_EQ(*text, "p: expected e, again p.\nBraces {stay} and }} alone.");
}

TEST(PromptSetTest, RenderWithoutAValueOrOfAnUnknownTemplateIsInternal) {
  const std::string dir = CopyOfBundledPrompts("render-missing");
  WriteRaw(dir + "/correction.txt", "# version: 1\n{{problem}} {{expected}}\n");
  Result<PromptSet> set = PromptSet::Load(dir);
  ASSERT_TRUE(set.ok()) << set.status().ToString();
  Result<std::string> text = set->Render("correction", {{"problem", "p"}});
  ASSERT_FALSE(text.ok());
  EXPECT_EQ(text.status().code(), Status::Code::kInternal);
  EXPECT_EQ(text.status().message(),
            dir + "/correction.txt: no value for {{expected}}");

  Result<std::string> unknown = set->Render("no_such_template", {});
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.status().code(), Status::Code::kInternal);
  EXPECT_THAT(unknown.status().message(), HasSubstr("no_such_template"));
}

}  // namespace
}  // namespace adse::llm
