// Parsing of valid scenarios: the reference example, defaults, paths, the
// repository's example files and the NormalizedYaml round trip.
#include "harness/spec/spec_parser.h"
#include "tests/testing/temp_files.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace adse::spec {
namespace {

namespace fs = std::filesystem;

// The reference study of the design brief, with a generated map.
constexpr char kReference[] = R"(adse: 1
name: robotaxi-parking-lot
world:
  map: {generate: parking_lot, params: {rows: 4, slots_per_row: 12, aisle_width_m: 7.0}}
  traffic: {seed: 7, flows: [{from: E0, to: E1, vehicles_per_hour: 120}], parked_occupancy: 0.6}
  weather: clear
  step_s: 0.05
task:
  kind: lane_driving
  start: {x: 0.0, y: 0.0}
  goal:  {x: 80.0, y: 40.0, tolerance_m: 2.0}
  speed_limit_kmh: 30
  timeout_s: 1500
stack:
  lidar: {rate_hz: 10, beams: 16, horizontal_resolution_deg: 0.4, range_m: 60}
platform: {kind: virtual, reference_ghz: 2.1, cost_model: measured}
design_space:
  cores:    {bind: platform.cores,      range: [1, 28]}
  freq_ghz: {bind: platform.freq_ghz,   values: [1.0, 1.2, 1.5, 1.8, 2.1]}
  lidar_hz: {bind: stack.lidar.rate_hz, values: [7, 14]}
cost: cores * freq_ghz
objectives: [{minimize: hardware_cost}, {minimize: nav_time_s}, {minimize: deviation_score}, {maximize: ctrl_rate_hz}]
constraints: [nav_time_s <= 400, ctrl_rate_hz >= 1, completed]
exploration: {strategy: agent, budget: 15, batch: 1, seed: 1, start_from: {cores: 12, freq_ghz: 1.5, lidar_hz: 14}}
llm: {backend: ollama, endpoint: "http://127.0.0.1:11434", models: {dse: deepseek-r1, vision: mistral-small3.1, text: "llama4:scout", command: llama3.1, interpretation: llama3.1}}
harness: {workers: auto, cores_per_worker: 1, memory_mb: 4096, run_timeout_s: 900, retries: 1, replicas: 1}
output: results/robotaxi-parking-lot
)";

constexpr double kTol = 1e-9;

void WriteText(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary);
  out << text;
}

Spec ParseOk(const std::string& text, const std::string& base_dir = "") {
  Result<Spec> spec = ParseSpec(text, "test.yaml", base_dir);
  EXPECT_TRUE(spec.ok()) << spec.status().message();
  return spec.ok() ? *spec : Spec();
}

TEST(SpecParserTest, ReferenceExampleGivesThe280PointSpace) {
  const Spec spec = ParseOk(kReference);
  EXPECT_EQ(spec.name, "robotaxi-parking-lot");
  ASSERT_EQ(spec.design_space.parameters.size(), 3u);
  EXPECT_EQ(spec.design_space.Size(), 280u);

  const DesignParameter* cores = spec.design_space.Find("cores");
  ASSERT_NE(cores, nullptr);
  EXPECT_EQ(cores->bind, "platform.cores");
  ASSERT_EQ(cores->values.size(), 28u);
  EXPECT_NEAR(cores->values.front(), 1, kTol);
  EXPECT_NEAR(cores->values.back(), 28, kTol);
  EXPECT_TRUE(cores->integer);

  const DesignParameter* freq = spec.design_space.Find("freq_ghz");
  ASSERT_NE(freq, nullptr);
  ASSERT_EQ(freq->values.size(), 5u);
  EXPECT_NEAR(freq->values[1], 1.2, kTol);
  EXPECT_FALSE(freq->integer);

  const DesignParameter* lidar = spec.design_space.Find("lidar_hz");
  ASSERT_NE(lidar, nullptr);
  EXPECT_EQ(lidar->bind, "stack.lidar.rate_hz");
  EXPECT_TRUE(lidar->integer);
  EXPECT_EQ(spec.design_space.FindByBind("stack.lidar.rate_hz"), lidar);
}

