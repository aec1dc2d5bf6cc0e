#include <fmt/core.h>

#include <cstdio>
#include <limits>
#include <string>

#include "harness/cli/cli_support.h"
#include "harness/cli/commands.h"
#include "harness/sim/run_key.h"
#include "harness/sim/simulator.h"
#include "harness/spec/spec_parser.h"

namespace adse::cli {

int RunValidate(const ValidateArgs& args) {
  std::optional<spec::Spec> spec = LoadScenarioOrReport(args.scenario);
  if (!spec) return 2;
  // Each case's world: its own start and goal must resolve.
  for (int i = 0; args.check_world && i < spec::CaseCount(*spec); ++i) {
    const spec::Spec task = sim::CaseSpec(*spec, i);
    Result<std::unique_ptr<world::World>> world =
        world::World::Open(sim::WorldSetupFromSpec(task));
    if (!world.ok()) {
      // The case's fields' marks stand in for task.*: the line cited is
      // the case's.
      ReportError(task, world.status());
      if (!task.task_case.empty()) {
        std::fprintf(stderr, "note: checking task.cases[%d] ('%s')\n", i,
                     task.task_case.c_str());
      }
      return ExitCodeFor(world.status());
    }
    const world::World& w = **world;
    std::fprintf(stderr,
                 "world%s%s: map %s, route of %zu edges, ideal path %.1f m, "
                 "%zu obstacles, %zu parking slots\n",
                 task.task_case.empty() ? "" : " of case ",
                 task.task_case.c_str(), w.map().net_path.c_str(),
                 w.route_edges().size(), w.ideal_path().length_m(),
                 w.scene().obstacles().size(),
                 w.scene().parking_slots().size());
  }
  if (!args.quiet) std::fputs(spec::NormalizedYaml(*spec).c_str(), stdout);
  std::string factors;
  for (const spec::DesignParameter& p : spec->design_space.parameters) {
    if (!factors.empty()) factors += " x ";
    factors += fmt::format("{} {}", p.name, p.values.size());
  }
  // Size() saturates at 2^64 - 1: past that, the product as a double.
  double points = 1.0;
  for (const spec::DesignParameter& p : spec->design_space.parameters) {
    points *= static_cast<double>(p.values.size());
  }
  const uint64_t size = spec->design_space.Size();
  const std::string count = size == std::numeric_limits<uint64_t>::max()
                                ? fmt::format("about {:.3g}", points)
                                : std::to_string(size);
  // A YAML comment, so stdout stays a loadable scenario.
  std::fprintf(stdout, "# %s: valid; design space: %s points (%s)\n",
               args.scenario.c_str(), count.c_str(), factors.c_str());
  return 0;
}

}  // namespace adse::cli
