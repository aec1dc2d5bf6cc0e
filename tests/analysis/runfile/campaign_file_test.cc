// WriteCampaignIndex / ReadCampaignIndex: exact round trips, atomic
// replacement, Corruption naming the file for damaged or foreign files, and
// a layout that h5py/pandas read with no adse code.
#include "analysis/runfile/campaign_file.h"

#if __has_include(<hdf5.h>)
#include <hdf5.h>
#else
#include <hdf5/serial/hdf5.h>  // Debian keeps it off the default path
#endif

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "analysis/runfile/run_file.h"
#include "stack/base/hash.h"
#include "stack/base/subprocess.h"

namespace adse::runfile {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

const std::vector<std::string> kParameters = {"v0_mps", "cores", "freq_ghz"};
const std::vector<std::string> kMetrics = {"nav_time_s", "ctrl_rate_hz",
                                           "hardware_cost", "deviation_score",
                                           "completed"};

std::string ReasonOf(size_t i) {
  if (i % 7 == 3) {
    return "crashed: signal 11, \"segfault\" in planner/a,b — "
           "Zeitüberschreitung "
           "✓ #" +
           std::to_string(i);
  }
  return i % 2 == 0 ? "goal_reached" : "timeout";
}

// A campaign as the harness writes it: failed rows without metrics, rows
// lacking a metric or a parameter (NaN in the file), strings with commas,
// quotes, newlines and non-ASCII text.
CampaignIndex MakeIndex(size_t rows) {
  CampaignIndex index;
  index.scenario_name = "robotaxi_small_äö";
  index.scenario_text =
      "name: robotaxi_small\n"
      "design_space:\n"
      "  cores: {bind: platform.cores, values: [1, 4, 16]}\n"
      "constraints: [nav_time_s <= 60, \"completed\"]  # ≤ 60 s, a,b\n";
  index.strategy = "nsga2";
  index.exploration_seed = std::numeric_limits<uint64_t>::max() - 7;
  index.budget = 500;
  index.isolation = "cgroup v2: memory.max 2 GiB, cpu.max \"200000 100000\"";
  index.adse_version = "0.4.0-dev+g5a0e183";
  index.parameters = kParameters;
  index.metrics = kMetrics;
  for (size_t i = 0; i < rows; ++i) {
    EvaluationRow row;
    row.index = static_cast<int64_t>(i);
    row.iteration = static_cast<int64_t>(i / 10);
    row.content_key = Sha256Hex("point " + std::to_string(i));
    const bool failed = i % 7 == 3;
    row.status = failed ? "failed" : "complete";
    row.reason = ReasonOf(i);
    row.source =
        std::vector<std::string>{"simulated", "campaign", "cache"}[i % 3];
    row.attempts = failed ? 3 : 1 + static_cast<int64_t>(i % 2);
    row.wall_s = i == 1 ? -0.0 : 0.5 + 0.25 * static_cast<double>(i);
    row.feasible = !failed && i % 2 == 0;
    row.seed = i == 0 ? std::numeric_limits<uint64_t>::max() : 1000 + i;
    row.point["v0_mps"] = 5.0 + static_cast<double>(i % 4) * 2.5;
    row.point["cores"] = static_cast<double>(1 << (i % 5));
    if (i % 13 != 5) row.point["freq_ghz"] = 1.0 + 0.1 * (i % 11);
    if (!failed) {
      row.metrics["nav_time_s"] = 20.0 + 0.125 * static_cast<double>(i);
      row.metrics["ctrl_rate_hz"] = i == 4 ? kInf : 10.0 + i % 3;
      row.metrics["hardware_cost"] = 100.0 * (1 << (i % 5));
      if (i % 5 != 2) row.metrics["deviation_score"] = 0.01 * (i % 17);
      row.metrics["completed"] = i % 11 == 0 ? 0.0 : 1.0;
      row.bottlenecks_json =
          R"([{"kind":"cpu","node":"planner, local","remedy":"add cores ")" +
          std::string("≥ 4") + R"(","severity":0.)" + std::to_string(i % 10) +
          "}]";
    }
    // Every fourth point ran three times: its replicas, one unstable.
    if (i % 4 == 2) {
      const EvaluationRow run = row;
      for (int64_t r = 0; r < 3; ++r) {
        EvaluationRow replica = run;
        replica.replica = r;
        replica.content_key = Sha256Hex("replica " + std::to_string(r) +
                                        " of point " + std::to_string(i));
        replica.seed = row.seed + 7 * static_cast<uint64_t>(r);
        replica.feasible = row.feasible && (i % 8 != 2 || r != 1);
        if (!failed) replica.metrics["nav_time_s"] += 0.5 * r;
        if (r == 2) replica.metrics.erase("deviation_score");
        row.replicas.push_back(std::move(replica));
      }
      row.unstable = i % 8 == 2 && row.feasible;
    }
    index.evaluations.push_back(std::move(row));
  }
  const size_t rounds = (rows + 9) / 10;
  for (size_t k = 0; k < rounds; ++k) {
    IterationRow round;
    round.iteration = static_cast<int64_t>(k);
    round.strategy = k == 0 ? "random" : "nsga2";
    round.rationale = "Round " + std::to_string(k) +
                      ": explore near the \"best\" point, ±10 %,\nsee #3, #4";
    for (size_t i = k * 10; i < std::min(rows, k * 10 + 10); ++i) {
      round.content_keys.push_back(index.evaluations[i].content_key);
    }
    index.iterations.push_back(std::move(round));
  }
  // A last round that proposed nothing (budget used up).
  index.iterations.push_back(
      {static_cast<int64_t>(rounds), "nsga2", "budget exhausted", {}});
  return index;
}