TEST(SpecParserTest, ReferenceExampleFillsEverySection) {
  const Spec spec = ParseOk(kReference);
  EXPECT_EQ(spec.world.map.generator, "parking_lot");
  EXPECT_TRUE(spec.world.map.net_path.empty());
  EXPECT_NEAR(spec.world.map.generator_params.at("rows"), 4, kTol);
  EXPECT_NEAR(spec.world.map.generator_params.at("aisle_width_m"), 7.0, kTol);
  // Defaults of params the file does not give.
  EXPECT_NEAR(spec.world.map.generator_params.at("slot_width_m"), 2.5, kTol);
  EXPECT_NEAR(spec.world.map.generator_params.at("slot_depth_m"), 5.0, kTol);
  EXPECT_EQ(spec.world.traffic.seed, 7u);
  ASSERT_EQ(spec.world.traffic.flows.size(), 1u);
  EXPECT_EQ(spec.world.traffic.flows[0].from_edge, "E0");
  EXPECT_NEAR(spec.world.traffic.flows[0].vehicles_per_hour, 120, kTol);
  EXPECT_NEAR(spec.world.traffic.parked_occupancy, 0.6, kTol);
  // Not given: a game's signal is switched as its player would.
  EXPECT_NEAR(spec.world.traffic.signal_program_switch_s, 30.0, kTol);
  EXPECT_EQ(spec.world.weather, world::Weather::kClear);
  EXPECT_NEAR(spec.world.step_s, 0.05, kTol);

  EXPECT_EQ(spec.task.kind, world::TaskKind::kLaneDriving);
  EXPECT_FALSE(spec.task.start.by_edge);
  EXPECT_NEAR(spec.task.goal.x_m, 80, kTol);
  EXPECT_NEAR(spec.task.goal.y_m, 40, kTol);
  EXPECT_NEAR(spec.task.goal_tolerance_m, 2.0, kTol);
  EXPECT_NEAR(spec.task.speed_limit_kmh, 30, kTol);
  EXPECT_NEAR(spec.task.timeout_s, 1500, kTol);

  EXPECT_NEAR(spec.stack.Get("lidar.rate_hz"), 10, kTol);
  EXPECT_NEAR(spec.stack.Get("lidar.range_m"), 60, kTol);

  EXPECT_EQ(spec.platform.kind, PlatformKind::kVirtual);
  EXPECT_NEAR(spec.platform.reference_ghz, 2.1, kTol);
  EXPECT_EQ(spec.platform.cores, 4);  // default, bound by the space anyway

  EXPECT_EQ(spec.cost, "cores * freq_ghz");
  ASSERT_EQ(spec.objectives.size(), 4u);
  EXPECT_EQ(spec.objectives[3].metric, "ctrl_rate_hz");
  EXPECT_FALSE(spec.objectives[3].minimize);
  ASSERT_EQ(spec.constraints.size(), 3u);
  EXPECT_EQ(spec.constraints[0], "nav_time_s <= 400");
  EXPECT_EQ(spec.constraints[2], "completed");

  EXPECT_EQ(spec.exploration.strategy, "agent");
  EXPECT_EQ(spec.exploration.budget, 15);
  EXPECT_EQ(spec.exploration.confirm_runs, 0);    // off unless asked for
  EXPECT_EQ(spec.exploration.initial_points, 0);  // the model picks
  EXPECT_NEAR(spec.exploration.start_from.at("freq_ghz"), 1.5, kTol);
  EXPECT_EQ(spec.exploration.population, 8);

  EXPECT_EQ(spec.llm.backend, "ollama");
  EXPECT_EQ(spec.llm.models.at("text"), "llama4:scout");
  EXPECT_EQ(spec.harness.workers, 0);
  EXPECT_EQ(spec.harness.memory_mb, 4096);
  EXPECT_EQ(spec.harness.isolation, "auto");
  EXPECT_EQ(spec.harness.slurm.time_limit, "02:00:00");
  EXPECT_EQ(spec.output, "results/robotaxi-parking-lot");
}

TEST(SpecParserTest, MarksPointAtWhereFieldsWereWritten) {
  const Spec spec = ParseOk(kReference);
  // task.goal is on line 11, its key in column 3.
  ASSERT_TRUE(spec.marks.count("task.goal"));
  EXPECT_EQ(spec.marks.at("task.goal").line, 11);
  EXPECT_EQ(spec.marks.at("task.goal").column, 3);
  EXPECT_EQ(spec.Where("task.goal"), "test.yaml:11:3: ");
  EXPECT_EQ(spec.Where("design_space.lidar_hz"), "test.yaml:20:3: ");
  EXPECT_EQ(spec.Where("constraints[1]").rfind("test.yaml:23:", 0), 0u);
  // A defaulted field cites its closest written parent.
  EXPECT_EQ(spec.Where("exploration.population").rfind("test.yaml:24:", 0), 0u);
  EXPECT_EQ(spec.Where("no_such_field"), "test.yaml: ");
}

