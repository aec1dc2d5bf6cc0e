// What the campaign index tests share: a realistic index (MakeIndex), a
// bit-exact comparison (Diff), raw HDF5 access for damaging files on
// purpose, and a fixture with a scratch folder. Holds HDF5 types, hence
// _impl.h.
#ifndef ADSE_TESTS_ANALYSIS_RUNFILE_TESTING_CAMPAIGN_INDEX_IMPL_H_
#define ADSE_TESTS_ANALYSIS_RUNFILE_TESTING_CAMPAIGN_INDEX_IMPL_H_

#if __has_include(<hdf5.h>)
#include <hdf5.h>
#else
#include <hdf5/serial/hdf5.h>  // Debian keeps it off the default path
#endif

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "analysis/runfile/campaign_file.h"
#include "stack/base/hash.h"
#include "tests/analysis/testing/temp_dir_test.h"

namespace adse::runfile::testing {

namespace fs = std::filesystem;

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr double kInf = std::numeric_limits<double>::infinity();

inline const std::vector<std::string> kParameters = {"v0_mps", "cores",
                                                     "freq_ghz"};
inline const std::vector<std::string> kMetrics = {
    "nav_time_s", "ctrl_rate_hz", "hardware_cost", "deviation_score",
    "completed"};

inline std::string ReasonOf(size_t i) {
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
inline CampaignIndex MakeIndex(size_t rows) {
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

inline bool SameBits(double a, double b) {
  return std::memcmp(&a, &b, sizeof(double)) == 0;
}

// The first differences between two indexes, empty if identical (numbers
// bit-exact).
inline std::string Diff(const CampaignIndex& a, const CampaignIndex& b) {
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
inline void ReplaceWithDoubles(hid_t file, const char* path, size_t rows) {
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

class CampaignFileTest : public ::adse::testing::TempDirTest {
 protected:
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
};

}  // namespace adse::runfile::testing

#endif  // ADSE_TESTS_ANALYSIS_RUNFILE_TESTING_CAMPAIGN_INDEX_IMPL_H_
