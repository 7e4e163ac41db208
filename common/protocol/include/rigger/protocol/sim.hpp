#pragma once
/// @file
/// The topics of simulator (idl/sim.idl), each declared once.

#include <rigger/idl/types.hpp>

#include "rigger/protocol/topic.hpp"

namespace rigger::protocol::sim {

/// cell_sim → tests, benchmarks.
inline constexpr Topic<rigger_vision_TrackedPose> kGroundTruth{
    "rigger/sim/ground_truth",
    QosProfile::kSensorStream,
    "object_id",
    "cell_sim",
    "tests, benchmarks",
    "— **the simulator's true poses, for tests and benchmarks only**",
    ""};

/// tests, demo → cell_sim.
inline constexpr Topic<rigger_sim_SimControl> kControl{
    "rigger/sim/control",
    QosProfile::kCommands,
    "",
    "tests, demo",
    "cell_sim",
    "(ESTOP on/off, SET_HOLDING_FORCE, SET_LOAD_FORCE, PLC_LINK down/up, RESET; seq)",
    ""};

/// cell_sim → tests, demo.
inline constexpr Topic<rigger_sim_SimEvent> kEvent{"rigger/sim/event",
                                                   QosProfile::kEvents,
                                                   "",
                                                   "cell_sim",
                                                   "tests, demo",
                                                   "(the answer to one control: accepted, message)",
                                                   ""};

/// cell_sim → tests, benchmarks.
inline constexpr Topic<rigger_sim_SimStatus> kStatus{
    "rigger/sim/status",
    QosProfile::kSensorStream,
    "",
    "cell_sim",
    "tests, benchmarks",
    "(simulated time, real-time factor, PLC registers, the crane's true axes, injected faults), 100 Hz",
    ""};

}  // namespace rigger::protocol::sim