TEST(SpecParserTest, MinimalSpecTakesDefaults) {
  const Spec spec = ParseOk(R"(adse: 1
world: {map: {generate: grid}}
task: {start: {edge: E0}, goal: {edge: E5, pos_m: 20, lane: 1}}
design_space: {n: {bind: platform.cores, values: [2, 4]}}
)");
  EXPECT_EQ(spec.name, "test");  // the file stem
  EXPECT_EQ(spec.output, "results/test");
  EXPECT_EQ(spec.world.map.generator, "grid");
  EXPECT_NEAR(spec.world.map.generator_params.at("number"), 3, kTol);
  EXPECT_NEAR(spec.world.map.generator_params.at("length_m"), 100, kTol);
  EXPECT_NEAR(spec.world.map.generator_params.at("lanes"), 1, kTol);
  EXPECT_TRUE(spec.task.start.by_edge);
  EXPECT_EQ(spec.task.start.edge, "E0");
  EXPECT_EQ(spec.task.goal.lane, 1);
  EXPECT_NEAR(spec.task.goal.pos_m, 20, kTol);
  ASSERT_EQ(spec.objectives.size(), 2u);
  EXPECT_EQ(spec.objectives[0].metric, "hardware_cost");
  EXPECT_EQ(spec.objectives[1].metric, "nav_time_s");
  ASSERT_EQ(spec.constraints.size(), 1u);
  EXPECT_EQ(spec.constraints[0], "completed");
  EXPECT_EQ(spec.cost, "cores * freq_ghz");
  EXPECT_EQ(spec.llm.models.size(), 5u);
  EXPECT_EQ(spec.exploration.strategy, "agent");
  EXPECT_TRUE(spec.exploration.start_from.empty());
  EXPECT_EQ(spec.Where("harness.memory_mb"), "test.yaml: ");
}

TEST(SpecParserTest, RangeWithStepExpandsAscending) {
  const Spec spec = ParseOk(R"(adse: 1
world: {map: {generate: grid}}
task: {start: {x: 0, y: 0}, goal: {x: 1, y: 1}}
design_space:
  f: {bind: platform.freq_ghz, range: [1.0, 2.0], step: 0.1}
  r: {bind: stack.lidar.range_m, range: [20, 100], step: 40}
)");
  const DesignParameter* f = spec.design_space.Find("f");
  ASSERT_NE(f, nullptr);
  ASSERT_EQ(f->values.size(), 11u);
  EXPECT_NEAR(f->values[3], 1.3, kTol);
  EXPECT_NEAR(f->values.back(), 2.0, kTol);
  EXPECT_EQ(f->IndexOf(1.3), 3);  // binary noise rounded away
  EXPECT_FALSE(f->integer);
  const DesignParameter* r = spec.design_space.Find("r");
  ASSERT_NE(r, nullptr);
  ASSERT_EQ(r->values.size(), 3u);
  EXPECT_NEAR(r->values[2], 100, kTol);
  EXPECT_TRUE(r->integer);
  EXPECT_EQ(spec.design_space.Size(), 33u);
}

TEST(SpecParserTest, ValuesAreStoredSorted) {
  const Spec spec = ParseOk(R"(adse: 1
world: {map: {generate: grid}}
task: {start: {x: 0, y: 0}, goal: {x: 1, y: 1}}
design_space: {hz: {bind: stack.lidar.rate_hz, values: [14, 7, 10]}}
)");
  const DesignParameter* hz = spec.design_space.Find("hz");
  ASSERT_NE(hz, nullptr);
  ASSERT_EQ(hz->values.size(), 3u);
  EXPECT_NEAR(hz->values[0], 7, kTol);
  EXPECT_NEAR(hz->values[1], 10, kTol);
  EXPECT_NEAR(hz->values[2], 14, kTol);
}

