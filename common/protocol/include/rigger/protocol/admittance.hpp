#pragma once
/// @file
/// The topics of admittance (idl/admittance.idl), each declared once.

#include <rigger/idl/types.hpp>

#include "rigger/protocol/topic.hpp"

namespace rigger::protocol::admittance {

/// skills → admittance_control.
inline constexpr Topic<rigger_admittance_AdmittanceCommand> kCommand{
    "rigger/admittance/command",
    QosProfile::kCommands,
    "",
    "skills",
    "admittance_control",
    "(mode OFF/ROBOT/ROBOT_AND_CRANE, reference NONE/JOYSTICK/VISUAL_SERVO, gains, axes; VISUAL_SERVO: `servo_object`, "
    "`servo_target`, `servo_goal_in_target` = the object's goal pose in the target's frame; `source` = the commander's "
    "service id, whose loss on `rigger/system/service_state` turns the mode OFF)",
    ""};

/// admittance_control → skills, UIs.
inline constexpr Topic<rigger_admittance_AdmittanceState> kState{
    "rigger/admittance/state",
    QosProfile::kState,
    "",
    "admittance_control",
    "skills, UIs",
    "(mode, fault + `fault_code` e.g. `COMMANDER_LOST`, `CRANE_FAULT`, `SERVO_REQUEST_INVALID`, `WRENCH_STALE`; "
    "filtered wrench, outputs in the robot base frame, crane velocity in the world; `servo_converged`, "
    "`servo_error_m`, `servo_error_rad`, NaN while unknown), at the crane rate (50 Hz) and on every command and fault "
    "change",
    ""};

}  // namespace rigger::protocol::admittance
