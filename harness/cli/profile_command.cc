// `adse profile import`, `show` and `check`: cost profiles from a CARET
// report (harness/profile), and a simulation held against their source. Exit 0
// ok, 2 bad input (a missing or malformed report, mapping or profile), 1
// anything else (e.g. the write failed); a failed import writes nothing.
#include <cstdio>
#include <filesystem>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "analysis/pictures/pictures.h"
#include "analysis/runfile/run_file.h"
#include "harness/cli/cli_support.h"
#include "harness/cli/commands.h"
#include "harness/profile/profile.h"
#include "harness/profile/profile_check.h"
#include "harness/sim/simulator.h"
#include "harness/spec/spec_parser.h"
#include "stack/base/files.h"

namespace adse::cli {

int RunProfileImport(const ProfileImportArgs& args) {
  // Never over its own input, nor over anything but an earlier profile.
  std::error_code same_ec;
  if (std::filesystem::exists(args.out, same_ec) &&
      std::filesystem::equivalent(args.out, args.mapping, same_ec)) {
    std::fprintf(stderr,
                 "error: -o %s: that is the mapping (--map) being read; give "
                 "the profile a path of its own\n",
                 args.out.c_str());
    return 2;
  }
  if (Status usable = CheckOutputFile(args.out, kProfileFile); !usable.ok()) {
    std::fprintf(stderr, "error: %s\n", usable.message().c_str());
    return 2;
  }
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

int RunProfileCheck(const ProfileCheckArgs& args) {
  std::optional<spec::Spec> loaded =
      LoadCaseOrReport(args.scenario, args.task_case);
  if (!loaded) return 2;
  spec::Spec spec = std::move(*loaded);
  if (spec.platform.profile.empty()) {
    std::fprintf(stderr,
                 "error: %s: platform.profile: expected a cost profile to "
                 "check, found none (profile check compares a profile's "
                 "source with adse)\n",
                 args.scenario.c_str());
    return 2;
  }
  Result<profile::Profile> costs = profile::ReadProfile(spec.platform.profile);
  if (!costs.ok()) {
    std::fprintf(stderr, "%s\n", costs.status().message().c_str());
    return ExitCodeFor(costs.status());
  }
  // The reference machine replaces what the design space would choose;
  // its other parameters take their exploration.start_from value, else
  // their first.
  spec.platform.cores = args.cores;
  spec.platform.freq_ghz = costs->costs.reference_ghz;
  const Status rate = spec.stack.Set("lidar.rate_hz", args.lidar_hz);
  if (!rate.ok()) {
    std::fprintf(stderr, "error: --lidar-hz: %s\n", rate.message().c_str());
    return 2;
  }
  std::vector<spec::DesignParameter> kept;
  spec::DesignPoint point;
  for (const spec::DesignParameter& p : spec.design_space.parameters) {
    if (p.bind == "platform.cores" || p.bind == "platform.freq_ghz" ||
        p.bind == "stack.lidar.rate_hz") {
      continue;
    }
    const auto from = spec.exploration.start_from.find(p.name);
    point[p.name] = from != spec.exploration.start_from.end()
                        ? from->second
                        : p.values.front();
    kept.push_back(p);
  }
  spec.design_space.parameters = std::move(kept);
  spec.exploration.start_from.clear();
  // By default one folder per case, as simulate and world keep theirs.
  const std::string out =
      !args.out.empty()
          ? args.out
          : spec.ResolvedOutput() + "/profile-check" +
                (spec.task_case.empty() ? "" : "/" + spec.task_case);
  OutputFolderLayout layout;
  layout.files = {"run.h5", "check.txt", "check.png"};
  if (Status usable = CheckOutputFolder(out, layout); !usable.ok()) {
    std::fprintf(stderr, "error: %s\n", usable.message().c_str());
    return 2;
  }
  std::fprintf(stderr,
               "simulating %s on the reference machine of profile '%s': %d "
               "cores at %g GHz, LiDAR %g Hz ...\n",
               spec.name.c_str(), costs->name.c_str(), args.cores,
               costs->costs.reference_ghz, args.lidar_hz);
  Result<runfile::RunData> run = sim::SimulatePoint(spec, point);
  if (!run.ok()) {
    std::fprintf(stderr, "%s\n", run.status().message().c_str());
    return ExitCodeFor(run.status());
  }
  const profile::ProfileCheck check = profile::CompareWithProfile(*run, *costs);
  // The text and the picture both say which case was driven.
  const std::string of_case =
      args.task_case.empty() ? "" : ", case " + args.task_case;
  const std::string text =
      fmt::format(
          "profile check of '{}' ({}){}: {} after {:.1f} s simulated\n\n",
          costs->name, costs->source.cpu, of_case, run->termination_reason,
          run->metrics.count("nav_time_s") ? run->metrics.at("nav_time_s")
                                           : 0.0) +
      profile::FormatProfileCheck(check);
  std::printf("%s", text.c_str());

  // The three files go into a private folder renamed into place whole.
  const std::string tmp = StartOutputFolder(out);
  Status saved = MakeDirs(tmp);
  if (saved.ok()) saved = runfile::WriteRunFile(tmp + "/run.h5", *run);
  if (saved.ok()) saved = WriteFileAtomic(tmp + "/check.txt", text);
  if (saved.ok()) {
    // The chains, then the callbacks that cost at least 1 ms at the source.
    std::vector<analysis::ComparisonRow> rows;
    for (const profile::CheckRow& r : check.chains) {
      rows.push_back({r.name, r.adse_avg_ms, r.source_avg_ms});
    }
    for (const profile::CheckRow& r : check.callbacks) {
      if (r.source_avg_ms.value_or(0.0) < 1.0) continue;
      rows.push_back({r.name, r.adse_avg_ms, r.source_avg_ms});
    }
    analysis::ComparisonChartOptions o;
    o.title = fmt::format(
        "profile check{}: mean latency, adse on {} cores at {} GHz vs {}",
        of_case, args.cores, costs->costs.reference_ghz, costs->name);
    o.reference_name = "measured by CARET";
    saved = analysis::RenderComparisonChart(rows, o, tmp + "/check.png");
  }
  if (saved.ok()) saved = PutFolderInPlace(tmp, out);
  if (!saved.ok()) {
    std::error_code ec;
    std::filesystem::remove_all(tmp, ec);
    std::fprintf(stderr, "error: %s\n", saved.message().c_str());
    return ExitCodeFor(saved);
  }
  std::printf("\nwrote %s/run.h5, check.txt, check.png\n", out.c_str());
  return 0;
}

}  // namespace adse::cli
