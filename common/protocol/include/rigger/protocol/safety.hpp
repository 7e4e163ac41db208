#pragma once
/// @file
/// The topics of safety (idl/safety.idl), each declared once.

#include <rigger/idl/types.hpp>

#include "rigger/protocol/topic.hpp"

namespace rigger::protocol::safety {

/// task_controller (escalations), riggerctl estop → admittance_control, crane_gateway, robot driver.
inline constexpr Topic<rigger_safety_SafeStop> kStop{
    "rigger/safety/stop",
    QosProfile::kState,
    "resource",
    "task_controller (escalations), riggerctl estop",
    "admittance_control, crane_gateway, robot driver (cell_sim)",
    "(active, source, reason: the software safe stop of one resource — robot, crane, gripper, admittance — "
    "latched until a reset; [safety.md](safety.md))",
    "devices read with state_changes(): every stop and reset"};

}  // namespace rigger::protocol::safety
