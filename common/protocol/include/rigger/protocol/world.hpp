#pragma once
/// @file
/// The topics of world model (idl/world.idl), each declared once.

#include <rigger/idl/types.hpp>

#include "rigger/protocol/topic.hpp"

namespace rigger::protocol::world {

/// world_model → all.
inline constexpr Topic<rigger_world_EntityState> kEntity{
    "rigger/world/entity",
    QosProfile::kState,
    "entity_id",
    "world_model",
    "all",
    "(kind, parent frame, has_pose, pose with covariance, quality, localized, stale, stamp, source, features, "
    "attributes, revision)",
    ""};

/// skills, vision_tracker → world_model.
inline constexpr Topic<rigger_world_EntityUpdate> kUpdate{
    "rigger/world/update",
    QosProfile::kCommands,
    "source",
    "skills, vision_tracker",
    "world_model",
    "(entity, optional re-parent, has_pose/has_covariance/has_quality/has_localized flags, stamp, attributes merge "
    "patch; seq correlates the result)",
    ""};

/// world_model → the updater.
inline constexpr Topic<rigger_world_UpdateResult> kUpdateResult{
    "rigger/world/update_result",
    QosProfile::kEvents,
    "source",
    "world_model",
    "the updater",
    "(accepted, code, reason, revision; source + seq of the update)",
    ""};

/// world_model → journals, UIs.
inline constexpr Topic<rigger_world_EntityChange> kChange{
    "rigger/world/change", QosProfile::kEvents, "entity_id", "world_model", "journals, UIs", "(who changed what)", ""};

/// task_controller, skills → world_model.
inline constexpr Topic<rigger_world_WorldQuery> kQuery{
    "rigger/world/query",
    QosProfile::kCommands,
    "client_id",
    "task_controller, skills",
    "world_model",
    "(POSE of A — or of its feature_id — in B, IS_LOCALIZED with max age, FEATURES, ENTITY, LIST with an optional "
    "kind; request id)",
    ""};

/// world_model → the querier.
inline constexpr Topic<rigger_world_WorldReply> kReply{"rigger/world/reply",
                                                       QosProfile::kEvents,
                                                       "client_id",
                                                       "world_model",
                                                       "the querier",
                                                       "(ok or code + message; pose, localized, age, JSON result)",
                                                       ""};

/// world_model → every reader of the cell file (common/cell_follower).
inline constexpr Topic<rigger_world_CellRevision> kCell{
    "rigger/world/cell",
    QosProfile::kState,
    "",
    "world_model",
    "cell_sim, vision_tracker, admittance_control, cad, console",
    "(the running cell revision: the whole validated cell document, its sha256, the previous revision, what "
    "changed by entity id, who, comment, stamp; a late joiner gets the last one)",
    ""};

/// world_model → every reader of the cell file whose folder lacks a pinned model's bytes.
inline constexpr Topic<rigger_world_CellModel> kCellModel{
    "rigger/world/cell_model",
    QosProfile::kState,
    "sha256",
    "world_model",
    "cell_sim, vision_tracker, admittance_control, cad, console",
    "(a STEP model pinned by the running revision: its sha256, its name, its bytes; a late joiner gets them)",
    ""};

/// riggerctl, console, the CalibrateCamera skill → world_model.
inline constexpr Topic<rigger_world_CellRequest> kCellRequest{
    "rigger/world/cell_request",
    QosProfile::kCommands,
    "client_id",
    "riggerctl, console, CalibrateCamera (robot-skills)",
    "world_model",
    "(APPLY a cell document with the STEP models it pins, optionally dry run; ROLLBACK to a revision; SHOW a revision; HISTORY; who, comment; "
    "request id)",
    ""};

/// world_model → the requester.
inline constexpr Topic<rigger_world_CellReply> kCellReply{
    "rigger/world/cell_reply",
    QosProfile::kEvents,
    "client_id",
    "world_model",
    "the requester",
    "(ok or code ACCEPTED, INVALID, HELD_BY_TASK, UNKNOWN_REVISION, UNCHANGED, TOO_LARGE, BAD_REQUEST + message; "
    "the running revision; JSON result)",
    ""};

}  // namespace rigger::protocol::world