TEST(SpecParserTest, KnobRolesDefaultFromTheBindAndMayBeDeclared) {
  const Spec spec = ParseOk(R"(adse: 1
world: {map: {generate: grid}}
task: {start: {x: 0, y: 0}, goal: {x: 1, y: 1}}
design_space:
  cores: {bind: platform.cores, range: [1, 4]}
  freq_ghz: {bind: platform.freq_ghz, values: [1, 2]}
  hz: {bind: stack.lidar.rate_hz, values: [7, 14]}
  odo: {bind: stack.odometry.rate_hz, values: [25, 50]}
  leaf: {bind: stack.localization.voxel_leaf_m, values: [1, 2]}
  step: {bind: stack.lidar.horizontal_resolution_deg, values: [0.2, 0.4]}
  iterations: {bind: stack.localization.ndt_max_iterations, values: [10, 30]}
  ctrl: {bind: stack.control.rate_hz, values: [10, 30], role: frequency}
  thin: {bind: stack.perception.min_cluster_points, values: [5, 10], role: downsample}
)");
  auto role = [&spec](const char* name) {
    return spec.design_space.Find(name)->role;
  };
  EXPECT_EQ(role("cores"), KnobRole::kCores);
  EXPECT_EQ(role("freq_ghz"), KnobRole::kFrequency);
  EXPECT_EQ(role("hz"), KnobRole::kSensorRate);
  EXPECT_EQ(role("odo"), KnobRole::kSensorRate);
  // A voxel or azimuth step thins the data the stack works on.
  EXPECT_EQ(role("leaf"), KnobRole::kDownsample);
  EXPECT_EQ(role("step"), KnobRole::kDownsample);
  // Any other knob has no role unless declared; a node's timer rate is no
  // sensor.
  EXPECT_EQ(role("iterations"), KnobRole::kNone);
  EXPECT_EQ(role("ctrl"), KnobRole::kFrequency);
  EXPECT_EQ(role("thin"), KnobRole::kDownsample);
  // Only a declared role that differs from the default is written back.
  const std::string yaml = NormalizedYaml(spec);
  EXPECT_NE(yaml.find("role: frequency"), std::string::npos) << yaml;
  EXPECT_EQ(yaml.find("role: cores"), std::string::npos) << yaml;
  Result<Spec> again = ParseSpec(yaml, "normalized.yaml", "");
  ASSERT_TRUE(again.ok()) << again.status().message();
  EXPECT_EQ(again->design_space.Find("ctrl")->role, KnobRole::kFrequency);
  EXPECT_EQ(again->design_space.Find("thin")->role, KnobRole::kDownsample);
  EXPECT_EQ(again->design_space.Find("leaf")->role, KnobRole::kDownsample);
}

TEST(SpecParserTest, NetAndPolygonPathsResolveFromTheFileFolder) {
  const std::string dir = adse::testing::TestScratch().string();
  WriteText(fs::path(dir) / "maps/town.net.xml",
            "<?xml version=\"1.0\"?>\n<net version=\"1.16\">\n</net>\n");
  WriteText(fs::path(dir) / "maps/town.poly.xml", "<additional/>\n");
  WriteText(fs::path(dir) / "town.yaml", R"(adse: 1
world:
  map: {net: maps/town.net.xml, polygons: maps/town.poly.xml}
task: {start: {edge: A, pos_m: 5}, goal: {edge: B}}
design_space: {cores: {bind: platform.cores, range: [1, 2]}}
)");
  Result<Spec> spec = LoadSpec(dir + "/town.yaml");
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  EXPECT_EQ(spec->world.map.net_path, dir + "/maps/town.net.xml");
  EXPECT_EQ(spec->world.map.polygons_path, dir + "/maps/town.poly.xml");
  EXPECT_TRUE(spec->world.map.generator.empty());
  EXPECT_EQ(spec->name, "town");
  EXPECT_EQ(spec->base_dir, dir);
  EXPECT_EQ(spec->source_path, dir + "/town.yaml");
  EXPECT_EQ(spec->Where("world.map.net").rfind(dir + "/town.yaml:3:", 0), 0u);
}

