#include "rigger/world_protocol/cell_protocol.hpp"

#include <stdexcept>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/sequences.hpp"

namespace rigger::world_protocol {
namespace {

rigger_world_CellOp op_to_wire(CellOp op) {
  switch (op) {
    case CellOp::kApply:
      return rigger_world_CELL_APPLY;
    case CellOp::kRollback:
      return rigger_world_CELL_ROLLBACK;
    case CellOp::kShow:
      return rigger_world_CELL_SHOW;
    case CellOp::kHistory:
      return rigger_world_CELL_HISTORY;
  }
  return rigger_world_CELL_HISTORY;
}

void request_fields_to_wire(const CellRequest& request, rigger_world_CellRequest& wire) {
  wire.client_id = dds::wire_string(request.client_id);
  wire.request_id = request.request_id;
  wire.op = request.op ? op_to_wire(*request.op) : static_cast<rigger_world_CellOp>(request.wire_op);
  wire.cell_json = dds::wire_string(request.cell_json);
  wire.revision = request.revision;
  wire.dry_run = request.dry_run;
  wire.who = dds::wire_string(request.who);
  wire.comment = dds::wire_string(request.comment);
}

std::optional<CellOp> op_from_wire(rigger_world_CellOp op) {
  switch (op) {
    case rigger_world_CELL_APPLY:
      return CellOp::kApply;
    case rigger_world_CELL_ROLLBACK:
      return CellOp::kRollback;
    case rigger_world_CELL_SHOW:
      return CellOp::kShow;
    case rigger_world_CELL_HISTORY:
      return CellOp::kHistory;
  }
  return std::nullopt;
}

}  // namespace

std::string_view to_string(CellOp op) {
  switch (op) {
    case CellOp::kApply:
      return "apply";
    case CellOp::kRollback:
      return "rollback";
    case CellOp::kShow:
      return "show";
    case CellOp::kHistory:
      return "history";
  }
  return "?";
}

void to_wire(const CellRevision& revision, rigger_world_CellRevision& wire) {
  wire.cell_revision = revision.cell_revision;
  wire.cell_json = dds::wire_string(revision.cell_json);
  wire.sha256 = dds::wire_string(revision.sha256);
  wire.previous_revision = revision.previous_revision;
  wire.changes_json = dds::wire_string(revision.changes_json);
  wire.who = dds::wire_string(revision.who);
  wire.comment = dds::wire_string(revision.comment);
  wire.stamp = dds::to_wire(revision.stamp);
}

CellRevision from_wire(const rigger_world_CellRevision& wire) {
  CellRevision r;
  r.cell_revision = wire.cell_revision;
  r.cell_json = dds::to_string(wire.cell_json);
  r.sha256 = dds::to_string(wire.sha256);
  r.previous_revision = wire.previous_revision;
  r.changes_json = dds::to_string(wire.changes_json);
  r.who = dds::to_string(wire.who);
  r.comment = dds::to_string(wire.comment);
  r.stamp = dds::to_domain(wire.stamp);
  return r;
}

void to_wire(const CellModel& model, rigger_world_CellModel& wire) {
  wire.sha256 = dds::wire_string(model.sha256);
  wire.name = dds::wire_string(model.name);
  // Borrowed, never written through: the writer serialises the bytes.
  dds::wire_buffer(wire.step, reinterpret_cast<std::uint8_t*>(const_cast<char*>(model.step.data())),
                   model.step.size());
}

CellModel from_wire(const rigger_world_CellModel& wire) {
  CellModel m;
  m.sha256 = dds::to_string(wire.sha256);
  m.name = dds::to_string(wire.name);
  const auto bytes = dds::elements(wire.step);
  m.step.assign(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  return m;
}

void to_wire(const CellRequest& request, rigger_world_CellRequest& wire,
             std::vector<rigger_world_CellModel>& storage) {
  request_fields_to_wire(request, wire);
  storage.assign(request.models.size(), rigger_world_CellModel{});
  for (std::size_t i = 0; i < request.models.size(); ++i) to_wire(request.models[i], storage[i]);
  dds::wire_sequence(wire.models, storage);
}

void to_wire(const CellRequest& request, rigger_world_CellRequest& wire) {
  if (!request.models.empty())
    throw std::invalid_argument("a cell request with models needs the storage of their wire form");
  request_fields_to_wire(request, wire);
}

CellRequest from_wire(const rigger_world_CellRequest& wire) {
  CellRequest r;
  r.client_id = dds::to_string(wire.client_id);
  r.request_id = wire.request_id;
  r.op = op_from_wire(wire.op);
  r.wire_op = static_cast<long long>(wire.op);
  r.cell_json = dds::to_string(wire.cell_json);
  r.revision = wire.revision;
  r.dry_run = wire.dry_run;
  r.who = dds::to_string(wire.who);
  r.comment = dds::to_string(wire.comment);
  for (const rigger_world_CellModel& m : dds::elements(wire.models)) r.models.push_back(from_wire(m));
  return r;
}

void to_wire(const CellReply& reply, rigger_world_CellReply& wire) {
  wire.client_id = dds::wire_string(reply.client_id);
  wire.request_id = reply.request_id;
  wire.ok = reply.ok;
  wire.code = dds::wire_string(reply.code);
  wire.message = dds::wire_string(reply.message);
  wire.cell_revision = reply.cell_revision;
  wire.result_json = dds::wire_string(reply.result_json);
}

CellReply from_wire(const rigger_world_CellReply& wire) {
  CellReply r;
  r.client_id = dds::to_string(wire.client_id);
  r.request_id = wire.request_id;
  r.ok = wire.ok;
  r.code = dds::to_string(wire.code);
  r.message = dds::to_string(wire.message);
  r.cell_revision = wire.cell_revision;
  r.result_json = dds::to_string(wire.result_json);
  return r;
}

}  // namespace rigger::world_protocol
