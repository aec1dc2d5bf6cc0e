// One table of names per enum. The parser, the factories, --help and the
// docs all read the same table, so no value can be known to one of them
// and missing from another. Each module keeps the tables of its own enums
// next to them and exposes an XToString / StringToX / XNames triple.
#ifndef ADSE_STACK_BASE_VOCABULARY_H_
#define ADSE_STACK_BASE_VOCABULARY_H_

#include <string>
#include <string_view>
#include <vector>

namespace adse {

template <typename E>
struct Term {
  E value;
  const char* name;
};

// The name of `value`; "unknown" for a value missing from the table (a
// cast of an out-of-range integer).
template <typename E>
const char* NameOf(const std::vector<Term<E>>& terms, E value) {
  for (const Term<E>& t : terms) {
    if (t.value == value) return t.name;
  }
  return "unknown";
}

// False when `name` is not in the table; `value` is then unchanged.
template <typename E>
bool ValueOf(const std::vector<Term<E>>& terms, std::string_view name,
             E* value) {
  for (const Term<E>& t : terms) {
    if (name == t.name) {
      *value = t.value;
      return true;
    }
  }
  return false;
}

template <typename E>
std::vector<std::string> NamesOf(const std::vector<Term<E>>& terms) {
  std::vector<std::string> names;
  for (const Term<E>& t : terms) names.push_back(t.name);
  return names;
}

// What a reader says of a token missing from its vocabulary: "unknown
// <what> '<token>'; valid kinds: a, b, c" (the caller adds where it was).
inline std::string UnknownTermMessage(std::string_view what,
                                      std::string_view token,
                                      const std::vector<std::string>& valid) {
  std::string message = "unknown ";
  message.append(what).append(" '").append(token).append("'; valid kinds: ");
  for (size_t i = 0; i < valid.size(); ++i) {
    if (i > 0) message += ", ";
    message += valid[i];
  }
  return message;
}

}  // namespace adse

#endif  // ADSE_STACK_BASE_VOCABULARY_H_
