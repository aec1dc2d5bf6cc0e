// `adse explore --replay`: strategies against a recorded campaign, without
// simulating, over many seeds; prints per strategy the distribution of
// true Pareto points found and of the hypervolume ratio.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <numeric>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "harness/campaign/headline.h"
#include "harness/campaign/replay.h"
#include "harness/cli/commands.h"
#include "harness/explore/strategy.h"
#include "harness/spec/spec_parser.h"
#include "harness/spec/text_util.h"

namespace adse::cli {
namespace {

struct Distribution {
  double min = 0, median = 0, mean = 0, max = 0;
};

Distribution Describe(std::vector<double> v) {
  Distribution d;
  if (v.empty()) return d;
  std::sort(v.begin(), v.end());
  d.min = v.front();
  d.max = v.back();
  d.mean =
      std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  const size_t n = v.size();
  d.median = n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  return d;
}

// " (median 8 left, 3 runs to settle them)" over the seeds that found the
// cheapest design; empty when none did.
std::string UntriedText(const std::vector<double>& left,
                        const std::vector<double>& settle) {
  if (left.empty()) return std::string();
  std::string settling;
  if (!settle.empty()) {
    const double runs = Describe(settle).median;
    settling =
        fmt::format(", {:g} run{} to settle them", runs, runs == 1 ? "" : "s");
  }
  return fmt::format(" (median {:g} left{})", Describe(left).median, settling);
}

// " after a median of 2 confirm runs of at most 3"; empty without any.
std::string ConfirmText(const std::vector<double>& used, int at_most) {
  if (at_most <= 0) return std::string();
  const double median = Describe(used).median;
  return fmt::format(" after a median of {:g} confirm run{} of at most {}",
                     median, median == 1 ? "" : "s", at_most);
}

}  // namespace

int RunExplore(const ExploreArgs& args) {
  // Seeds first..first+seeds-1, none past the largest.
  if (args.seeds > 0 &&
      args.first_seed > std::numeric_limits<uint64_t>::max() -
                            static_cast<uint64_t>(args.seeds - 1)) {
    std::fprintf(
        stderr,
        "error: --first-seed %llu: with --seeds %d the seeds run "
        "past %llu; give a smaller first seed\n",
        static_cast<unsigned long long>(args.first_seed), args.seeds,
        static_cast<unsigned long long>(std::numeric_limits<uint64_t>::max()));
    return 2;
  }
  // Each strategy once, none empty ("agent,,random").
  for (size_t i = 0; i < args.strategies.size(); ++i) {
    const std::string& name = args.strategies[i];
    if (name.empty() ||
        std::find(args.strategies.begin(), args.strategies.begin() + i, name) !=
            args.strategies.begin() + i) {
      std::fprintf(stderr, "error: --strategy: %s; name each strategy once\n",
                   name.empty() ? "an empty name in the list"
                                : ("'" + name + "' given twice").c_str());
      return 2;
    }
  }
  Result<campaign::Recording> recording = campaign::LoadRecording(args.replay);
  if (!recording.ok()) {
    std::fprintf(stderr, "error: --replay: %s\n",
                 recording.status().message().c_str());
    return ExitCodeFor(recording.status());
  }
  if (!args.objectives.empty()) {
    Status kept = campaign::KeepObjectives(args.objectives, &*recording);
    if (!kept.ok()) {
      std::fprintf(stderr, "error: --objectives: %s\n", kept.message().c_str());
      return ExitCodeFor(kept);
    }
  }
  std::vector<std::string> strategies = args.strategies;
  if (strategies.empty()) strategies = explore::StrategyNames();
  const int budget =
      args.budget > 0 ? args.budget : recording->spec.exploration.budget;
  const int confirm_runs = args.confirm_runs >= 0
                               ? args.confirm_runs
                               : recording->spec.exploration.confirm_runs;
  const int initial_points = args.initial_points >= 0
                                 ? args.initial_points
                                 : recording->spec.exploration.initial_points;
  nlohmann::json out = {{"recording", args.replay},
                        {"recorded_evaluations", recording->rows.size()},
                        {"budget", budget},
                        {"confirm_runs", confirm_runs},
                        {"initial_points", initial_points},
                        {"seeds", args.seeds},
                        {"objectives", nlohmann::json::array()},
                        {"strategies", nlohmann::json::object()}};
  for (const spec::Objective& objective : recording->spec.objectives) {
    out["objectives"].push_back(objective.metric);
  }
  // The recording's own answer, from the same front as adse run's.
  const campaign::Headline answer =
      campaign::ComputeHeadline(recording->spec, recording->rows);
  out["answer"] =
      campaign::AnswerJson(recording->spec, recording->rows, answer);
  // The table is printed once every strategy has replayed: one that cannot
  // (an llm strategy without recorded exchanges) leaves no half table.
  std::string table;
  // --rationale: every seed's rounds, printed after the table.
  const bool show_rationale = args.rationale && !args.json;
  std::string rationales;
  for (const std::string& name : strategies) {
    const auto started = std::chrono::steady_clock::now();
    std::vector<double> found, ratio, first, left, settle, confirming;
    int front = 0, missing = 0, cheapest = 0, confirmed = 0;
    nlohmann::json runs = nlohmann::json::array();
    for (int i = 0; i < args.seeds; ++i) {
      const uint64_t seed = args.first_seed + static_cast<uint64_t>(i);
      Result<campaign::ReplayRun> run = campaign::Replay(
          *recording, name, seed, budget, confirm_runs, initial_points);
      if (!run.ok()) {
        std::fprintf(stderr, "error: --strategy %s: %s\n", name.c_str(),
                     run.status().message().c_str());
        return ExitCodeFor(run.status());
      }
      found.push_back(run->true_pareto_found);
      ratio.push_back(run->hypervolume_ratio);
      if (run->first_true_pareto_at > 0)
        first.push_back(run->first_true_pareto_at);
      front = run->front_size;
      missing += run->missing;
      cheapest += run->found_cheapest_feasible;
      confirmed += run->cheapest_confirmed;
      confirming.push_back(run->confirm_evaluations);
      if (run->cheaper_left_untried >= 0) {
        left.push_back(static_cast<double>(run->cheaper_left_untried));
      }
      if (run->runs_to_settle >= 0) {
        settle.push_back(static_cast<double>(run->runs_to_settle));
      }
      const spec::DesignSpace& space = recording->spec.design_space;
      nlohmann::json proposals = nlohmann::json::array();
      for (const spec::DesignPoint& point : run->proposals) {
        proposals.push_back(spec::FormatPoint(space, point));
      }
      nlohmann::json iterations = nlohmann::json::array();
      if (show_rationale) {
        rationales += fmt::format("{} seed {}:\n", name, seed);
      }
      for (const campaign::ReplayIteration& iteration : run->iterations) {
        std::vector<std::string> points;
        for (const spec::DesignPoint& point : iteration.points) {
          points.push_back(spec::FormatPoint(space, point));
        }
        if (show_rationale) {
          rationales += fmt::format(
              "  iteration {}: {}{}{}\n", iteration.iteration,
              fmt::join(points, "; "),
              iteration.rationale.empty() ? "" : " <- ", iteration.rationale);
        }
        iterations.push_back({{"iteration", iteration.iteration},
                              {"points", points},
                              {"rationale", iteration.rationale}});
      }
      runs.push_back(
          {{"seed", seed},
           {"proposals", proposals},
           {"iterations", iterations},
           {"evaluations", run->evaluations},
           {"confirm_evaluations", run->confirm_evaluations},
           {"true_pareto_found", run->true_pareto_found},
           {"hypervolume_ratio", run->hypervolume_ratio},
           {"first_true_pareto_at", run->first_true_pareto_at},
           {"found_cheapest_feasible", run->found_cheapest_feasible},
           {"cheapest_confirmed", run->cheapest_confirmed},
           {"cheaper_left_untried",
            run->cheaper_left_untried >= 0
                ? nlohmann::json(run->cheaper_left_untried)
                : nlohmann::json()},
           {"runs_to_settle", run->runs_to_settle >= 0
                                  ? nlohmann::json(run->runs_to_settle)
                                  : nlohmann::json()},
           {"not_recorded", run->missing}});
    }
    const Distribution f = Describe(found), r = Describe(ratio),
                       a = Describe(first);
    out["strategies"][name] = {{"true_pareto_found",
                                {{"min", f.min},
                                 {"median", f.median},
                                 {"mean", f.mean},
                                 {"max", f.max}}},
                               {"hypervolume_ratio",
                                {{"min", r.min},
                                 {"median", r.median},
                                 {"mean", r.mean},
                                 {"max", r.max}}},
                               {"true_front_size", front},
                               {"seeds_that_found_cheapest_feasible", cheapest},
                               {"seeds_that_confirmed_cheapest", confirmed},
                               {"runs", runs}};
    table += fmt::format(
        "| {} | {:g} / {:g} / {:.2f} / {:g} | {} | {:.3f} / {:.3f} / {:.3f} / "
        "{:.3f} | {} | {} of {} seeds | {} of {} seeds{}{} | {} |\n",
        name, f.min, f.median, f.mean, f.max, front, r.min, r.median, r.mean,
        r.max,
        first.empty() ? "never"
                      : fmt::format("{:g} ({} of {} seeds)", a.median,
                                    first.size(), args.seeds),
        cheapest, args.seeds, confirmed, args.seeds,
        ConfirmText(confirming, confirm_runs), UntriedText(left, settle),
        missing);
    if (!args.json) {  // with --json, stdout's JSON alone
      std::fprintf(
          stderr, "%s: %s replayed in %.0f s\n", name.c_str(),
          spec::Counted(static_cast<size_t>(args.seeds), "seed").c_str(),
          std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                        started)
              .count());
    }
  }
  if (!args.json) {
    std::printf(
        "replay of %s: %zu recorded evaluations, budget %d%s%s, seeds "
        "%llu..%llu\n",
        args.replay.c_str(), recording->rows.size(), budget,
        confirm_runs > 0
            ? fmt::format(" and up to {} confirm runs", confirm_runs).c_str()
            : "",
        initial_points > 0
            ? fmt::format(" (the agent's {} initial point{} seeded)",
                          initial_points, initial_points == 1 ? "" : "s")
                  .c_str()
            : "",
        static_cast<unsigned long long>(args.first_seed),
        static_cast<unsigned long long>(args.first_seed + args.seeds - 1));
    std::printf("the recording's answer:\n%s\n",
                campaign::HeadlineText(recording->spec, recording->rows, answer)
                    .c_str());
    std::printf(
        "| strategy | true Pareto points found (min / median / mean / max) | "
        "of front | hypervolume ratio (min / median / mean / max) | first "
        "true Pareto point at (median eval) | cheapest feasible found | "
        "cheapest confirmed (no cheaper design left untried) | not "
        "recorded |\n|---|---|---|---|---|---|---|---|\n%s",
        table.c_str());
  }
  if (!rationales.empty()) std::printf("\n%s", rationales.c_str());
  if (args.json) std::printf("%s\n", out.dump(2).c_str());
  return 0;
}

}  // namespace adse::cli