bool SameBits(double a, double b) {
  return std::memcmp(&a, &b, sizeof(double)) == 0;
}

// The first differences between two indexes, empty if identical (numbers
// bit-exact).
std::string Diff(const CampaignIndex& a, const CampaignIndex& b) {
  std::ostringstream out;
  auto str = [&](const std::string& what, const std::string& x,
                 const std::string& y) {
    if (x != y) out << what << ": '" << x << "' vs '" << y << "'\n";
  };
  auto num = [&](const std::string& what, double x, double y) {
    if (!SameBits(x, y)) out << what << ": " << x << " vs " << y << "\n";
  };
  auto integer = [&](const std::string& what, int64_t x, int64_t y) {
    if (x != y) out << what << ": " << x << " vs " << y << "\n";
  };
  auto map = [&](const std::string& what,
                 const std::map<std::string, double>& x,
                 const std::map<std::string, double>& y) {
    if (x.size() != y.size()) {
      out << what << " size: " << x.size() << " vs " << y.size() << "\n";
      return;
    }
    for (auto i = x.begin(), j = y.begin(); i != x.end(); ++i, ++j) {
      str(what + " key", i->first, j->first);
      num(what + " " + i->first, i->second, j->second);
    }
  };
  str("scenario_name", a.scenario_name, b.scenario_name);
  str("scenario_text", a.scenario_text, b.scenario_text);
  str("strategy", a.strategy, b.strategy);
  if (a.exploration_seed != b.exploration_seed) out << "exploration_seed\n";
  integer("budget", a.budget, b.budget);
  str("isolation", a.isolation, b.isolation);
  str("adse_version", a.adse_version, b.adse_version);
  if (a.parameters != b.parameters) out << "parameters differ\n";
  if (a.metrics != b.metrics) out << "metrics differ\n";
  if (a.evaluations.size() != b.evaluations.size()) {
    out << "evaluations size: " << a.evaluations.size() << " vs "
        << b.evaluations.size() << "\n";
  } else {
    std::function<void(const std::string&, const EvaluationRow&,
                       const EvaluationRow&)>
        rows = [&](const std::string& row, const EvaluationRow& x,
                   const EvaluationRow& y) {
          integer(row + "index", x.index, y.index);
          integer(row + "iteration", x.iteration, y.iteration);
          str(row + "content_key", x.content_key, y.content_key);
          str(row + "status", x.status, y.status);
          str(row + "reason", x.reason, y.reason);
          str(row + "source", x.source, y.source);
          integer(row + "attempts", x.attempts, y.attempts);
          num(row + "wall_s", x.wall_s, y.wall_s);
          if (x.feasible != y.feasible) out << row << "feasible\n";
          if (x.seed != y.seed) out << row << "seed\n";
          map(row + "point", x.point, y.point);
          map(row + "metrics", x.metrics, y.metrics);
          str(row + "bottlenecks_json", x.bottlenecks_json, y.bottlenecks_json);
          integer(row + "replica", x.replica, y.replica);
          if (x.unstable != y.unstable) out << row << "unstable\n";
          if (x.replicas.size() != y.replicas.size()) {
            out << row << "replicas size: " << x.replicas.size() << " vs "
                << y.replicas.size() << "\n";
            return;
          }
          for (size_t r = 0; r < x.replicas.size(); ++r) {
            rows(row + "replica " + std::to_string(r) + " ", x.replicas[r],
                 y.replicas[r]);
          }
        };
    for (size_t i = 0; i < a.evaluations.size(); ++i) {
      rows("evaluation " + std::to_string(i) + " ", a.evaluations[i],
           b.evaluations[i]);
    }
  }
  if (a.iterations.size() != b.iterations.size()) {
    out << "iterations size: " << a.iterations.size() << " vs "
        << b.iterations.size() << "\n";
  } else {
    for (size_t i = 0; i < a.iterations.size(); ++i) {
      const IterationRow& x = a.iterations[i];
      const IterationRow& y = b.iterations[i];
      const std::string row = "iteration " + std::to_string(i) + " ";
      integer(row + "iteration", x.iteration, y.iteration);
      str(row + "strategy", x.strategy, y.strategy);
      str(row + "rationale", x.rationale, y.rationale);
      if (x.content_keys != y.content_keys) {
        out << row << "content_keys: " << x.content_keys.size() << " vs "
            << y.content_keys.size() << " keys\n";
      }
    }
  }
  return out.str();
}

// Raw HDF5 access for damaging files on purpose.
class RawFile {
 public:
  explicit RawFile(const std::string& path)
      : file_(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT)) {}
  ~RawFile() {
    if (file_ >= 0) H5Fclose(file_);
  }
  hid_t get() const { return file_; }

 private:
  hid_t file_;
};

