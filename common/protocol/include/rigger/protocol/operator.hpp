#pragma once
/// @file
/// The topics of operator (idl/operator.idl), each declared once.

#include <rigger/idl/types.hpp>

#include "rigger/protocol/topic.hpp"

namespace rigger::protocol::operator_ui {

/// Screw skill, task_controller (OperatorDecision) → riggerctl operator, UIs.
inline constexpr Topic<rigger_operator_ui_OperatorPrompt> kPrompt{"rigger/operator/prompt",
                                                                  QosProfile::kState,
                                                                  "prompt_id",
                                                                  "Screw skill, task_controller (OperatorDecision)",
                                                                  "riggerctl operator, UIs",
                                                                  "(e.g. screw hole, type, torque; options)",
                                                                  ""};

/// riggerctl operator, scripted operator → skills, task_controller.
inline constexpr Topic<rigger_operator_ui_OperatorResponse> kResponse{
    "rigger/operator/response", QosProfile::kState,     "prompt_id", "riggerctl operator, scripted operator",
    "skills, task_controller",  "(one of the options)", ""};

/// riggerctl jog → admittance_control.
inline constexpr Topic<rigger_sensing_TwistCommand> kJoystick{
    "rigger/operator/joystick", QosProfile::kSetpoints, "", "riggerctl jog", "admittance_control", "", ""};

}  // namespace rigger::protocol::operator_ui