TEST(SpecParserTest, NormalizedYamlRoundTrips) {
  const Spec spec = ParseOk(kReference);
  const std::string yaml = NormalizedYaml(spec);
  Result<Spec> again = ParseSpec(yaml, "normalized.yaml", "");
  ASSERT_TRUE(again.ok()) << again.status().message() << "\n" << yaml;
  // Normalising is idempotent: the text is a fixed point.
  EXPECT_EQ(NormalizedYaml(*again), yaml);

  EXPECT_EQ(again->name, spec.name);
  EXPECT_EQ(again->output, spec.output);
  EXPECT_EQ(again->design_space.Size(), 280u);
  for (const DesignParameter& p : spec.design_space.parameters) {
    const DesignParameter* q = again->design_space.Find(p.name);
    ASSERT_NE(q, nullptr) << p.name;
    EXPECT_EQ(q->bind, p.bind);
    EXPECT_EQ(q->values, p.values);
    EXPECT_EQ(q->integer, p.integer);
  }
  EXPECT_EQ(again->world.map.generator_params, spec.world.map.generator_params);
  EXPECT_EQ(again->world.traffic.flows.size(), 1u);
  EXPECT_EQ(again->world.traffic.seed, 7u);
  EXPECT_NEAR(again->task.goal.x_m, 80, kTol);
  EXPECT_NEAR(again->task.goal_tolerance_m, 2.0, kTol);
  for (const KnobInfo& knob : StackKnobs()) {
    EXPECT_NEAR(again->stack.Get(knob.path), spec.stack.Get(knob.path), kTol);
  }
  EXPECT_EQ(again->cost, spec.cost);
  ASSERT_EQ(again->objectives.size(), spec.objectives.size());
  EXPECT_FALSE(again->objectives[3].minimize);
  EXPECT_EQ(again->constraints, spec.constraints);
  EXPECT_EQ(again->exploration.start_from, spec.exploration.start_from);
  EXPECT_EQ(again->llm.models, spec.llm.models);
  EXPECT_EQ(again->llm.endpoint, spec.llm.endpoint);
  EXPECT_EQ(again->harness.workers, 0);
  EXPECT_EQ(again->harness.slurm.time_limit, "02:00:00");
  // An unset initial design is left out of the text, a set one kept.
  EXPECT_EQ(yaml.find("initial_points"), std::string::npos);
  Spec seeded = spec;
  seeded.exploration.initial_points = 3;
  Result<Spec> kept = ParseSpec(NormalizedYaml(seeded), "n.yaml", "");
  ASSERT_TRUE(kept.ok()) << kept.status().message();
  EXPECT_EQ(kept->exploration.initial_points, 3);
}

TEST(SpecParserTest, ValetGoalBySlotWithHeadingRoundTrips) {
  const std::string text = R"(adse: 1
world:
  map: {generate: parking_lot, params: {rows: 2}}
  traffic: {seed: 3, parked_slots: [slot_r1_s3, slot_r1_s5]}
task:
  kind: valet_parking
  start: {x: 12, y: -1.75}
  goal: {slot: slot_r1_s4, yaw_deg: -90, tolerance_m: 0.4, yaw_tolerance_deg: 8}
design_space:
  cores: {bind: platform.cores, range: [1, 4]}
)";
  Result<Spec> first = ParseSpec(text, "valet.yaml", "/");
  ASSERT_TRUE(first.ok()) << first.status().message();
  const std::string yaml = NormalizedYaml(*first);
  Result<Spec> again = ParseSpec(yaml, "normalized.yaml", "/");
  ASSERT_TRUE(again.ok()) << again.status().message() << "\n" << yaml;
  EXPECT_EQ(NormalizedYaml(*again), yaml);
  EXPECT_EQ(again->task.goal.slot, "slot_r1_s4");
  EXPECT_TRUE(again->task.goal.has_yaw);
  EXPECT_NEAR(again->task.goal.yaw_deg, -90, kTol);
  EXPECT_NEAR(again->task.goal_tolerance_m, 0.4, kTol);
  EXPECT_NEAR(again->task.goal_yaw_tolerance_deg, 8, kTol);
  // Unwritten, a car stalls after 60 s.
  EXPECT_NEAR(again->task.stall_timeout_s, 60, kTol);
  EXPECT_EQ(again->world.traffic.parked_slots,
            (std::vector<std::string>{"slot_r1_s3", "slot_r1_s5"}));
  // Lane driving's normal form carries no heading tolerance.
  EXPECT_EQ(NormalizedYaml(*ParseSpec(R"(adse: 1
world: {map: {generate: grid}}
task: {start: {x: 0, y: 0}, goal: {x: 100, y: 0}}
design_space: {cores: {bind: platform.cores, range: [1, 4]}}
)",
                                      "lane.yaml", "/"))
                .find("yaw_tolerance_deg"),
            std::string::npos);
}