// Replaces `path` with a 1-D float64 dataset of `rows` zeros.
void ReplaceWithDoubles(hid_t file, const char* path, size_t rows) {
  ASSERT_GE(H5Ldelete(file, path, H5P_DEFAULT), 0) << path;
  const hsize_t dims[1] = {rows};
  const hid_t space = H5Screate_simple(1, dims, nullptr);
  const hid_t dataset = H5Dcreate2(file, path, H5T_IEEE_F64LE, space,
                                   H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(dataset, 0) << path;
  const std::vector<double> zeros(rows, 0.0);
  if (rows > 0) {
    H5Dwrite(dataset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT,
             zeros.data());
  }
  H5Dclose(dataset);
  H5Sclose(space);
}

class CampaignFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = ::testing::TempDir() + "campaign_file_test_XXXXXX";
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string Path(const std::string& name) const {
    return (fs::path(dir_) / name).string();
  }
  std::vector<std::string> Listing() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) {
      names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }
  // Reads `path`, expecting Corruption whose message names the file and
  // contains `detail`.
  void ExpectCorruption(const std::string& path, const std::string& detail) {
    Result<CampaignIndex> back = ReadCampaignIndex(path);
    ASSERT_FALSE(back.ok()) << path;
    EXPECT_EQ(back.status().code(), Status::Code::kCorruption)
        << back.status().ToString();
    EXPECT_NE(back.status().message().find(path), std::string::npos)
        << back.status().message();
    EXPECT_NE(back.status().message().find(detail), std::string::npos)
        << back.status().message();
  }

  std::string dir_;
};

class CampaignFileRoundTripTest : public CampaignFileTest,
                                  public ::testing::WithParamInterface<size_t> {
};

TEST_P(CampaignFileRoundTripTest, RealisticIndexRoundTripsExactly) {
  const CampaignIndex index = MakeIndex(GetParam());
  const std::string path = Path("campaign.h5");
  const Status written = WriteCampaignIndex(path, index);
  ASSERT_TRUE(written.ok()) << written.ToString();
  Result<CampaignIndex> back = ReadCampaignIndex(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(Diff(index, *back), "");
  EXPECT_EQ(back->evaluations.size(), GetParam());
  EXPECT_EQ(back->parameters, kParameters);  // order kept, not sorted
  EXPECT_EQ(back->metrics, kMetrics);
}

INSTANTIATE_TEST_SUITE_P(Rows, CampaignFileRoundTripTest,
                         ::testing::Values(size_t{0}, size_t{1}, size_t{500}));

TEST_F(CampaignFileTest, LlmExchangesRoundTripAndOlderIndexesHaveNone) {
  CampaignIndex index = MakeIndex(3);
  LlmExchangeRow a;
  a.seq = 0;
  a.iteration = 0;
  a.agent = "dse";
  a.model = "deepseek-r1";
  a.backend = "ollama";
  a.request_sha256 = Sha256Hex("request");
  a.prompt =
      "[system]\nYou are ... ≤ 60 s\n\n[user]\n" + std::string(20000, 'p');
  a.answer = R"({"point": {"cores": 4}, "rationale": "NDT lags"})";
  a.prompt_tokens = 5123;
  a.completion_tokens = 40;
  a.latency_s = 12.5;
  a.attempts = 1;
  LlmExchangeRow b;
  b.seq = 1;
  b.iteration = 0;
  b.agent = "vision";
  b.model = "mistral-small3.1";
  b.image_sha256 = Sha256Hex("png") + "," + Sha256Hex("png2");
  b.ok = false;
  b.error = "unavailable: did not answer within 120 s";
  b.attempts = 3;
  index.llm_exchanges = {a, b};
  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, index).ok());
  Result<CampaignIndex> back = ReadCampaignIndex(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  ASSERT_EQ(back->llm_exchanges.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    const LlmExchangeRow& w = index.llm_exchanges[i];
    const LlmExchangeRow& r = back->llm_exchanges[i];
    EXPECT_EQ(r.seq, w.seq);
    EXPECT_EQ(r.iteration, w.iteration);
    EXPECT_EQ(r.agent, w.agent);
    EXPECT_EQ(r.model, w.model);
    EXPECT_EQ(r.backend, w.backend);
    EXPECT_EQ(r.request_sha256, w.request_sha256);
    EXPECT_EQ(r.prompt, w.prompt);
    EXPECT_EQ(r.image_sha256, w.image_sha256);
    EXPECT_EQ(r.ok, w.ok);
    EXPECT_EQ(r.answer, w.answer);
    EXPECT_EQ(r.error, w.error);
    EXPECT_EQ(r.prompt_tokens, w.prompt_tokens);
    EXPECT_EQ(r.completion_tokens, w.completion_tokens);
    EXPECT_EQ(r.latency_s, w.latency_s);
    EXPECT_EQ(r.attempts, w.attempts);
  }
  // The recorded robotaxi campaign predates the group.
  Result<CampaignIndex> old =
      ReadCampaignIndex(std::string(ADSE_SOURCE_DIR) +
                        "/tests/data/robotaxi_exhaustive/campaign.h5");
  ASSERT_TRUE(old.ok()) << old.status().ToString();
  EXPECT_TRUE(old->llm_exchanges.empty());
  EXPECT_EQ(old->evaluations.size(), 280u);
}

