// `adse profile import` and `adse profile show`: cost profiles from a CARET
// report (harness/profile). Exit 0 ok, 2 bad input (a missing or malformed
// report, mapping or profile), 1 anything else (e.g. the write failed); a
// failed import writes nothing.
#include <cstdio>
#include <set>
#include <string>

#include "harness/cli/commands.h"
#include "harness/profile/profile.h"

namespace adse::cli {

int RunProfileImport(const ProfileImportArgs& args) {
  Result<profile::Profile> imported =
      profile::ImportCaret(args.caret, args.mapping);
  if (!imported.ok()) {
    std::fprintf(stderr, "%s\n", imported.status().message().c_str());
    std::fprintf(stderr, "no profile written\n");
    return ExitCodeFor(imported.status());
  }
  const Status written = profile::WriteProfile(args.out, *imported);
  if (!written.ok()) {
    std::fprintf(stderr, "error: writing %s: %s\n", args.out.c_str(),
                 written.message().c_str());
    return ExitCodeFor(written);
  }
  // One CARET callback may stand for several adse callbacks.
  std::set<std::string> sources;
  for (const auto& entry : imported->provenance) {
    sources.insert(entry.second.sources.begin(), entry.second.sources.end());
  }
  std::printf(
      "wrote %s: profile '%s', %zu callbacks from %zu CARET callbacks; total "
      "load %.2f cores busy at %g GHz%s\n",
      args.out.c_str(), imported->name.c_str(),
      imported->costs.callbacks.size(), sources.size(),
      profile::TotalLoadCores(*imported), imported->costs.reference_ghz,
      imported->source.reference_ghz_assumed ? " (assumed clock)" : "");
  return 0;
}

int RunProfileShow(const ProfileShowArgs& args) {
  Result<profile::Profile> loaded = profile::ReadProfile(args.profile);
  if (!loaded.ok()) {
    std::fprintf(stderr, "%s\n", loaded.status().message().c_str());
    return ExitCodeFor(loaded.status());
  }
  std::printf("%s", profile::FormatProfileTable(*loaded).c_str());
  return 0;
}

}  // namespace adse::cli
