#include "physics_crane_axes.hpp"

#include <gtest/gtest.h>

#include "cell_sim_config.hpp"
#include "rigger/sim/cell_geometry.hpp"

namespace rigger::cell_sim {
namespace {

using namespace std::chrono_literals;

TEST(PhysicsCraneAxes, ConvertsRopeLengthToHookHeightAndFlipsTheHoistVelocity) {
  sim::CraneState crane;
  crane.position_m = {3.0, 1.5, 2.0};      // 2 m of rope paid out
  crane.velocity_mps = {0.1, -0.2, 0.05};  // paying out: the hook goes down
  crane.load_mass_estimate_kg = 40.0;
  const plc::CraneAxesMeasurement m = to_plc_axes(crane, 4.5);
  EXPECT_DOUBLE_EQ(m.position_m.z(), 2.5);
  EXPECT_DOUBLE_EQ(m.velocity_mps.z(), -0.05);
  EXPECT_DOUBLE_EQ(m.position_m.x(), 3.0);
  EXPECT_DOUBLE_EQ(m.velocity_mps.y(), -0.2);
  EXPECT_DOUBLE_EQ(m.load_kg, 40.0);
  EXPECT_EQ(to_physics_setpoint({0.1, 0.2, 0.15}), Eigen::Vector3d(0.1, 0.2, -0.15));
}

TEST(PhysicsCraneAxes, AHoistCommandUpRaisesTheHookInThePhysics) {
  sim::CellPhysics physics(sim::load_cell_geometry(default_cell_file()));
  PhysicsCraneAxes axes(physics);
  const plc::CraneAxesMeasurement before = axes.read();
  EXPECT_NEAR(before.position_m.z(), physics.geometry().crane.rail_height_m - physics.crane_state().position_m.z(),
              1e-12);
  EXPECT_GT(before.load_kg, 30.0);  // the 40 kg load hangs on the hook

  axes.apply_velocity({0.1, 0.0, 0.1});  // bridge forward, hook up
  physics.step(1s);
  const plc::CraneAxesMeasurement after = axes.read();
  EXPECT_GT(after.position_m.z(), before.position_m.z() + 0.05);
  EXPECT_GT(after.velocity_mps.z(), 0.05);
  EXPECT_GT(after.position_m.x(), before.position_m.x() + 0.05);
  EXPECT_EQ(axes.rejected_commands(), 0u);
}

TEST(PhysicsCraneAxes, CountsCommandsThePhysicsRefuses) {
  sim::CellPhysics physics(sim::load_cell_geometry(default_cell_file()));
  PhysicsCraneAxes axes(physics);
  axes.apply_velocity({std::nan(""), 0.0, 0.0});
  axes.apply_velocity({100.0, 0.0, 0.0});
  EXPECT_EQ(axes.rejected_commands(), 2u);
}

}  // namespace
}  // namespace rigger::cell_sim