TEST_F(CampaignFileTest, ReplicasRoundTripAndOlderIndexesHaveNone) {
  const CampaignIndex index = MakeIndex(12);
  size_t with_replicas = 0;
  for (const EvaluationRow& row : index.evaluations) {
    with_replicas += !row.replicas.empty();
  }
  ASSERT_EQ(with_replicas, 3u);
  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, index).ok());
  Result<CampaignIndex> back = ReadCampaignIndex(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(Diff(index, *back), "");
  EXPECT_TRUE(back->evaluations[2].unstable);
  EXPECT_EQ(back->evaluations[2].replicas[1].replica, 1);

  // An index written before replicas: no /replicas, no unstable column.
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    ASSERT_GE(H5Ldelete(raw.get(), "/replicas", H5P_DEFAULT), 0);
    ASSERT_GE(H5Ldelete(raw.get(), "/evaluations/unstable", H5P_DEFAULT), 0);
  }
  back = ReadCampaignIndex(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  for (const EvaluationRow& row : back->evaluations) {
    EXPECT_TRUE(row.replicas.empty());
    EXPECT_FALSE(row.unstable);
  }
}

TEST_F(CampaignFileTest, AReplicaOfAnUnknownEvaluationIsCorruption) {
  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(4)).ok());
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    // The replicas of evaluation 2 claim one that does not exist.
    const hid_t dataset = H5Dopen2(raw.get(), "/replicas/index", H5P_DEFAULT);
    ASSERT_GE(dataset, 0);
    const int64_t bad[3] = {99, 99, 99};
    ASSERT_GE(
        H5Dwrite(dataset, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, bad),
        0);
    H5Dclose(dataset);
  }
  ExpectCorruption(path, "replica of evaluation 99");
}

TEST_F(CampaignFileTest, DiffSeesADifference) {
  // The round-trip check is only as good as Diff.
  const CampaignIndex a = MakeIndex(30);
  CampaignIndex b = a;
  b.evaluations[17].metrics["nav_time_s"] += 1e-12;
  EXPECT_NE(Diff(a, b), "");
  b = a;
  b.iterations[1].content_keys.pop_back();
  EXPECT_NE(Diff(a, b), "");
  b = a;
  b.evaluations[3].reason += " ";
  EXPECT_NE(Diff(a, b), "");
  b = a;
  b.evaluations[6].replicas[2].metrics["nav_time_s"] += 1e-12;
  EXPECT_NE(Diff(a, b), "");
}

TEST_F(CampaignFileTest, MissingValuesAreNaNInTheFileAndAbsentOnRead) {
  CampaignIndex index = MakeIndex(20);
  index.evaluations[0].metrics.clear();
  index.evaluations[1].metrics["ctrl_rate_hz"] = kNaN;  // explicit NaN
  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, index).ok());
  Result<CampaignIndex> back = ReadCampaignIndex(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_TRUE(back->evaluations[0].metrics.empty());
  EXPECT_EQ(back->evaluations[1].metrics.count("ctrl_rate_hz"), 0u);
  EXPECT_EQ(back->evaluations[1].metrics.count("nav_time_s"), 1u);
  EXPECT_EQ(back->evaluations[5].point.count("freq_ghz"), 0u);  // 5 % 13

  // In the file: one full-length column per name, NaN where missing.
  RawFile raw(path);
  ASSERT_GE(raw.get(), 0);
  const hid_t dataset =
      H5Dopen2(raw.get(), "/evaluations/metrics/ctrl_rate_hz", H5P_DEFAULT);
  ASSERT_GE(dataset, 0);
  std::vector<double> values(20, 0.0);
  ASSERT_GE(H5Dread(dataset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                    values.data()),
            0);
  H5Dclose(dataset);
  EXPECT_TRUE(std::isnan(values[0]));
  EXPECT_TRUE(std::isnan(values[1]));
  EXPECT_TRUE(std::isnan(values[3]));  // a failed row
  EXPECT_EQ(values[2], 12.0);
}

