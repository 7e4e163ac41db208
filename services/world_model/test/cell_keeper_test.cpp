// CellKeeper: revisions made, refused, rolled back, kept on disk and found again at start.
#include "cell_keeper.hpp"

#include <fstream>
#include <iterator>

#include <gtest/gtest.h>

#include "cell_fixture.hpp"
#include "rigger/base/sha256.hpp"
#include "rigger/cell_config/cell_diff.hpp"
#include "world_store.hpp"

namespace rigger::world {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using world_protocol::CellOp;
using world_protocol::CellRequest;

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class CellKeeperTest : public ::testing::Test {
 protected:
  CellKeeperTest() {
    folder_ = fs::temp_directory_path() / ("rigger_cell_keeper_" + std::to_string(::getpid()) + "_" +
                                           ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(folder_);
    fs::create_directories(folder_);
    cell_file_ = folder_ / "cell.json";
    std::ofstream(cell_file_) << read_text(testing::fixture_cell_path());
  }
  ~CellKeeperTest() override { fs::remove_all(folder_); }

  CellKeeper keeper() { return CellKeeper({cell_file_, folder_ / "history", 5}, std::chrono::system_clock::now()); }

  json document() const { return json::parse(read_text(cell_file_)); }

  static json& entity(json& doc, const std::string& id) {
    for (json& e : doc["entities"])
      if (e["id"] == id) return e;
    throw std::runtime_error("no " + id);
  }

  static CellRequest request(CellOp op, const std::string& text = "", std::uint64_t revision = 0) {
    CellRequest r;
    r.client_id = "test";
    r.request_id = 1;
    r.op = op;
    r.cell_json = text;
    r.revision = revision;
    r.who = "ada";
    r.comment = "c";
    return r;
  }

  json moved_load() const {
    json doc = document();
    entity(doc, "load")["pose"]["position_m"][0] = entity(doc, "load")["pose"]["position_m"][0].get<double>() + 0.25;
    return doc;
  }

  fs::path folder_, cell_file_;
};

TEST_F(CellKeeperTest, TheFileIsTheFirstRevisionAndARestartComesBackOnTheLatest) {
  {
    CellKeeper k = keeper();
    EXPECT_TRUE(k.started_new());
    EXPECT_EQ(k.running().record.revision, 1U);
    EXPECT_EQ(k.running().record.cell_json, read_text(cell_file_));
    EXPECT_EQ(k.running().record.changes["added"].size(), 7U);
    const CellOutcome out =
        k.handle(request(CellOp::kApply, moved_load().dump()), {}, std::chrono::system_clock::now());
    ASSERT_TRUE(out.reply.ok) << out.reply.message;
    ASSERT_TRUE(out.revision.has_value());
    EXPECT_EQ(out.reply.cell_revision, 2U);
    const json changes = json::parse(out.reply.result_json)["changes"];
    ASSERT_EQ(changes["moved"].size(), 1U);
    EXPECT_EQ(changes["moved"][0]["id"], "load");
    EXPECT_NEAR(changes["moved"][0]["distance_m"].get<double>(), 0.25, 1e-9);
    EXPECT_TRUE(changes["changed"].empty());
  }
  CellKeeper again = keeper();
  EXPECT_FALSE(again.started_new());
  EXPECT_EQ(again.running().record.revision, 2U);
  EXPECT_EQ(again.running().record.who, "ada");
  // An edit of the file on disk is a revision on top of the history.
  json edited = document();
  entity(edited, "target")["attributes"] = {{"description", "edited"}};
  std::ofstream(cell_file_) << edited.dump(2);
  CellKeeper third = keeper();
  EXPECT_TRUE(third.started_new());
  EXPECT_EQ(third.running().record.revision, 3U);
  EXPECT_EQ(third.running().record.previous_revision, 2U);
  EXPECT_EQ(third.running().record.who, "file");
  EXPECT_EQ(third.running().record.changes["moved"][0]["id"], "load");  // back where the file has it
  EXPECT_EQ(third.running().record.changes["changed"][0]["id"], "target");
}

TEST_F(CellKeeperTest, AnInvalidRevisionIsRefusedWithTheFileAndPointerAndNothingChanges) {
  CellKeeper k = keeper();
  json doc = document();
  entity(doc, "load")["model"]["mass_kg"] = 0.0;
  CellOutcome out = k.handle(request(CellOp::kApply, doc.dump()), {}, std::chrono::system_clock::now());
  EXPECT_FALSE(out.reply.ok);
  EXPECT_EQ(out.reply.code, "INVALID");
  EXPECT_NE(out.reply.message.find(cell_file_.string() + ": /entities/5/model/mass_kg"), std::string::npos)
      << out.reply.message;
  EXPECT_FALSE(out.revision.has_value());
  EXPECT_EQ(k.running().record.revision, 1U);
  out = k.handle(request(CellOp::kApply, "{\"cell_version\": "), {}, std::chrono::system_clock::now());
  EXPECT_EQ(out.reply.code, "INVALID");
  out = k.handle(request(CellOp::kApply, std::string(cell::kMaxCellFileBytes + 1, ' ')), {},
                 std::chrono::system_clock::now());
  EXPECT_EQ(out.reply.code, "TOO_LARGE");
  out = k.handle(request(CellOp::kApply, read_text(cell_file_)), {}, std::chrono::system_clock::now());
  EXPECT_EQ(out.reply.code, "UNCHANGED");
  out = k.handle(request(CellOp::kRollback, "", 42), {}, std::chrono::system_clock::now());
  EXPECT_EQ(out.reply.code, "UNKNOWN_REVISION");
  CellRequest unknown = request(CellOp::kShow);
  unknown.op.reset();
  unknown.wire_op = 9;
  EXPECT_EQ(k.handle(unknown, {}, std::chrono::system_clock::now()).reply.code, "BAD_REQUEST");
  CellRequest not_utf8 = request(CellOp::kApply, read_text(cell_file_));
  not_utf8.who = "\xf9\xff";  // would make the history file unwritable JSON
  EXPECT_EQ(k.handle(not_utf8, {}, std::chrono::system_clock::now()).reply.code, "BAD_REQUEST");
  EXPECT_EQ(k.history().revisions().size(), 1U);
}

TEST_F(CellKeeperTest, ARevisionTouchingAHeldObjectIsRefusedUntilTheRunEnds) {
  CellKeeper k = keeper();
  const std::vector<HeldResource> held{{"load", "robot-skills", "t1", "insert", "Insert"}};
  CellOutcome out = k.handle(request(CellOp::kApply, moved_load().dump()), held, std::chrono::system_clock::now());
  EXPECT_EQ(out.reply.code, "HELD_BY_TASK");
  EXPECT_NE(out.reply.message.find("\"load\" is held by task t1 node insert"), std::string::npos) << out.reply.message;
  EXPECT_EQ(k.running().record.revision, 1U);
  // The holder's own executor may (the run that holds it proposes it); an executor of a similar name may not.
  CellRequest from_holder = request(CellOp::kApply, moved_load().dump());
  from_holder.dry_run = true;
  from_holder.client_id = "robot-skills-2-4711";
  EXPECT_EQ(k.handle(from_holder, held, std::chrono::system_clock::now()).reply.code, "HELD_BY_TASK");
  from_holder.client_id = "robot-skills-4711";
  EXPECT_TRUE(k.handle(from_holder, held, std::chrono::system_clock::now()).reply.ok);
  out = k.handle(request(CellOp::kApply, moved_load().dump()), {}, std::chrono::system_clock::now());
  EXPECT_TRUE(out.reply.ok) << out.reply.message;
}

TEST_F(CellKeeperTest, DryRunShowHistoryAndRollback) {
  CellKeeper k = keeper();
  CellRequest dry = request(CellOp::kApply, moved_load().dump());
  dry.dry_run = true;
  CellOutcome out = k.handle(dry, {}, std::chrono::system_clock::now());
  EXPECT_TRUE(out.reply.ok);
  EXPECT_FALSE(out.revision.has_value());
  EXPECT_EQ(k.running().record.revision, 1U);
  ASSERT_TRUE(k.handle(request(CellOp::kApply, moved_load().dump()), {}, std::chrono::system_clock::now()).reply.ok);
  out = k.handle(request(CellOp::kRollback, "", 1), {}, std::chrono::system_clock::now());
  ASSERT_TRUE(out.reply.ok) << out.reply.message;
  EXPECT_EQ(k.running().record.revision, 3U);
  EXPECT_EQ(k.running().record.cell_json, read_text(cell_file_));
  EXPECT_EQ(k.running().record.comment, "c");
  out = k.handle(request(CellOp::kHistory), {}, std::chrono::system_clock::now());
  const json history = json::parse(out.reply.result_json);
  ASSERT_EQ(history["revisions"].size(), 3U);
  EXPECT_EQ(history["revisions"][1]["summary"], "1 moved");
  EXPECT_EQ(history["running"], 3);
  out = k.handle(request(CellOp::kShow, "", 2), {}, std::chrono::system_clock::now());
  ASSERT_TRUE(out.reply.ok);
  EXPECT_EQ(json::parse(json::parse(out.reply.result_json)["cell_json"].get<std::string>()), moved_load());
}

TEST_F(CellKeeperTest, TheHistoryIsBounded) {
  CellKeeper k = keeper();
  for (int i = 1; i <= 6; ++i) {
    json doc = document();
    entity(doc, "load")["pose"]["position_m"][1] = 0.01 * i;
    ASSERT_TRUE(k.handle(request(CellOp::kApply, doc.dump()), {}, std::chrono::system_clock::now()).reply.ok);
  }
  EXPECT_EQ(k.history().revisions().size(), 5U);
  EXPECT_EQ(k.history().revisions().front().revision, 3U);
  EXPECT_EQ(k.running().record.revision, 7U);
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& f : fs::directory_iterator(folder_ / "history")) ++files;
  EXPECT_EQ(files, 5U);
}

TEST_F(CellKeeperTest, TheStoreFollowsARevision) {
  CellKeeper k = keeper();
  WorldStore store = WorldStore::from_config(k.running().cell, std::chrono::system_clock::now());
  json doc = moved_load();
  json part = entity(doc, "load");
  part["id"] = "part_2";
  part["features"].erase("rope_attachment");  // the crane carries one load
  doc["entities"].push_back(part);
  for (std::size_t i = 0; i < doc["entities"].size(); ++i)
    if (doc["entities"][i]["id"] == "target") doc["entities"].erase(i);
  // target is removed; load's insertion names it, so drop that too.
  entity(doc, "load")["features"].erase("insertion");
  entity(doc, "part_2")["features"].erase("insertion");
  entity(doc, "part_2")["features"].erase("markers");  // marker ids are unique across the cell
  const CellOutcome out = k.handle(request(CellOp::kApply, doc.dump()), {}, std::chrono::system_clock::now());
  ASSERT_TRUE(out.reply.ok) << out.reply.message;
  const json& changes = out.revision->record.changes;
  std::set<std::string> changed;
  for (const auto& c : changes["changed"]) changed.insert(c["id"].get<std::string>());
  const auto records = store.apply_revision(out.revision->cell, cell::moved_entities(changes), changed,
                                            std::chrono::system_clock::now(), "cell:ada");
  EXPECT_EQ(store.find("target"), nullptr);
  ASSERT_NE(store.find("part_2"), nullptr);
  ASSERT_TRUE(store.find("load")->pose.has_value());
  EXPECT_NEAR(store.find("load")->pose->pose_parent_entity.translation().x(),
              out.revision->cell.find("load")->pose_parent_entity->translation().x(), 1e-12);
  EXPECT_EQ(records.size(), 3U);  // removed, moved (and changed), added
}

}  // namespace
}  // namespace rigger::world

