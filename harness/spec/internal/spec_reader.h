// The scenario reader: walks the YAML tree along the schema (never
// generically, so shared alias nodes are visited a bounded number of
// times) and fills a Spec. Its sections are spread over spec_reader.cc
// (world, task, stack, platform), design_space_reader.cc (design space,
// cost, objectives, constraints) and run_settings_reader.cc (exploration,
// llm, harness, output).
#ifndef ADSE_HARNESS_SPEC_INTERNAL_SPEC_READER_H_
#define ADSE_HARNESS_SPEC_INTERNAL_SPEC_READER_H_

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "harness/spec/internal/yaml_reader.h"
#include "harness/spec/spec.h"

namespace adse::spec::internal {

inline constexpr char kPlatformCores[] = "platform.cores";
inline constexpr char kPlatformFreq[] = "platform.freq_ghz";

// What a design parameter may bind: the platform's cores and frequency and
// every stack knob ("stack.<path>").
std::vector<std::string> BindTargets();
// The names of KnownMetrics().
std::vector<std::string> MetricNames();
// The models of the reference study, for roles the file leaves out.
const std::map<std::string, std::string>& DefaultModels();
bool IsIdentifier(std::string_view s);
bool IsSpecName(std::string_view s);
// A usable name from a file stem: "my scenario.yaml" -> "my-scenario".
std::string NameFromFile(const std::string& file_name);
// Slurm's --time formats: M, M:S, H:M:S, D-H, D-H:M, D-H:M:S.
bool IsSlurmTime(const std::string& s);

class SpecReader : public YamlReader {
 public:
  SpecReader(Spec* spec, bool check_files)
      : YamlReader(spec->source_path, spec->base_dir, &spec->marks),
        spec_(*spec),
        check_files_(check_files) {}

  void Read(const YAML::Node& root);

 private:
  // --- sections ---
  void ReadWorld(const Val& v);
  void ReadMapSource(const Val& v);
  void ReadTraffic(const Val& v);
  void ReadTask(const Val& v);
  void ReadVia(const Val& v, std::vector<world::Location>* via);
  void ReadCases(const Val& v);
  // A start or waypoint; a goal when `goal_of` is given, whose tolerances
  // it may set.
  void ReadLocation(const Val& v, world::TaskOptions* goal_of,
                    world::Location* location);
  void ReadStack(const Val& v, const std::string& prefix);
  void ReadPlatform(const Val& v);
  void ReadDesignSpace(const Val& v);
  void ReadParameter(const std::string& name, const Val& v,
                     std::map<std::string, std::string>* bound);
  bool CheckBinding(const DesignParameter& p, const Val& at,
                    const std::vector<Val>* items);
  // False, with an error at `v`, when `metric` is one the scenario's task
  // kind does not report (a valet_parking metric in lane driving).
  bool ReportedByTask(const Val& v, const std::string& metric);
  void ReadCost(const Val& v);
  void ReadObjectives(const Val& v);
  void ReadConstraints(const Val& v);
  void ReadExploration(const Val& v);
  void ReadStartFrom(const Val& v);
  void ReadLlm(const Val& v);
  void ReadHarness(const Val& v);
  void ReadSlurm(const Val& v);
  void ReadOutput(const Val* v);
  void ReadExpression(const Val& v, const std::vector<std::string>& names,
                      const std::string& expected);

  Spec& spec_;
  bool check_files_ = true;
  bool space_ok_ = false;
};

}  // namespace adse::spec::internal

#endif  // ADSE_HARNESS_SPEC_INTERNAL_SPEC_READER_H_