TEST_F(CampaignFileTest, EmptyIndexKeepsEmptyDatasets) {
  CampaignIndex index;  // no rows, no rounds, no parameters or metrics
  const std::string path = Path("campaign.h5");
  const Status written = WriteCampaignIndex(path, index);
  ASSERT_TRUE(written.ok()) << written.ToString();
  Result<CampaignIndex> back = ReadCampaignIndex(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(Diff(index, *back), "");

  RawFile raw(path);
  ASSERT_GE(raw.get(), 0);
  for (const char* name :
       {"/evaluations/index", "/evaluations/content_key", "/evaluations/seed",
        "/evaluations/bottlenecks_json", "/iterations/content_keys"}) {
    const hid_t dataset = H5Dopen2(raw.get(), name, H5P_DEFAULT);
    ASSERT_GE(dataset, 0) << name;
    const hid_t space = H5Dget_space(dataset);
    EXPECT_EQ(H5Sget_simple_extent_ndims(space), 1) << name;
    EXPECT_EQ(H5Sget_simple_extent_npoints(space), 0) << name;
    H5Sclose(space);
    H5Dclose(dataset);
  }
}

TEST_F(CampaignFileTest, WritesAtomicallyAndReplacesAnExistingFile) {
  const std::string path = Path("campaign.h5");
  {
    // Junk larger than the index: a partial overwrite would leave a tail.
    std::ofstream junk(path, std::ios::binary);
    junk << std::string(4 << 20, 'J');
  }
  const CampaignIndex first = MakeIndex(500);
  ASSERT_TRUE(WriteCampaignIndex(path, first).ok());
  EXPECT_EQ(Listing(), std::vector<std::string>{"campaign.h5"});
  EXPECT_LT(fs::file_size(path), size_t{4} << 20);
  Result<CampaignIndex> back = ReadCampaignIndex(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(Diff(first, *back), "");

  CampaignIndex second = MakeIndex(12);
  second.strategy = "random";
  ASSERT_TRUE(WriteCampaignIndex(path, second).ok());
  EXPECT_EQ(Listing(), std::vector<std::string>{"campaign.h5"});  // no *.tmp.*
  back = ReadCampaignIndex(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(Diff(second, *back), "");
  EXPECT_EQ(back->evaluations.size(), 12u);
}

TEST_F(CampaignFileTest, CreatesParentFolders) {
  const std::string path = Path("out/campaign/campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(3)).ok());
  EXPECT_TRUE(ReadCampaignIndex(path).ok());
}

TEST_F(CampaignFileTest, FailedWriteLeavesNoTemporary) {
  // The target is an existing folder: the rename must fail.
  fs::create_directories(Path("campaign.h5/inside"));
  const Status status = WriteCampaignIndex(Path("campaign.h5"), MakeIndex(5));
  EXPECT_EQ(status.code(), Status::Code::kIoError);
  EXPECT_NE(status.message().find("campaign.h5"), std::string::npos);
  EXPECT_EQ(Listing(), std::vector<std::string>{"campaign.h5"});
}

TEST_F(CampaignFileTest, RejectsWhatCannotBeStoredAndWritesNothing) {
  const std::string path = Path("campaign.h5");
  auto expect_rejected = [&](const CampaignIndex& index,
                             const std::string& detail) {
    const Status status = WriteCampaignIndex(path, index);
    EXPECT_EQ(status.code(), Status::Code::kInvalidArgument)
        << status.ToString();
    EXPECT_NE(status.message().find(detail), std::string::npos)
        << status.message();
    EXPECT_TRUE(Listing().empty());
  };
  CampaignIndex index = MakeIndex(10);
  index.evaluations[4].point["lidar_hz"] = 7.0;  // not a listed parameter
  expect_rejected(index, "lidar_hz");
  index = MakeIndex(10);
  index.evaluations[2].metrics["energy_j"] = 1.0;  // not a listed metric
  expect_rejected(index, "energy_j");
  index = MakeIndex(10);
  index.parameters.push_back("a/b");
  expect_rejected(index, "a/b");
  index = MakeIndex(10);
  index.metrics.push_back("completed");
  expect_rejected(index, "twice");
  index = MakeIndex(10);
  index.iterations[0].content_keys[0] += ",x";
  expect_rejected(index, "content key");
  index = MakeIndex(10);
  index.evaluations[6].reason = std::string("a\0b", 3);
  expect_rejected(index, "NUL");
}

TEST_F(CampaignFileTest, MissingFileIsNotFound) {
  const std::string path = Path("nope.h5");
  Result<CampaignIndex> back = ReadCampaignIndex(path);
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.status().code(), Status::Code::kNotFound);
  EXPECT_NE(back.status().message().find(path), std::string::npos);
}

TEST_F(CampaignFileTest, DirectoryIsRejected) {
  Result<CampaignIndex> back = ReadCampaignIndex(dir_);
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.status().code(), Status::Code::kInvalidArgument);
}

TEST_F(CampaignFileTest, NonHdf5FileIsCorruption) {
  const std::string path = Path("campaign.h5");
  std::ofstream(path) << "index,status\n0,complete\n";
  ExpectCorruption(path, "not an HDF5 file");
  const std::string empty = Path("empty.h5");
  std::ofstream(empty).close();
  ExpectCorruption(empty, "");
}

TEST_F(CampaignFileTest, TruncatedFileIsCorruption) {
  const std::string good = Path("good.h5");
  ASSERT_TRUE(WriteCampaignIndex(good, MakeIndex(500)).ok());
  const auto size = fs::file_size(good);
  for (const auto cut : {size / 2, size - 1, size_t{1000}, size_t{100}}) {
    SCOPED_TRACE("cut at " + std::to_string(cut));
    const std::string path = Path("cut_" + std::to_string(cut) + ".h5");
    fs::copy_file(good, path);
    fs::resize_file(path, cut);
    ExpectCorruption(path, "");
  }
}

TEST_F(CampaignFileTest, FlippedBytesAreCorruptionNotGarbage) {
  // Metadata and column chunks are checksummed.
  const std::string good = Path("good.h5");
  ASSERT_TRUE(WriteCampaignIndex(good, MakeIndex(500)).ok());
  std::string bytes;
  {
    std::ifstream in(good, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  for (const size_t pos :
       {bytes.size() / 3, bytes.size() / 2, 2 * bytes.size() / 3}) {
    SCOPED_TRACE("flip at " + std::to_string(pos));
    std::string damaged = bytes;
    damaged[pos] = static_cast<char>(damaged[pos] ^ 0x5A);
    const std::string path = Path("flip_" + std::to_string(pos) + ".h5");
    std::ofstream(path, std::ios::binary) << damaged;
    ExpectCorruption(path, "");
  }
}

TEST_F(CampaignFileTest, WrongSchemaVersionIsCorruption) {
  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(10)).ok());
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    ASSERT_GE(H5Adelete(raw.get(), "schema_version"), 0);
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t attr = H5Acreate2(raw.get(), "schema_version", H5T_STD_I32LE,
                                  space, H5P_DEFAULT, H5P_DEFAULT);
    ASSERT_GE(attr, 0);
    const int32_t version = kCampaignSchemaVersion + 1;
    H5Awrite(attr, H5T_NATIVE_INT32, &version);
    H5Aclose(attr);
    H5Sclose(space);
  }
  ExpectCorruption(path, "schema_version 2");
}

TEST_F(CampaignFileTest, RunFileIsNotACampaignIndex) {
  RunData run;
  run.status = "complete";
  run.termination_reason = "goal_reached";
  run.scenario_name = "follow";
  run.scenario_text = "name: follow\n";
  const std::string path = Path("run.h5");
  ASSERT_TRUE(WriteRunFile(path, run).ok());
  ExpectCorruption(path, "kind");
}

TEST_F(CampaignFileTest, MissingDatasetIsCorruptionNamingIt) {
  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(10)).ok());
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    ASSERT_GE(H5Ldelete(raw.get(), "/evaluations/status", H5P_DEFAULT), 0);
    ASSERT_GE(
        H5Ldelete(raw.get(), "/evaluations/metrics/completed", H5P_DEFAULT), 0);
  }
  ExpectCorruption(path, "/evaluations/status: missing dataset");
}

