// The iiwa in the MuJoCo model: reach, Cartesian velocity control, joint limits, point-to-point
// motions, bad commands, the wrist sensor, and speed.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <iostream>

#include "physics_test_support.hpp"
#include "rigger/sim/iiwa14.hpp"
#include "rigger/sim/pose_math.hpp"

namespace rigger::sim {
namespace {

using namespace std::chrono_literals;
using namespace test_support;

constexpr double kDeg = M_PI / 180.0;

double angle_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return rotation_error(a, b).norm();
}

void expect_tool_at(const CellPhysics& physics, const Eigen::Isometry3d& goal_base_tool,
                    double position_tolerance_m, double angle_tolerance_rad) {
  const Eigen::Isometry3d tool = physics.robot_state().pose_base_tool;
  EXPECT_LT((tool.translation() - goal_base_tool.translation()).norm(), position_tolerance_m)
      << "tool at " << tool.translation().transpose() << ", goal "
      << goal_base_tool.translation().transpose();
  EXPECT_LT(angle_between(tool.linear(), goal_base_tool.linear()), angle_tolerance_rad);
}

TEST(RobotPhysics, ReachesGraspSideOnTheLoadAndTheInsertionGraspPoint) {
  CellPhysics physics(reachable_cell());
  const CellGeometry& cell = physics.geometry();
  const Eigen::Isometry3d grasp_load_tool = *cell.grasp_frame("grasp_side");
  ASSERT_FALSE(cell.load.approach_waypoints.empty());

  // Where the tool must be to grasp the hanging load, and where it will be when the load sits in
  // its insertion pose on the target: both have an inverse kinematics solution.
  const Eigen::Isometry3d grasp_base = feature_in_base(physics, grasp_load_tool);
  const Eigen::Isometry3d inserted_base = physics.pose_world_robot_base().inverse() *
                                          physics.pose_world_target() *
                                          *cell.load.pose_target_load_inserted * grasp_load_tool;
  for (const Eigen::Isometry3d& goal : {grasp_base, inserted_base}) {
    const IkResult ik = physics.solve_ik(goal);
    ASSERT_TRUE(ik.converged) << "unreachable: " << goal.translation().transpose();
    EXPECT_TRUE((ik.position_rad.array() <= physics.arm_limits().position_max_rad.array()).all());
    EXPECT_TRUE((ik.position_rad.array() >= physics.arm_limits().position_min_rad.array()).all());
    const Eigen::Isometry3d check = physics.tool_pose_for(ik.position_rad);
    EXPECT_LT((check.translation() - goal.translation()).norm(), 2e-4);
  }

  // And the arm gets there: straight-line moves to pre-grasp, then onto the face.
  const Eigen::Isometry3d pre_grasp_base =
      feature_in_base(physics, cell.load.approach_waypoints.front().pose_entity_feature);
  const CommandResult pre = physics.move_tool(pre_grasp_base, 0.5);
  ASSERT_TRUE(pre.ok()) << pre.message;
  ASSERT_TRUE(finish_motion(physics)) << physics.robot_state().motion.message;
  EXPECT_EQ(physics.robot_state().motion.id, pre.motion_id);
  expect_tool_at(physics, pre_grasp_base, 2e-3, 0.5 * kDeg);
  ASSERT_TRUE(physics.move_tool(grasp_base, 0.2).ok());
  ASSERT_TRUE(finish_motion(physics)) << physics.robot_state().motion.message;
  expect_tool_at(physics, grasp_base, 3e-3, 0.5 * kDeg);
  // The tool's z points into the load's -x face.
  const Eigen::Vector3d tool_z_world = physics.robot_state().pose_world_tool.linear().col(2);
  EXPECT_GT(tool_z_world.dot(physics.pose_world_load().linear().col(0)), std::cos(0.5 * kDeg));
  EXPECT_EQ(physics.diagnostics().mujoco_warning_count, 0);
}

TEST(RobotPhysics, UnreachableToolGoalIsRejectedBeforeMoving) {
  CellPhysics physics(reachable_cell());
  // The shared cell JSON's grasp_side pose relative to its robot base (0.35, -0.25, 0.30) m, tool
  // z along base x: the wrist centre would be 0.28 m from A2, but A4's 120 deg limit keeps it at
  // least 0.41 m away.
  const Eigen::Isometry3d too_close =
      pose_from_position_rpy(Eigen::Vector3d(0.35, -0.25, 0.30), Eigen::Vector3d(0, 90 * kDeg, 0));
  EXPECT_FALSE(physics.solve_ik(too_close).converged);
  const CommandResult result = physics.move_tool(too_close);
  EXPECT_EQ(result.status, CommandStatus::RejectedUnreachable);
  EXPECT_THAT(result.message, ::testing::HasSubstr("unreachable"));
  // Out of reach altogether.
  const Eigen::Isometry3d too_far =
      pose_from_position_rpy(Eigen::Vector3d(1.6, 0, 0.3), Eigen::Vector3d(0, 90 * kDeg, 0));
  EXPECT_EQ(physics.move_tool(too_far).status, CommandStatus::RejectedUnreachable);
  physics.step(200ms);
  EXPECT_EQ(physics.robot_state().mode, RobotMode::Hold);
  EXPECT_LT(physics.robot_state().velocity_rad_per_s.cwiseAbs().maxCoeff(), 1e-3);
}

TEST(RobotPhysics, TwistMovesTheToolInTheCommandedDirectionAndZeroStopsIt) {
  CellPhysics physics(reachable_cell());
  physics.step(100ms);
  const Eigen::Isometry3d start = physics.robot_state().pose_base_tool;
  const Eigen::Vector3d flange_start = physics.robot_state().pose_base_flange.translation();
  Twist twist;
  twist.linear_mps = Eigen::Vector3d(0.05, 0.03, -0.02);
  for (int i = 0; i < 100; ++i) {  // 1 s of commands at 100 Hz
    ASSERT_TRUE(physics.set_tool_twist(twist).ok());
    physics.step(10ms);
  }
  const Eigen::Isometry3d moved = physics.robot_state().pose_base_tool;
  const Eigen::Vector3d displacement = moved.translation() - start.translation();
  EXPECT_GT(displacement.normalized().dot(twist.linear_mps.normalized()), 0.995);
  const Eigen::Vector3d flange_displacement =
      physics.robot_state().pose_base_flange.translation() - flange_start;
  EXPECT_GT(flange_displacement.normalized().dot(twist.linear_mps.normalized()), 0.995);
  EXPECT_NEAR(displacement.norm(), twist.linear_mps.norm() * 1.0, 0.1 * twist.linear_mps.norm());
  EXPECT_LT(angle_between(moved.linear(), start.linear()), 0.5 * kDeg);
  EXPECT_EQ(physics.robot_state().mode, RobotMode::Twist);
  EXPECT_NEAR(physics.robot_state().twist_base_tool.linear_mps.x(), 0.05, 0.005);

  ASSERT_TRUE(physics.set_tool_twist(Twist{}).ok());
  physics.step(300ms);
  EXPECT_LT(physics.robot_state().twist_base_tool.linear_mps.norm(), 1e-3);
  const Eigen::Vector3d stopped = physics.robot_state().pose_base_tool.translation();
  ASSERT_TRUE(physics.set_tool_twist(Twist{}).ok());
  physics.step(1s);
  EXPECT_LT((physics.robot_state().pose_base_tool.translation() - stopped).norm(), 5e-4);
}

TEST(RobotPhysics, TwistStopsWhenCommandsAreNotRenewed) {
  CellPhysics physics(reachable_cell());
  const Eigen::Vector3d start = physics.robot_state().pose_base_tool.translation();
  Twist twist;
  twist.linear_mps = Eigen::Vector3d(0.0, 0.1, 0.0);
  ASSERT_TRUE(physics.set_tool_twist(twist).ok());
  physics.step(2s);  // no fresh command: 200 ms of motion, then a stop
  const RobotState state = physics.robot_state();
  EXPECT_EQ(state.mode, RobotMode::Hold);
  EXPECT_LT(state.twist_base_tool.linear_mps.norm(), 1e-3);
  const double travelled = (state.pose_base_tool.translation() - start).norm();
  EXPECT_GT(travelled, 0.01);
  EXPECT_LT(travelled, 0.1 * 0.25);
}

// A stop during a twist stream (a safe stop, the driver's twist timeout) brakes the tool on its line at the
// Cartesian deceleration limit (1 m/s²), as a robot controller's path-maintaining stop does: from 0.1 m/s the
// tool is at rest after about 0.1 s and 5 mm, along the direction it moved.
TEST(RobotPhysics, AStopDuringATwistBrakesOnThePathAtTheCartesianLimit) {
  CellPhysics physics(reachable_cell());
  physics.step(100ms);
  Twist twist;
  twist.linear_mps = Eigen::Vector3d(0.0, 0.1, 0.0);
  for (int i = 0; i < 100; ++i) {
    ASSERT_TRUE(physics.set_tool_twist(twist).ok());
    physics.step(10ms);
  }
  const Eigen::Vector3d at_stop = physics.robot_state().pose_base_tool.translation();
  physics.stop_robot();
  double rest_s = -1.0;
  for (int i = 1; i <= 500; ++i) {
    physics.step(1ms);
    if (rest_s < 0.0 && physics.robot_state().twist_base_tool.linear_mps.norm() < 1e-3) rest_s = i * 1e-3;
  }
  const Eigen::Vector3d travel = physics.robot_state().pose_base_tool.translation() - at_stop;
  EXPECT_NEAR(rest_s, 0.1, 0.03);
  EXPECT_NEAR(travel.y(), 0.1 * 0.1 / 2.0, 0.002);
  EXPECT_LT(std::hypot(travel.x(), travel.z()), 5e-4);
  EXPECT_EQ(physics.robot_state().mode, RobotMode::Hold);
}

TEST(RobotPhysics, JointLimitsAreNeverExceeded) {
  CellPhysics physics(reachable_cell());
  const ArmLimits& limits = physics.arm_limits();
  double worst_soft_overshoot = -1.0;
  const auto drive = [&](const Twist& twist, int steps) {
    for (int i = 0; i < steps; ++i) {
      if (i % 10 == 0) {
        ASSERT_TRUE(physics.set_tool_twist(twist).ok());
      }
      physics.step(1ms);
      const JointVector q = physics.robot_state().position_rad;
      const JointVector reference = physics.robot_state().reference_position_rad;
      for (int j = 0; j < kArmJointCount; ++j) {
        ASSERT_LE(std::abs(q[j]), limits.hard_position_max_rad[j]) << "joint A" << j + 1;
        ASSERT_LE(reference[j], limits.position_max_rad[j] + 1e-12);
        ASSERT_GE(reference[j], limits.position_min_rad[j] - 1e-12);
        worst_soft_overshoot =
            std::max(worst_soft_overshoot, std::abs(q[j]) - limits.position_max_rad[j]);
      }
    }
  };
  // Spin the tool about its own axis until A7 (and whatever helps it) runs out of range, then
  // pull the tool towards the base until the elbow (A4) is folded to its limit.
  Twist spin;
  spin.angular_rad_per_s = Eigen::Vector3d(1.0, 0.0, 0.0);
  drive(spin, 6000);
  Twist pull;
  pull.linear_mps = Eigen::Vector3d(-0.2, 0.0, 0.0);
  drive(pull, 4000);
  const JointVector reference = physics.robot_state().reference_position_rad;
  const bool some_joint_at_its_limit =
      ((limits.position_max_rad - reference.cwiseAbs()).array() < 0.5 * kDeg).any();
  EXPECT_TRUE(some_joint_at_its_limit) << reference.transpose();
  // Measured joints stay within a tracking error of the software limits.
  EXPECT_LT(worst_soft_overshoot, 0.5 * kDeg);
  EXPECT_EQ(physics.diagnostics().mujoco_warning_count, 0);
}

TEST(RobotPhysics, JointMotionIsSynchronizedWithinSpeedLimitsAndSettles) {
  CellPhysics physics(reachable_cell());
  JointVector goal = physics.robot_state().position_rad;
  goal[0] += 0.8;
  goal[3] += 0.4;
  goal[6] -= 1.0;
  const CommandResult command = physics.move_joints(goal, 0.5);
  ASSERT_TRUE(command.ok()) << command.message;
  const JointVector speed_limit = 0.5 * physics.arm_limits().speed_max_rad_per_s;
  while (physics.robot_state().motion.status == MotionStatus::Running && physics.sim_time() < 20s) {
    physics.step(5ms);
    const JointVector reference_speed =
        physics.robot_state().reference_velocity_rad_per_s.cwiseAbs();
    ASSERT_TRUE((reference_speed.array() <= speed_limit.array() + 1e-9).all())
        << reference_speed.transpose();
  }
  EXPECT_EQ(physics.robot_state().motion.status, MotionStatus::Reached)
      << physics.robot_state().motion.message;
  EXPECT_LT((physics.robot_state().position_rad - goal).cwiseAbs().maxCoeff(), 2e-3);
}

TEST(RobotPhysics, ANewMotionWhileMovingStopsTheOldOneFirst) {
  CellPhysics physics(reachable_cell());
  JointVector first = physics.robot_state().position_rad;
  first[0] += 1.0;
  const CommandResult one = physics.move_joints(first);
  physics.step(400ms);
  JointVector second = physics.robot_state().position_rad;
  second[0] -= 0.3;
  const CommandResult two = physics.move_joints(second);
  ASSERT_TRUE(two.ok());
  EXPECT_GT(two.motion_id, one.motion_id);
  physics.step(1ms);
  EXPECT_EQ(physics.robot_state().mode, RobotMode::Stopping);
  ASSERT_TRUE(finish_motion(physics)) << physics.robot_state().motion.message;
  EXPECT_EQ(physics.robot_state().motion.id, two.motion_id);

  // stop_robot() ends a running motion as Stopped, at rest.
  JointVector third = second;
  third[1] += 0.3;
  ASSERT_TRUE(physics.move_joints(third).ok());
  physics.step(200ms);
  physics.stop_robot();
  physics.step(1s);
  EXPECT_EQ(physics.robot_state().motion.status, MotionStatus::Stopped);
  EXPECT_EQ(physics.robot_state().mode, RobotMode::Hold);
  EXPECT_LT(physics.robot_state().velocity_rad_per_s.cwiseAbs().maxCoeff(), 1e-3);
}

TEST(RobotPhysics, BadCommandsAreRejectedAndChangeNothing) {
  CellPhysics physics(reachable_cell());
  JointVector beyond = physics.robot_state().position_rad;
  beyond[3] = 2.1;  // A4 beyond 120 deg
  const CommandResult out_of_range = physics.move_joints(beyond);
  EXPECT_EQ(out_of_range.status, CommandStatus::RejectedOutOfRange);
  EXPECT_THAT(out_of_range.message, ::testing::HasSubstr("A4"));
  JointVector not_finite = physics.robot_state().position_rad;
  not_finite[2] = std::nan("");
  EXPECT_EQ(physics.move_joints(not_finite).status, CommandStatus::RejectedNonFinite);
  EXPECT_EQ(physics.move_joints(physics.robot_state().position_rad, 0.0).status,
            CommandStatus::RejectedOutOfRange);
  EXPECT_EQ(physics.move_joints(physics.robot_state().position_rad, 1.5).status,
            CommandStatus::RejectedOutOfRange);
  Eigen::Isometry3d skewed = physics.robot_state().pose_base_tool;
  skewed.linear()(0, 0) = 2.0;
  EXPECT_EQ(physics.move_tool(skewed).status, CommandStatus::RejectedOutOfRange);
  Twist bad_twist;
  bad_twist.angular_rad_per_s.y() = INFINITY;
  EXPECT_EQ(physics.set_tool_twist(bad_twist).status, CommandStatus::RejectedNonFinite);
  Twist fast;
  fast.linear_mps.x() = 5.0;
  const CommandResult scaled = physics.set_tool_twist(fast);
  EXPECT_TRUE(scaled.ok());
  EXPECT_THAT(scaled.message, ::testing::HasSubstr("scaled"));
  physics.step(100ms);
  EXPECT_LE(physics.robot_state().twist_base_tool.linear_mps.norm(), 0.5 + 1e-3);
}

TEST(RobotPhysics, WristSensorReadsTheGripperWeightAndTheConfiguredNoise) {
  CellPhysics exact(reachable_cell());
  exact.step(500ms);
  const Eigen::Matrix3d rotation_world_tool = exact.robot_state().pose_world_tool.linear();
  const Eigen::Vector3d weight_tool =
      rotation_world_tool.transpose() * Eigen::Vector3d(0.0, 0.0, -2.0 * 9.81);
  EXPECT_LT((exact.wrench_tool().force_n - weight_tool).norm(), 0.05);
  EXPECT_LT(exact.external_wrench_tool().force_n.norm(), 0.05);
  EXPECT_LT(exact.external_wrench_tool().torque_nm.norm(), 0.01);

  CellPhysicsOptions options;
  options.wrench_noise.force_stddev_n = 0.5;
  options.wrench_noise.torque_stddev_nm = 0.02;
  CellPhysics noisy(reachable_cell(), options);
  double sum = 0.0;
  double sum_sq = 0.0;
  const int samples = 2000;
  for (int i = 0; i < samples; ++i) {
    noisy.step(1ms);
    const double value = noisy.external_wrench_tool().force_n.y();
    sum += value;
    sum_sq += value * value;
  }
  const double mean = sum / samples;
  const double stddev = std::sqrt(sum_sq / samples - mean * mean);
  EXPECT_NEAR(mean, 0.0, 0.05);
  EXPECT_NEAR(stddev, 0.5, 0.05);
}

TEST(RobotPhysics, KeepsRealTimeWithMargin) {
  CellPhysics physics(reachable_cell());
  ASSERT_TRUE(physics.set_crane_velocity({0.2, 0.1, 0.0}).ok());
  Twist twist;
  twist.linear_mps = Eigen::Vector3d(0.0, 0.05, 0.0);
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 500; ++i) {  // 5 s of cell time with the crane and the arm moving
    ASSERT_TRUE(physics.set_tool_twist(twist).ok());
    physics.step(10ms);
  }
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const PhysicsDiagnostics diagnostics = physics.diagnostics();
  std::cout << "physics: " << diagnostics.steps_per_second << " steps/s, real-time factor "
            << diagnostics.measured_real_time_factor << " (5 s simulated in " << wall_s
            << " s wall)\n";
  // Loose on purpose (shared CI machine); the benchmark measures it properly.
  EXPECT_GT(diagnostics.measured_real_time_factor, 1.0);
  EXPECT_EQ(diagnostics.mujoco_warning_count, 0);
}

}  // namespace
}  // namespace rigger::sim
