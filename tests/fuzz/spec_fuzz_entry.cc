#include <string>
#include <string_view>

#include "harness/spec/spec_parser.h"
#include "tests/fuzz/fuzz_entries.h"

namespace adse::fuzz {

Status FuzzSpecParser(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  spec::ParseOptions options;
  options.check_files = false;
  Result<spec::Spec> parsed =
      spec::ParseSpec(text, "fuzz.yaml", "/tmp", options);
  if (!parsed.ok()) return Status::Ok();  // rejected: fine
  const std::string normalized = spec::NormalizedYaml(*parsed);
  Result<spec::Spec> again =
      spec::ParseSpec(normalized, "fuzz.yaml", "/tmp", options);
  if (!again.ok()) {
    return Status::Internal("the normalised spec does not parse back:\n" +
                            again.status().message() + "\n--- normalised:\n" +
                            normalized);
  }
  const std::string renormalized = spec::NormalizedYaml(*again);
  if (renormalized != normalized) {
    return Status::Internal("normalising is not a fixed point:\n--- first:\n" +
                            normalized + "\n--- second:\n" + renormalized);
  }
  return Status::Ok();
}

}  // namespace adse::fuzz
