// Content hashing for cache keys and run keys.
#ifndef ADSE_STACK_BASE_HASH_H_
#define ADSE_STACK_BASE_HASH_H_

#include <string>
#include <string_view>

namespace adse {

// Lower-case hex SHA-256 of `data`.
std::string Sha256Hex(std::string_view data);

// Incremental hasher; Add() length-prefixes each part so that
// ("ab","c") and ("a","bc") hash differently.
class ContentHasher {
 public:
  ContentHasher& Add(std::string_view part);
  ContentHasher& Add(double value);
  ContentHasher& Add(long long value);
  // Hex digest of all parts so far (64 characters).
  std::string Hex() const;

 private:
  std::string buffer_;
};

}  // namespace adse

#endif  // ADSE_STACK_BASE_HASH_H_
