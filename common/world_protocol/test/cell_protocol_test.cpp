#include "rigger/world_protocol/cell_protocol.hpp"

#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace rigger::world_protocol {
namespace {

TEST(CellProtocol, RevisionRoundTrip) {
  CellRevision r;
  r.cell_revision = 7;
  r.cell_json = R"({"cell_version":1})";
  r.sha256 = "ab12";
  r.previous_revision = 6;
  r.changes_json = R"({"added":["part_4"]})";
  r.who = "ada";
  r.comment = "moved the fixture";
  r.stamp = from_unix_ns(1'700'000'000'123'456'789);
  rigger_world_CellRevision wire{};
  to_wire(r, wire);
  const CellRevision back = from_wire(wire);
  EXPECT_EQ(back.cell_revision, 7U);
  EXPECT_EQ(back.cell_json, r.cell_json);
  EXPECT_EQ(back.sha256, "ab12");
  EXPECT_EQ(back.previous_revision, 6U);
  EXPECT_EQ(back.changes_json, r.changes_json);
  EXPECT_EQ(back.who, "ada");
  EXPECT_EQ(back.comment, r.comment);
  EXPECT_EQ(back.stamp, r.stamp);
}

TEST(CellProtocol, EveryRequestOpRoundTrips) {
  for (CellOp op : {CellOp::kApply, CellOp::kRollback, CellOp::kShow, CellOp::kHistory}) {
    CellRequest q;
    q.client_id = "riggerctl-1";
    q.request_id = 3;
    q.op = op;
    q.cell_json = "{}";
    q.revision = 2;
    q.dry_run = true;
    q.who = "ada";
    q.comment = "c";
    rigger_world_CellRequest wire{};
    to_wire(q, wire);
    const CellRequest back = from_wire(wire);
    EXPECT_EQ(back.op, op) << to_string(op);
    EXPECT_EQ(back.client_id, "riggerctl-1");
    EXPECT_EQ(back.request_id, 3U);
    EXPECT_EQ(back.cell_json, "{}");
    EXPECT_EQ(back.revision, 2U);
    EXPECT_TRUE(back.dry_run);
    EXPECT_EQ(back.who, "ada");
    EXPECT_EQ(back.comment, "c");
  }
}

TEST(CellProtocol, TheModelsOfARequestRoundTripWithTheirBytes) {
  CellRequest q;
  q.client_id = "console";
  q.op = CellOp::kApply;
  q.cell_json = "{}";
  // Bytes a STEP file may hold: any octet, NUL included.
  const std::string bytes("ISO-10303-21;\0\xff\x01 END-ISO-10303-21;", 37);
  q.models = {{"ab12", "imported/plate.step", bytes}, {"cd34", "b.stp", ""}};
  rigger_world_CellRequest wire{};
  std::vector<rigger_world_CellModel> storage;
  to_wire(q, wire, storage);
  const CellRequest back = from_wire(wire);
  ASSERT_EQ(back.models.size(), 2U);
  EXPECT_EQ(back.models[0].sha256, "ab12");
  EXPECT_EQ(back.models[0].name, "imported/plate.step");
  EXPECT_EQ(back.models[0].step, bytes);
  EXPECT_EQ(back.models[1].step, "");
  EXPECT_EQ(back.cell_json, "{}");
  rigger_world_CellRequest plain{};
  EXPECT_THROW(to_wire(q, plain), std::invalid_argument) << "models without their storage";
  rigger_world_CellModel one{};
  to_wire(q.models[0], one);
  EXPECT_EQ(from_wire(one).step, bytes);
}

TEST(CellProtocol, AnUnknownOpIsKeptForTheMessage) {
  rigger_world_CellRequest wire{};
  wire.op = static_cast<rigger_world_CellOp>(9);
  const CellRequest q = from_wire(wire);
  EXPECT_FALSE(q.op.has_value());
  EXPECT_EQ(q.wire_op, 9);
  EXPECT_EQ(q.client_id, "");  // a null string reads as empty
  rigger_world_CellRequest again{};
  to_wire(q, again);
  EXPECT_EQ(static_cast<int>(again.op), 9);
}

TEST(CellProtocol, ReplyRoundTrip) {
  CellReply r;
  r.client_id = "console";
  r.request_id = 11;
  r.ok = false;
  r.code = cell_code::kHeldByTask;
  r.message = "load is held by task t1 node insert";
  r.cell_revision = 4;
  r.result_json = "{}";
  rigger_world_CellReply wire{};
  to_wire(r, wire);
  const CellReply back = from_wire(wire);
  EXPECT_EQ(back.client_id, "console");
  EXPECT_EQ(back.request_id, 11U);
  EXPECT_FALSE(back.ok);
  EXPECT_EQ(back.code, "HELD_BY_TASK");
  EXPECT_EQ(back.message, r.message);
  EXPECT_EQ(back.cell_revision, 4U);
  EXPECT_EQ(back.result_json, "{}");
}

}  // namespace
}  // namespace rigger::world_protocol
