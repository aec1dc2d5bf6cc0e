#include "analysis/diagnosis/remedy.h"

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

namespace adse::analysis {
namespace {

TEST(RemedyTest, EveryKindRoundTripsThroughItsToken) {
  const std::vector<std::string> tokens = RemedyKindTokens();
  ASSERT_EQ(tokens.size(), 8u);
  EXPECT_EQ(std::set<std::string>(tokens.begin(), tokens.end()).size(),
            tokens.size());
  for (size_t i = 0; i < tokens.size(); ++i) {
    const RemedyKind kind = static_cast<RemedyKind>(i);
    EXPECT_EQ(RemedyKindToString(kind), tokens[i]);
    Result<RemedyKind> back = StringToRemedyKind(tokens[i]);
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    EXPECT_EQ(*back, kind);
  }
  EXPECT_STREQ(RemedyKindToString(RemedyKind::kMoreCores), "more_cores");
  EXPECT_STREQ(RemedyKindToString(RemedyKind::kRaisePublisherRate),
               "raise_publisher_rate");
}

TEST(RemedyTest, AnUnknownTokenIsRefusedByName) {
  for (const std::string token : {"more cores", "More_Cores", "", "faster"}) {
    Result<RemedyKind> kind = StringToRemedyKind(token);
    ASSERT_FALSE(kind.ok()) << token;
    EXPECT_EQ(kind.status().code(), Status::Code::kInvalidArgument);
    EXPECT_NE(kind.status().message().find("'" + token + "'"),
              std::string::npos)
        << kind.status().message();
    EXPECT_NE(kind.status().message().find("more_cores, higher_frequency"),
              std::string::npos)
        << kind.status().message();
  }
}

TEST(RemedyTest, EveryFindingKindRoundTripsAndAnUnknownOneIsNamed) {
  const std::vector<std::string> tokens = FindingKindTokens();
  ASSERT_EQ(tokens, (std::vector<std::string>{"cpu_bound", "frequency_bound",
                                              "starved_input"}));
  for (size_t i = 0; i < tokens.size(); ++i) {
    const FindingKind kind = static_cast<FindingKind>(i);
    EXPECT_EQ(FindingKindToString(kind), tokens[i]);
    Result<FindingKind> back = StringToFindingKind(tokens[i]);
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    EXPECT_EQ(*back, kind);
  }
  Result<FindingKind> unknown = StringToFindingKind("memory_bound");
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.status().code(), Status::Code::kInvalidArgument);
  EXPECT_NE(unknown.status().message().find(
                "'memory_bound'; valid kinds: cpu_bound, frequency_bound, "
                "starved_input"),
            std::string::npos)
      << unknown.status().message();
}

TEST(RemedyTest, TextIsTheDiagnosisWording) {
  const std::vector<Remedy> cpu_bound = {
      {RemedyKind::kMoreCores, "lidar_driver"},
      {RemedyKind::kLowerSensorRate, "/sensing/lidar/points_raw"}};
  EXPECT_EQ(RemediesText(cpu_bound), "more cores; lower sensor rate");
  EXPECT_EQ(RemedyText({RemedyKind::kHigherFrequency, "ndt_scan_matcher"}),
            "higher frequency");
  const std::vector<Remedy> frequency_bound = {
      {RemedyKind::kRaisePublisherRate, "/objects", "cluster"},
      {RemedyKind::kRaiseSensorRate, "/raw"}};
  EXPECT_EQ(RemediesText(frequency_bound),
            "raise the rate of /objects's publisher (cluster); raise the "
            "rate of sensor /raw");
  EXPECT_EQ(RemedyText({RemedyKind::kShortenTimerPeriod, "pub1/on_timer"}),
            "shorten the period of pub1/on_timer");
  EXPECT_EQ(RemedyText({RemedyKind::kRelieveNode, "slow"}),
            "relieve slow (cpu_bound)");
  EXPECT_EQ(RemedyText({RemedyKind::kOwnCallbackGroup, "planner/pose"}),
            "give planner/pose a callback group of its own");
  EXPECT_EQ(RemediesText({}), "");
}

TEST(RemedyTest, EqualityComparesEveryField) {
  const Remedy a{RemedyKind::kRaisePublisherRate, "/mid", "slow"};
  EXPECT_EQ(a, (Remedy{RemedyKind::kRaisePublisherRate, "/mid", "slow"}));
  EXPECT_NE(a, (Remedy{RemedyKind::kRaisePublisherRate, "/mid", "fast"}));
  EXPECT_NE(a, (Remedy{RemedyKind::kRaisePublisherRate, "/out", "slow"}));
  EXPECT_NE(a, (Remedy{RemedyKind::kRaiseSensorRate, "/mid", "slow"}));
}

}  // namespace
}  // namespace adse::analysis
