#include "stack/algorithms/command_gate.h"

#include <gtest/gtest.h>

#include <string>

namespace adse::algorithms {
namespace {

TEST(CommandGate, FreshCommandsPassThrough) {
  CommandGate gate;
  gate.OnCommand(1.0, 0.8, 0.1);
  const GateOutput out = gate.Output(1.3);
  EXPECT_FALSE(out.braking);
  EXPECT_EQ(out.reason, GateReason::kNone);
  EXPECT_DOUBLE_EQ(out.accel_mps2, 0.8);
  EXPECT_DOUBLE_EQ(out.steer_rad, 0.1);
  EXPECT_NEAR(out.command_age_s, 0.3, 1e-12);
  EXPECT_FALSE(gate.Output(1.5).braking);  // exactly at the limit
}

TEST(CommandGate, StaleCommandBrakesWithSteerHeld) {
  CommandGate gate;
  gate.OnCommand(1.0, 1.5, -0.2);
  const GateOutput out = gate.Output(1.51);
  EXPECT_TRUE(out.braking);
  EXPECT_EQ(out.reason, GateReason::kStale);
  EXPECT_DOUBLE_EQ(out.accel_mps2, -3.0);
  EXPECT_DOUBLE_EQ(out.steer_rad, -0.2);
  EXPECT_STREQ(GateReasonName(out.reason), "stale");
  gate.OnCommand(1.6, 0.5, 0.0);  // fresh again: passthrough
  EXPECT_FALSE(gate.Output(1.7).braking);
  gate.OnCommand(1.2, 9.0, 9.0);  // an older command arriving late
  EXPECT_DOUBLE_EQ(gate.Output(1.7).accel_mps2, 0.5);
}

TEST(CommandGate, GearPassesAndIsHeldWhileBraking) {
  CommandGate gate;
  EXPECT_FALSE(gate.Output(0.0).reverse);
  gate.OnCommand(1.0, 0.4, 0.2, true);
  EXPECT_TRUE(gate.Output(1.1).reverse);
  // Stale: brakes in the same gear (braking takes speed off either way).
  const GateOutput out = gate.Output(2.0);
  EXPECT_TRUE(out.braking);
  EXPECT_TRUE(out.reverse);
  gate.OnCommand(2.1, 0.4, 0.2, false);
  EXPECT_FALSE(gate.Output(2.2).reverse);
}

TEST(CommandGate, LostLocalizationBrakes) {
  CommandGateParams params;
  params.emergency_decel_mps2 = 4.0;
  CommandGate gate(params);
  gate.OnCommand(1.0, 1.0, 0.05);
  gate.OnLocalization(1.0, false);
  GateOutput out = gate.Output(1.1);
  EXPECT_TRUE(out.braking);
  EXPECT_EQ(out.reason, GateReason::kLocalizationLost);
  EXPECT_DOUBLE_EQ(out.accel_mps2, -4.0);
  EXPECT_DOUBLE_EQ(out.steer_rad, 0.05);
  gate.OnLocalization(1.2, true);
  EXPECT_FALSE(gate.Output(1.25).braking);
}

TEST(CommandGate, NoCommandYetBrakes) {
  CommandGate gate;
  const GateOutput out = gate.Output(0.0);
  EXPECT_TRUE(out.braking);
  EXPECT_EQ(out.reason, GateReason::kNoCommand);
  EXPECT_EQ(out.command_age_s, -1.0);
  EXPECT_EQ(std::string(GateReasonName(GateReason::kNone)), "none");
}

}  // namespace
}  // namespace adse::algorithms
