#pragma once
/// @file
/// The topics of cad (idl/cad.idl), each declared once.

#include <rigger/idl/types.hpp>

#include "rigger/protocol/topic.hpp"

namespace rigger::protocol::cad {

/// riggerctl, console, planner → cad.
inline constexpr Topic<rigger_cad_CadRequest> kRequest{
    "rigger/cad/request",
    QosProfile::kCommands,
    "client_id",
    "riggerctl, console, planner",
    "cad",
    "(kind: LOAD, FEATURES, TESSELLATION, FRAME, DERIVE; model as `object:<id>`, `sha256:<hex>` or a path; args JSON; "
    "request id)",
    ""};

/// cad → its clients.
inline constexpr Topic<rigger_cad_CadReply> kReply{
    "rigger/cad/reply",
    QosProfile::kEvents,
    "client_id",
    "cad",
    "its clients",
    "(ok, code, message, model sha256, result JSON, GLB bytes for a tessellation)",
    ""};

}  // namespace rigger::protocol::cad
