// WriteCampaignIndex / ReadCampaignIndex: exact round trips (replicas and
// LLM exchanges included), missing values, atomic replacement, and what
// cannot be stored refused before anything is written.
#include "analysis/runfile/campaign_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "stack/base/hash.h"

#include "tests/analysis/runfile/testing/campaign_index_impl.h"

namespace adse::runfile {
namespace {

namespace fs = std::filesystem;
using testing::CampaignFileTest;
using testing::Diff;
using testing::kMetrics;
using testing::kNaN;
using testing::kParameters;
using testing::MakeIndex;
using testing::RawFile;

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
  // An index written before LLM exchanges were kept: no /llm_exchanges.
  {
    RawFile raw(path);
    ASSERT_GE(raw.get(), 0);
    ASSERT_GE(H5Ldelete(raw.get(), "/llm_exchanges", H5P_DEFAULT), 0);
  }
  back = ReadCampaignIndex(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_TRUE(back->llm_exchanges.empty());
  EXPECT_EQ(back->evaluations.size(), index.evaluations.size());
  // The recorded robotaxi campaign (exhaustive, no LLM) exchanged none.
  Result<CampaignIndex> recorded =
      ReadCampaignIndex(std::string(ADSE_SOURCE_DIR) +
                        "/tests/data/robotaxi_exhaustive/campaign.h5");
  ASSERT_TRUE(recorded.ok()) << recorded.status().ToString();
  EXPECT_TRUE(recorded->llm_exchanges.empty());
  EXPECT_EQ(recorded->evaluations.size(), 280u);
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

}  // namespace
}  // namespace adse::runfile