namespace rigger::world {
namespace {

// A part whose STEP model the world model's folder lacks: sent with the request, pinned by the document.
class CellKeeperModelsTest : public CellKeeperTest {
 protected:
  CellKeeperModelsTest() : step_(read_text(fs::path(RIGGER_SOURCE_DIR) / "deploy/cell/models/part.step")) {}

  json with_extra(const std::string& pinned_sha256) const {
    json doc = document();
    doc["entities"].push_back({{"id", "extra"},
                               {"kind", "object"},
                               {"parent", "world"},
                               {"pose", {{"position_m", {8.0, 8.0, 0.2}}, {"rpy_deg", {0, 0, 0}}}},
                               {"model",
                                {{"frame", "box centre"},
                                 {"mass_kg", 3.0},
                                 {"step", "imported/extra.step"},
                                 {"sha256", pinned_sha256}}}});
    return doc;
  }

  CellRequest apply_with(const json& doc, std::vector<world_protocol::CellModel> models, bool dry_run = false) const {
    CellRequest r = request(CellOp::kApply, doc.dump());
    r.models = std::move(models);
    r.dry_run = dry_run;
    return r;
  }

  std::string step_;
};

TEST_F(CellKeeperModelsTest, AModelSentWithTheRequestIsStoredOnlyWhenItsRevisionIsMade) {
  const std::string sha = sha256_hex(step_);
  const fs::path stored = folder_ / "history/models" / (sha + ".step");
  CellKeeper k = keeper();
  const auto now = std::chrono::system_clock::now();

  const CellOutcome unsent = k.handle(apply_with(with_extra(sha), {}), {}, now);
  EXPECT_FALSE(unsent.reply.ok);
  EXPECT_NE(unsent.reply.message.find("/entities/7/model/sha256"), std::string::npos) << unsent.reply.message;
  EXPECT_NE(unsent.reply.message.find("imported/extra.step"), std::string::npos) << unsent.reply.message;

  const CellOutcome dry = k.handle(apply_with(with_extra(sha), {{sha, "imported/extra.step", step_}}, true), {}, now);
  ASSERT_TRUE(dry.reply.ok) << dry.reply.message;
  EXPECT_FALSE(fs::exists(stored)) << "a dry run keeps nothing";

  const CellOutcome made = k.handle(apply_with(with_extra(sha), {{"", "imported/extra.step", step_}}), {}, now);
  ASSERT_TRUE(made.reply.ok) << made.reply.message;
  ASSERT_TRUE(made.revision.has_value());
  EXPECT_TRUE(fs::exists(stored));
  const std::vector<world_protocol::CellModel> pinned = k.pinned_models();
  ASSERT_EQ(pinned.size(), 1U);
  EXPECT_EQ(pinned[0].sha256, sha);
  EXPECT_EQ(pinned[0].name, "imported/extra.step");
  EXPECT_EQ(pinned[0].step, step_);
  // Published already: listed, its bytes not read again.
  const std::vector<world_protocol::CellModel> again_listed = k.pinned_models(nullptr, {sha});
  ASSERT_EQ(again_listed.size(), 1U);
  EXPECT_EQ(again_listed[0].sha256, sha);
  EXPECT_TRUE(again_listed[0].step.empty());

  // A restart runs it again from the store.
  CellKeeper again = keeper();
  EXPECT_EQ(again.running().record.revision, 2U);
  EXPECT_EQ(again.pinned_models().size(), 1U);
}

TEST_F(CellKeeperModelsTest, ModelsThatDoNotMatchTheirPinOrLeaveTheFolderAreRefusedAndNothingIsKept) {
  const std::string sha = sha256_hex(step_);
  CellKeeper k = keeper();
  const auto now = std::chrono::system_clock::now();
  const auto refused = [&](const CellRequest& r, const std::string& says) {
    const CellOutcome out = k.handle(r, {}, now);
    EXPECT_FALSE(out.reply.ok);
    EXPECT_EQ(out.reply.code, world_protocol::cell_code::kInvalid);
    EXPECT_NE(out.reply.message.find(says), std::string::npos) << out.reply.message;
    EXPECT_EQ(k.running().record.revision, 1U);
  };
  // Other bytes than the document pins.
  refused(apply_with(with_extra(sha), {{"", "imported/extra.step", step_ + " "}}), "found sha256 " + sha);
  // Bytes that are not what the request says they are.
  refused(apply_with(with_extra(sha), {{sha256_hex("other"), "imported/extra.step", step_}}),
          "its sha256 says " + sha256_hex("other"));
  // A model no object pins.
  refused(apply_with(with_extra(sha), {{"", "imported/other.step", step_}}), "found none");
  // A name outside the cell folder.
  refused(apply_with(with_extra(sha), {{"", "../extra.step", step_}}), "inside the cell folder");
  EXPECT_FALSE(fs::exists(folder_ / "history/models" / (sha + ".step")));
}

}  // namespace
}  // namespace rigger::world