TEST_F(CampaignFileTest, MissingMetricColumnIsCorruptionNamingIt) {
  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(10)).ok());
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    ASSERT_GE(
        H5Ldelete(raw.get(), "/evaluations/metrics/completed", H5P_DEFAULT), 0);
  }
  ExpectCorruption(path, "/evaluations/metrics/completed: missing dataset");
}

TEST_F(CampaignFileTest, UnequalColumnLengthsAreCorruption) {
  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(10)).ok());
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    ReplaceWithDoubles(raw.get(), "/evaluations/point/cores", 9);
  }
  ExpectCorruption(path, "/evaluations/point/cores: 9 rows, expected 10");

  ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(10)).ok());
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    ReplaceWithDoubles(raw.get(), "/evaluations/wall_s", 11);
  }
  ExpectCorruption(path, "/evaluations/wall_s: 11 rows, expected 10");
}

TEST_F(CampaignFileTest, WrongColumnTypeIsCorruption) {
  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(10)).ok());
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    ReplaceWithDoubles(raw.get(), "/iterations/rationale", 1);
  }
  ExpectCorruption(path, "/iterations/rationale: is float, expected string");
}

TEST_F(CampaignFileTest, ReadsVariableLengthStringsToo) {
  // What h5py writes by default, e.g. after someone edits the file.
  const std::string path = Path("campaign.h5");
  CampaignIndex index = MakeIndex(3);
  ASSERT_TRUE(WriteCampaignIndex(path, index).ok());
  const std::vector<std::string> reasons = {"ä, \"b\"", "", "timeout"};
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    ASSERT_GE(H5Ldelete(raw.get(), "/evaluations/reason", H5P_DEFAULT), 0);
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, H5T_VARIABLE);
    H5Tset_cset(type, H5T_CSET_UTF8);
    const hsize_t dims[1] = {3};
    const hid_t space = H5Screate_simple(1, dims, nullptr);
    const hid_t dataset =
        H5Dcreate2(raw.get(), "/evaluations/reason", type, space, H5P_DEFAULT,
                   H5P_DEFAULT, H5P_DEFAULT);
    ASSERT_GE(dataset, 0);
    const char* texts[3] = {reasons[0].c_str(), reasons[1].c_str(),
                            reasons[2].c_str()};
    ASSERT_GE(H5Dwrite(dataset, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, texts), 0);
    H5Dclose(dataset);
    H5Sclose(space);
    H5Tclose(type);
  }
  Result<CampaignIndex> back = ReadCampaignIndex(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back->evaluations[i].reason, reasons[i]);
    index.evaluations[i].reason = reasons[i];
  }
  EXPECT_EQ(Diff(index, *back), "");
}

std::string CampaignSchemaPath() {
  return std::string(ADSE_SOURCE_DIR) + "/results-schema/campaign.schema.json";
}

TEST_F(CampaignFileTest, PassesTheSchemaCheck) {
  for (const size_t rows : {size_t{0}, size_t{25}}) {
    const std::string path = Path("campaign" + std::to_string(rows) + ".h5");
    ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(rows)).ok());
    std::vector<std::string> problems;
    const Status status = CheckRunFile(path, CampaignSchemaPath(), &problems);
    EXPECT_TRUE(status.ok()) << status.ToString();
    EXPECT_TRUE(problems.empty()) << problems.front();
  }
}

