// The muParser wrapper: names, syntax, evaluation.
#include "harness/spec/expression.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

namespace adse::spec {
namespace {

using ::testing::HasSubstr;

TEST(ExpressionTest, EvaluatesWithVariables) {
  Result<Expression> e = Expression::Parse("cores * freq_ghz + 0.5",
                                           {"cores", "freq_ghz", "unused"});
  ASSERT_TRUE(e.ok()) << e.status().message();
  EXPECT_EQ(e->variables(), (std::vector<std::string>{"cores", "freq_ghz"}));
  EXPECT_NEAR(e->Evaluate({{"cores", 4}, {"freq_ghz", 1.2}}), 5.3, 1e-12);
  EXPECT_NEAR(e->Evaluate({{"cores", 2}, {"freq_ghz", 2}}), 4.5, 1e-12);
  EXPECT_EQ(e->text(), "cores * freq_ghz + 0.5");
}

TEST(ExpressionTest, ComparisonsAndBareBooleans) {
  Result<Expression> e = Expression::Parse("nav_time_s <= 400 && completed",
                                           {"nav_time_s", "completed"});
  ASSERT_TRUE(e.ok()) << e.status().message();
  EXPECT_EQ(e->Evaluate({{"nav_time_s", 165}, {"completed", 1}}), 1.0);
  EXPECT_EQ(e->Evaluate({{"nav_time_s", 505}, {"completed", 1}}), 0.0);
  EXPECT_EQ(e->Evaluate({{"nav_time_s", 165}, {"completed", 0}}), 0.0);
  Result<Expression> bare = Expression::Parse("completed", {"completed"});
  ASSERT_TRUE(bare.ok());
  EXPECT_NE(bare->Evaluate({{"completed", 1}}), 0.0);
}

TEST(ExpressionTest, UnknownNameIsReportedWithASuggestion) {
  Result<Expression> e =
      Expression::Parse("nav_tme_s <= 400", {"nav_time_s", "completed"});
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.status().message(),
            "unknown name 'nav_tme_s' (did you mean 'nav_time_s'?)");
}

TEST(ExpressionTest, SyntaxErrors) {
  for (const char* text : {"cores *", "(cores", "cores cores", "foo(3)", ""}) {
    Result<Expression> e = Expression::Parse(text, {"cores"});
    EXPECT_FALSE(e.ok()) << text;
  }
  EXPECT_THAT(Expression::Parse("cores *", {"cores"}).status().message(),
              HasSubstr("syntax error"));
  EXPECT_THAT(Expression::Parse("cores = 3", {"cores"}).status().message(),
              HasSubstr("use '==' to compare"));
  EXPECT_THAT(Expression::Parse("cores, 3", {"cores"}).status().message(),
              HasSubstr("several"));
  EXPECT_TRUE(Expression::Parse("cores == 3", {"cores"}).ok());
  EXPECT_TRUE(Expression::Parse("cores != 3", {"cores"}).ok());
  EXPECT_TRUE(Expression::Parse("cores >= 3 ? 1 : 2", {"cores"}).ok());
}

TEST(ExpressionTest, MissingValueGivesNaNOrAnError) {
  Result<Expression> e = Expression::Parse("a + b", {"a", "b"});
  ASSERT_TRUE(e.ok());
  EXPECT_TRUE(std::isnan(e->Evaluate({{"a", 1}})));
  Result<double> v = e->TryEvaluate({{"a", 1}});
  ASSERT_FALSE(v.ok());
  EXPECT_THAT(v.status().message(), HasSubstr("no value for 'b'"));
}

TEST(ExpressionTest, CopiesAreIndependent) {
  Result<Expression> e = Expression::Parse("2 * x", {"x"});
  ASSERT_TRUE(e.ok());
  Expression copy = *e;
  Expression moved = std::move(*e);
  EXPECT_EQ(copy.Evaluate({{"x", 3}}), 6.0);
  EXPECT_EQ(moved.Evaluate({{"x", 4}}), 8.0);
  EXPECT_EQ(copy.Evaluate({{"x", 5}}), 10.0);
  Expression assigned = *Expression::Parse("1", {});
  assigned = copy;
  EXPECT_EQ(assigned.Evaluate({{"x", 1}}), 2.0);
}

TEST(ExpressionTest, ReservedNamesIncludeBuiltins) {
  const std::vector<std::string>& names = Expression::ReservedNames();
  EXPECT_NE(std::find(names.begin(), names.end(), "sin"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "_pi"), names.end());
}

}  // namespace
}  // namespace adse::spec
