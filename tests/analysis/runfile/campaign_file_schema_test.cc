// The campaign index against results-schema/campaign.schema.json (checked,
// and documenting everything the writer writes), and read by h5py and
// pandas with no adse code.
#include "analysis/runfile/campaign_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "analysis/runfile/run_file.h"
#include "stack/base/subprocess.h"

#include "tests/analysis/runfile/testing/campaign_index_impl.h"

namespace adse::runfile {
namespace {

using nlohmann::json;
using testing::CampaignFileTest;
using testing::MakeIndex;
using testing::RawFile;

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
         "replicas", "unstable", "task_case"]), columns
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