TEST_F(CampaignFileTest, SchemaCheckReportsProblems) {
  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(10)).ok());
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    ASSERT_GE(H5Ldelete(raw.get(), "/evaluations/seed", H5P_DEFAULT), 0);
    ASSERT_GE(H5Adelete_by_name(raw.get(), "/evaluations/point", "names",
                                H5P_DEFAULT),
              0);
    // A string column where float columns belong.
    ASSERT_GE(H5Lmove(raw.get(), "/evaluations/status", raw.get(),
                      "/evaluations/metrics/status", H5P_DEFAULT, H5P_DEFAULT),
              0);
  }
  std::vector<std::string> problems;
  EXPECT_EQ(CheckRunFile(path, CampaignSchemaPath(), &problems).code(),
            Status::Code::kCorruption);
  std::string all;
  for (const auto& line : problems) all += line + "\n";
  EXPECT_NE(all.find("/evaluations/seed: missing dataset"), std::string::npos)
      << all;
  EXPECT_NE(all.find("/evaluations/point: missing attribute 'names'"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("/evaluations/metrics/status: is string, expected float"),
            std::string::npos)
      << all;
  // A run file is not a campaign index.
  RunData run;
  run.status = "complete";
  ASSERT_TRUE(WriteRunFile(Path("run.h5"), run).ok());
  problems.clear();
  EXPECT_EQ(
      CheckRunFile(Path("run.h5"), CampaignSchemaPath(), &problems).code(),
      Status::Code::kCorruption);
}

// The schema documents every root attribute and column the writer writes:
// the two cannot drift apart silently.
TEST_F(CampaignFileTest, SchemaDocumentsEverythingTheWriterWrites) {
  std::ifstream in(CampaignSchemaPath());
  ASSERT_TRUE(in) << CampaignSchemaPath();
  const json schema = json::parse(in);
  EXPECT_EQ(schema.at("schema_version").get<int>(), kCampaignSchemaVersion);

  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, MakeIndex(5)).ok());
  RawFile raw(path);
  ASSERT_GE(raw.get(), 0);

  std::set<std::string> documented;
  for (const auto& attr : schema.at("root_attributes")) {
    documented.insert(attr.at("name").get<std::string>());
  }
  std::set<std::string> written;
  hsize_t position = 0;
  ASSERT_GE(
      H5Aiterate2(
          raw.get(), H5_INDEX_NAME, H5_ITER_INC, &position,
          [](hid_t, const char* name, const H5A_info_t*, void* data) -> herr_t {
            static_cast<std::set<std::string>*>(data)->insert(name);
            return 0;
          },
          &written),
      0);
  EXPECT_EQ(written, documented);

  // Every member of /evaluations, /iterations and /llm_exchanges is a
  // documented dataset or group.
  documented.clear();
  for (const auto& dataset : schema.at("datasets")) {
    documented.insert(dataset.at("path").get<std::string>());
  }
  for (const auto& group : schema.at("groups")) {
    documented.insert(group.at("path").get<std::string>());
  }
  written.clear();
  for (const char* group :
       {"/evaluations", "/replicas", "/iterations", "/llm_exchanges"}) {
    H5G_info_t info;
    ASSERT_GE(H5Gget_info_by_name(raw.get(), group, &info, H5P_DEFAULT), 0);
    for (hsize_t i = 0; i < info.nlinks; ++i) {
      char name[256] = {};
      H5Lget_name_by_idx(raw.get(), group, H5_INDEX_NAME, H5_ITER_INC, i, name,
                         sizeof(name), H5P_DEFAULT);
      written.insert(std::string(group) + "/" + name);
    }
  }
  for (const std::string& name : written) {
    EXPECT_EQ(documented.count(name), 1u) << name << " is not documented";
  }
  EXPECT_EQ(written.size(), documented.size() - 4)  // minus the four groups
      << "documented items missing from the file";
}

// Finds a python3 that has h5py and pandas; empty if none.
std::string PythonWithPandas() {
  for (const char* candidate : {"/usr/bin/python3", "python3"}) {
    Result<ProcessResult> probe =
        RunProcess({candidate, "-c", "import h5py, numpy, pandas"});
    if (probe.ok() && probe->exit_code == 0) return candidate;
  }
  return "";
}

