#include "stack/base/hash.h"

#include <openssl/evp.h>

#include <cstdio>

namespace adse {

std::string Sha256Hex(std::string_view data) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  EVP_Digest(data.data(), data.size(), digest, &length, EVP_sha256(), nullptr);
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(2 * length);
  for (unsigned int i = 0; i < length; ++i) {
    out.push_back(kHex[digest[i] >> 4]);
    out.push_back(kHex[digest[i] & 0xf]);
  }
  return out;
}

ContentHasher& ContentHasher::Add(std::string_view part) {
  buffer_ += std::to_string(part.size());
  buffer_.push_back(':');
  buffer_.append(part);
  return *this;
}

ContentHasher& ContentHasher::Add(double value) {
  // %.17g round-trips doubles exactly and is locale-independent for "C".
  char text[40];
  std::snprintf(text, sizeof(text), "%.17g", value);
  return Add(std::string_view(text));
}

ContentHasher& ContentHasher::Add(long long value) {
  return Add(std::string_view(std::to_string(value)));
}

std::string ContentHasher::Hex() const { return Sha256Hex(buffer_); }

}  // namespace adse
