// The crane and its swinging load in the MuJoCo model: sway period, drives, freeze, end stops,
// slack rope and load cell.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "physics_test_support.hpp"

namespace rigger::sim {
namespace {

using namespace std::chrono_literals;
using namespace test_support;

constexpr double kGravity = 9.81;

struct SwayMeasurement {
  double period_s = 0.0;
  double pendulum_length_m = 0.0;  // sheave to the load's centre of mass
  double amplitude_rad = 0.0;
  int crossings = 0;
};

// Pushes the hanging load sideways (a person's push), lets go and times the sway by the zero
// crossings of the rope angle, interpolated between steps.
SwayMeasurement measure_sway(CellPhysics& physics) {
  EXPECT_TRUE(physics.set_load_external_force({40.0, 0.0, 0.0}).ok());
  physics.step(300ms);
  EXPECT_TRUE(physics.set_load_external_force(Eigen::Vector3d::Zero()).ok());
  physics.step(1s);

  SwayMeasurement result;
  const CellGeometry& cell = physics.geometry();
  result.pendulum_length_m = physics.crane_state().hook_distance_m +
                             cell.load.pose_load_rope_attachment.translation().norm();
  std::vector<double> crossings;
  double previous_angle = physics.crane_state().sway_angle_rad.y();
  double previous_time = seconds(physics.sim_time());
  while (crossings.size() < 11 && seconds(physics.sim_time()) < 60.0) {
    physics.step(1ms);
    const double angle = physics.crane_state().sway_angle_rad.y();
    const double time = seconds(physics.sim_time());
    result.amplitude_rad = std::max(result.amplitude_rad, std::abs(angle));
    if ((previous_angle < 0.0) != (angle < 0.0)) {
      crossings.push_back(previous_time +
                          (time - previous_time) * previous_angle / (previous_angle - angle));
    }
    previous_angle = angle;
    previous_time = time;
  }
  result.crossings = static_cast<int>(crossings.size());
  if (crossings.size() >= 2) {
    result.period_s =
        2.0 * (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  }
  return result;
}

// Small-oscillation period of the slow mode of the real system: a massless rope of length
// `rope_m` with a rigid box hung at a point `offset_m` above its centre (radius of gyration
// squared k2 about the swing axis).  Tends to 2 pi sqrt((rope + offset) / g) for a point mass.
double compound_pendulum_period(double rope_m, double offset_m, double k2) {
  const double b = offset_m * offset_m + k2 + rope_m * offset_m;
  const double a = rope_m * k2;
  const double lambda = (b - std::sqrt(b * b - 4.0 * a * offset_m)) / (2.0 * a);
  return 2.0 * M_PI / std::sqrt(kGravity * lambda);
}

class SwayPeriod : public ::testing::TestWithParam<double> {};

TEST_P(SwayPeriod, MatchesThePendulumFormulaWithinTwoPercent) {
  CellPhysics physics(reachable_cell());
  ASSERT_TRUE(hoist_to(physics, GetParam()));
  physics.step(2s);
  const SwayMeasurement sway = measure_sway(physics);
  ASSERT_EQ(sway.crossings, 11);
  const double simple = 2.0 * M_PI * std::sqrt(sway.pendulum_length_m / kGravity);
  const CellGeometry& cell = physics.geometry();
  const Eigen::Vector3d size = cell.load.size_m;
  const double k2 = (size.x() * size.x() + size.z() * size.z()) / 12.0;  // about the y axis
  const double exact =
      compound_pendulum_period(physics.crane_state().hook_distance_m,
                               cell.load.pose_load_rope_attachment.translation().norm(), k2);
  std::cout << "rope " << GetParam() << " m: L = " << sway.pendulum_length_m
            << " m, measured T = " << sway.period_s << " s, 2 pi sqrt(L/g) = " << simple << " s ("
            << 100.0 * (sway.period_s / simple - 1.0) << " %), compound pendulum = " << exact
            << " s, amplitude " << sway.amplitude_rad * 180.0 / M_PI << " deg\n";
  EXPECT_NEAR(sway.period_s / simple, 1.0, 0.02);
  EXPECT_NEAR(sway.period_s / exact, 1.0, 0.005);
  EXPECT_GT(sway.amplitude_rad, 0.01);  // it did swing
  EXPECT_EQ(physics.diagnostics().mujoco_warning_count, 0);
}

INSTANTIATE_TEST_SUITE_P(RopeLengths, SwayPeriod, ::testing::Values(1.0, 3.5),
                         [](const ::testing::TestParamInfo<double>& rope) {
                           return "Rope" + std::to_string(std::lround(rope.param * 1000.0)) + "mm";
                         });

TEST(CranePhysics, TrolleyAccelerationMakesTheLoadLagAndSway) {
  CellPhysics physics(reachable_cell());
  ASSERT_TRUE(physics.set_crane_velocity({0.0, 0.3, 0.0}).ok());
  physics.step(300ms);
  // Accelerating in +y: the load lags behind, the rope leans back (negative about x).
  EXPECT_LT(physics.crane_state().sway_angle_rad.x(), -0.005);
  physics.step(1200ms);
  physics.set_crane_velocity(Eigen::Vector3d::Zero());
  double amplitude = 0.0;
  for (int i = 0; i < 400; ++i) {
    physics.step(10ms);
    amplitude = std::max(amplitude, std::abs(physics.crane_state().sway_angle_rad.x()));
  }
  // Stopping from 0.3 m/s leaves a sway of about v / (omega L) = 0.05 rad on a 3.3 m pendulum.
  EXPECT_GT(amplitude, 0.02);
  EXPECT_LT(amplitude, 0.12);
  EXPECT_NEAR(physics.crane_state().velocity_mps.y(), 0.0, 1e-3);
}

TEST(CranePhysics, TravelAxesTrackTheirVelocitySetpoints) {
  CellPhysics physics(reachable_cell());
  const Eigen::Vector3d start = physics.crane_state().position_m;
  ASSERT_TRUE(physics.set_crane_velocity({0.3, -0.2, 0.1}).ok());
  physics.step(2s);
  const CraneState state = physics.crane_state();
  EXPECT_NEAR(state.velocity_mps.x(), 0.3, 0.005);
  EXPECT_NEAR(state.velocity_mps.y(), -0.2, 0.005);
  EXPECT_NEAR(state.velocity_mps.z(), 0.1, 1e-6);
  EXPECT_NEAR(state.position_m.x() - start.x(), 0.6, 0.02);
  EXPECT_NEAR(state.position_m.y() - start.y(), -0.4, 0.02);
  EXPECT_NEAR(state.position_m.z() - start.z(), 0.2, 0.01);
  EXPECT_TRUE(state.velocity_setpoint_mps.isApprox(Eigen::Vector3d(0.3, -0.2, 0.1)));
}

TEST(CranePhysics, FreezeBrakesEveryAxisAndHoldsAgainstAPush) {
  CellPhysics physics(reachable_cell());
  ASSERT_TRUE(physics.set_crane_velocity({0.5, 0.3, 0.1}).ok());
  physics.step(1500ms);
  physics.set_crane_frozen(true);
  // The drives brake along their ramps and stay where they stop: no axis runs backwards (a few
  // mm/s of servo overshoot as the ramp ends, not a return to where the stop was commanded).
  double most_negative_mps = 0.0;
  for (int i = 0; i < 500; ++i) {
    physics.step(1ms);
    most_negative_mps = std::min(most_negative_mps, physics.crane_state().velocity_mps.minCoeff());
  }
  EXPECT_GT(most_negative_mps, -0.01);
  CraneState state = physics.crane_state();
  EXPECT_TRUE(state.frozen);
  EXPECT_LT(state.velocity_mps.cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_TRUE(state.velocity_setpoint_mps.isZero());

  // Commands while frozen change nothing; a push on the load does not move the crane.
  const CommandResult ignored = physics.set_crane_velocity({0.5, 0.0, 0.0});
  EXPECT_TRUE(ignored.ok());
  EXPECT_THAT(ignored.message, ::testing::HasSubstr("frozen"));
  const Eigen::Vector3d held = state.position_m;
  ASSERT_TRUE(physics.set_load_external_force({100.0, 50.0, 0.0}).ok());
  physics.step(2s);
  state = physics.crane_state();
  EXPECT_LT((state.position_m - held).cwiseAbs().maxCoeff(), 2e-3);

  // Unfreezing does not restart the old motion.
  ASSERT_TRUE(physics.set_load_external_force(Eigen::Vector3d::Zero()).ok());
  physics.set_crane_frozen(false);
  physics.step(1s);
  EXPECT_LT(physics.crane_state().velocity_mps.cwiseAbs().maxCoeff(), 1e-3);
}

TEST(CranePhysics, AxesStopAtTheirEndStops) {
  CellPhysics physics(reachable_cell());
  ASSERT_TRUE(physics.set_crane_velocity({0.0, -0.5, -0.2}).ok());
  physics.step(16s);
  const CraneState state = physics.crane_state();
  // Trolley: against the buffer 5 cm beyond its range; hoist: the drum's top limit.
  EXPECT_NEAR(state.position_m.y(), state.range_min_m.y() - 0.05, 2e-3);
  EXPECT_DOUBLE_EQ(state.position_m.z(), state.range_min_m.z());
  EXPECT_LT(state.velocity_mps.cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_EQ(physics.diagnostics().mujoco_warning_count, 0);
}

TEST(CranePhysics, LoadCellReadsTheLoadAndARestingLoadSlacksTheRope) {
  CellPhysics physics(reachable_cell());
  physics.step(1s);
  EXPECT_NEAR(physics.crane_state().load_mass_estimate_kg, 40.0, 0.5);
  EXPECT_NEAR(physics.crane_state().rope_tension_n, (40.0 + 1.0) * kGravity, 5.0);
  EXPECT_FALSE(physics.crane_state().rope_slack);

  // Trolley slowly over the target (0.5 m in +y), let the sway die down a little, then lower the
  // load onto the fixture and beyond: the rope goes slack, the load cell reads nothing.
  ASSERT_TRUE(physics.set_crane_velocity({0.0, 0.1, 0.0}).ok());
  physics.step(5s);
  ASSERT_TRUE(physics.set_crane_velocity({0.0, 0.0, 0.1}).ok());
  physics.step(2500ms);
  physics.set_crane_velocity(Eigen::Vector3d::Zero());
  physics.step(3s);
  const CraneState lowered = physics.crane_state();
  EXPECT_TRUE(lowered.rope_slack);
  EXPECT_LT(lowered.rope_tension_n, 1.0);
  EXPECT_LT(lowered.load_mass_estimate_kg, 1.0);
  // Resting on the fixture's top face (0.95 m) with its 0.10 m half height.
  EXPECT_NEAR(physics.pose_world_load().translation().z(), 1.05, 0.01);

  // Lift it again: tension and mass come back.
  ASSERT_TRUE(physics.set_crane_velocity({0.0, 0.0, -0.1}).ok());
  physics.step(3s);
  physics.set_crane_velocity(Eigen::Vector3d::Zero());
  physics.step(3s);
  EXPECT_FALSE(physics.crane_state().rope_slack);
  EXPECT_NEAR(physics.crane_state().load_mass_estimate_kg, 40.0, 1.0);
  EXPECT_EQ(physics.diagnostics().mujoco_warning_count, 0);
}

TEST(CranePhysics, RejectsNonsenseSetpoints) {
  CellPhysics physics(reachable_cell());
  EXPECT_EQ(physics.set_crane_velocity({std::nan(""), 0, 0}).status,
            CommandStatus::RejectedNonFinite);
  EXPECT_EQ(physics.set_crane_velocity({0, INFINITY, 0}).status, CommandStatus::RejectedNonFinite);
  EXPECT_EQ(physics.set_crane_velocity({0, 0, 11.0}).status, CommandStatus::RejectedOutOfRange);
  physics.step(100ms);
  EXPECT_TRUE(physics.crane_state().velocity_setpoint_mps.isZero());
  EXPECT_EQ(physics.set_load_external_force({std::nan(""), 0, 0}).status,
            CommandStatus::RejectedNonFinite);
  EXPECT_EQ(physics.set_load_external_force({2e5, 0, 0}).status, CommandStatus::RejectedOutOfRange);
}

TEST(CranePhysics, GeometryOutsideTheCraneRangeIsAClearError) {
  CellGeometry cell = reachable_cell();
  cell.load.pose_world_load.translation().x() = 9.0;  // beyond the 8 m bridge range
  try {
    CellPhysics physics(cell);
    FAIL() << "expected CellGeometryError";
  } catch (const CellGeometryError& error) {
    EXPECT_THAT(error.what(), ::testing::HasSubstr("bridge_range_m"));
  }
  CellPhysicsOptions options;
  options.model_path = "/nonexistent/cell.xml";
  EXPECT_THROW(CellPhysics(reachable_cell(), options), PhysicsModelError);
}

}  // namespace
}  // namespace rigger::sim
