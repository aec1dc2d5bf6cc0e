// Recorded campaigns under tests/data, as the replay tests read them.
#ifndef ADSE_TESTS_HARNESS_TESTING_RECORDING_H_
#define ADSE_TESTS_HARNESS_TESTING_RECORDING_H_

#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <set>
#include <string>

#include "harness/campaign/replay.h"

namespace adse::testing {

// tests/data/<name>, loaded once per test binary (an empty recording, and a
// test failure, when it does not load).
inline const campaign::Recording& RecordingUnderTestData(
    const std::string& name) {
  static std::map<std::string, std::unique_ptr<campaign::Recording>> loaded;
  std::unique_ptr<campaign::Recording>& slot = loaded[name];
  if (!slot) {
    Result<campaign::Recording> r = campaign::LoadRecording(
        std::string(ADSE_SOURCE_DIR) + "/tests/data/" + name);
    EXPECT_TRUE(r.ok()) << r.status().message();
    slot = std::make_unique<campaign::Recording>(
        r.ok() ? std::move(r).value() : campaign::Recording{});
  }
  return *slot;
}

// How many distinct design points a recording holds, and how many of its
// rows are feasible.
struct Census {
  size_t distinct_points = 0;
  int feasible = 0;
};
inline Census CensusOf(const campaign::Recording& recording) {
  std::set<spec::DesignPoint> points;
  Census census;
  for (const campaign::EvaluationRow& row : recording.rows) {
    points.insert(row.point);
    census.feasible += row.feasible;
  }
  census.distinct_points = points.size();
  return census;
}

}  // namespace adse::testing

#endif  // ADSE_TESTS_HARNESS_TESTING_RECORDING_H_
