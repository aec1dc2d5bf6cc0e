// The profile file: what is written reads back as the same profile, the
// text is deterministic and written atomically, and every malformed file is
// refused with its file, line and field path.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "harness/profile/profile.h"
#include "stack/base/files.h"
#include "tests/stack/base/testing/fault_injection_env.h"

namespace adse::profile {
namespace {

namespace fs = std::filesystem;

// A fresh folder for one test.
fs::path TestDir() {
  const ::testing::TestInfo* info =
      ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = fs::temp_directory_path() /
                       (std::string("adse_profile_io_") + info->name());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string ReadText(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

stack::CallbackCost Cost(std::vector<double> ms) {
  stack::CallbackCost c;
  const double qs[] = {0.0, 0.5, 0.95, 0.99, 1.0};
  for (size_t i = 0; i < ms.size(); ++i) {
    c.quantiles.push_back({qs[i], ms[i] / 1000.0});
  }
  return c;
}

// Two callbacks with awkward numbers (sums of decimal milliseconds, an
// Amdahl division) and strings that need quoting.
Profile Example() {
  Profile p;
  p.name = "example";
  p.source.description = "a test: \"quoted\", with a # and a colon: here";
  p.source.license = "Apache-2.0";
  p.source.cpu = "yes";
  p.source.note = "line one\nline two";
  p.source.reference_ghz_assumed = true;
  p.costs.reference_ghz = 4.9;
  stack::CallbackCost ndt =
      Cost({8.0 / 0.53125, 19.328 / 0.53125, 43.792 / 0.53125, 51.3 / 0.53125,
            55.686 / 0.53125});
  ndt.reference_units = 4298;
  ndt.parallel_fraction = 0.625;
  ndt.max_threads = 4;
  ndt.freq_exponent = 0.8;
  p.costs.callbacks["ndt_scan_matcher/points"] = ndt;
  p.costs.callbacks["trajectory_follower/control"] =
      Cost({0.7, 1.822, 4.209, 6.1 + 0.2, 11.192});
  p.provenance["ndt_scan_matcher/points"] = {
      {"/localization/pose_estimator/ndt_scan_matcher/callback_1"},
      9.636,
      21.173};
  p.provenance["trajectory_follower/control"] = {
      {"/control/a/callback_1", "/control/b/callback_0"}, 33.3, 2.169 + 0.1};
  p.chains["sensing"] = {"component_sensing_0", 85.125, 116.72, 250.757};
  return p;
}

void ExpectSameProfile(const Profile& a, const Profile& b) {
  EXPECT_EQ(a.format_version, b.format_version);
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.source.description, b.source.description);
  EXPECT_EQ(a.source.license, b.source.license);
  EXPECT_EQ(a.source.cpu, b.source.cpu);
  EXPECT_EQ(a.source.note, b.source.note);
  EXPECT_EQ(a.source.reference_ghz_assumed, b.source.reference_ghz_assumed);
  EXPECT_EQ(a.costs.reference_ghz, b.costs.reference_ghz);
  ASSERT_EQ(a.costs.callbacks.size(), b.costs.callbacks.size());
  for (const auto& [name, ca] : a.costs.callbacks) {
    SCOPED_TRACE(name);
    ASSERT_EQ(b.costs.callbacks.count(name), 1u);
    const stack::CallbackCost& cb = b.costs.callbacks.at(name);
    ASSERT_EQ(ca.quantiles.size(), cb.quantiles.size());
    for (size_t i = 0; i < ca.quantiles.size(); ++i) {
      EXPECT_EQ(ca.quantiles[i].q, cb.quantiles[i].q);
      EXPECT_EQ(ca.quantiles[i].cost_s, cb.quantiles[i].cost_s);
    }
    EXPECT_EQ(ca.reference_units, cb.reference_units);
    EXPECT_EQ(ca.freq_exponent, cb.freq_exponent);
    EXPECT_EQ(ca.parallel_fraction, cb.parallel_fraction);
    EXPECT_EQ(ca.max_threads, cb.max_threads);
    const CallbackProvenance& pa = a.provenance.at(name);
    const CallbackProvenance& pb = b.provenance.at(name);
    EXPECT_EQ(pa.sources, pb.sources);
    EXPECT_EQ(pa.rate_hz, pb.rate_hz);
    EXPECT_EQ(pa.avg_ms, pb.avg_ms);
  }
  ASSERT_EQ(a.chains.size(), b.chains.size());
  for (const auto& [name, chain] : a.chains) {
    SCOPED_TRACE(name);
    ASSERT_EQ(b.chains.count(name), 1u);
    EXPECT_EQ(chain.source, b.chains.at(name).source);
    EXPECT_EQ(chain.avg_ms, b.chains.at(name).avg_ms);
    EXPECT_EQ(chain.p95_ms, b.chains.at(name).p95_ms);
    EXPECT_EQ(chain.worst_max_ms, b.chains.at(name).worst_max_ms);
  }
}

TEST(ProfileIoTest, AWrittenProfileReadsBackIdentical) {
  const fs::path file = TestDir() / "p.yaml";
  const Profile written = Example();
  ASSERT_TRUE(WriteProfile(file.string(), written).ok());
  Result<Profile> read = ReadProfile(file.string());
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ExpectSameProfile(written, *read);
}

TEST(ProfileIoTest, WritingTheSameProfileTwiceGivesTheSameSortedText) {
  const fs::path dir = TestDir();
  ASSERT_TRUE(WriteProfile((dir / "a.yaml").string(), Example()).ok());
  Result<Profile> read = ReadProfile((dir / "a.yaml").string());
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_TRUE(WriteProfile((dir / "b.yaml").string(), *read).ok());
  const std::string text = ReadText(dir / "a.yaml");
  EXPECT_EQ(text, ReadText(dir / "b.yaml"));
  // A header says where it came from; callbacks are in name order; the
  // quantiles use the documented keys.
  EXPECT_EQ(text.rfind("# Generated by `adse profile import` from:", 0), 0u)
      << text;
  EXPECT_LT(text.find("ndt_scan_matcher/points:"),
            text.find("trajectory_follower/control:"));
  EXPECT_NE(text.find("adse_profile: 1\n"), std::string::npos);
  EXPECT_NE(text.find("reference: {ghz: 4.9, assumed: true}"),
            std::string::npos);
  EXPECT_NE(text.find("cost_ms: {min: 0.7, p50: 1.822, p95: 4.209, p99: "
                      "6.3, max: 11.192}"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("sources: [/control/a/callback_1, "
                      "/control/b/callback_0]"),
            std::string::npos);
}

TEST(ProfileIoTest, AFailedWriteLeavesNoProfile) {
  const fs::path file = TestDir() / "p.yaml";
  adse::testing::FaultInjectionEnv env;
  env.Inject({adse::testing::FaultOp::kRenameFile, "p.yaml", EIO});
  EXPECT_FALSE(WriteProfile(file.string(), Example(), &env).ok());
  EXPECT_TRUE(fs::is_empty(file.parent_path()));
  env.Inject({adse::testing::FaultOp::kWriteFile, "p.yaml", ENOSPC});
  EXPECT_FALSE(WriteProfile(file.string(), Example(), &env).ok());
  EXPECT_TRUE(fs::is_empty(file.parent_path()));
}

TEST(ProfileIoTest, AProfileTheExecutorWouldRefuseIsNotWritten) {
  const fs::path file = TestDir() / "p.yaml";
  Profile p = Example();
  p.costs.callbacks["trajectory_follower/control"].max_threads = 0;
  const Status s = WriteProfile(file.string(), p);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("max_threads"), std::string::npos);
  EXPECT_FALSE(fs::exists(file));
}

// The example's text with `from` replaced by `to` (which must occur once).
std::string Mutated(const std::string& from, const std::string& to) {
  const fs::path dir = TestDir();
  EXPECT_TRUE(WriteProfile((dir / "good.yaml").string(), Example()).ok());
  std::string text = ReadText(dir / "good.yaml");
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  EXPECT_EQ(text.find(from, at + 1), std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  const fs::path bad = dir / "bad.yaml";
  std::ofstream(bad) << text;
  return bad.string();
}

struct BadProfile {
  std::string from, to;
  std::vector<std::string> expected;  // substrings of the message
};

TEST(ProfileIoTest, EveryMalformedProfileIsRefusedAtItsLineAndField) {
  const std::string cb = "callbacks.trajectory_follower/control";
  const std::vector<BadProfile> cases = {
      {"p95: 4.209, ",
       "",
       {cb + ".cost_ms.p95: expected a cost in ms (required", "nothing"}},
      {"p50: 1.822",
       "p50: -1",
       {cb + ".cost_ms.p50: expected a number >= 0, found '-1'"}},
      {"p50: 1.822",
       "p50: .nan",
       {cb + ".cost_ms.p50: expected a number >= 0, found '.nan'"}},
      {"p95: 4.209", "p95: fast", {cb + ".cost_ms.p95", "found 'fast'"}},
      {"p99: 6.3",
       "p99: 1",
       {cb + ".cost_ms.p99: expected a cost >= 4.209 ms (p95)"}},
      {"p99: 6.3", "p97: 6.3, p99: 6.3", {}},  // another quantile is fine
      {"p99: 6.3", "q99: 6.3", {cb + ".cost_ms.q99: expected a quantile key"}},
      {"adse_profile: 1",
       "adse_profile: 2",
       {"adse_profile: expected 1 (the profile format this adse reads), "
        "found '2'"}},
      {"reference: {ghz: 4.9",
       "reference: {ghz: 0",
       {"reference.ghz: expected a number > 0, found '0'"}},
      {"    freq_exponent: 1\n    parallel_fraction: 0\n    max_threads: 1",
       "    freq_exponent: 5\n    parallel_fraction: 0\n    max_threads: 1",
       {cb + ".freq_exponent: expected a number in [0, 4], found '5'"}},
      {"max_threads: 4",
       "max_threads: 2.5",
       {"callbacks.ndt_scan_matcher/points.max_threads: expected an integer "
        ">= 1, found '2.5'"}},
      {"    rate_hz: 33.3",
       "    rate_hx: 33.3",
       {cb + ".rate_hx: expected one of the keys", "did you mean 'rate_hz'"}},
      {"callbacks:\n",
       "callbacks: [a, b]\nunused:\n",
       {"error: unused: expected one of the keys"}},
      {"name: example",
       "name: ''",
       {"name: expected a non-empty string, found ''"}},
      {"adse_profile: 1",
       "adse_profile: [1",
       {"(file): expected valid YAML with a cost profile"}},
  };
  for (const BadProfile& c : cases) {
    SCOPED_TRACE(c.from + " -> " + c.to);
    const std::string file = Mutated(c.from, c.to);
    Result<Profile> read = ReadProfile(file);
    if (c.expected.empty()) {
      EXPECT_TRUE(read.ok()) << read.status().ToString();
      continue;
    }
    ASSERT_FALSE(read.ok());
    EXPECT_EQ(read.status().code(), Status::Code::kInvalidArgument);
    const std::string& m = read.status().message();
    // "<file>:<line>:<column>: error: <field>: expected ..., found ..."
    ASSERT_EQ(m.rfind(file + ":", 0), 0u) << m;
    EXPECT_TRUE(std::regex_search(m.substr(file.size()),
                                  std::regex("^:[0-9]+:[0-9]+: error: ")))
        << m;
    for (const std::string& e : c.expected) {
      EXPECT_NE(m.find(e), std::string::npos) << m << "\nwanted: " << e;
    }
  }
}

TEST(ProfileIoTest, AMissingProfileIsNotFoundByName) {
  Result<Profile> read = ReadProfile("/nonexistent/profile.yaml");
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), Status::Code::kNotFound);
  EXPECT_NE(read.status().message().find("/nonexistent/profile.yaml"),
            std::string::npos);
}

TEST(ProfileIoTest, TheTableGivesPercentilesLoadAndTheTotal) {
  const Profile p = Example();
  const std::string table = FormatProfileTable(p);
  // The follower: mean of the piecewise-linear quantile function x 33.3 Hz.
  const double mean_ms =
      MeanCostMs(p.costs.callbacks.at("trajectory_follower/control"));
  EXPECT_NEAR(mean_ms,
              0.5 * (0.7 + 1.822) / 2 + 0.45 * (1.822 + 4.209) / 2 +
                  0.04 * (4.209 + 6.3) / 2 + 0.01 * (6.3 + 11.192) / 2,
              1e-9);
  EXPECT_NE(table.find("trajectory_follower/control"), std::string::npos);
  EXPECT_NE(table.find("1.822"), std::string::npos) << table;
  EXPECT_NE(table.find("4.209"), std::string::npos) << table;
  EXPECT_NEAR(TotalLoadCores(p),
              mean_ms / 1000 * 33.3 +
                  MeanCostMs(p.costs.callbacks.at("ndt_scan_matcher/points")) /
                      1000 * 9.636,
              1e-12);
  EXPECT_NE(table.find(fmt::format("total load at 4.9 GHz: {:.2f} cores busy",
                                   TotalLoadCores(p))),
            std::string::npos)
      << table;
}

}  // namespace
}  // namespace adse::profile
