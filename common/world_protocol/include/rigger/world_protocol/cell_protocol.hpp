#pragma once
/// @file
/// The cell revisions on the wire (idl/world.idl: rigger/world/cell, rigger/world/cell_request,
/// rigger/world/cell_reply) in one domain form: the world model publishes revisions and answers requests;
/// riggerctl and the console send requests; every reader of the cell file follows the revisions
/// (common/cell_follower). Converted here once, to_wire and from_wire, with round-trip tests.
///
/// As in world_protocol.hpp: from_wire checks nothing a wire value can carry (bounds, JSON, revisions are
/// the world model's to judge); to_wire's strings borrow the message's.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <rigger/idl/types.hpp>

#include "rigger/base/time.hpp"

namespace rigger::world_protocol {

/// What a cell request asks (rigger/world/cell_request op).
enum class CellOp { kApply, kRollback, kShow, kHistory };

/// "apply", "rollback", "show", "history".
std::string_view to_string(CellOp op);

/// The codes of a CellReply.
namespace cell_code {
inline constexpr const char* kAccepted = "ACCEPTED";  ///< applied (or, dry run, would be); SHOW, HISTORY answered
inline constexpr const char* kInvalid = "INVALID";    ///< the document breaks a rule: file, JSON pointer, expected
inline constexpr const char* kHeldByTask = "HELD_BY_TASK";  ///< it touches an object a running skill holds
inline constexpr const char* kUnknownRevision = "UNKNOWN_REVISION";
inline constexpr const char* kUnchanged = "UNCHANGED";     ///< the document equals the running revision's
inline constexpr const char* kTooLarge = "TOO_LARGE";      ///< cell_json over the size bound
inline constexpr const char* kBadRequest = "BAD_REQUEST";  ///< an unknown op, a missing client id, ...
}  // namespace cell_code

/// rigger/world/cell: the running revision of the cell.
struct CellRevision {
  std::uint64_t cell_revision = 0;
  std::string cell_json;                ///< the whole validated cell document; model paths as in the file
  std::string sha256;                   ///< hex SHA-256 of cell_json
  std::uint64_t previous_revision = 0;  ///< 0 for the first
  /// What changed against previous_revision, by entity id:
  /// {"added":[id],"removed":[id],"moved":[{"id","distance_m","angle_deg"}],"changed":[{"id","keys":[...]}]}.
  std::string changes_json;
  std::string who;
  std::string comment;
  WallTime stamp{};
};

/// A STEP model as bytes: an upload of CellRequest::models, or a sample of rigger/world/cell_model.
struct CellModel {
  std::string sha256;  ///< hex SHA-256 of `step`, as the document's model.sha256 pins it
  std::string name;    ///< the object's model.step (a path relative to the cell folder)
  std::string step;    ///< the STEP file's bytes
};

/// rigger/world/cell_request: answered on rigger/world/cell_reply with (client_id, request_id).
struct CellRequest {
  std::string client_id;
  std::uint64_t request_id = 0;
  /// nullopt after from_wire when the sample's op is a value this build does not know; `wire_op` holds it.
  std::optional<CellOp> op = CellOp::kHistory;
  long long wire_op = 0;
  std::string cell_json;       ///< kApply: the proposed document
  std::uint64_t revision = 0;  ///< kRollback: the revision to bring back; kShow: 0 for the running one
  bool dry_run = false;        ///< kApply, kRollback: validate and diff, change nothing
  std::string who;             ///< the person (or identity) behind it, journaled
  std::string comment;
  std::vector<CellModel> models;  ///< kApply: models the world model's folder may lack (pinned by cell_json)
};

/// rigger/world/cell_reply: the answer to a CellRequest. On !ok, `code` and `message` say why.
struct CellReply {
  std::string client_id;
  std::uint64_t request_id = 0;
  bool ok = false;
  std::string code;  ///< one of cell_code
  std::string message;
  std::uint64_t cell_revision = 0;  ///< the running revision after the request
  std::string result_json;          ///< op-specific JSON (see idl/world.idl); empty: none
};

void to_wire(const CellRevision& revision, rigger_world_CellRevision& wire);
CellRevision from_wire(const rigger_world_CellRevision& wire);

/// to_wire borrows `model`'s bytes; the wire form must not outlive it.
void to_wire(const CellModel& model, rigger_world_CellModel& wire);
CellModel from_wire(const rigger_world_CellModel& wire);

/// A request without models (throws std::invalid_argument when it has some).
void to_wire(const CellRequest& request, rigger_world_CellRequest& wire);
/// `wire.models` points into `storage`, which to_wire fills: keep both alive together.
void to_wire(const CellRequest& request, rigger_world_CellRequest& wire, std::vector<rigger_world_CellModel>& storage);
CellRequest from_wire(const rigger_world_CellRequest& wire);

void to_wire(const CellReply& reply, rigger_world_CellReply& wire);
CellReply from_wire(const rigger_world_CellReply& wire);

}  // namespace rigger::world_protocol
