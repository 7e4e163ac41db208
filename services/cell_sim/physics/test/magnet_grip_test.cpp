#include "rigger/sim/magnet_grip.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace rigger::sim {
namespace {

MagnetCapacity capacity_of(double holding_force_n) {
  MagnetCapacity capacity;
  capacity.holding_force_n = holding_force_n;
  return capacity;
}

TEST(MagnetUtilisation, StraightPullUsesItsShareOfTheHoldingForce) {
  const MagnetCapacity capacity = capacity_of(1200.0);
  // Pulling the load off the face: the magnet pulls it back, along -z of the tool.
  EXPECT_NEAR(magnet_utilisation({0, 0, -600}, Eigen::Vector3d::Zero(), capacity), 0.5, 1e-12);
  EXPECT_NEAR(magnet_utilisation({0, 0, -1200}, Eigen::Vector3d::Zero(), capacity), 1.0, 1e-12);
  // Pushing is carried by the face contact.
  EXPECT_DOUBLE_EQ(magnet_utilisation({0, 0, 5000}, Eigen::Vector3d::Zero(), capacity), 0.0);
}

TEST(MagnetUtilisation, ShearPeelAndTwistHaveLowerCapacities) {
  const MagnetCapacity capacity = capacity_of(1200.0);  // friction 0.5, levers 0.05 / 0.04 m
  EXPECT_NEAR(magnet_utilisation({600, 0, 0}, Eigen::Vector3d::Zero(), capacity), 1.0, 1e-12);
  EXPECT_NEAR(magnet_utilisation({0, 0, 0}, {0, 60, 0}, capacity), 1.0, 1e-12);
  EXPECT_NEAR(magnet_utilisation({0, 0, 0}, {0, 0, 24}, capacity), 1.0, 1e-12);
  // Linear interaction: half a pull plus half a shear is full.
  EXPECT_NEAR(magnet_utilisation({300, 0, -600}, Eigen::Vector3d::Zero(), capacity), 1.0, 1e-12);
}

TEST(MagnetUtilisation, NoCapacityCannotHoldAnything) {
  EXPECT_TRUE(std::isinf(magnet_utilisation({0, 0, -1}, Eigen::Vector3d::Zero(), capacity_of(0))));
  EXPECT_DOUBLE_EQ(
      magnet_utilisation(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), capacity_of(0)), 0.0);
}

TEST(MagnetGripLogic, GripsOnlyWhenEnergizedAndInFlatContact) {
  MagnetGripLogic logic;
  EXPECT_EQ(logic.update(true, 0.0, 0.001), GripAction::None);  // not energized
  EXPECT_EQ(logic.phase(), GripperPhase::Off);
  logic.set_energized(true);
  EXPECT_EQ(logic.phase(), GripperPhase::Searching);
  EXPECT_EQ(logic.update(false, 0.0, 0.001), GripAction::None);
  EXPECT_EQ(logic.update(true, 0.0, 0.001), GripAction::Attach);
  EXPECT_EQ(logic.phase(), GripperPhase::Holding);
  EXPECT_EQ(logic.update(true, 0.5, 0.001), GripAction::None);
}

TEST(MagnetGripLogic, SustainedOverloadSlipsButASpikeDoesNot) {
  MagnetGripLogic logic(0.005);
  logic.set_energized(true);
  ASSERT_EQ(logic.update(true, 0.0, 0.001), GripAction::Attach);
  // One 1 ms spike to 3x capacity: filtered to 0.6, holds.
  EXPECT_EQ(logic.update(true, 3.0, 0.001), GripAction::None);
  EXPECT_LT(logic.filtered_utilisation(), 1.0);
  for (int i = 0; i < 50; ++i) {
    ASSERT_EQ(logic.update(true, 0.2, 0.001), GripAction::None);
  }
  // Sustained 1.5x capacity: slips within a few filter time constants.
  int steps = 0;
  GripAction action = GripAction::None;
  while (action == GripAction::None && steps < 100) {
    action = logic.update(true, 1.5, 0.001);
    ++steps;
  }
  EXPECT_EQ(action, GripAction::Release);
  EXPECT_LT(steps, 20);
  EXPECT_EQ(logic.phase(), GripperPhase::Slipped);
  EXPECT_EQ(logic.slip_count(), 1u);
  // Still touching: no re-grip until the face has left the load.
  EXPECT_EQ(logic.update(true, 0.0, 0.001), GripAction::None);
  EXPECT_EQ(logic.update(false, 0.0, 0.001), GripAction::None);
  EXPECT_EQ(logic.phase(), GripperPhase::Searching);
  EXPECT_EQ(logic.update(true, 0.0, 0.001), GripAction::Attach);
}

TEST(MagnetGripLogic, DeEnergizingReleases) {
  MagnetGripLogic logic;
  logic.set_energized(true);
  ASSERT_EQ(logic.update(true, 0.0, 0.001), GripAction::Attach);
  logic.set_energized(false);
  EXPECT_EQ(logic.phase(), GripperPhase::Off);
  EXPECT_EQ(logic.update(true, 0.0, 0.001), GripAction::Release);
  EXPECT_EQ(logic.update(true, 0.0, 0.001), GripAction::None);
  EXPECT_FALSE(logic.energized());
}

TEST(MagnetGripLogic, NonFiniteUtilisationCountsAsOverload) {
  MagnetGripLogic logic(0.0);
  logic.set_energized(true);
  ASSERT_EQ(logic.update(true, 0.0, 0.001), GripAction::Attach);
  EXPECT_EQ(logic.update(true, std::nan(""), 0.001), GripAction::Release);
}

}  // namespace
}  // namespace rigger::sim