// h5py and pandas read the index with no adse code, and see the values
// that were written (compared against a JSON dump of the index).
TEST_F(CampaignFileTest, H5pyAndPandasReadTheFile) {
  const std::string python = PythonWithPandas();
  if (python.empty()) {
    GTEST_SKIP() << "no python3 with h5py and pandas is installed";
  }
  const CampaignIndex index = MakeIndex(40);
  const std::string path = Path("campaign.h5");
  ASSERT_TRUE(WriteCampaignIndex(path, index).ok());

  json expected;
  expected["scenario_name"] = index.scenario_name;
  expected["scenario_text"] = index.scenario_text;
  expected["exploration_seed"] = index.exploration_seed;
  expected["parameters"] = index.parameters;
  expected["metrics"] = index.metrics;
  json& rows = expected["rows"];
  for (const EvaluationRow& row : index.evaluations) {
    json r;
    r["index"] = row.index;
    r["iteration"] = row.iteration;
    r["content_key"] = row.content_key;
    r["status"] = row.status;
    r["reason"] = row.reason;
    r["source"] = row.source;
    r["attempts"] = row.attempts;
    r["wall_s"] = row.wall_s;
    r["feasible"] = row.feasible ? 1 : 0;
    r["seed"] = row.seed;
    r["bottlenecks_json"] = row.bottlenecks_json;
    for (const auto& [group, names, values] :
         {std::tuple{"point", &index.parameters, &row.point},
          std::tuple{"metrics", &index.metrics, &row.metrics}}) {
      for (const std::string& name : *names) {
        const auto found = values->find(name);
        // null: missing, must be NaN in the file; infinities as strings.
        if (found == values->end()) {
          r[group][name] = nullptr;
        } else if (std::isinf(found->second)) {
          r[group][name] = found->second > 0 ? "inf" : "-inf";
        } else {
          r[group][name] = found->second;
        }
      }
    }
    rows.push_back(r);
  }
  for (const IterationRow& round : index.iterations) {
    expected["iterations"].push_back({{"iteration", round.iteration},
                                      {"rationale", round.rationale},
                                      {"content_keys", round.content_keys}});
  }
  const std::string expected_path = Path("expected.json");
  std::ofstream(expected_path) << expected.dump();

  // What a user would type: one DataFrame of the scalar columns, one each
  // for the design points and metrics.
  const std::string script = R"PY(
import json, math, sys
import h5py, numpy as np, pandas as pd

exp = json.load(open(sys.argv[2], encoding="utf-8"))
with h5py.File(sys.argv[1], "r") as f:
    assert f.attrs["kind"] == b"adse-campaign", f.attrs["kind"]
    assert int(f.attrs["schema_version"]) == 1
    assert f.attrs["scenario_name"].decode() == exp["scenario_name"]
    assert f.attrs["scenario_text"].decode() == exp["scenario_text"]
    assert int(f.attrs["exploration_seed"]) == exp["exploration_seed"]

    ev = f["evaluations"]
    columns = [k for k in ev if isinstance(ev[k], h5py.Dataset)]
    assert sorted(columns) == sorted(
        ["index", "iteration", "content_key", "status", "reason", "source",
         "attempts", "wall_s", "feasible", "seed", "bottlenecks_json",
         "replicas", "unstable"]), columns
    df = pd.DataFrame({k: ev[k][...] for k in columns})
    for k in ("content_key", "status", "reason", "source", "bottlenecks_json"):
        df[k] = df[k].str.decode("utf-8")
    assert len(df) == len(exp["rows"]), (len(df), len(exp["rows"]))
    assert df["index"].dtype == np.int64 and df["seed"].dtype == np.uint64
    assert df["feasible"].dtype == np.uint8 and df["wall_s"].dtype == np.float64

    names = [n.decode() for n in ev["point"].attrs["names"]]
    assert names == exp["parameters"], names
    point = pd.DataFrame({n: ev["point"][n][...] for n in names})
    metric_names = [n.decode() for n in ev["metrics"].attrs["names"]]
    assert metric_names == exp["metrics"], metric_names
    metrics = pd.DataFrame({n: ev["metrics"][n][...] for n in metric_names})
    assert list(point.columns) == exp["parameters"]

    def same(value, want):
        if want is None:
            return math.isnan(value)
        if isinstance(want, str):
            return value == float(want)
        return value == want

    for i, want in enumerate(exp["rows"]):
        row = df.iloc[i]
        for k in ("index", "iteration", "attempts", "feasible", "seed",
                  "content_key", "status", "reason", "source",
                  "bottlenecks_json"):
            assert row[k] == want[k], (i, k, row[k], want[k])
        assert row["wall_s"] == want["wall_s"], (i, row["wall_s"])
        for n in names:
            assert same(point[n].iloc[i], want["point"][n]), (i, n)
        for n in metric_names:
            assert same(metrics[n].iloc[i], want["metrics"][n]), (i, n)

    # Typical use: join and filter.
    table = df.join(point).join(metrics)
    done = table[table["status"] == "complete"]
    assert done["nav_time_s"].notna().all()
    assert table[table["status"] == "failed"]["nav_time_s"].isna().all()
    assert int(table["feasible"].sum()) == sum(r["feasible"] for r in exp["rows"])

    # Replicas: one row per run, joined to their evaluation by index.
    rep = f["replicas"]
    runs = pd.DataFrame({k: rep[k][...] for k in rep
                         if isinstance(rep[k], h5py.Dataset)})
    assert len(runs) == int(df["replicas"][df["replicas"] > 1].sum()), runs
    per_point = runs.groupby("index")["replica"].count()
    for i, count in per_point.items():
        assert df.set_index("index").loc[i, "replicas"] == count, (i, count)
    rep_metrics = pd.DataFrame(
        {n: rep["metrics"][n][...] for n in metric_names})
    assert len(rep_metrics) == len(runs)

    it = f["iterations"]
    rounds = pd.DataFrame({k: it[k][...] for k in it})
    assert len(rounds) == len(exp["iterations"])
    for i, want in enumerate(exp["iterations"]):
        assert rounds["iteration"].iloc[i] == want["iteration"]
        assert rounds["rationale"].iloc[i].decode() == want["rationale"]
        text = rounds["content_keys"].iloc[i].decode()
        keys = text.split(",") if text else []
        assert keys == want["content_keys"], (i, keys)
print("ok", len(df))
)PY";
  Result<ProcessResult> run =
      RunProcess({python, "-c", script, path, expected_path});
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_EQ(run->exit_code, 0) << run->output;
  EXPECT_NE(run->output.find("ok 40"), std::string::npos) << run->output;
}

}  // namespace
}  // namespace adse::runfile
