// Arithmetic/comparison expressions of the scenario (`cost`, `constraints`),
// backed by muParser behind a small pimpl so its header stays out of users.
//
// Syntax (muParser): numbers, names, + - * / ^, parentheses, comparisons
// (< <= > >= == !=), && ||, the ternary `c ? a : b` and functions such as
// min(), max(), abs(), sqrt(), log(), exp(). A value is "true" when non-zero.
#ifndef ADSE_HARNESS_SPEC_EXPRESSION_H_
#define ADSE_HARNESS_SPEC_EXPRESSION_H_

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "stack/base/status.h"

namespace adse::spec {

class Expression {
 public:
  // Parses `text`, which may use only `allowed_names` as variables. Errors
  // (InvalidArgument) are one line: a syntax error with its position, an
  // unknown name with a suggestion, an assignment, or several results.
  static Result<Expression> Parse(
      const std::string& text, const std::vector<std::string>& allowed_names);

  Expression(const Expression& other);
  Expression& operator=(const Expression& other);
  Expression(Expression&& other) noexcept;
  Expression& operator=(Expression&& other) noexcept;
  ~Expression();

  // The value with the given variable values. A used variable missing from
  // `values`, or a failure inside muParser, gives NaN. Not thread-safe on
  // one object (muParser keeps state); copies are independent.
  double Evaluate(const std::map<std::string, double>& values) const;
  // Like Evaluate, but says which variable is missing.
  Result<double> TryEvaluate(const std::map<std::string, double>& values) const;

  const std::string& text() const;
  // Variable names the expression uses, sorted.
  const std::vector<std::string>& variables() const;

  // Names muParser reserves (built-in functions and constants); a design
  // parameter cannot use them.
  static const std::vector<std::string>& ReservedNames();

 private:
  struct Impl;
  explicit Expression(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace adse::spec

#endif  // ADSE_HARNESS_SPEC_EXPRESSION_H_
