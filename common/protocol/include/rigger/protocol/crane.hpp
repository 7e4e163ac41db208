#pragma once
/// @file
/// The topics of crane (idl/crane.idl), each declared once.

#include <rigger/idl/types.hpp>

#include "rigger/protocol/topic.hpp"

namespace rigger::protocol::crane {

/// crane_gateway → skills, admittance_control, UIs.
inline constexpr Topic<rigger_crane_CraneState> kState{
    "rigger/crane/state",
    QosProfile::kState,
    "",
    "crane_gateway",
    "skills, admittance_control, UIs",
    "(positions, velocities, load, mode, status bits, fault, PLC heartbeat, link)",
    ""};

/// admittance_control → crane_gateway.
inline constexpr Topic<rigger_crane_CraneVelocityCommand> kCmdVelocity{
    "rigger/crane/cmd_velocity",
    QosProfile::kSetpoints,
    "",
    "admittance_control",
    "crane_gateway",
    "(bridge, trolley, hoist m/s; stamp, seq, timeout)",
    ""};

/// skills → crane_gateway.
inline constexpr Topic<rigger_crane_CraneControl> kControl{
    "rigger/crane/control",
    QosProfile::kCommands,
    "",
    "skills",
    "crane_gateway",
    "(ENABLE, DISABLE, RESET, REQUEST_EXTERNAL, RELEASE_EXTERNAL)",
    ""};

}  // namespace rigger::protocol::crane