TEST(SpecParserTest, StoppedVehiclesRoundTripAndABadOneIsNamedByIndex) {
  const std::string text = R"(adse: 1
world:
  map: {generate: grid}
  traffic: {stopped_vehicles: [{x: 40, y: -1.6}, {edge: A0B0, pos_m: 30, lane: 0}]}
task: {start: {x: 0, y: 0}, goal: {x: 100, y: 0}}
design_space: {cores: {bind: platform.cores, range: [1, 4]}}
)";
  Result<Spec> first = ParseSpec(text, "stopped.yaml", "/");
  ASSERT_TRUE(first.ok()) << first.status().message();
  const std::string yaml = NormalizedYaml(*first);
  Result<Spec> again = ParseSpec(yaml, "normalized.yaml", "/");
  ASSERT_TRUE(again.ok()) << again.status().message() << "\n" << yaml;
  EXPECT_EQ(NormalizedYaml(*again), yaml);
  const auto& stopped = again->world.traffic.stopped_vehicles;
  ASSERT_EQ(stopped.size(), 2u);
  EXPECT_FALSE(stopped[0].by_edge);
  EXPECT_NEAR(stopped[0].x_m, 40, kTol);
  EXPECT_TRUE(stopped[1].by_edge);
  EXPECT_EQ(stopped[1].edge, "A0B0");
  EXPECT_NEAR(stopped[1].pos_m, 30, kTol);

  Result<Spec> bad = ParseSpec(R"(adse: 1
world:
  map: {generate: grid}
  traffic: {stopped_vehicles: [{x: 40, y: -1.6}, {x: 40, edge: A0B0}]}
task: {start: {x: 0, y: 0}, goal: {x: 100, y: 0}}
design_space: {cores: {bind: platform.cores, range: [1, 4]}}
)",
                               "bad.yaml", "/");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("world.traffic.stopped_vehicles[1]"),
            std::string::npos)
      << bad.status().message();
  EXPECT_NE(bad.status().message().find("bad.yaml:4:"), std::string::npos)
      << bad.status().message();
}

TEST(SpecParserTest, TaskCasesRoundTripAndEachCaseIsTheTaskWithItsPlaces) {
  const std::string text = R"(adse: 1
world:
  map: {generate: parking_lot, params: {rows: 2}}
task:
  kind: valet_parking
  start: {x: 12, y: -1.75}
  goal: {slot: slot_r1_s4, yaw_deg: -90, tolerance_m: 0.4, yaw_tolerance_deg: 8}
  cases:
    - {name: backing_in, goal: {slot: slot_r1_s4, yaw_deg: -90}}
    - name: nose_in
      goal: {slot: slot_r1_s7, yaw_deg: 90, tolerance_m: 0.3}
  timeout_s: 200
design_space:
  cores: {bind: platform.cores, range: [1, 4]}
)";
  Result<Spec> first = ParseSpec(text, "valet.yaml", "/");
  ASSERT_TRUE(first.ok()) << first.status().message();
  const std::string yaml = NormalizedYaml(*first);
  Result<Spec> again = ParseSpec(yaml, "normalized.yaml", "/");
  ASSERT_TRUE(again.ok()) << again.status().message() << "\n" << yaml;
  EXPECT_EQ(NormalizedYaml(*again), yaml);
  ASSERT_EQ(again->cases.size(), 2u);
  EXPECT_EQ(CaseCount(*again), 2);
  EXPECT_EQ(CaseNames(*again), "backing_in, nose_in");
  EXPECT_EQ(FindCase(*again, "nose_in"), 1);
  EXPECT_EQ(FindCase(*again, "sideways"), -1);

  // A case is the task with its places: the rest, and the tolerances it
  // leaves out, are the task's.
  const Spec nose = ForCase(*first, 1);
  EXPECT_TRUE(nose.cases.empty());
  EXPECT_EQ(nose.task_case, "nose_in");
  EXPECT_EQ(nose.task.goal.slot, "slot_r1_s7");
  EXPECT_NEAR(nose.task.goal.yaw_deg, 90, kTol);
  EXPECT_NEAR(nose.task.goal_tolerance_m, 0.3, kTol);
  EXPECT_NEAR(nose.task.goal_yaw_tolerance_deg, 8, kTol);
  EXPECT_NEAR(nose.task.timeout_s, 200, kTol);
  EXPECT_NEAR(nose.task.start.x_m, 12, kTol);
  const Spec back = ForCase(*first, 0);
  EXPECT_NEAR(back.task.goal_tolerance_m, 0.4, kTol);
  // An error about the case's goal cites the case's line.
  EXPECT_EQ(nose.Where("task.goal.slot"), "valet.yaml:11:14: ");
  EXPECT_EQ(back.Where("task.goal"), "valet.yaml:9:26: ");
  // Without cases a scenario is one case.
  EXPECT_EQ(CaseCount(ForCase(*first, 0)), 1);
}

