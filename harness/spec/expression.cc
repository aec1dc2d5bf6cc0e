#include "harness/spec/expression.h"

#include <muParser.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "harness/spec/text_util.h"

namespace adse::spec {

struct Expression::Impl {
  std::string text;
  std::vector<std::string> variables;
  // muParser keeps raw pointers to these; the vector is sized once and
  // never reallocated, and a copy of Impl rebuilds the parser.
  std::vector<double> storage;
  mu::Parser parser;

  // Binds every variable to its storage slot and sets the expression.
  void Bind() {
    parser.ClearVar();
    storage.assign(variables.size(), 0.0);
    for (size_t i = 0; i < variables.size(); ++i) {
      parser.DefineVar(variables[i], &storage[i]);
    }
    parser.SetExpr(text);
  }
};

namespace {

// muParser's own `=` (and `+=` ...) assign to variables; in a constraint
// that is almost always a mistyped `==`, so refuse it.
bool HasAssignment(const std::string& text, size_t* position) {
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '=') continue;
    const char prev = i > 0 ? text[i - 1] : '\0';
    const char next = i + 1 < text.size() ? text[i + 1] : '\0';
    if (next == '=' || prev == '<' || prev == '>' || prev == '!' ||
        prev == '=') {
      continue;
    }
    *position = i;
    return true;
  }
  return false;
}

}  // namespace

Expression::Expression(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Expression::~Expression() = default;
Expression::Expression(Expression&& other) noexcept = default;
Expression& Expression::operator=(Expression&& other) noexcept = default;

Expression::Expression(const Expression& other)
    : impl_(std::make_unique<Impl>()) {
  impl_->text = other.impl_->text;
  impl_->variables = other.impl_->variables;
  // Parsed successfully once already, so this cannot throw in practice.
  try {
    impl_->Bind();
  } catch (const mu::Parser::exception_type&) {
  }
}

Expression& Expression::operator=(const Expression& other) {
  if (this != &other) *this = Expression(other);
  return *this;
}

Result<Expression> Expression::Parse(
    const std::string& text, const std::vector<std::string>& allowed_names) {
  auto impl = std::make_unique<Impl>();
  impl->text = text;
  if (text.find_first_not_of(" \t\r\n") == std::string::npos) {
    return Status::InvalidArgument("empty expression");
  }
  if (size_t position = 0; HasAssignment(text, &position)) {
    return Status::InvalidArgument("assignment '=' at position " +
                                   std::to_string(position + 1) +
                                   " (use '==' to compare)");
  }
  try {
    impl->parser.SetExpr(text);
    // Reports the names used without needing them defined; throws on syntax
    // errors.
    for (const auto& [name, unused] : impl->parser.GetUsedVar()) {
      impl->variables.push_back(name);
    }
    if (impl->parser.GetNumResults() != 1) {
      return Status::InvalidArgument(
          "several comma-separated results, expected one value");
    }
  } catch (const mu::Parser::exception_type& e) {
    return Status::InvalidArgument("syntax error: " + e.GetMsg());
  }
  std::vector<std::string> unknown;
  for (const std::string& name : impl->variables) {
    if (std::find(allowed_names.begin(), allowed_names.end(), name) ==
        allowed_names.end()) {
      return Status::InvalidArgument("unknown name '" + name + "'" +
                                     DidYouMean(name, allowed_names));
    }
  }
  try {
    impl->Bind();
    impl->parser.Eval();  // surfaces errors found only when evaluating
  } catch (const mu::Parser::exception_type& e) {
    return Status::InvalidArgument("syntax error: " + e.GetMsg());
  }
  return Expression(std::move(impl));
}

Result<double> Expression::TryEvaluate(
    const std::map<std::string, double>& values) const {
  for (size_t i = 0; i < impl_->variables.size(); ++i) {
    auto it = values.find(impl_->variables[i]);
    if (it == values.end()) {
      return Status::InvalidArgument("'" + impl_->text + "': no value for '" +
                                     impl_->variables[i] + "'");
    }
    impl_->storage[i] = it->second;
  }
  try {
    return impl_->parser.Eval();
  } catch (const mu::Parser::exception_type& e) {
    return Status::InvalidArgument("'" + impl_->text + "': " + e.GetMsg());
  }
}

double Expression::Evaluate(const std::map<std::string, double>& values) const {
  Result<double> value = TryEvaluate(values);
  return value.ok() ? *value : std::numeric_limits<double>::quiet_NaN();
}

const std::string& Expression::text() const { return impl_->text; }

const std::vector<std::string>& Expression::variables() const {
  return impl_->variables;
}

const std::vector<std::string>& Expression::ReservedNames() {
  static const std::vector<std::string> kNames = [] {
    std::vector<std::string> names;
    try {
      mu::Parser parser;
      for (const auto& [name, unused] : parser.GetFunDef()) {
        names.push_back(name);
      }
      for (const auto& [name, unused] : parser.GetConst()) {
        names.push_back(name);
      }
    } catch (const mu::Parser::exception_type&) {
    }
    return names;
  }();
  return kNames;
}

}  // namespace adse::spec
