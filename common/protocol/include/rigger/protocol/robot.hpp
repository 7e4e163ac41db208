#pragma once
/// @file
/// The topics of robot and gripper (idl/robot.idl, idl/sensing.idl), each declared once.

#include <rigger/idl/types.hpp>

#include "rigger/protocol/topic.hpp"

namespace rigger::protocol::robot {

/// robot driver / cell_sim / ros2_bridge → admittance_control, monitor_host.
inline constexpr Topic<rigger_sensing_WrenchStamped> kWrench{"rigger/robot/wrench",
                                                             QosProfile::kSensorStream,
                                                             "",
                                                             "robot driver / cell_sim / ros2_bridge",
                                                             "admittance_control, monitor_host",
                                                             "(wrist F/T, sensor frame) ≥ 500 Hz",
                                                             ""};

/// robot driver / cell_sim / ros2_bridge (from a ROS 2 driver's joint states) → skills, admittance_control,
/// vision_tracker (a held object's model tracking follows the tool).
inline constexpr Topic<rigger_robot_RobotState> kState{"rigger/robot/state",
                                                       QosProfile::kSensorStream,
                                                       "",
                                                       "robot driver / cell_sim / ros2_bridge",
                                                       "skills, admittance_control, vision_tracker",
                                                       "(joints, flange and tool pose in base frame, tool twist, mode)",
                                                       ""};

/// admittance_control → robot driver / cell_sim / ros2_bridge.
inline constexpr Topic<rigger_sensing_TwistCommand> kCmdTwist{"rigger/robot/cmd_twist",
                                                              QosProfile::kSetpoints,
                                                              "",
                                                              "admittance_control",
                                                              "robot driver / cell_sim / ros2_bridge",
                                                              "(tool twist in base frame, stamp, seq, timeout)",
                                                              ""};

/// skills → robot driver / cell_sim.
inline constexpr Topic<rigger_robot_MotionCommand> kCmdMotion{"rigger/robot/cmd_motion",
                                                              QosProfile::kCommands,
                                                              "motion_id",
                                                              "skills",
                                                              "robot driver / cell_sim",
                                                              "(joint or Cartesian goal, speed scale)",
                                                              ""};

/// robot driver / cell_sim → skills.
inline constexpr Topic<rigger_robot_MotionStatus> kMotionStatus{
    "rigger/robot/motion_status", QosProfile::kEvents, "motion_id", "robot driver / cell_sim", "skills", "", ""};

/// skills → gripper driver / cell_sim.
inline constexpr Topic<rigger_robot_GripperCommand> kGripperCmd{
    "rigger/gripper/cmd", QosProfile::kCommands, "", "skills", "gripper driver / cell_sim", "(energize)", ""};

/// gripper driver / cell_sim → skills.
inline constexpr Topic<rigger_robot_GripperState> kGripperState{"rigger/gripper/state",
                                                                QosProfile::kState,
                                                                "",
                                                                "gripper driver / cell_sim",
                                                                "skills",
                                                                "(energized, contact, holding)",
                                                                ""};

}  // namespace rigger::protocol::robot