TEST(SpecParserTest, BadTaskCasesAreNamedByIndex) {
  auto error = [](const std::string& cases) {
    Result<Spec> spec = ParseSpec(R"(adse: 1
world: {map: {generate: grid}}
task:
  start: {x: 0, y: 0}
  goal: {x: 100, y: 0}
  cases: )" + cases + R"(
design_space: {cores: {bind: platform.cores, range: [1, 4]}}
)",
                                  "cases.yaml", "/");
    return spec.ok() ? std::string("ok") : spec.status().message();
  };
  EXPECT_NE(error("[{name: a, goal: {x: 50, y: 0}}]").find("task.cases"),
            std::string::npos);
  EXPECT_NE(error("[{name: a, goal: {x: 50, y: 0}}, {name: a, goal: {x: 60, "
                  "y: 0}}]")
                .find("a second case of that name"),
            std::string::npos);
  EXPECT_NE(error("[{name: a, goal: {x: 50, y: 0}}, {name: b}]")
                .find("task.cases[1]: expected a case that changes the task's "
                      "start, via or goal"),
            std::string::npos)
      << error("[{name: a, goal: {x: 50, y: 0}}, {name: b}]");
  EXPECT_NE(error("[{name: a, goal: {x: 50, y: 0}}, {goal: {x: 60, y: 0}}]")
                .find("task.cases[1]"),
            std::string::npos);
  EXPECT_NE(error("[{name: 1a, goal: {x: 50, y: 0}}, {name: b, goal: {x: 60, "
                  "y: 0}}]")
                .find("task.cases[0].name"),
            std::string::npos);
  EXPECT_NE(error("[{name: a, goal: {x: 50}}, {name: b, goal: {x: 60, y: 0}}]")
                .find("task.cases[0].goal"),
            std::string::npos);
  EXPECT_NE(error("[{name: a, goal: {x: 50, y: 0}, speed_limit_kmh: 20}, "
                  "{name: b, goal: {x: 60, y: 0}}]")
                .find("speed_limit_kmh"),
            std::string::npos);
  EXPECT_EQ(error("[{name: a, goal: {x: 50, y: 0}}, {name: b, start: {x: 10, "
                  "y: 0}, via: [{x: 30, y: 0}]}]"),
            "ok");
}

TEST(SpecParserTest, NormalizedYamlRoundTripsNetMapsAndEdges) {
  const std::string dir = adse::testing::TestScratch().string();
  WriteText(fs::path(dir) / "a.net.xml", "<net version=\"1.16\"></net>\n");
  const std::string text = R"(adse: 1
name: weird.name_1
world: {map: {net: a.net.xml}, weather: fog, step_s: 0.1}
task: {kind: valet_parking, start: {edge: "E:0", pos_m: 1.5, lane: 2}, via: [{x: 3, y: -4.5}, {edge: "E7", pos_m: 2}], goal: {edge: "-E9", tolerance_m: 0.5}}
platform: {kind: cgroup, cost_model: counted, cores: 8, freq_ghz: 3.2}
design_space: {hz: {bind: stack.lidar.rate_hz, values: [0.5, 7.25]}}
cost: "2 * cores + hz / 10"
constraints: ["collisions == 0", "nav_time_s <= 400 && completed"]
exploration: {strategy: ga, seed: 18446744073709551615, population: 12}
llm: {backend: openai, endpoint: "https://api.example.com/v1", models: {dse: "gpt: 4o"}}
harness: {workers: 3, early_stop: true, executor: slurm, slurm: {partition: gpu, time_limit: "1-00:30", extra_args: ["--qos=long", "--comment=#x #y"]}}
output: /tmp/adse out/x
)";
  Result<Spec> first = ParseSpec(text, "edge.yaml", dir);
  ASSERT_TRUE(first.ok()) << first.status().message();
  const std::string yaml = NormalizedYaml(*first);
  Result<Spec> again = ParseSpec(yaml, "normalized.yaml", "/");
  ASSERT_TRUE(again.ok()) << again.status().message() << "\n" << yaml;
  EXPECT_EQ(NormalizedYaml(*again), yaml);
  EXPECT_EQ(again->world.map.net_path, dir + "/a.net.xml");
  EXPECT_EQ(again->world.weather, world::Weather::kFog);
  EXPECT_EQ(again->task.kind, world::TaskKind::kValetParking);
  EXPECT_EQ(again->task.start.edge, "E:0");
  EXPECT_EQ(again->task.goal.edge, "-E9");
  EXPECT_EQ(again->task.start.lane, 2);
  ASSERT_EQ(again->task.via.size(), 2u);
  EXPECT_NEAR(again->task.via[0].y_m, -4.5, kTol);
  EXPECT_EQ(again->task.via[1].edge, "E7");
  EXPECT_NEAR(again->task.via[1].pos_m, 2.0, kTol);
  EXPECT_EQ(again->harness.early_stop, true);
  EXPECT_EQ(again->platform.kind, PlatformKind::kCgroup);
  EXPECT_EQ(again->platform.cost_model, CostModel::kCounted);
  EXPECT_NEAR(again->platform.freq_ghz, 3.2, kTol);
  EXPECT_EQ(again->exploration.seed, 18446744073709551615ull);
  EXPECT_EQ(again->llm.models.at("dse"), "gpt: 4o");
  EXPECT_EQ(again->harness.workers, 3);
  EXPECT_EQ(again->harness.slurm.extra_args,
            (std::vector<std::string>{"--qos=long", "--comment=#x #y"}));
  EXPECT_EQ(again->output, "/tmp/adse out/x");
  EXPECT_EQ(again->constraints[1], "nav_time_s <= 400 && completed");
}

TEST(SpecParserTest, EveryExampleScenarioInTheRepositoryParses) {
  const fs::path folder = fs::path(ADSE_SOURCE_DIR) / "scenarios";
  int found = 0;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    if (entry.path().extension() != ".yaml") continue;
    ++found;
    Result<Spec> spec = LoadSpec(entry.path().string());
    EXPECT_TRUE(spec.ok()) << entry.path() << ":\n" << spec.status().message();
    if (!spec.ok()) continue;
    EXPECT_GT(spec->design_space.Size(), 0u) << entry.path();
    // What the tools print must read back.
    Result<Spec> again = ParseSpec(NormalizedYaml(*spec), "n.yaml", "");
    EXPECT_TRUE(again.ok()) << entry.path() << ": " << again.status().message();
  }
  // Guard against passing vacuously when the examples go missing.
  EXPECT_GE(found, 1) << "no scenarios/*.yaml in " << folder;
}

TEST(SpecParserTest, FullExamplesInTheFormatReferenceParse) {
  // Every ```yaml block of scenarios/README.md that is a whole spec.
  std::ifstream in(fs::path(ADSE_SOURCE_DIR) / "scenarios/README.md");
  ASSERT_TRUE(in) << "scenarios/README.md is missing";
  std::string line, block;
  bool inside = false;
  int checked = 0;
  while (std::getline(in, line)) {
    if (!inside && line == "```yaml") {
      inside = true;
      block.clear();
    } else if (inside && line == "```") {
      inside = false;
      if (block.rfind("adse:", 0) != 0) continue;
      ++checked;
      Result<Spec> spec = ParseSpec(block, "README.md", "");
      EXPECT_TRUE(spec.ok()) << spec.status().message() << "\n" << block;
      if (spec.ok()) {
        EXPECT_EQ(spec->design_space.Size(), 280u);
      }
    } else if (inside) {
      block += line + "\n";
    }
  }
  EXPECT_GE(checked, 1);
}

TEST(SpecParserTest, ResolvedOutputIsAbsolute) {
  Spec spec = ParseOk(kReference);
  const std::string resolved = spec.ResolvedOutput();
  EXPECT_TRUE(fs::path(resolved).is_absolute());
  EXPECT_EQ(resolved,
            (fs::current_path() / "results/robotaxi-parking-lot").string());
  spec.output = "/data/x/../y";
  EXPECT_EQ(spec.ResolvedOutput(), "/data/y");
}

}  // namespace
}  // namespace adse::spec
